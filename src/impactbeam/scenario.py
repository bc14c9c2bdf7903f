"""Scenario files: TOML <-> validated objects (see the scenario reference).

A scenario describes one simulation: the beam and its supports, the
contactors, damping, the excitation, the initial state, solver options and
the output points. :func:`load_scenario` reads a TOML file,
:func:`parse_scenario` a mapping; both return a validated, immutable
:class:`Scenario`. Numbers are SI; strings with units are accepted
(``"0.229 mm"``, ``"15 g"``, ``"15 ms"``, ``"1834 MPa"``; see :mod:`impactbeam.units`).

Every problem is reported as a :class:`~impactbeam.exceptions.ScenarioError`
whose message starts with the dotted key of the offending field and whose
``key`` attribute holds that key, for example::

    contactors.0.position: 0.2 m is off the beam (length 0.1092 m)
    unknown key "beam.lenght" (did you mean "beam.length"?)

Parameter studies vary a scenario through dotted paths
(:func:`set_path`, :meth:`Scenario.with_values`), so a sweep of
``contactors.0.gap`` re-validates every case exactly as a file would be.
The file format is described in ``examples/README.md``.
"""

from __future__ import annotations

import copy
import dataclasses
import difflib
import math
import os
import re
import tomllib
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ._atomic import write_text
from ._checks import check_magnitudes, warn_numeric_strings, warn_unusual
from ._textdata import numeric_columns, read_delimited
from ._validation import choice, nonnegative_finite, positive_finite
from .beam import (
    SUPPORT_PRESETS,
    Beam,
    Contactor,
    InteriorSpring,
    PointMass,
    Section,
    Support,
)
from .exceptions import ParameterError, ScenarioError
from .loading import Excitation, InitialCondition
from .solver.options import BASES, Damping, SolverOptions
from .units import DIMENSIONS, describe_dimension, scale_decimal, to_si, unit_scale

__all__ = [
    "Scenario",
    "load_scenario",
    "parse_scenario",
    "set_path",
    "scenario_paths",
    "dump_scenario",
    "read_table",
    "EXCITATION_DIMENSIONS",
    "SUPPORT_DEFAULTS",
]

#: Physical dimension of ``excitation.amplitude`` (and of a table's values) per kind.
EXCITATION_DIMENSIONS: dict[str, str] = {
    "base_acceleration": "acceleration",
    "point_force": "force",
    "distributed_force": "force_per_length",
}

_KINDS = ("base_acceleration", "point_force", "distributed_force", "none")
_SHAPES = ("half_sine", "step", "table")
_HOLDS = ("constant", "linear")
_SIDES = ("below", "above")


# --------------------------------------------------------------------------- schema


@dataclass(frozen=True)
class _Leaf:
    """A value. ``list_ok``: a list of values is allowed too; ``list_only``: must be a list."""

    list_ok: bool = False
    list_only: bool = False


@dataclass(frozen=True)
class _Table:
    """A TOML table. ``preset_ok``: a string (preset name) may stand in for the table."""

    fields: Mapping[str, Any]
    preset_ok: bool = False


@dataclass(frozen=True)
class _Array:
    """An array of tables (``[[contactors]]``)."""

    item: _Table


def _leaves(*names: str, **kw: bool) -> dict[str, _Leaf]:
    return {n: _Leaf(**kw) for n in names}


_SUPPORT_NODE = _Table(_leaves("translational", "rotational"), preset_ok=True)

_SCHEMA = _Table(
    {
        "name": _Leaf(),
        "description": _Leaf(),
        "beam": _Table(
            {
                **_leaves("length", "width", "height", "area", "second_moment", "youngs_modulus", "density"),
                "sections": _Array(
                    _Table(
                        _leaves("length", "width", "height", "area", "second_moment", "youngs_modulus", "density")
                    )
                ),
            }
        ),
        "supports": _Table({"left": _SUPPORT_NODE, "right": _SUPPORT_NODE}),
        "contactors": _Array(_Table(_leaves("position", "position_ratio", "stiffness", "gap", "side"))),
        "masses": _Array(_Table(_leaves("position", "position_ratio", "mass", "rotary_inertia"))),
        "springs": _Array(_Table(_leaves("position", "position_ratio", "translational", "rotational"))),
        "damping": _Table(_leaves("free", "contact", list_ok=True)),
        "excitation": _Table(
            _leaves(
                "kind", "shape", "amplitude", "duration", "start", "position", "position_ratio",
                "scale", "file", "hold",
            )
        ),
        "initial": _Table(
            {
                **_leaves("tip_displacement", "position"),
                **_leaves("modal_displacement", "modal_velocity", list_ok=True, list_only=True),
            }
        ),
        "solver": _Table(
            _leaves(
                "modes", "time_step", "end_time", "max_events", "event_tolerance", "projection", "tolerance", "basis"
            )
        ),
        "output": _Table(_leaves("points", "point_ratios", list_ok=True, list_only=True)),
    }
)

