"""The scenario schema: every key, its structure and its physical dimension.

The one description of what a scenario file may hold (tables, arrays of
tables, values, lists) and, for every value, the dimension its units are read
in (:func:`path_dimension`). Structure checks with "did you mean"
suggestions, and the list of settable dotted paths, are read off it.
"""

from __future__ import annotations

import difflib
import json
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..exceptions import ScenarioError

__all__ = ["EXCITATION_DIMENSIONS", "PSD_DIMENSIONS", "PRELOAD_DIMENSIONS", "SUPPORT_DEFAULTS", "AMPLITUDE", "PRELOAD_AMPLITUDE", "OUTPUT_FIELDS", "OUTPUT_FIELD_ALIASES", "scenario_paths", "path_dimension", "describe_value"]


#: Physical dimension of ``excitation.amplitude`` (and of a table's values) per kind.
EXCITATION_DIMENSIONS: dict[str, str] = {
    "base_acceleration": "acceleration",
    "point_force": "force",
    "distributed_force": "force_per_length",
}

#: Physical dimension of the levels of ``excitation.psd`` per kind (one-sided densities).
PSD_DIMENSIONS: dict[str, str] = {
    "base_acceleration": "acceleration_psd",
    "point_force": "force_psd",
    "distributed_force": "force_per_length_psd",
}

_KINDS = ("base_acceleration", "point_force", "distributed_force", "none")
_SHAPES = ("half_sine", "step", "table", "harmonic", "random")
_MEAN_STRESS = ("none", "goodman")
_HOLDS = ("constant", "linear")
_SIDES = ("below", "above")
#: Fields ``[output] fields`` may name: the deflection and velocity (always written), the bending
#: moment and the bending stress (which also adds its maximum to the metrics).
OUTPUT_FIELDS = ("displacement", "velocity", "moment", "stress")
#: Other spellings accepted for the fields, by their canonical name.
OUTPUT_FIELD_ALIASES = {"bending_moment": "moment", "bending_stress": "stress", "deflection": "displacement"}


#: The dimension of ``excitation.amplitude``: set by ``excitation.kind`` (:data:`EXCITATION_DIMENSIONS`).
AMPLITUDE = "amplitude"
#: The dimension of a level of ``excitation.psd``: set by ``excitation.kind`` (:data:`PSD_DIMENSIONS`).
PSD_LEVEL = "psd_level"
#: The dimension of ``preload.amplitude``: set by ``preload.kind`` (:data:`PRELOAD_DIMENSIONS`).
PRELOAD_AMPLITUDE = "preload_amplitude"
#: Physical dimension of ``preload.amplitude`` per ``preload.kind``.
PRELOAD_DIMENSIONS: dict[str, str] = {
    "gravity": "acceleration",
    "base_acceleration": "acceleration",
    "point_force": "force",
}
_PRELOAD_KINDS = tuple(PRELOAD_DIMENSIONS)


@dataclass(frozen=True)
class _Leaf:
    """A value.

    ``dimension``: a key of :data:`impactbeam.units.DIMENSIONS`, ``"integer"``,
    :data:`AMPLITUDE`, :data:`PRELOAD_AMPLITUDE`, or None for a word (a name, a choice, a file).
    ``list_ok``: a list of values is allowed too; ``list_only``: must be a list.
    ``columns``: a list of rows (``[[f, G], ...]``, ``[[x, v], ...]``), each with these dimensions
    (with ``list_ok`` and not ``list_only``, a single value is allowed too).
    """

    dimension: str | None = None
    list_ok: bool = False
    list_only: bool = False
    columns: tuple[str, ...] = ()


@dataclass(frozen=True)
class _Table:
    """A TOML table. ``preset_ok``: a string (preset name) may stand in for the table."""

    fields: Mapping[str, Any]
    preset_ok: bool = False


@dataclass(frozen=True)
class _Array:
    """An array of tables (``[[contactors]]``)."""

    item: _Table


def _values(list_ok: bool = False, list_only: bool = False, **dimensions: str | None) -> dict[str, _Leaf]:
    """Leaves named by the keywords, each with its dimension."""
    return {name: _Leaf(dim, list_ok, list_only) for name, dim in dimensions.items()}


