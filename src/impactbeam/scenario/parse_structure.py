"""The structure tables of a scenario: ``[beam]``, ``[supports]``, ``[[beam.sections]]``,
``[[masses]]``, ``[[springs]]`` and ``[[contactors]]`` into model objects (paper section 2).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

from ..model.beam import (
    SUPPORT_PRESETS,
    Beam,
    Contactor,
    InteriorSpring,
    PointMass,
    Section,
    Support,
)
from ..exceptions import ScenarioError
from ..units import to_si
from .fields import _choice, _nonnegative, _position, _positive, _relabel, _required
from .schema import SUPPORT_DEFAULTS, _SIDES, _join

__all__ = []


def _parse_support(value: Any, key: str) -> Support:
    if isinstance(value, str):
        if value not in SUPPORT_PRESETS:
            raise ScenarioError(
                f"{key}: must be one of {', '.join(repr(p) for p in SUPPORT_PRESETS)} "
                f"or a table {{translational, rotational}}, got {value!r}",
                key=key,
            )
        return Support.preset(value)
    springs = {}
    for name, dimension in (("translational", "stiffness"), ("rotational", "rotational_stiffness")):
        sub = _join(key, name)
        k = to_si(value.get(name, 0.0), dimension, sub)
        if k < 0.0:
            raise ScenarioError(f"{sub}: must be >= 0 (0 = free, inf = rigid), got {k!r}", key=sub)
        springs[name] = k
    with _relabel(key, (("translational", f"{key}.translational"), ("rotational", f"{key}.rotational"))):
        return Support(springs["translational"], springs["rotational"])


def _parse_beam(raw: Mapping[str, Any]) -> Beam:
    """The ``[beam]`` table with its supports, ``[[beam.sections]]``, ``[[masses]]`` and ``[[springs]]``."""
    beam = _parse_uniform_beam(raw)
    theory = _parse_theory(raw["beam"], beam.youngs_modulus)
    sections = _parse_sections(raw["beam"], beam)
    masses, springs = _parse_attachments(raw, beam.length)
    with _relabel("beam", (("beam.sections", "beam.sections"),)):
        return dataclasses.replace(beam, sections=sections, masses=masses, springs=springs, **theory)


def _parse_sections(b: Mapping[str, Any], beam: Beam) -> tuple[Section, ...]:
    """``[[beam.sections]]``: each overrides the ``[beam]`` section values on its length."""
    out = []
    for i, sec in enumerate(b.get("sections", [])):
        prefix = f"beam.sections.{i}"
        _required(sec, prefix, "length")
        length = _positive(sec, prefix, "length", "length")
        modulus = _positive(sec, prefix, "youngs_modulus", "modulus") if "youngs_modulus" in sec else beam.youngs_modulus
        density = _positive(sec, prefix, "density", "density") if "density" in sec else beam.density
        rect = [n for n in ("width", "height") if n in sec]
        given = [n for n in ("area", "second_moment") if n in sec]
        if rect and given:
            raise ScenarioError(
                f"{prefix}.{given[0]}: give either width/height or area/second_moment, not both", key=f"{prefix}.{given[0]}"
            )
        width, height = beam.width, beam.height
        area, second = beam.area, beam.second_moment
        if rect:
            if width is None and len(rect) < 2:
                other = "width" if "width" not in sec else "height"
                _required(sec, prefix, other, " ([beam] gives no rectangle to take it from)")
            width = _positive(sec, prefix, "width", "length") if "width" in sec else width
            height = _positive(sec, prefix, "height", "length") if "height" in sec else height
            area, second = width * height, width * height**3 / 12.0
        elif given:
            area = _positive(sec, prefix, "area", "area") if "area" in sec else area
            second = _positive(sec, prefix, "second_moment", "second_moment") if "second_moment" in sec else second
            width = height = None
        out.append(Section(length, modulus, density, area, second, width, height))
    if out:
        total = math.fsum(sec.length for sec in out)
        if abs(total - beam.length) > 1e-9 * beam.length:
            raise ScenarioError(
                f"beam.sections: the section lengths sum to {total:.10g} m, not beam.length = {beam.length:.10g} m",
                key="beam.sections",
            )
    return tuple(out)


def _parse_attachments(
    raw: Mapping[str, Any], length: float
) -> tuple[tuple[PointMass, ...], tuple[InteriorSpring, ...]]:
    """``[[masses]]`` (point masses) and ``[[springs]]`` (permanent supports)."""
    masses = []
    for i, m in enumerate(raw.get("masses", [])):
        prefix = f"masses.{i}"
        position = _position(m, prefix, length, required=True)
        _required(m, prefix, "mass")
        mass = _nonnegative(f"{prefix}.mass", m["mass"], "mass")
        inertia = _nonnegative(f"{prefix}.rotary_inertia", m.get("rotary_inertia", 0.0), "rotary_inertia")
        masses.append(PointMass(position, mass, inertia))
    springs = []
    for i, sp in enumerate(raw.get("springs", [])):
        prefix = f"springs.{i}"
        position = _position(sp, prefix, length, required=True)
        if "translational" not in sp and "rotational" not in sp:
            raise ScenarioError(f"{prefix}.translational: required (or rotational)", key=f"{prefix}.translational")
        vals = {}
        for name, dimension in (("translational", "stiffness"), ("rotational", "rotational_stiffness")):
            key = f"{prefix}.{name}"
            vals[name] = to_si(sp.get(name, 0.0), dimension, key)
            if not vals[name] >= 0.0:
                raise ScenarioError(f"{key}: must be >= 0 (0 = none, inf = rigid), got {vals[name]!r}", key=key)
        springs.append(InteriorSpring(position, vals["translational"], vals["rotational"]))
    return tuple(masses), tuple(springs)


def _parse_theory(b: Mapping[str, Any], modulus: float) -> dict[str, Any]:
    """``beam.theory`` and the Timoshenko keys (refused by name on an Euler-Bernoulli beam, never ignored)."""
    theory = _choice("beam.theory", b.get("theory", "euler-bernoulli"), ("euler-bernoulli", "timoshenko"))
    if theory == "euler-bernoulli":
        for name in ("poisson_ratio", "shear_modulus", "shear_coefficient"):
            if name in b:
                raise ScenarioError(f'beam.{name}: only used by a Timoshenko beam (beam.theory = "timoshenko"); '
                                    "remove it", key=f"beam.{name}")
        return {}
    if "poisson_ratio" in b and "shear_modulus" in b:
        raise ScenarioError("beam.shear_modulus: give poisson_ratio or shear_modulus, not both", key="beam.shear_modulus")
    if "shear_modulus" in b:
        shear = _positive(b, "beam", "shear_modulus", "modulus")
        nu = modulus / (2.0 * shear) - 1.0
        if not -1.0 < nu < 0.5:
            raise ScenarioError(f"beam.shear_modulus: G = {shear:g} Pa gives a Poisson ratio E / 2G - 1 = {nu:.4g}, "
                                "outside (-1, 0.5)", key="beam.shear_modulus")
    elif "poisson_ratio" in b:
        nu = to_si(b["poisson_ratio"], "dimensionless", "beam.poisson_ratio")
        if not -1.0 < nu < 0.5:
            raise ScenarioError(f"beam.poisson_ratio: must lie in (-1, 0.5), got {nu!r}", key="beam.poisson_ratio")
    else:
        raise ScenarioError('beam.poisson_ratio: required for beam.theory = "timoshenko" (or beam.shear_modulus)',
                            key="beam.poisson_ratio")
    out: dict[str, Any] = {"theory": theory, "poisson_ratio": nu}
    if "shear_coefficient" in b:
        out["shear_coefficient"] = _positive(b, "beam", "shear_coefficient", "dimensionless")
    return out


def _parse_uniform_beam(raw: Mapping[str, Any]) -> Beam:
    if "beam" not in raw:
        raise ScenarioError("beam: the [beam] table is required", key="beam")
    b = raw["beam"]
    for name in ("length", "youngs_modulus", "density"):
        _required(b, "beam", name)
    length = _positive(b, "beam", "length", "length")
    modulus = _positive(b, "beam", "youngs_modulus", "modulus")
    density = _positive(b, "beam", "density", "density")

    sup = raw.get("supports", {})
    left = _parse_support(sup.get("left", SUPPORT_DEFAULTS["left"]), "supports.left")
    right = _parse_support(sup.get("right", SUPPORT_DEFAULTS["right"]), "supports.right")

    rect = [n for n in ("width", "height") if n in b]
    section = [n for n in ("area", "second_moment") if n in b]
    if rect and section:
        raise ScenarioError(
            f"beam.{section[0]}: give either width and height or area and second_moment, not both",
            key=f"beam.{section[0]}",
        )
    with _relabel("beam"):
        if rect:
            other = "width" if "width" not in b else "height"
            _required(b, "beam", other, f" with beam.{rect[0]} (a rectangular section needs width and height)")
            width = _positive(b, "beam", "width", "length")
            height = _positive(b, "beam", "height", "length")
            return Beam.rectangular(length, width, height, modulus, density, left, right)
        if section:
            other = "area" if "area" not in b else "second_moment"
            _required(b, "beam", other, f" with beam.{section[0]} (give both area and second_moment)")
            area = _positive(b, "beam", "area", "area")
            second = _positive(b, "beam", "second_moment", "second_moment")
            return Beam(length, modulus, density, area, second, left, right)
    raise ScenarioError(
        "beam: give the cross-section as width and height, or as area and second_moment", key="beam"
    )


def _contact_stiffness(table: Mapping[str, Any], prefix: str) -> float:
    """A contactor's stiffness: positive, finite or ``"inf"`` (a rigid stop)."""
    key = _join(prefix, "stiffness")
    k = to_si(table["stiffness"], "stiffness", key)
    if not k > 0.0:
        raise ScenarioError(f'{key}: must be positive ("inf" = rigid), got {k!r}', key=key)
    return k


def _parse_contactors(raw: Mapping[str, Any], beam: Beam) -> tuple[Contactor, ...]:
    out = []
    for i, c in enumerate(raw.get("contactors", [])):
        prefix = f"contactors.{i}"
        position = _position(c, prefix, beam.length, required=True)
        _required(c, prefix, "stiffness")
        stiffness = _contact_stiffness(c, prefix)
        gap = _nonnegative(f"{prefix}.gap", c.get("gap", 0.0), "length")
        side = _choice(f"{prefix}.side", c.get("side", "below"), _SIDES)
        damping = _nonnegative(f"{prefix}.damping", c.get("damping", 0.0), "damping_coefficient")
        restitution = None
        if "restitution" in c:
            restitution = to_si(c["restitution"], "dimensionless", f"{prefix}.restitution")
        with _relabel(prefix, (("contactor.", f"{prefix}."),)):
            contactor = Contactor(position, stiffness, gap, side, damping, restitution)  # type: ignore[arg-type]
            contactor.check_on(beam, prefix)
            out.append(contactor)
    return tuple(out)
