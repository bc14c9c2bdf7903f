"""The fitted parameters: their current values, their bounds, and how bounds are read.

A fitted parameter is a dotted path of the scenario (``contactors.0.stiffness``);
its starting value is the scenario's, and its bounds are the user's or a
default by kind (positive quantities within a factor 1000, damping ratios in
[0, 1], gaps non-negative).
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from ..exceptions import ParameterError, ScenarioError
from ..scenario import path_dimension

if TYPE_CHECKING:
    from ..scenario import Scenario

__all__ = ["current_value", "parse_bounds", "bounds_for"]


# dotted-path leaves whose value must stay positive (default bounds [x0/1000, 1000 x0])
_POSITIVE = {
    "stiffness", "youngs_modulus", "density", "length", "width", "height", "area", "second_moment",
    "duration", "translational", "rotational",
}
_RATIOS = {"free", "contact"}  # damping ratios: default bounds [0, 1]
_NONNEGATIVE = {"gap", "start"}

def current_value(scenario: Scenario, path: str) -> float:
    """The SI value of a dotted scenario path (``contactors.0.stiffness`` -> 4030.0).

    Parameters
    ----------
    scenario : Scenario
    path : str
        Dotted path, as for :func:`impactbeam.scenario.set_path`.

    Returns
    -------
    float

    Raises
    ------
    ScenarioError
        For a path that does not name a single number of the scenario.
    """
    obj: Any = scenario
    parts = path.split(".")
    for i, part in enumerate(parts):
        if isinstance(obj, (list, tuple)):
            if not re.fullmatch(r"\d+", part) or int(part) >= len(obj):
                raise ScenarioError(f"{path}: no item {part!r} (there are {len(obj)})", key=path)
            obj = obj[int(part)]
            continue
        if i == 0 and part == "supports":
            part = "beam"
            obj = getattr(obj, "beam")
            continue
        if not hasattr(obj, part) or part.startswith("_"):
            raise ScenarioError(
                f"{path}: cannot fit this path: {'.'.join(parts[: i + 1])!r} is not a numeric field of the scenario",
                key=path,
            )
        obj = getattr(obj, part)
    if isinstance(obj, tuple) and obj and all(isinstance(v, (int, float)) for v in obj):
        if len(set(obj)) == 1:  # one ratio given for every mode
            obj = obj[0]
        else:
            raise ScenarioError(f"{path}: is a list of per-mode values; fit one item ({path}.0)", key=path)
    if isinstance(obj, bool) or not isinstance(obj, (int, float)):
        raise ScenarioError(f"{path}: is not a number ({type(obj).__name__}); it cannot be fitted", key=path)
    return float(obj)


def _default_bounds(path: str, x0: float) -> tuple[float, float]:
    leaf = path.split(".")[-1]
    parent = path.split(".")[0]
    if parent == "damping":
        return 0.0, 1.0
    if leaf in _POSITIVE and x0 > 0:
        return x0 / 1000.0, x0 * 1000.0
    if leaf in _NONNEGATIVE:
        return 0.0, math.inf
    return -math.inf, math.inf


def parse_bounds(
    items: Sequence[str] | Mapping[str, Any], kind: str = "base_acceleration", preload_kind: str | None = None
) -> dict[str, tuple[float, float]]:
    """Bounds from ``["PATH=LO:HI", ...]`` (either end may be empty; values SI or with units).

    Parameters
    ----------
    items : sequence of str, or mapping path -> (lower, upper)
        ``PATH=LO:HI`` strings, or a mapping whose ends may be None (open).
        Ends with units are read in the dimension of the path
        (:func:`impactbeam.scenario.path_dimension`).
    kind : str
        ``excitation.kind`` of the scenario (the dimension of ``excitation.amplitude``).
    preload_kind : str, optional
        ``preload.kind`` of the scenario (the dimension of ``preload.amplitude``).

    Returns
    -------
    dict of str -> (float, float)

    Examples
    --------
    >>> parse_bounds(["contactors.0.stiffness=1000:2e4", "excitation.scale=0.5:"])
    {'contactors.0.stiffness': (1000.0, 20000.0), 'excitation.scale': (0.5, inf)}
    """
    from ..units import to_si

    if isinstance(items, Mapping):
        out = {}
        for k, v in items.items():
            lo, hi = v
            out[str(k)] = (-math.inf if lo is None else float(lo), math.inf if hi is None else float(hi))
        return out
    out = {}
    for item in items:
        path, eq, rng = item.partition("=")
        lo_s, colon, hi_s = rng.partition(":")
        if not eq or not colon or not path.strip():
            raise ParameterError(f'--bounds: "{item}" is not of the form PATH=LO:HI')
        path = path.strip()
        dim = path_dimension(path, kind, preload_kind)
        dim = "dimensionless" if dim in (None, "integer") else dim
        vals = []
        for text, default in ((lo_s, -math.inf), (hi_s, math.inf)):
            text = text.strip()
            if not text:
                vals.append(default)
                continue
            try:
                vals.append(float(text))
            except ValueError:
                vals.append(to_si(text, dim, f"--bounds {path}"))
        out[path] = (vals[0], vals[1])
    return out


def bounds_for(
    initial: Mapping[str, float], user_bounds: Mapping[str, tuple[float, float]]
) -> dict[str, tuple[float, float]]:
    """The bounds of each fitted path: the user's, else the default of its kind; checked.

    Parameters
    ----------
    initial : mapping path -> float
        Starting values (SI).
    user_bounds : mapping path -> (lower, upper)
        Bounds given by the user (:func:`parse_bounds`).

    Returns
    -------
    dict of str -> (float, float)

    Raises
    ------
    ParameterError
        A lower bound not below the upper one, or a starting value outside.
    """
    out = {}
    for p, x0 in initial.items():
        lo, hi = user_bounds.get(p, _default_bounds(p, x0))
        _check_bounds(p, lo, hi, x0)
        out[p] = (lo, hi)
    return out


def _check_bounds(path: str, lo: float, hi: float, x0: float) -> None:
    if math.isnan(lo) or math.isnan(hi):
        raise ParameterError(f"bounds {path}: NaN is not a bound")
    if lo > hi:
        raise ParameterError(f"bounds {path}: lower bound {lo:g} is above the upper bound {hi:g}")
    if lo == hi:
        raise ParameterError(f"bounds {path}: lower and upper bound are both {lo:g}; leave the parameter out to fix it")
    if not lo <= x0 <= hi:
        raise ParameterError(
            f"bounds {path}: the starting value {x0:g} lies outside [{lo:g}, {hi:g}]; "
            "change the scenario's value or the bounds"
        )


