"""Scenario checks beyond single values: extreme magnitudes and inputs that need a word.

The checks run by :func:`impactbeam.scenario.parse_scenario`:

* :func:`check_magnitudes` (before the data classes are built) refuses values
  whose derived quantities would overflow or underflow in the modal analysis,
  naming the key the user wrote (``beam.height``, not the derived
  ``beam.second_moment``);
* :func:`check_response` and :func:`check_run` (on the model objects) refuse
  a load or an initial state that would drive the beam beyond what double
  precision represents (:mod:`impactbeam.model.magnitudes`) and a run whose
  work is out of proportion, each with its estimate;
* :func:`warn_numeric_strings` emits an
  :class:`~impactbeam.exceptions.ImpactBeamWarning` for a number written as
  a string without a unit (``"109.2"``), taken as SI (the unit from
  :func:`~impactbeam.scenario.schema.path_dimension`).

The checks of the validated scenario (``warn_unusual``) are in :mod:`.core`.

The limits and why
------------------
The mode solver forms ``beta^4 = rho A omega^2 / (E I)`` and the solver
squares frequencies (``omega^2``) and products of the beam's section
properties, so the derived quantities ``A``, ``I``, ``E I``, ``rho A`` and the
beam's frequency scale ``omega_0 = sqrt(E I / (rho A)) / L^2`` [rad/s] must
stay within 10^+-150, whose squares (10^+-300) are still normal doubles
(max ~1.8e308, min normal ~2.2e-308). The frequency scale itself is
kept within 10^+-50 (:data:`FREQUENCY_SCALE_LIMIT`). A contactor's stiffness relative to the
beam, ``kappa = k L^3 / (E I)``, is limited to 10^+-15: above 1e15 the
spring is rigid to within double round-off (1/kappa < 10 eps), below 1e-15
it changes nothing at that precision; either way the contact state's modes
cannot be computed meaningfully (use ``stiffness = "inf"`` for a rigid prop,
or remove the contactor).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

from .._warnings import emit_user_level_warning
from .._memory import check_work
from ..exceptions import ScenarioError
from ..model.magnitudes import RESPONSE_FLOOR, RESPONSE_LIMIT, frequency_scale, response_estimates, scan_work
from ..units import DIMENSIONS, to_si
from .schema import path_dimension

__all__ = ["DERIVED_LIMIT", "FREQUENCY_SCALE_LIMIT", "STIFFNESS_RATIO_LIMIT", "check_magnitudes", "check_response", "check_run",
           "warn_numeric_strings"]

#: Derived quantities (A, I, E I, rho A) must lie in [1/limit, limit] (SI).
DERIVED_LIMIT = 1e150
#: The frequency scale omega_0 [rad/s] must lie in [1/limit, limit]: the closed form squares a
#: frequency twice (omega^4 in its resonance denominator), so the highest retained frequency (up to
#: ~1e7 omega_0: 200 modes, the stiffest contactor) must stay below ~1e76, and a load pulse of any
#: length is integrated at most at 1e70 rad/s (model.loading) far above it.
FREQUENCY_SCALE_LIMIT = 1e50
#: k L^3 / (E I) of a contactor must lie in [1/limit, limit] (or k = inf).
STIFFNESS_RATIO_LIMIT = 1e15

def _value(raw: Mapping[str, Any], key: str) -> Any:
    """The raw value at dotted ``key`` (list indices allowed), or None."""
    node: Any = raw
    for part in key.split("."):
        if isinstance(node, Mapping) and part in node:
            node = node[part]
        elif isinstance(node, list) and part.isdigit() and int(part) < len(node):
            node = node[int(part)]
        else:
            return None
    return node


def _log10(raw: Mapping[str, Any], key: str, dimension: str) -> float | None:
    """log10 of the SI value at dotted ``key`` of ``raw``; None if absent, unreadable or not positive finite."""
    node = _value(raw, key)
    if node is None:
        return None
    try:
        x = to_si(node, dimension, key)
    except ScenarioError:
        return None  # the ordinary parse reports it
    if not (isinstance(x, float) and math.isfinite(x) and x > 0.0):
        return None
    return math.log10(x)


def _section_keys(raw: Mapping[str, Any], prefix: str) -> dict[str, str] | None:
    """The keys giving E, rho and the cross-section of ``prefix`` (``beam`` or ``beam.sections.i``).

    A section inherits from ``[beam]`` what it does not give; None for a
    section that gives nothing of its own (it is the ``[beam]`` section).
    """
    table = _value(raw, prefix)
    beam = raw["beam"]
    if not isinstance(table, Mapping):
        return None
    own = lambda name: f"{prefix}.{name}" if name in table else f"beam.{name}"  # noqa: E731
    rect = any(n in table for n in ("width", "height")) or (
        not any(n in table for n in ("area", "second_moment")) and ("width" in beam or "height" in beam))
    names = ("youngs_modulus", "density", *(("width", "height") if rect else ("area", "second_moment")))
    keys = {n: own(n) for n in names}
    if prefix != "beam" and all(k.startswith("beam.") and k.count(".") == 1 for k in keys.values()):
        return None
    return keys


def _check_section(raw: Mapping[str, Any], keys: dict[str, str], L: float) -> None:
    """The derived-quantity checks of one cross-section (see the module notes)."""
    E, rho = _log10(raw, keys["youngs_modulus"], "modulus"), _log10(raw, keys["density"], "density")
    if "width" in keys:
        w, h = _log10(raw, keys["width"], "length"), _log10(raw, keys["height"], "length")
        if w is None or h is None:
            return
        section = {keys["width"]: w, keys["height"]: h}
        log_a, log_i = w + h, w + 3 * h - math.log10(12.0)
        a_terms = i_terms = section
    else:
        a, i = _log10(raw, keys["area"], "area"), _log10(raw, keys["second_moment"], "second_moment")
        if a is None or i is None:
            return
        section = {keys["area"]: a, keys["second_moment"]: i}
        log_a, log_i = a, i
        a_terms, i_terms = {keys["area"]: a}, {keys["second_moment"]: i}
    if E is None or rho is None:
        return
    lim, f_lim = math.log10(DERIVED_LIMIT), math.log10(FREQUENCY_SCALE_LIMIT)
    checks = (
        ("an area A", log_a, a_terms, lim),
        ("a second moment I", log_i, i_terms, lim),
        ("a bending stiffness E I", E + log_i, {keys["youngs_modulus"]: E, **i_terms}, lim),
        ("a mass per length rho A", rho + log_a, {keys["density"]: rho, **section}, lim),
        ("a frequency scale sqrt(E I / rho A) / L^2 [rad/s]", 0.5 * (E + log_i - rho - log_a) - 2 * L,
         {"beam.length": -2 * L, keys["youngs_modulus"]: 0.5 * E, keys["density"]: -0.5 * rho,
          **{k: 0.5 * v for k, v in section.items()}}, f_lim),
    )
    for what, value, terms, limit in checks:
        if abs(value) > limit:
            # terms are signed contributions: pick the biggest in the direction of the excess
            _refuse_contribution(what, value, terms, raw, "check the value and its unit", limit)


def check_magnitudes(raw: Mapping[str, Any]) -> None:
    """Refuse values whose derived quantities overflow or underflow (see the module notes).

    The ``[beam]`` section and every ``[[beam.sections]]`` (with what it
    inherits from ``[beam]``) are checked alike.

    Raises
    ------
    ScenarioError
        Naming the key the user wrote, the derived quantity and its magnitude.
    """
    beam = raw.get("beam")
    if not isinstance(beam, Mapping):
        return
    L = _log10(raw, "beam.length", "length")
    keys = _section_keys(raw, "beam")
    if L is None or keys is None:
        return
    _check_section(raw, keys, L)
    sections = beam.get("sections")
    for i in range(len(sections) if isinstance(sections, list) else 0):
        sec_keys = _section_keys(raw, f"beam.sections.{i}")
        if sec_keys is not None:
            _check_section(raw, sec_keys, L)
    E = _log10(raw, keys["youngs_modulus"], "modulus")
    if "width" in keys:
        w, h = _log10(raw, keys["width"], "length"), _log10(raw, keys["height"], "length")
        log_i = None if w is None or h is None else w + 3 * h - math.log10(12.0)
    else:
        log_i = _log10(raw, keys["second_moment"], "second_moment")
    if E is None or log_i is None:
        return
    log_ei = E + log_i
    for i, c in enumerate(raw.get("contactors") or []):
        key = f"contactors.{i}.stiffness"
        if not isinstance(c, Mapping) or "stiffness" not in c:
            continue
        try:
            k = to_si(c["stiffness"], "stiffness", key)
        except ScenarioError:
            continue
        if not (math.isfinite(k) and k > 0):
            continue
        kappa = math.log10(k) + 3 * L - log_ei
        if abs(kappa) > math.log10(STIFFNESS_RATIO_LIMIT):
            hint = ('use stiffness = "inf" for a rigid prop' if kappa > 0
                    else "the contactor has no effect at double precision: remove it")
            raise ScenarioError(
                f"{key}: {k:g} N/m is ~1e{kappa:.0f} times the beam's bending stiffness E I / L^3 "
                f"(allowed: 1e-{math.log10(STIFFNESS_RATIO_LIMIT):.0f} to 1e{math.log10(STIFFNESS_RATIO_LIMIT):.0f}); {hint}",
                key=key,
            )


def check_response(beam: Any, excitation: Any, initial: Any, end_time: float) -> None:
    """Refuse a load or initial state that would drive the beam beyond :data:`~impactbeam.model.magnitudes.RESPONSE_LIMIT`.

    Parameters
    ----------
    beam : Beam
    excitation : Excitation
    initial : InitialCondition
    end_time : float, [s]

    Raises
    ------
    ScenarioError
        Naming the key, the estimate and why.
    """
    for key, metres in response_estimates(beam, excitation, initial, end_time):
        if 0.0 < metres < RESPONSE_FLOOR and key.startswith("excitation"):
            raise ScenarioError(
                f"{key}: would move the beam by ~{metres:.1e} m at most (estimated from the value, the beam's "
                f"frequency scale {frequency_scale(beam):.3g} rad/s and solver.end_time), below the "
                f"{RESPONSE_FLOOR:.0e} m under which the closed form underflows to zero; check the value and its "
                "unit (the load has no effect at double precision)",
                key=key,
            )
        if not metres <= RESPONSE_LIMIT:
            raise ScenarioError(
                f"{key}: would drive the beam to a deflection of ~{metres:.1e} m (estimated from the value, the "
                f"beam's frequency scale {frequency_scale(beam):.3g} rad/s and solver.end_time), beyond the "
                f"{RESPONSE_LIMIT:.0e} m the solver can square in double precision (energies k w^2, bounds "
                "omega^2 w); check the value and its unit",
                key=key,
            )


def check_run(beam: Any, modes: int | str, end_time: float) -> None:
    """Refuse a run whose exact extrema would scan too many mode-periods (:func:`impactbeam._memory.check_work`).

    Parameters
    ----------
    beam : Beam
    modes : int or "auto"
        ``solver.modes`` ("auto" is counted as 32 modes, a count it typically reaches).
    end_time : float, [s]
    """
    n = 32 if modes == "auto" else int(modes)
    check_work(scan_work(beam, n, end_time),
               f"solver.end_time: {end_time:g} s with {n} modes per state",
               "shorten solver.end_time (a damped response that has decayed needs no simulating), or use "
               "fewer modes")


def _refuse_contribution(what: str, value: float, terms: dict[str, float], raw: Mapping[str, Any], remedy: str,
                         lim: float) -> None:
    sign = 1.0 if value > 0 else -1.0
    key = max(terms, key=lambda k: sign * terms[k])
    node = _value(raw, key)
    raise ScenarioError(
        f"{key}: {node!r} gives {what} of ~1e{value:.0f}, outside what the modal analysis can "
        f"represent (1e-{lim:.0f} to 1e{lim:.0f} in SI); {remedy}",
        key=key,
    )


def _walk(node: Any, prefix: str = "") -> Iterable[tuple[str, Any]]:
    if isinstance(node, Mapping):
        for k, v in node.items():
            yield from _walk(v, f"{prefix}.{k}" if prefix else str(k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _walk(v, f"{prefix}.{i}")
    else:
        yield prefix, node


def _is_plain_number(text: str) -> bool:
    try:
        x = float(text)
    except ValueError:
        return False
    return math.isfinite(x)


def _si_unit(key: str, raw: Mapping[str, Any]) -> str | None:
    """The SI unit a unit-less number at ``key`` is read in; None for pure numbers and words."""
    excitation = raw.get("excitation")
    kind = excitation.get("kind") if isinstance(excitation, Mapping) else None
    preload = raw.get("preload")
    preload_kind = preload.get("kind") if isinstance(preload, Mapping) else None
    try:
        dimension = path_dimension(key, kind if isinstance(kind, str) else None,
                                   preload_kind if isinstance(preload_kind, str) else None)
    except ScenarioError:
        return None
    if dimension is None and key == "excitation.amplitude":
        return "SI (m/s^2, N or N/m by excitation.kind)"
    if dimension in (None, "integer", "dimensionless"):
        return None
    return DIMENSIONS[dimension].si_unit


def warn_numeric_strings(raw: Mapping[str, Any]) -> None:
    """Warn for each physical quantity written as a string with no unit (``"109.2"``).

    Decision (issue: a numeric string was silently taken as SI): such a value
    is still accepted as SI, as a plain number is, because a quoted number is
    legal TOML and sweeps and command-line overrides produce them; but it is
    most often a unit left out by mistake (``"109.2"`` meant as mm), so it is
    reported with the key and the SI unit assumed.
    """
    for key, value in _walk(raw):
        if not isinstance(value, str) or not _is_plain_number(value.strip()):
            continue
        unit = _si_unit(key, raw)
        if unit is None:
            continue
        emit_user_level_warning(
            f'{key}: "{value}" is a number written as a string without a unit; it is taken as SI ({unit}). '
            f"Write it as a number ({value.strip()}) or with its unit (e.g. \"{value.strip()} {unit}\")"
        )