#: Supports used when [supports] or one of its sides is absent (a cantilever).
SUPPORT_DEFAULTS = {"left": "clamped", "right": "free"}

# Alternatives within one table: setting one through set_path removes the other.
_ALTERNATIVES = {"position": "position_ratio", "position_ratio": "position",
                 "points": "point_ratios", "point_ratios": "points"}


def _join(prefix: str, key: str | int) -> str:
    return f"{prefix}.{key}" if prefix else str(key)


def _suggest(path: str, siblings: list[str], everything: list[str]) -> str:
    """`` (did you mean "x"?)`` or a list of the valid keys at that level."""
    match = difflib.get_close_matches(path, siblings, n=1, cutoff=0.6)
    if not match:
        match = difflib.get_close_matches(path, everything, n=1, cutoff=0.75)
    if match:
        return f' (did you mean "{match[0]}"?)'
    if siblings:
        names = ", ".join(s.rsplit(".", 1)[-1] for s in siblings)
        return f" (valid keys here: {names})"
    return ""


def _unknown(path: str, value: Any, siblings: list[str], data: Any) -> ScenarioError:
    is_table = isinstance(value, dict) or (
        isinstance(value, list) and bool(value) and all(isinstance(v, dict) for v in value)
    )
    what = "table" if is_table else "key"
    return ScenarioError(
        f'unknown {what} "{path}"{_suggest(path, siblings, scenario_paths(data))}', key=path
    )


def _describe(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "a list"
    return repr(value)


def _check_structure(value: Any, node: Any, path: str, root: Any) -> None:
    """Reject unknown keys and values of the wrong structure (table/list/value)."""
    if isinstance(node, _Table):
        if node.preset_ok and isinstance(value, str):
            return
        if not isinstance(value, dict):
            expected = "a preset name or a table" if node.preset_ok else "a table"
            raise ScenarioError(f"{path}: expected {expected}, got {_describe(value)}", key=path)
        siblings = [_join(path, k) for k in node.fields]
        for key, sub in value.items():
            sub_path = _join(path, key)
            if key not in node.fields:
                raise _unknown(sub_path, sub, siblings, root)
            _check_structure(sub, node.fields[key], sub_path, root)
    elif isinstance(node, _Array):
        if not isinstance(value, list):
            raise ScenarioError(
                f"{path}: expected an array of tables ([[{path}]]), got {_describe(value)}", key=path
            )
        for i, item in enumerate(value):
            _check_structure(item, node.item, _join(path, i), root)
    else:
        if isinstance(value, dict):
            raise ScenarioError(f"{path}: expected a value, got a table", key=path)
        if isinstance(value, list):
            if not node.list_ok:
                raise ScenarioError(f"{path}: expected a single value, got a list", key=path)
            for i, item in enumerate(value):
                if isinstance(item, (dict, list)):
                    raise ScenarioError(
                        f"{_join(path, i)}: expected a value, got {_describe(item)}", key=_join(path, i)
                    )
        elif node.list_only:
            raise ScenarioError(f"{path}: expected a list, got {_describe(value)}", key=path)


def scenario_paths(data: Mapping[str, Any] | None = None) -> list[str]:
    """Every settable dotted path of a scenario mapping.

    The paths of the schema (present or not: ``damping.contact`` is listed even
    when absent), with list indices for the contactors and list-valued fields
    present in ``data`` (``contactors.0.gap``, ``output.points.1``). Used for
    "did you mean" suggestions and by sweeps to check their parameters.
    """
    out: list[str] = []

    def walk(node: Any, value: Any, prefix: str) -> None:
        for key, child in node.fields.items():
            path = _join(prefix, key)
            out.append(path)
            sub = value.get(key) if isinstance(value, Mapping) else None
            if isinstance(child, _Table):
                walk(child, sub, path)
            elif isinstance(child, _Array):
                if isinstance(sub, list):
                    for i, item in enumerate(sub):
                        out.append(_join(path, i))
                        walk(child.item, item, _join(path, i))
            elif child.list_ok and isinstance(sub, list):
                out.extend(_join(path, i) for i in range(len(sub)))

    walk(_SCHEMA, data, "")
    return out


# --------------------------------------------------------------------------- raw mappings


def _normalise(value: Any, path: str = "") -> Any:
    """Deep copy into plain TOML-able types: dict, list, str, int, float, bool.

    Tuples and arrays become lists, numpy scalars Python scalars, paths
    strings; keys whose value is None are dropped (None means "not given").
    """
    if type(value) in (str, float, int, bool):  # immutable plain leaves: nothing to copy (numpy scalars below)
        return value
    if isinstance(value, Mapping):
        out = {}
        for key, sub in value.items():
            if not isinstance(key, str):
                raise ScenarioError(f"{_join(path, str(key))}: keys must be strings, got {key!r}")
            if sub is None:
                continue
            out[key] = _normalise(sub, _join(path, key))
        return out
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, (list, tuple)):
        return [_normalise(v, _join(path, i)) for i, v in enumerate(value)]
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    return copy.deepcopy(value)


