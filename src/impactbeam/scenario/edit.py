"""Editing scenario mappings by dotted path, and writing them as TOML.

:func:`set_path` is how sweeps, fits, the explorer and the command line vary a
scenario: it sets one dotted path of the raw mapping (creating tables,
expanding support presets, replacing alternatives), after which the mapping
is parsed again exactly as a file would be.
"""

from __future__ import annotations

import copy
import os
import re
from collections.abc import Mapping
from typing import Any
import numpy as np

from .._io import write_text
from ..model.beam import SUPPORT_PRESETS
from ..exceptions import ScenarioError
from .schema import (
    SUPPORT_DEFAULTS,
    _ALTERNATIVES,
    _Array,
    _Leaf,
    _SCHEMA,
    _Table,
    describe_value,
    _join,
    _suggest,
    scenario_paths,
)

__all__ = ["dump_scenario", "scenario_toml", "set_path"]


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
                raise ScenarioError(f"{here}: expected a table, got {describe_value(sub)}", key=path)
            elif isinstance(child, _Array) and not isinstance(sub, list):
                raise ScenarioError(f"{here}: expected an array of tables, got {describe_value(sub)}", key=path)
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
                raise ScenarioError(f"{here}: expected a table, got {describe_value(container[i])}", key=path)
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

    Parameters
    ----------
    data : mapping
        A raw scenario mapping (``Scenario.data``).
    path : str or path-like
        The ``.toml`` file.
    """
    write_text(path, scenario_toml(data))


def scenario_toml(data: Mapping[str, Any]) -> str:
    """The scenario mapping ``data`` as TOML text (what :func:`dump_scenario` writes).

    Parameters
    ----------
    data : mapping
        A raw scenario mapping (``Scenario.data``).
    """
    import tomli_w

    try:
        return tomli_w.dumps(_normalise(data))
    except (TypeError, ValueError) as exc:
        raise ScenarioError(f"cannot write the scenario as TOML: {exc}") from None