_SECTION = {"length": "length", "width": "length", "height": "length", "area": "area",
            "second_moment": "second_moment", "youngs_modulus": "modulus", "density": "density"}
_POSITION = {"position": "length", "position_ratio": "dimensionless"}
_SPRINGS = {"translational": "stiffness", "rotational": "rotational_stiffness"}
_SUPPORT_NODE = _Table(_values(**_SPRINGS), preset_ok=True)

_SCHEMA = _Table(
    {
        **_values(name=None, description=None),
        "beam": _Table({
            **_values(**_SECTION),
            **_values(theory=None, poisson_ratio="dimensionless", shear_modulus="modulus",
                      shear_coefficient="dimensionless"),
            "sections": _Array(_Table(_values(**_SECTION))),
        }),
        "supports": _Table({"left": _SUPPORT_NODE, "right": _SUPPORT_NODE}),
        "contactors": _Array(_Table(_values(**_POSITION, stiffness="stiffness", gap="length", side=None,
                                             damping="damping_coefficient", restitution="dimensionless"))),
        "masses": _Array(_Table(_values(**_POSITION, mass="mass", rotary_inertia="rotary_inertia"))),
        "springs": _Array(_Table(_values(**_POSITION, **_SPRINGS))),
        "damping": _Table({
            **_values(free="dimensionless", contact="dimensionless", list_ok=True),
            **_values(model=None, alpha="rate", beta="time"),
        }),
        "excitation": _Table(
            _values(
                kind=None, shape=None, amplitude=AMPLITUDE, duration="time", start="time", **_POSITION,
                scale="dimensionless", file=None, hold=None, frequency="frequency", phase="angle",
                seed="integer", stream="integer", sample_rate="frequency",
            )
            | {"psd": _Leaf(None, True, True, ("frequency", PSD_LEVEL))}
        ),
        "initial": _Table(
            {
                **_values(tip_displacement="length", position="length"),
                **_values(modal_displacement="dimensionless", modal_velocity="dimensionless",
                          list_ok=True, list_only=True),
                "velocity": _Leaf("velocity", True, False, ("length", "velocity")),
                "displacement": _Leaf("length", True, True, ("length", "length")),
                **_values(angular_velocity="angular_velocity", pivot="length", displacement_file=None,
                          velocity_file=None, equilibrium=None),
            }
        ),
        "preload": _Table({**_values(kind=None, amplitude=PRELOAD_AMPLITUDE, **_POSITION)}),
        "solver": _Table(
            _values(
                modes="integer", time_step="time", end_time="time", max_events="integer", event_tolerance="time",
                projection=None, tolerance="dimensionless", basis=None,
            )
        ),
        "output": _Table(_values(points="length", point_ratios="dimensionless", fields=None, list_ok=True, list_only=True)),
        "fatigue": _Table(
            _values(points="length", list_ok=True, list_only=True)
            | _values(sn_stress="stress", sn_cycles="dimensionless", sn_exponent="dimensionless",
                      endurance_limit="stress", mean_stress=None, ultimate_strength="stress")
        ),
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
    """`` (did you mean "x"?)`` or a list of the valid keys at that level (a key the typed one begins first)."""
    match = [s for s in (siblings or everything) if s.startswith(path)][:1]  # a shortened key: excitation.freq
    match = match or difflib.get_close_matches(path, siblings, n=1, cutoff=0.6)
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


def describe_value(value: Any) -> str:
    """A raw TOML value as an error message shows it: ``true``, ``"text"``, ``a table``, ``a list``, ``1.5``."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, str):
        return json.dumps(value)
    return repr(value)


def _check_structure(value: Any, node: Any, path: str, root: Any) -> None:
    """Reject unknown keys and values of the wrong structure (table/list/value)."""
    if isinstance(node, _Table):
        if node.preset_ok and isinstance(value, str):
            return
        if not isinstance(value, dict):
            expected = "a preset name or a table" if node.preset_ok else "a table"
            raise ScenarioError(f"{path}: expected {expected}, got {describe_value(value)}", key=path)
        siblings = [_join(path, k) for k in node.fields]
        for key, sub in value.items():
            sub_path = _join(path, key)
            if key not in node.fields:
                raise _unknown(sub_path, sub, siblings, root)
            _check_structure(sub, node.fields[key], sub_path, root)
    elif isinstance(node, _Array):
        if not isinstance(value, list):
            raise ScenarioError(
                f"{path}: expected an array of tables ([[{path}]]), got {describe_value(value)}", key=path
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
                if node.columns and not (isinstance(item, list) and len(item) == len(node.columns)):
                    raise ScenarioError(
                        f"{_join(path, i)}: expected a row of {len(node.columns)} values "
                        f"({', '.join(node.columns)}), got {describe_value(item)}", key=_join(path, i)
                    )
                for j, sub in enumerate(item if node.columns else [item]):
                    if isinstance(sub, (dict, list)):
                        where = _join(_join(path, i), j) if node.columns else _join(path, i)
                        raise ScenarioError(f"{where}: expected a value, got {describe_value(sub)}", key=where)
        elif node.list_only:
            raise ScenarioError(f"{path}: expected a list, got {describe_value(value)}", key=path)


def scenario_paths(data: Mapping[str, Any] | None = None) -> list[str]:
    """Every settable dotted path of a scenario mapping.

    The paths of the schema (present or not: ``damping.contact`` is listed even
    when absent), with list indices for the contactors and list-valued fields
    present in ``data`` (``contactors.0.gap``, ``output.points.1``). Used for
    "did you mean" suggestions and by sweeps to check their parameters.

    Parameters
    ----------
    data : mapping, optional
        A raw scenario mapping; its lists give the indexed paths.
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


def path_dimension(path: str, kind: str | None = None, preload_kind: str | None = None) -> str | None:
    """The dimension in which the value at a dotted scenario path is read.

    The one rule for the units of every scenario key: the scenario parser,
    sweeps, fits, bifurcation diagrams and the checks of numeric strings all
    read it here.

    Parameters
    ----------
    path : str
        A dotted path of the schema, list indices included (``"contactors.0.gap"``,
        ``"damping.free.2"``, ``"output.points.1"``).
    kind : str, optional
        ``excitation.kind``, which sets the dimension of ``excitation.amplitude``.
    preload_kind : str, optional
        ``preload.kind``, which sets the dimension of ``preload.amplitude``.

    Returns
    -------
    str or None
        A key of :data:`impactbeam.units.DIMENSIONS`, ``"integer"``, or None for
        a word (name, choice, file) and for an amplitude without a kind.

    Raises
    ------
    ScenarioError
        For a path that is not a value of the schema.

    Examples
    --------
    >>> path_dimension("contactors.0.gap")
    'length'
    >>> path_dimension("excitation.amplitude", "point_force")
    'force'
    """
    node: Any = _SCHEMA
    indices: list[int] = []
    for part in path.split("."):
        if isinstance(node, _Array) and part.isdigit():
            node = node.item
        elif isinstance(node, _Leaf) and node.list_ok and part.isdigit() and len(indices) < 1 + bool(node.columns):
            indices.append(int(part))
            continue
        elif isinstance(node, _Table) and part in node.fields:
            node = node.fields[part]
        else:
            raise ScenarioError(f'unknown key "{path}"{_suggest(path, [], scenario_paths())}', key=path)
    if not isinstance(node, _Leaf):
        raise ScenarioError(f"{path}: is a table, not a value", key=path)
    if node.dimension == AMPLITUDE:
        return EXCITATION_DIMENSIONS.get(kind or "")
    if node.columns:
        if not indices:
            return node.dimension  # a single value where one is allowed (a uniform initial velocity)
        if len(indices) < 2 or indices[1] >= len(node.columns):
            return None  # a row or the whole table: no single dimension
        column = node.columns[indices[1]]
        return PSD_DIMENSIONS.get(kind or "") if column == PSD_LEVEL else column
    if node.dimension == PRELOAD_AMPLITUDE:
        return PRELOAD_DIMENSIONS.get(preload_kind or "")
    return node.dimension