def _index(part: str, items: list[Any], path: str, what: str) -> int:
    """The list index ``part`` of ``items`` (named ``what``); errors carry the full ``path``."""
    if not re.fullmatch(r"\d+", part):
        raise ScenarioError(f'{path}: "{part}" is not an index of {what} (use 0, 1, ...)', key=path)
    i = int(part)
    if i >= len(items):
        raise ScenarioError(
            f"{path}: index {i} is out of range ({what} has {len(items)} element"
            f"{'' if len(items) == 1 else 's'})",
            key=path,
        )
    return i


def set_path(data: Mapping[str, Any], path: str, value: Any) -> dict[str, Any]:
    """Return a deep copy of the scenario mapping ``data`` with ``path`` set to ``value``.

    Parameters
    ----------
    data : mapping
        A raw scenario mapping (as read from TOML, or ``Scenario.data``).
    path : str
        Dotted path in the schema: ``"beam.length"``, ``"contactors.0.gap"``
        (list index), ``"supports.left.rotational"``, ``"damping.free.2"``.
        A key of the schema that is absent from ``data`` (``"damping.contact"``)
        may be set; its tables are created.
    value : Any
        The new value: a number (SI), a string with units, a list, a table.
        ``None`` removes the key (the field returns to its default). Numpy
        scalars and arrays are converted to plain Python values.

    Returns
    -------
    dict
        The new mapping; ``data`` is not modified. The result is not validated:
        pass it to :func:`parse_scenario`.

    Notes
    -----
    ``position`` / ``position_ratio`` and ``points`` / ``point_ratios`` are
    alternatives: setting one removes the other from the same table. Setting
    a field inside a support given as a preset (``supports.left.rotational``
    when ``left = "clamped"``) first expands the preset into its
    ``{translational, rotational}`` table.

    Raises
    ------
    ScenarioError
        For a path that is not in the schema (``key`` = ``path``, with a
        "did you mean" suggestion) or a list index out of range.
    """
    new = _normalise(data)
    if not isinstance(new, dict):
        raise ScenarioError(f"expected a mapping, got {type(data).__name__}")
    value = _normalise(value, path)
    parts = path.split(".") if isinstance(path, str) else []
    if not parts or any(not p for p in parts):
        raise ScenarioError(f'invalid path "{path}": expected dotted keys such as "beam.length"', key=str(path))

    node: Any = _SCHEMA
    container: Any = new
    prefix = ""
    for depth, part in enumerate(parts):
        last = depth == len(parts) - 1
        here = _join(prefix, part)
        if isinstance(node, _Table):
            if part not in node.fields:
                siblings = [_join(prefix, k) for k in node.fields]
                raise ScenarioError(
                    f'unknown key "{path}"{_suggest(path, siblings, scenario_paths(new))}', key=path
                )
            child = node.fields[part]
            if last:
                if value is None:
                    container.pop(part, None)
                else:
                    container[part] = value
                    other = _ALTERNATIVES.get(part)
                    if other is not None and isinstance(child, _Leaf):
                        container.pop(other, None)
                return new
            sub = container.get(part)
            if sub is None and isinstance(child, _Table) and child.preset_ok:
                sub = SUPPORT_DEFAULTS[part]  # expand the default preset below, keeping its springs
            if sub is None:
                if isinstance(child, _Table):
                    sub = container[part] = {}
                elif isinstance(child, _Array):
                    sub = container[part] = []
                else:
                    raise ScenarioError(f"{here}: is not set, so it has no element {parts[depth + 1]!r}", key=path)
            elif isinstance(child, _Table) and child.preset_ok and isinstance(sub, str):
                if sub not in SUPPORT_PRESETS:
                    raise ScenarioError(f"{here}: unknown support preset {sub!r}", key=path)
                k, kt = SUPPORT_PRESETS[sub]
                sub = container[part] = {"translational": k, "rotational": kt}
            elif isinstance(child, _Table) and not isinstance(sub, dict):
                raise ScenarioError(f"{here}: expected a table, got {_describe(sub)}", key=path)
            elif isinstance(child, _Array) and not isinstance(sub, list):
                raise ScenarioError(f"{here}: expected an array of tables, got {_describe(sub)}", key=path)
            node, container, prefix = child, sub, here
        elif isinstance(node, _Array):
            i = _index(part, container, path, prefix)
            if last:
                if value is None:
                    del container[i]
                else:
                    container[i] = value
                return new
            if not isinstance(container[i], dict):
                raise ScenarioError(f"{here}: expected a table, got {_describe(container[i])}", key=path)
            node, container, prefix = node.item, container[i], here
        else:  # a leaf: only a list-valued leaf has elements
            if not (node.list_ok and isinstance(container, list)):
                raise ScenarioError(
                    f'unknown key "{path}": "{prefix}" is a single value, it has no "{part}"', key=path
                )
            i = _index(part, container, path, prefix)
            if not last:
                raise ScenarioError(f'unknown key "{path}": "{here}" is a single value', key=path)
            if value is None:
                raise ScenarioError(f"{path}: cannot remove one element of a list; set {prefix} instead", key=path)
            container[i] = value
            return new
    return new  # pragma: no cover - the loop always returns


