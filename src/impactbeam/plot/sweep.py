"""Selecting cases of sweep results and plotting one metric (a line or a heat map)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any
import numpy as np

from .._optional import require
from ..exceptions import ParameterError

__all__ = ["plot_sweep", "select_cases"]


def _axis_label(ds: Any, name: str) -> str:
    return _axis(ds, name)[0]


def _axis(ds: Any, name: str) -> tuple[str, float]:
    """Display label ("gap [mm]") and the factor from the stored SI values."""
    from .style import display_label

    return display_label(name, ds[name].attrs.get("units"))


def select_cases(ds: Any, keep: Sequence[str], sel: Mapping[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
    """Reduce a grid result to the dimensions ``keep``.

    Other grid dimensions take the value in ``sel`` (nearest coordinate,
    within 1e-6 of the coordinate spacing) or else their first value.
    Returns the selection and the values chosen per dimension.

    Parameters
    ----------
    ds : xarray.Dataset
        Sweep results on a grid.
    keep : sequence of str
        Dimensions to keep.
    sel : mapping, optional
        Values of the other dimensions.
    """
    sel = dict(sel or {})
    chosen: dict[str, Any] = {}
    for name in sel:
        if name not in ds.dims:
            raise ParameterError(f'--sel: "{name}" is not a dimension of the results ({", ".join(map(str, ds.dims))})')
        if name in keep:
            raise ParameterError(f'--sel: "{name}" is plotted, it cannot also be selected')
    for dim in ds.dims:
        if dim in keep or dim in ("time", "point"):
            continue
        coord = ds[dim].values
        if dim in sel:
            value = sel[dim]
            if coord.dtype.kind in "fiu":
                v = _in_si(value, dim, str(ds[dim].attrs.get("units", "")))
                i = int(np.argmin(np.abs(coord - v)))
                spacing = float(np.min(np.diff(np.sort(coord)))) if coord.size > 1 else max(abs(v), 1.0)
                if abs(coord[i] - v) > 1e-6 * spacing:
                    raise ParameterError(f"--sel {dim}: {value} is not one of its values {coord.tolist()}")
            else:
                matches = np.nonzero([str(c) == str(value) for c in coord.tolist()])[0]  # any string dtype
                if not matches.size:
                    raise ParameterError(f"--sel {dim}: {value!r} is not one of its values {coord.tolist()}")
                i = int(matches[0])
        else:
            i = 0
        chosen[dim] = np.asarray(coord[i]).item()  # a Python number or string
        ds = ds.isel({dim: i})
    return ds, chosen


def plot_sweep(
    ds: Any,
    x: str,
    metric: str,
    *,
    y: str | None = None,
    sel: Mapping[str, Any] | None = None,
    ax: Any = None,
) -> Any:
    """Plot one metric of a sweep: a line over ``x``, or a heat map over (``x``, ``y``).

    For a sampled design (``case`` dimension) a scatter plot of the metric
    over ``x`` (colour-coded over ``x`` and ``y`` when ``y`` is given).
    Failed and not-run cases (NaN) are left blank.

    Parameters
    ----------
    ds : xarray.Dataset
        Sweep results.
    x : str
        Parameter on the horizontal axis.
    metric : str
        Metric to plot.
    y : str, optional
        Second parameter: a heat map.
    sel : mapping, optional
        Values of the other grid parameters.
    ax : matplotlib Axes, optional
        Draw here (default: a new figure).

    Returns
    -------
    matplotlib artist
        The Line2D, QuadMesh or PathCollection drawn.
    """
    plt = require("matplotlib.pyplot", "plot")

    names = sorted(v for v in ds.data_vars if v not in ("status", "w") and np.issubdtype(ds[v].dtype, np.number))
    if metric not in names:  # the status, the messages and warnings (text) and the histories are no metrics
        raise ParameterError(f'--metric: "{metric}" is not in the results (use {", ".join(names)})')
    for opt, name in (("--x", x), ("--y", y)):
        if name is not None and name not in ds.coords:
            params = [c for c in ds.coords if c not in ("case", "time", "point")]
            raise ParameterError(f'{opt}: "{name}" is not a parameter of the results (use {", ".join(params)})')
    if y is not None and y == x:
        raise ParameterError("--y: must differ from --x")
    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 4.4))
    label, fm = _axis(ds, metric)
    fx = _axis(ds, x)[1]
    fy = _axis(ds, y)[1] if y is not None else 1.0
    if "case" in ds.dims:
        xs = ds[x].values * fx
        vals = ds[metric].values * fm
        if y is None:
            handle = ax.scatter(xs, vals, s=10)
            ax.set_ylabel(label)
        else:
            handle = ax.scatter(xs, ds[y].values * fy, c=vals, s=14, cmap="viridis")
            ax.figure.colorbar(handle, ax=ax, label=label)
            ax.set_ylabel(_axis_label(ds, y))
        ax.set_xlabel(_axis_label(ds, x))
        ax.set_title(f"{metric} ({ds.sizes['case']} samples)")
        return handle
    sub, chosen = select_cases(ds, [d for d in (x, y) if d is not None], sel)
    da = sub[metric].load()
    numeric_x = da[x].dtype.kind in "fiu"
    if y is None:
        xs = da[x].values * fx if numeric_x else np.arange(da.sizes[x])
        (handle,) = ax.plot(xs, da.values * fm, marker="o", ms=3)
        if not numeric_x:
            ax.set_xticks(xs, [str(v) for v in da[x].values])
        ax.set_ylabel(label)
    else:
        da = da.transpose(y, x)
        handle = ax.pcolormesh(_edges(da[x].values * fx), _edges(da[y].values * fy), da.values * fm, shading="flat",
                               cmap="viridis")
        ax.figure.colorbar(handle, ax=ax, label=label)
        ax.set_ylabel(_axis_label(ds, y))
    ax.set_xlabel(_axis_label(ds, x))
    where = ", ".join(f"{k} = {v:.4g}" if isinstance(v, float) else f"{k} = {v}" for k, v in chosen.items())
    ax.set_title(metric + (f" at {where}" if where else ""), fontsize=9)
    return handle


def _edges(c: np.ndarray) -> np.ndarray:
    """Cell edges around coordinate values (midpoints; categorical: unit cells)."""
    if c.dtype.kind not in "fiu":
        return np.arange(c.size + 1) - 0.5
    c = c.astype(float)
    if c.size == 1:
        return np.array([c[0] - 0.5, c[0] + 0.5]) if c[0] == 0 else np.array([0.5, 1.5]) * c[0]
    mid = 0.5 * (c[1:] + c[:-1])
    return np.concatenate([[c[0] - (mid[0] - c[0])], mid, [c[-1] + (c[-1] - mid[-1])]])


def _in_si(value: Any, dim: str, unit: str) -> float:
    """A ``--sel`` value as a number in the coordinate's SI ``unit``: a number, or a string with a unit."""
    try:
        return float(value)
    except (TypeError, ValueError):
        pass
    from ..units import DIMENSIONS, to_si

    dimension = "dimensionless" if unit in ("", "1") else next(
        (name for name, d in DIMENSIONS.items() if d.si_unit == unit), None)  # "2 %" for a ratio too
    if dimension is None or not isinstance(value, str):
        raise ParameterError(f"--sel {dim}: expected a number{f' [{unit}]' if unit else ''}, got {value!r}")
    return to_si(value, dimension, f"--sel {dim}")
