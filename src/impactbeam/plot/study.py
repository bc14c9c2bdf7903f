"""Figures of parameter studies: a metric against a parameter, and convergence in the number of modes.

Styled like :mod:`impactbeam.plot` (journal sizes, line styles that survive
grey-scale, legends outside the data); returned as
:class:`~impactbeam.plot.figure.PlotHandles`.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from .figure import PlotHandles, _finish, _new_figure
from .._optional import require
from ..exceptions import ParameterError
from .style import SERIES_STYLES, _log_ticks, _outside_legend, _side_legend, _styled, _wrap, figure_size

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["plot_parameter_study", "plot_convergence", "plot_convergence_study"]


@_styled
def plot_parameter_study(
    values: Sequence[float] | np.ndarray,
    metrics: Mapping[str, Sequence[float] | np.ndarray],
    *,
    axes: Sequence[Axes] | None = None,
    parameter_label: str = "parameter",
    metric_labels: Mapping[str, str] | None = None,
    baseline: float | None = None,
    xscale: Literal["linear", "log"] = "linear",
    title: str | None = None,
    size: str | tuple[float, float] = "double",
    path: str | os.PathLike[str] | None = None,
    dpi: int = 300,
) -> PlotHandles:
    """One panel per metric against one varied parameter (one-at-a-time study).

    Parameters
    ----------
    values : array_like, (n,)
        Parameter values, already in the unit named by ``parameter_label``.
    metrics : mapping of name -> array_like (n,)
        Metric values, already in display units (NaN points are left out).
    axes : sequence of Axes, optional
        One per metric; default a grid of 2 columns.
    parameter_label : str
        x-axis label with unit.
    metric_labels : mapping of name -> str, optional
        y-axis labels with units (default: the names).
    baseline : float, optional
        Marks the reference value with a vertical dotted line.
    xscale : {"linear", "log"}
        On a log axis only the decades and 2, 5 times them are labelled.
    title : str, optional
    size : {"single", "double"} or (width, height)
    path : path-like, optional
    dpi : int
    """
    names = list(metrics)
    if not names:
        raise ParameterError("metrics: at least one metric is needed")
    xv = np.asarray(values, dtype=float)
    fig, axes = _metric_panels(names, axes, size, lambda ncols, width: (0.3 if ncols == 2 else 0.55) * width, 0.3)
    labels = dict(metric_labels or {})
    lines = []
    for a, name in zip(axes, names):
        y = np.asarray(metrics[name], dtype=float)
        if y.shape != xv.shape:
            raise ParameterError(f"metrics.{name}: {y.size} values for {xv.size} parameter values")
        ok = np.isfinite(y)
        lines.extend(a.plot(xv[ok], y[ok], marker="o", ms=3, lw=1.0, color="#000000"))
        if baseline is not None:
            a.axvline(baseline, color="0.45", ls=":", lw=0.9)
        a.set_xscale(xscale)
        if ok.any() and np.all(y[ok] == np.round(y[ok])):  # counts: integer ticks
            a.yaxis.set_major_locator(require("matplotlib.ticker", "plot").MaxNLocator(integer=True))
        if xscale == "log":
            _log_ticks(a.xaxis)
        a.set_xlabel(_wrap(parameter_label) if len(axes) > 1 else parameter_label)
        a.set_ylabel(labels.get(name, name))
        a.grid(True, alpha=0.3)
    if title:
        fig.suptitle(title)
    return _finish(PlotHandles(fig, tuple(axes), tuple(lines)), path, dpi)


@_styled
def plot_convergence(
    modes: Sequence[int],
    series: Mapping[str, Sequence[float] | np.ndarray],
    *,
    ax: Axes | None = None,
    reference_index: int = -1,
    title: str | None = None,
    size: str | tuple[float, float] = "single",
    path: str | os.PathLike[str] | None = None,
    dpi: int = 300,
) -> PlotHandles:
    """Relative change of metrics against the number of modes (log scale).

    Each series is drawn as ``|v_N - v_ref| / |v_ref|`` in percent, ``v_ref``
    its value at ``reference_index`` (default: the most modes). The reference
    point itself (zero) is not drawn on the log axis.

    Parameters
    ----------
    modes : sequence of int
        Modes per state of each run.
    series : mapping name -> sequence of float
        A metric's value for each entry of ``modes``.
    ax : matplotlib Axes, optional
        Draw here instead of on a new figure.
    reference_index : int
        Which run is the reference.
    title : str, optional
    size : "single", "double" or (width, height)
        Figure size (:func:`figure_size`).
    path : str or path-like, optional
        Also save the figure there (:func:`save_figure`).
    dpi : int
        Resolution of raster formats.

    Returns
    -------
    PlotHandles
    """
    own = ax is None
    if own:
        fig, grid = _new_figure(figure_size(size, 0.8))
        ax = grid[0, 0]
    else:
        fig = ax.figure
    n = np.asarray(modes, dtype=float)
    lines = []
    for i, (name, vals) in enumerate(series.items()):
        v = np.asarray(vals, dtype=float)
        ref = v[reference_index]
        rel = np.abs(v - ref) / abs(ref) * 100.0 if ref != 0 else np.full_like(v, np.nan)
        ok = np.isfinite(rel) & (rel > 0)
        color, ls, marker = SERIES_STYLES[i % len(SERIES_STYLES)]
        lines.extend(ax.plot(n[ok], rel[ok], marker=marker, ms=3.5, color=color, ls=ls, label=name))
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    _log_ticks(ax.yaxis)
    ax.set_xticks(n, [str(int(k)) for k in n])
    ax.xaxis.set_minor_locator(require("matplotlib.ticker", "plot").NullLocator())
    ax.set_xlabel("modes per state N [-]")
    ax.set_ylabel(f"change from N = {int(n[reference_index])} [%]")
    ax.grid(True, which="both", alpha=0.3)
    if title:
        ax.set_title(title)
    leg = _outside_legend(fig, ax, ncols=1) if own else _side_legend(ax)
    return _finish(PlotHandles(fig, (ax,), tuple(lines), {"legend": leg}), path, dpi)


@_styled
def plot_convergence_study(
    modes: Sequence[int],
    values: Mapping[str, Sequence[float | None]],
    estimates: Mapping[str, Sequence[float | None]],
    *,
    axes: Sequence[Axes] | None = None,
    metric_labels: Mapping[str, str] | None = None,
    tolerance: float | None = None,
    title: str | None = None,
    size: str | tuple[float, float] = "double",
    path: str | os.PathLike[str] | None = None,
    dpi: int = 300,
) -> PlotHandles:
    """One panel per metric: its estimated relative error and its change from the most modes, against the modes.

    The estimate (solid, filled markers) is what every result of that count
    reports (``result.convergence``); the change from the largest count
    (dotted, open markers) is the error of the smaller counts as far as the
    largest one is converged. Both on log axes; zeros and missing values are
    left out.

    Parameters
    ----------
    modes : sequence of int
        Modes per state of each run, ascending.
    values : mapping of name -> sequence
        Each metric's value per count (None where undefined).
    estimates : mapping of name -> sequence
        Each metric's estimated relative error per count (None where there is none).
    axes : sequence of Axes, optional
        One per metric; default a grid of 2 columns.
    metric_labels : mapping of name -> str, optional
        Panel titles (default the names).
    tolerance : float, optional
        Draws ``solver.tolerance`` as a grey dashed line.
    title : str, optional
    size : {"single", "double"} or (width, height)
    path : path-like, optional
        Also save the figure there.
    dpi : int
        Resolution of raster formats.

    Returns
    -------
    PlotHandles
    """
    names = list(values)
    if not names:
        raise ParameterError("values: at least one metric is needed")
    n = np.asarray(modes, dtype=float)
    fig, axes = _metric_panels(names, axes, size, lambda ncols, width: 0.32 * width, 0.5, sharex=True)
    labels = dict(metric_labels or {})
    lines = []
    for a, name in zip(axes, names):
        v = np.array([np.nan if x is None else float(x) for x in values[name]])
        e = np.array([np.nan if x is None else float(x) for x in estimates.get(name, [None] * n.size)])
        if v.shape != n.shape or e.shape != n.shape:
            raise ParameterError(f"values.{name}: {v.size} values and {e.size} estimates for {n.size} mode counts")
        ref = v[-1]
        change = np.abs(v - ref) / abs(ref) if np.isfinite(ref) and ref != 0 else np.full_like(v, np.nan)
        change[-1] = np.nan
        ok_e = np.isfinite(e) & (e > 0)
        ok_c = np.isfinite(change) & (change > 0)
        lines.extend(a.plot(n[ok_e], e[ok_e], marker="o", ms=3.5, lw=1.0, color="#000000", label="estimate"))
        lines.extend(a.plot(n[ok_c], change[ok_c], marker="s", ms=3.5, lw=0.9, ls=":", color="#0072B2",
                            mfc="none", label=f"change from N = {int(n[-1])}"))
        if tolerance is not None:
            lines.append(a.axhline(tolerance, color="0.45", ls="--", lw=0.8, label="solver.tolerance"))
        a.set_xscale("log", base=2)
        shown = np.concatenate([e[ok_e], change[ok_c], [] if tolerance is None else [tolerance]])
        a.set_yscale("log")
        _decade_ticks(a.yaxis, float(shown.min(initial=1.0)), float(shown.max(initial=1.0)))
        if not (ok_e.any() or ok_c.any()):
            a.text(0.5, 0.5, "zero at every count", transform=a.transAxes, ha="center", va="center")
        a.set_xticks(n, [str(int(k)) for k in n])
        a.xaxis.set_minor_locator(require("matplotlib.ticker", "plot").NullLocator())
        a.set_title(labels.get(name, name), fontsize="medium")
        a.set_ylabel("relative [-]")
        a.grid(True, which="both", alpha=0.3)
    for a in axes[-2:]:
        a.set_xlabel("modes per state N [-]")
    if title:
        fig.suptitle(title)
    leg = _outside_legend(fig, axes[0], ncols=3)
    return _finish(PlotHandles(fig, tuple(axes), tuple(lines), {"legend": leg}), path, dpi)


def _decade_ticks(axis, lo: float, hi: float) -> None:
    """Log ticks at 1, 2, 5 per decade over a short range, at decades (every k-th) over a long one."""
    decades = math.log10(hi / lo) if lo > 0 else 0.0
    if decades <= 3.0:
        _log_ticks(axis)
        return
    ticker = require("matplotlib.ticker", "plot")
    step = max(1, math.ceil(decades / 5))
    axis.set_major_locator(ticker.LogLocator(base=10.0 ** step, numticks=12))
    axis.set_major_formatter(ticker.LogFormatterSciNotation(base=10.0))
    axis.set_minor_locator(ticker.NullLocator())


def _metric_panels(names: list[str], axes: Any, size: Any, row_height: Any, margin: float,
                   **grid_options: Any) -> tuple[Any, list[Any]]:
    """One panel per metric: the given ``axes``, or a grid of two columns (one for a single metric).

    ``row_height(ncols, width)`` [in] is the height of a row of the new grid, ``margin`` [in] added once.
    """
    if axes is not None:
        axes = list(axes)
        if len(axes) < len(names):
            raise ParameterError(f"axes: {len(axes)} axes for {len(names)} metrics")
        return axes[0].figure, axes
    ncols = 2 if len(names) > 1 else 1
    nrows = math.ceil(len(names) / ncols)
    width = figure_size(size)[0]
    fig, grid = _new_figure((width, row_height(ncols, width) * nrows + margin), nrows, ncols, **grid_options)
    panels = list(np.atleast_1d(grid).ravel())
    for extra in panels[len(names):]:
        extra.set_visible(False)
    return fig, panels[: len(names)]