def dump_scenario(data: Mapping[str, Any], path: str | os.PathLike[str]) -> None:
    """Write the scenario mapping ``data`` to ``path`` as TOML, atomically.

    The text goes to a temporary file in the same directory, which then
    replaces ``path`` (``os.replace``), so a reader never sees half a file.
    Numpy values are converted; ``inf`` is written as the TOML float ``inf``.
    ``load_scenario(path)`` gives back the same scenario.
    """
    write_text(path, scenario_toml(data))


def scenario_toml(data: Mapping[str, Any]) -> str:
    """The scenario mapping ``data`` as TOML text (what :func:`dump_scenario` writes)."""
    import tomli_w

    try:
        return tomli_w.dumps(_normalise(data))
    except (TypeError, ValueError) as exc:
        raise ScenarioError(f"cannot write the scenario as TOML: {exc}") from None


# --------------------------------------------------------------------------- value helpers


@contextmanager
def _relabel(key: str, rename: tuple[tuple[str, str], ...] = ()) -> Iterator[None]:
    """Turn a ParameterError from a data class into a ScenarioError led by a dotted key.

    ``rename`` maps message prefixes of the data class (``"contactor."``) to
    the scenario's dotted prefix (``"contactors.0."``). A message that does
    not start with a key gets ``key`` in front.
    """
    try:
        yield
    except ScenarioError:
        raise
    except ParameterError as exc:
        msg = str(exc)
        for old, new in rename:
            if msg.startswith(old):
                msg = new + msg[len(old):]
                break
        head, sep, rest = msg.partition(": ")
        if sep and " " not in head:
            head = re.sub(r"\[(\d+)\]", r".\1", head)
            raise ScenarioError(f"{head}: {rest}", key=head) from None
        raise ScenarioError(f"{key}: {msg}", key=key) from None


def _positive(table: Mapping[str, Any], prefix: str, name: str, dimension: str) -> float:
    key = _join(prefix, name)
    with _relabel(key):
        return positive_finite(key, to_si(table[name], dimension, key))


def _nonnegative(key: str, value: Any, dimension: str) -> float:
    with _relabel(key):
        return nonnegative_finite(key, to_si(value, dimension, key))


def _required(table: Mapping[str, Any], prefix: str, name: str, why: str = "") -> None:
    if name not in table:
        key = _join(prefix, name)
        raise ScenarioError(f"{key}: required{why}", key=key)


def _choice(key: str, value: Any, allowed: tuple[str, ...]) -> str:
    with _relabel(key):
        return choice(key, value, allowed)


def _string(key: str, value: Any) -> str:
    if not isinstance(value, str):
        raise ScenarioError(f"{key}: expected a string, got {_describe(value)}", key=key)
    return value


def _integer(key: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ScenarioError(f"{key}: expected an integer, got {_describe(value)}", key=key)
    if isinstance(value, float) and not (math.isfinite(value) and value.is_integer()):
        raise ScenarioError(f"{key}: expected an integer, got {value!r}", key=key)
    return int(value)


def _fmt_m(x: float) -> str:
    return f"{x:g} m"


def _on_beam(key: str, position: float, length: float) -> float:
    """Check that ``position`` [m] lies on a beam of ``length``; round-off at the ends is accepted."""
    tol = 1e-12 * length
    if not (-tol <= position <= length + tol):
        raise ScenarioError(
            f"{key}: {_fmt_m(position)} is off the beam (length {_fmt_m(length)})", key=key
        )
    return min(max(position, 0.0), length)


def _ratio(key: str, value: Any) -> float:
    r = to_si(value, "dimensionless", key)
    if not 0.0 <= r <= 1.0:
        raise ScenarioError(f"{key}: must be between 0 and 1 (a fraction of the beam length), got {r!r}", key=key)
    return r


def _position(table: Mapping[str, Any], prefix: str, length: float, *, required: bool) -> float | None:
    """``position`` or ``position_ratio`` (exactly one when required) as metres on the beam."""
    has_pos, has_ratio = "position" in table, "position_ratio" in table
    if has_pos and has_ratio:
        key = _join(prefix, "position")
        raise ScenarioError(f"{key}: give either {key} or {key}_ratio, not both", key=key)
    if has_ratio:
        key = _join(prefix, "position_ratio")
        return _on_beam(key, _ratio(key, table["position_ratio"]) * length, length)
    if has_pos:
        key = _join(prefix, "position")
        return _on_beam(key, to_si(table["position"], "length", key), length)
    if required:
        raise ScenarioError(
            f"{_join(prefix, 'position')}: required (or position_ratio, a fraction of the length)",
            key=_join(prefix, "position"),
        )
    return None


# --------------------------------------------------------------------------- sections


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
    sections = _parse_sections(raw["beam"], beam)
    masses, springs = _parse_attachments(raw, beam.length)
    with _relabel("beam", (("beam.sections", "beam.sections"),)):
        return dataclasses.replace(beam, sections=sections, masses=masses, springs=springs)


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
        with _relabel(prefix, (("contactor.", f"{prefix}."),)):
            out.append(Contactor(position, stiffness, gap, side))  # type: ignore[arg-type]
    return tuple(out)


def _ratios(table: Mapping[str, Any], name: str) -> float | tuple[float, ...]:
    key = f"damping.{name}"
    value = table.get(name, 0.0)
    if isinstance(value, list):
        if not value:
            raise ScenarioError(f"{key}: the list of damping ratios is empty", key=key)
        return tuple(
            _nonnegative(_join(key, i), v, "dimensionless") for i, v in enumerate(value)
        )
    return _nonnegative(key, value, "dimensionless")


def _parse_damping(raw: Mapping[str, Any]) -> Damping:
    d = raw.get("damping", {})
    with _relabel("damping"):
        return Damping(_ratios(d, "free"), _ratios(d, "contact"))


def _reject_unused(table: Mapping[str, Any], names: tuple[str, ...], why: str) -> None:
    for name in names:
        if name in table:
            key = f"excitation.{name}"
            raise ScenarioError(f"{key}: has no effect {why}", key=key)


def _parse_excitation(raw: Mapping[str, Any], beam: Beam, base_dir: Path | None) -> Excitation:
    ex = raw.get("excitation", {})
    kind = _choice("excitation.kind", ex.get("kind", "none"), _KINDS)
    if kind == "none":
        _reject_unused(ex, tuple(k for k in ex if k != "kind"), 'with excitation.kind = "none"')
        return Excitation()
    shape = _choice("excitation.shape", ex.get("shape", "half_sine"), _SHAPES)
    dimension = EXCITATION_DIMENSIONS[kind]
    start = _nonnegative("excitation.start", ex.get("start", 0.0), "time")
    scale = to_si(ex.get("scale", 1.0), "dimensionless", "excitation.scale")

    amplitude = 0.0
    times = values = None
    hold = "constant"
    if shape == "table":
        if "amplitude" in ex:
            raise ScenarioError(
                'excitation.amplitude: has no effect with shape = "table" (the file holds the '
                "values; use excitation.scale to scale them)",
                key="excitation.amplitude",
            )
        _required(ex, "excitation", "file", ' for shape = "table"')
        file = _string("excitation.file", ex["file"])
        path = Path(file).expanduser()
        if not path.is_absolute() and base_dir is not None:
            path = Path(base_dir) / path
        times, values = read_table(path, value_dimension=dimension, key="excitation.file", label=file)
        hold = _choice("excitation.hold", ex.get("hold", "constant"), _HOLDS)
    else:
        _reject_unused(ex, ("file", "hold"), f'with shape = "{shape}" (only with shape = "table")')
        _required(ex, "excitation", "amplitude", f' for kind = "{kind}" ({describe_dimension(dimension)})')
        amplitude = to_si(ex["amplitude"], dimension, "excitation.amplitude")

    duration = None
    if shape == "half_sine":
        _required(ex, "excitation", "duration", " for a half_sine pulse")
        duration = _positive(ex, "excitation", "duration", "time")
    else:
        _reject_unused(ex, ("duration",), f'with shape = "{shape}" (only with shape = "half_sine")')

    position = None
    if kind == "point_force":
        position = _position(ex, "excitation", beam.length, required=True)
    else:
        _reject_unused(ex, ("position", "position_ratio"), f'with kind = "{kind}" (only with "point_force")')

    with _relabel("excitation"):
        return Excitation(
            kind=kind,  # type: ignore[arg-type]
            shape=shape,  # type: ignore[arg-type]
            amplitude=amplitude,
            duration=duration,
            start=start,
            position=position,
            times=times,
            values=values,
            hold=hold,  # type: ignore[arg-type]
            scale=scale,
        )


def _float_list(key: str, value: list[Any]) -> tuple[float, ...]:
    return tuple(to_si(v, "dimensionless", _join(key, i)) for i, v in enumerate(value))


def _parse_initial(raw: Mapping[str, Any], beam: Beam) -> InitialCondition:
    ini = raw.get("initial", {})
    tip = None
    if "tip_displacement" in ini:
        tip = to_si(ini["tip_displacement"], "length", "initial.tip_displacement")
    position = None
    if "position" in ini:
        if tip is None:
            raise ScenarioError(
                "initial.position: has no effect without initial.tip_displacement", key="initial.position"
            )
        position = _on_beam("initial.position", to_si(ini["position"], "length", "initial.position"), beam.length)
    modal = {
        name: _float_list(f"initial.{name}", ini[name]) if name in ini else None
        for name in ("modal_displacement", "modal_velocity")
    }
    with _relabel("initial"):
        return InitialCondition(tip, position, modal["modal_displacement"], modal["modal_velocity"])


def _parse_solver(raw: Mapping[str, Any]) -> SolverOptions:
    s = raw.get("solver", {})
    kw: dict[str, Any] = {}
    if isinstance(s.get("modes"), str) and s["modes"].strip().lower() == "auto":
        kw["modes"] = "auto"
    elif "modes" in s:
        kw["modes"] = _integer("solver.modes", s["modes"])
    if "max_events" in s:
        kw["max_events"] = _integer("solver.max_events", s["max_events"])
    if "tolerance" in s:
        kw["tolerance"] = to_si(s["tolerance"], "dimensionless", "solver.tolerance")
    for name in ("time_step", "end_time", "event_tolerance"):
        if name in s:
            kw[name] = to_si(s[name], "time", f"solver.{name}")
    if "projection" in s:
        kw["projection"] = _choice("solver.projection", s["projection"], ("contact", "paper"))
    if "basis" in s:
        kw["basis"] = _choice("solver.basis", s["basis"], BASES)
    with _relabel("solver"):
        return SolverOptions(**kw)


def _parse_output(raw: Mapping[str, Any], beam: Beam, contactors: tuple[Contactor, ...]) -> tuple[float, ...]:
    out = raw.get("output", {})
    if "points" in out and "point_ratios" in out:
        raise ScenarioError(
            "output.points: give either output.points or output.point_ratios, not both", key="output.points"
        )
    if "points" not in out and "point_ratios" not in out:
        points: list[float] = []
        for x in [c.position for c in contactors] + [beam.length]:
            if x not in points:
                points.append(x)
        return tuple(points)
    name = "points" if "points" in out else "point_ratios"
    values = out[name]
    if not values:
        raise ScenarioError(f"output.{name}: the list is empty", key=f"output.{name}")
    points = []
    for i, v in enumerate(values):
        key = f"output.{name}.{i}"
        x = _ratio(key, v) * beam.length if name == "point_ratios" else to_si(v, "length", key)
        x = _on_beam(key, x, beam.length)
        if x in points:
            raise ScenarioError(f"{key}: {_fmt_m(x)} is listed twice", key=key)
        points.append(x)
    return tuple(points)


# --------------------------------------------------------------------------- scenario


@dataclass(frozen=True, eq=False)
class Scenario:
    """A validated simulation case (see the scenario reference).

    Attributes
    ----------
    beam : Beam
    contactors : tuple of Contactor
    damping : Damping
    excitation : Excitation
    initial : InitialCondition
    solver : SolverOptions
    output_points : tuple of float, [m]
        Where the response is recorded; default: the contactor positions,
        then the right end (without repeats).
    data : dict
        The normalised raw mapping (a private deep copy): vary a dotted path
        with :func:`set_path` / :meth:`with_values` and re-parse.
    source : Path or None
        The file the scenario came from.
    base_dir : Path or None
        Directory against which relative file names (trace CSV) are resolved.
    name : str
        ``name`` from the file, else the file stem.
    """

    beam: Beam
    contactors: tuple[Contactor, ...]
    damping: Damping
    excitation: Excitation
    initial: InitialCondition
    solver: SolverOptions
    output_points: tuple[float, ...]
    data: dict[str, Any] = field(repr=False)
    source: Path | None = None
    base_dir: Path | None = None
    name: str = "scenario"

    def to_toml(self) -> str:
        """The scenario as TOML text (``load_scenario`` of it gives the same scenario)."""
        return scenario_toml(self.data)

    @property
    def description(self) -> str | None:
        """The ``description`` string of the file, if any."""
        return self.data.get("description")

    def _repr_html_(self) -> str:
        """Compact summary table for Jupyter."""
        from ._html import scenario_html

        return scenario_html(self)

    def with_values(self, values: Mapping[str, Any]) -> Scenario:
        """A new scenario with the dotted paths in ``values`` set, re-validated.

        >>> sc2 = sc.with_values({"contactors.0.gap": "0.432 mm", "solver.modes": 12})  # doctest: +SKIP

        Raises :class:`ScenarioError` for an unknown path or an invalid value
        (the message starts with the dotted key).
        """
        data: dict[str, Any] = self.data
        for path, value in values.items():
            data = set_path(data, path, value)
        return parse_scenario(data, base_dir=self.base_dir, source=self.source, name=self.name)


def parse_scenario(
    data: Mapping[str, Any],
    *,
    base_dir: str | os.PathLike[str] | None = None,
    source: str | os.PathLike[str] | None = None,
    name: str = "scenario",
) -> Scenario:
    """Validate a scenario mapping (the TOML schema of the scenario reference).

    Parameters
    ----------
    data : mapping
        Tables ``beam`` (required), ``supports``, ``contactors`` (list),
        ``damping``, ``excitation``, ``initial``, ``solver``, ``output`` and
        the strings ``name`` and ``description``. Values are SI numbers or
        strings with units. ``None`` values count as absent.
    base_dir : path-like, optional
        Directory for relative file names (``excitation.file``); default: the
        current directory.
    source : path-like, optional
        The file ``data`` came from (recorded in the result).
    name : str
        Name used when ``data`` has no ``name``.

    Returns
    -------
    Scenario

    Raises
    ------
    ScenarioError
        Naming the dotted key of the first problem found.
    """
    if not isinstance(data, Mapping):
        raise ScenarioError(f"a scenario must be a mapping of tables, got {type(data).__name__}")
    raw = _normalise(data)
    _check_structure(raw, _SCHEMA, "", raw)
    check_magnitudes(raw)
    warn_numeric_strings(raw)
    if "name" in raw:
        name = _string("name", raw["name"])
    if "description" in raw:
        _string("description", raw["description"])
    base = Path(base_dir) if base_dir is not None else None

    beam = _parse_beam(raw)
    contactors = _parse_contactors(raw, beam)
    damping = _parse_damping(raw)
    excitation = _parse_excitation(raw, beam, base)
    initial = _parse_initial(raw, beam)
    solver = _parse_solver(raw)
    points = _parse_output(raw, beam, contactors)
    scenario = Scenario(
        beam=beam,
        contactors=contactors,
        damping=damping,
        excitation=excitation,
        initial=initial,
        solver=solver,
        output_points=points,
        data=raw,
        source=Path(source) if source is not None else None,
        base_dir=base,
        name=name,
    )
    warn_unusual(scenario)
    return scenario


def load_scenario(path: str | os.PathLike[str]) -> Scenario:
    """Read and validate a scenario TOML file.

    Relative file names inside it (``excitation.file``) are resolved against
    the file's directory; the scenario's name is its ``name`` or the file stem.

    Raises
    ------
    ScenarioError
        For a missing or unreadable file, a TOML syntax error (with the
        parser's line and column) or invalid content.
    """
    if not str(path).strip():
        raise ScenarioError("cannot read scenario: the path is empty; give a scenario file (.toml)")
    p = Path(path)
    try:
        text = p.read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise ScenarioError(f'cannot read scenario "{path}": file not found') from None
    except IsADirectoryError:
        raise ScenarioError(f'cannot read scenario "{path}": it is a directory, not a scenario file (.toml)') from None
    except UnicodeDecodeError:
        raise ScenarioError(f'cannot read scenario "{path}": not UTF-8 text') from None
    except OSError as exc:
        raise ScenarioError(f'cannot read scenario "{path}": {exc.strerror or exc}') from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f'"{path}": invalid TOML: {exc}') from None
    resolved = p.resolve()
    return parse_scenario(data, base_dir=resolved.parent, source=resolved, name=p.stem)


# --------------------------------------------------------------------------- tables


def read_table(
    path: str | os.PathLike[str],
    *,
    value_dimension: str,
    key: str,
    label: str | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Read a two-column trace ``time, value`` from a CSV file, in SI units.

    The file is read by the same reader as measured records
    (:func:`impactbeam.experiment.load_record`), so both honour the same
    unit headers.

    Parameters
    ----------
    path : path-like
        The file. Cells are separated by commas (or semicolons, or tabs, or
        blanks when the file has none of those). Blank lines and lines starting
        with ``#`` are skipped.
    value_dimension : str
        Dimension of the value column (see :mod:`impactbeam.units`), e.g.
        ``"acceleration"``.
    key : str
        Dotted key reported in errors (``"excitation.file"``).
    label : str, optional
        How the file is named in messages (default: ``path`` as given).

    Returns
    -------
    times : ndarray, shape (n,), [s]
        Strictly increasing, n >= 2.
    values : ndarray, shape (n,)
        In the SI unit of ``value_dimension``.

    Notes
    -----
    An optional first line names the columns, with units in brackets or
    parentheses: ``time [ms],acceleration [g]`` or ``time (ms),acceleration
    (g)`` (``g`` = 9.80665 m/s^2 for an acceleration). A column without a
    unit, or a file without a header, is SI. Each number is scaled in decimal
    arithmetic, so ``1.5`` ms gives exactly the float ``0.0015``.

    Raises
    ------
    ScenarioError
        With ``key``, the file name and the line number: missing or unreadable
        file, one column only, fewer than two rows, a wrong number of columns,
        a non-numeric cell, NaN or infinity, non-increasing times, an unknown
        unit or one of the wrong dimension (naming the column and the unit).
    """
    name = str(path) if label is None else label

    def fail(detail: str) -> ScenarioError:
        return ScenarioError(f'{key}: "{name}" {detail}', key=key)

    where = "" if str(path) == name else f" (looked for {path})"
    table = read_delimited(
        path, fail, what="a trace", example=f"time [s],value [{DIMENSIONS[value_dimension].si_unit}]",
        not_found=f"not found{where}",
    )
    if table.ncol != 2:
        raise fail(
            f"line {table.first_line}: {table.ncol} columns ({', '.join(table.names)}), expected 2 (time, value)"
        )
    scales = [1.0, 1.0]
    for j, dimension in enumerate(("time", value_dimension)):
        unit = table.units[j]
        if unit is not None:
            try:
                scales[j] = unit_scale(unit, dimension, key)
            except ScenarioError as exc:
                detail = str(exc).partition(": ")[2]
                raise fail(
                    f'line {table.first_line}, column {j + 1} ({table.names[j]!r}), unit "{unit}": {detail}'
                ) from None
    (times, values), _ = numeric_columns(table, (0, 1), scales, fail)
    if times.size < 2:
        raise fail(f"has {times.size} data row{'' if times.size == 1 else 's'}; a trace needs at least 2")
    return times, values
