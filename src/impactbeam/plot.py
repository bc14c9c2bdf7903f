"""Matplotlib figures of simulation results (optional layer, Agg backend).

Every function takes an optional ``ax=`` (or ``axes=``), never touches the
global pyplot state when it creates its own figure (a bare
:class:`matplotlib.figure.Figure` on the Agg canvas), labels its axes with
units and returns a :class:`PlotHandles`. Functions given ``path`` write the
figure atomically (a temporary file in the same directory, then
:func:`os.replace`), so an interrupted run never leaves half an image.

Deflections are plotted in millimetres and times in seconds, as in the
figures of Xu & Ervin (2013).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from ._atomic import atomic_path
from ._optional import require
from .exceptions import ParameterError

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from .result import SimulationResult

__all__ = [
    "PlotHandles",
    "plot_result",
    "plot_response",
    "plot_excitation",
    "plot_parameter_study",
    "plot_convergence",
    "surface_distance",
    "save_figure",
]

#: Image formats :func:`save_figure` accepts (by file suffix).
FIGURE_SUFFIXES = (".png", ".pdf", ".svg", ".jpg", ".jpeg", ".eps", ".ps", ".tif", ".tiff", ".webp")

_MM = 1e3
_G = 9.80665


@dataclass(frozen=True)
class PlotHandles:
    """What a plotting function drew.

    Attributes
    ----------
    figure : matplotlib.figure.Figure
    axes : tuple of Axes
        Every axes drawn on, main axes first.
    lines : tuple of Line2D
        The data lines, in drawing order.
    artists : dict
        Other named artists (``"contact_spans"``, ``"impacts"``, ``"legend"`` ...).
    """

    figure: Figure
    axes: tuple[Axes, ...]
    lines: tuple[Any, ...]
    artists: dict[str, Any] = field(default_factory=dict)


# --------------------------------------------------------------------------- helpers


def _new_figure(figsize: tuple[float, float], nrows: int = 1, ncols: int = 1, **kw: Any) -> tuple[Figure, Any]:
    """A figure on the Agg canvas, independent of pyplot's global state."""
    FigureCanvasAgg = require("matplotlib.backends.backend_agg", "plot").FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=False, **kw)
    return fig, axes


def save_figure(figure: Figure, path: str | os.PathLike[str], *, dpi: int = 110) -> Path:
    """Write ``figure`` to ``path`` atomically (temporary file + :func:`os.replace`).

    Raises
    ------
    ParameterError
        The suffix is not an image format matplotlib writes.
    OSError
        The directory does not exist or is not writable.
    """
    p = Path(path)
    suffix = p.suffix.lower()
    if suffix not in FIGURE_SUFFIXES:
        raise ParameterError(f'figure path: unsupported file type "{p.suffix or p.name}" (use {", ".join(FIGURE_SUFFIXES)})')
    with atomic_path(p) as tmp:
        meta = {"Software": None} if suffix == ".png" else None
        figure.savefig(tmp, format=suffix.lstrip("."), dpi=dpi, metadata=meta)
    return p


def _finish(handles: PlotHandles, path: str | os.PathLike[str] | None, dpi: int = 110) -> PlotHandles:
    if path is not None:
        save_figure(handles.figure, path, dpi=dpi)
    return handles


def _contact_point(result: SimulationResult) -> tuple[float, np.ndarray, str]:
    """Position, sampled w and a label of the first contactor, else the first output point."""
    if len(result.contactors):
        c = result.contactors[0]
        return c.position, np.asarray(result.w_contact[:, 0]), "first contactor"
    return float(result.points[0]), np.asarray(result.w[:, 0]), "first output point"


def _w_at(result: SimulationResult, x: float | None) -> tuple[float, np.ndarray]:
    """Sampled deflection at ``x`` (exact dense output when x is not an output point)."""
    if x is None:
        x0, w, _ = _contact_point(result)
        return x0, w
    pts = np.asarray(result.points, dtype=float)
    hit = np.nonzero(np.isclose(pts, x, rtol=0.0, atol=1e-12))[0]
    if hit.size:
        return float(x), np.asarray(result.w[:, hit[0]])
    for i, c in enumerate(result.contactors):
        if math.isclose(c.position, x, rel_tol=0.0, abs_tol=1e-12):
            return float(x), np.asarray(result.w_contact[:, i])
    return float(x), result.displacement([x], result.time)[0]


def surface_distance(
    result: SimulationResult, *, x: float | None = None, side: Literal["above", "below"] = "above"
) -> np.ndarray:
    """The paper's plotted deflection: distance from the contactor surface [m], positive away.

    With a contactor this is its gap function ``g = c - s w(a, t)`` (``s = +1``
    for a contactor above, ``-1`` below; see the model page), i.e. ``u + c``
    with ``u`` the metrics' deflection positive away from the contactor:
    negative values mean contact, as in Figs. 4-8 of Xu & Ervin (2013).
    Without a contactor it is ``-s w(x, t)`` at ``x`` (default the first
    output point), oriented as if a contactor were on ``side`` with no gap.
    """
    if len(result.contactors):
        c = result.contactors[0]
        return c.gap - c.direction * np.asarray(result.w_contact[:, 0])
    _, w = _w_at(result, x)
    s = 1.0 if side == "above" else -1.0
    return -s * w


# --------------------------------------------------------------------------- one result


def plot_result(
    result: SimulationResult,
    path: str | os.PathLike[str] | None = None,
    *,
    ax: Axes | None = None,
    force: bool = True,
    title: str | None = None,
    dpi: int = 110,
) -> PlotHandles:
    """Deflection at the first contactor (or first output point) against time.

    Contact intervals are shaded, impacts and rebounds marked at their exact
    times, the contactor surface drawn as a dashed line, and the contact force
    shown in a lower panel (or on a twin axis when ``ax`` is given).

    Parameters
    ----------
    result : SimulationResult
    path : path-like, optional
        Write the figure there (atomically); the format follows the suffix.
    ax : Axes, optional
        Draw the deflection on it; the force goes on ``ax.twinx()``.
    force : bool
        Draw the contact force (only when there is a contactor).
    title : str, optional
    dpi : int

    Returns
    -------
    PlotHandles
        ``axes`` = (deflection axes[, force axes]); ``artists`` holds
        ``contact_spans``, ``impacts``, ``rebounds``, ``surface``.
    """
    from .metrics import contact_intervals

    x, w, where = _contact_point(result)
    has_c = len(result.contactors) > 0
    show_force = force and has_c
    if ax is None:
        if show_force:
            fig, grid = _new_figure((8.0, 5.6), 2, 1, sharex=True, height_ratios=[2.2, 1.0])
            ax_w, ax_f = grid[0, 0], grid[1, 0]
        else:
            fig, grid = _new_figure((8.0, 4.2))
            ax_w, ax_f = grid[0, 0], None
    else:
        fig = ax.figure
        ax_w = ax
        ax_f = ax.twinx() if show_force else None
    t = np.asarray(result.time)
    lines = list(ax_w.plot(t, w * _MM, color="C0", lw=1.2, label=f"w at x = {x * _MM:.4g} mm ({where})"))
    artists: dict[str, Any] = {"contact_spans": [], "impacts": None, "rebounds": None, "surface": None}
    if has_c:
        c = result.contactors[0]
        artists["surface"] = ax_w.axhline(c.direction * c.gap * _MM, color="k", ls="--", lw=0.8, label="contactor surface")
        t_end = float(t[-1])
        for k, (a, b) in enumerate(contact_intervals(result, 0)):
            span = ax_w.axvspan(a, min(b, t_end), color="C3", alpha=0.15, lw=0, label="in contact" if k == 0 else None)
            artists["contact_spans"].append(span)
        for kind, marker, color in (("impact", "v", "C3"), ("rebound", "^", "C2")):
            times = [e.time for e in result.events if e.kind == kind and e.contactor == 0]
            if times:
                wv = result.displacement([x], times)[0]
                (m,) = ax_w.plot(times, wv * _MM, ls="none", marker=marker, color=color, ms=5, label=f"{kind}s")
                artists[f"{kind}s"] = m
        if ax_f is not None:
            (lf,) = ax_f.plot(t, result.contact_force[:, 0], color="C1", lw=1.0, label="contact force")
            lines.append(lf)
            ax_f.set_ylabel("contact force F [N]")
            if ax is None:
                ax_f.set_xlabel("time t [s]")
                ax_f.grid(True, alpha=0.3)
    ax_w.set_ylabel("deflection w [mm]")
    if ax is not None or ax_f is None:
        ax_w.set_xlabel("time t [s]")
    ax_w.grid(True, alpha=0.3)
    artists["legend"] = ax_w.legend(loc="lower right", fontsize=8)
    ax_w.set_title(title if title is not None else f"{result.scenario_name}: response at x = {x * _MM:.4g} mm")
    axes = (ax_w,) if ax_f is None else (ax_w, ax_f)
    return _finish(PlotHandles(fig, axes, tuple(lines), artists), path, dpi)


# --------------------------------------------------------------------------- groups of histories


def plot_response(
    results: SimulationResult | Sequence[SimulationResult],
    *,
    ax: Axes | None = None,
    labels: Sequence[str] | None = None,
    quantity: Literal["surface", "w"] = "surface",
    x: float | None = None,
    side: Literal["above", "below"] = "above",
    time_window: tuple[float, float] | None = None,
    reference: Sequence[tuple[float, str]] = (),
    title: str | None = None,
    path: str | os.PathLike[str] | None = None,
    dpi: int = 110,
) -> PlotHandles:
    """Response histories of several runs on one axes (the manner of Figs. 4-8 of the paper).

    Parameters
    ----------
    results : SimulationResult or sequence of them
    ax : Axes, optional
    labels : sequence of str, optional
        Legend entries (default: the scenario names).
    quantity : {"surface", "w"}
        ``"surface"``: distance from the first contactor's surface, positive
        away from it, negative in contact (:func:`surface_distance`; the
        paper's plotted quantity); ``"w"``: deflection from rest at ``x``.
    x : float, optional, [m]
        Position for ``"w"`` or for a run without contactor (default: the
        first contactor, else the first output point).
    side : {"above", "below"}
        Orientation of a run without contactor under ``"surface"``.
    time_window : (float, float), optional, [s]
    reference : sequence of (value [m], label)
        Horizontal reference lines (e.g. published peak values).
    title : str, optional
    path : path-like, optional
    dpi : int

    Returns
    -------
    PlotHandles
    """
    runs = [results] if not isinstance(results, Sequence) else list(results)
    if labels is not None and len(labels) != len(runs):
        raise ParameterError(f"labels: {len(labels)} labels for {len(runs)} results")
    if quantity not in ("surface", "w"):
        raise ParameterError(f'quantity: must be "surface" or "w", got {quantity!r}')
    if ax is None:
        fig, grid = _new_figure((8.0, 4.2))
        ax = grid[0, 0]
    else:
        fig = ax.figure
    lines = []
    for i, r in enumerate(runs):
        t = np.asarray(r.time)
        y = surface_distance(r, x=x, side=side) if quantity == "surface" else _w_at(r, x)[1]
        if time_window is not None:
            sel = (t >= time_window[0]) & (t <= time_window[1])
            t, y = t[sel], y[sel]
        lab = labels[i] if labels is not None else r.scenario_name
        lines.extend(ax.plot(t, y * _MM, lw=1.1, color=f"C{i % 10}", label=lab))
    artists: dict[str, Any] = {"reference": []}
    styles = ("--", ":", "-.")
    for j, (val, lab) in enumerate(reference):
        artists["reference"].append(ax.axhline(val * _MM, color="0.3", ls=styles[j % 3], lw=0.9, label=lab))
    if quantity == "surface":
        artists["surface"] = ax.axhline(0.0, color="k", lw=0.6)
        ax.set_ylabel("deflection from contactor surface d [mm]\n(positive away; < 0: contact)")
    else:
        ax.set_ylabel("deflection w [mm]")
    ax.set_xlabel("time t [s]")
    ax.grid(True, alpha=0.3)
    if title:
        ax.set_title(title)
    artists["legend"] = ax.legend(loc="upper right", fontsize=8)
    return _finish(PlotHandles(fig, (ax,), tuple(lines), artists), path, dpi)


def plot_excitation(
    excitations: Sequence[Any],
    *,
    ax: Axes | None = None,
    labels: Sequence[str] | None = None,
    end_time: float = 0.03,
    n: int = 601,
    path: str | os.PathLike[str] | None = None,
    dpi: int = 110,
) -> PlotHandles:
    """Base-acceleration histories in g (Fig. 4(a) of the paper).

    Parameters
    ----------
    excitations : sequence of Excitation
        ``kind = "base_acceleration"`` (values in m/s^2, shown divided by
        g = 9.80665 m/s^2).
    ax, labels, path, dpi
        As :func:`plot_response`.
    end_time : float, [s]
    n : int
        Samples.
    """
    if ax is None:
        fig, grid = _new_figure((8.0, 3.2))
        ax = grid[0, 0]
    else:
        fig = ax.figure
    t = np.linspace(0.0, end_time, n)
    lines = []
    for i, ex in enumerate(excitations):
        lab = labels[i] if labels is not None else f"excitation {i}"
        lines.extend(ax.plot(t, ex.history(t) / _G, lw=1.2, color=f"C{i % 10}", label=lab))
    ax.set_xlabel("time t [s]")
    ax.set_ylabel("base acceleration [g]")
    ax.grid(True, alpha=0.3)
    leg = ax.legend(loc="upper right", fontsize=8)
    return _finish(PlotHandles(fig, (ax,), tuple(lines), {"legend": leg}), path, dpi)


# --------------------------------------------------------------------------- studies


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
    path: str | os.PathLike[str] | None = None,
    dpi: int = 110,
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
    title : str, optional
    path : path-like, optional
    dpi : int
    """
    names = list(metrics)
    if not names:
        raise ParameterError("metrics: at least one metric is needed")
    xv = np.asarray(values, dtype=float)
    if axes is None:
        ncols = 2 if len(names) > 1 else 1
        nrows = math.ceil(len(names) / ncols)
        fig, grid = _new_figure((8.0, 2.4 * nrows + 0.6), nrows, ncols)
        axes = list(grid.ravel())
        for extra in axes[len(names):]:
            extra.set_visible(False)
        axes = axes[: len(names)]
    else:
        axes = list(axes)
        if len(axes) < len(names):
            raise ParameterError(f"axes: {len(axes)} axes for {len(names)} metrics")
        fig = axes[0].figure
    labels = dict(metric_labels or {})
    lines = []
    for a, name in zip(axes, names):
        y = np.asarray(metrics[name], dtype=float)
        if y.shape != xv.shape:
            raise ParameterError(f"metrics.{name}: {y.size} values for {xv.size} parameter values")
        ok = np.isfinite(y)
        lines.extend(a.plot(xv[ok], y[ok], marker="o", ms=4, lw=1.2, color="C0"))
        if baseline is not None:
            a.axvline(baseline, color="0.4", ls=":", lw=1.0)
        a.set_xscale(xscale)
        a.set_xlabel(parameter_label)
        a.set_ylabel(labels.get(name, name))
        a.grid(True, alpha=0.3)
    if title:
        fig.suptitle(title)
    return _finish(PlotHandles(fig, tuple(axes), tuple(lines)), path, dpi)


def plot_convergence(
    modes: Sequence[int],
    series: Mapping[str, Sequence[float] | np.ndarray],
    *,
    ax: Axes | None = None,
    reference_index: int = -1,
    title: str | None = None,
    path: str | os.PathLike[str] | None = None,
    dpi: int = 110,
) -> PlotHandles:
    """Relative change of metrics against the number of modes (log scale).

    Each series is drawn as ``|v_N - v_ref| / |v_ref|`` in percent, ``v_ref``
    its value at ``reference_index`` (default: the most modes). The reference
    point itself (zero) is not drawn on the log axis.
    """
    if ax is None:
        fig, grid = _new_figure((7.0, 3.8))
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
        lines.extend(ax.plot(n[ok], rel[ok], marker="o", color=f"C{i % 10}", label=name))
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xticks(n, [str(int(k)) for k in n])
    ax.set_xlabel("modes per state N [-]")
    ax.set_ylabel(f"change from N = {int(n[reference_index])} [%]")
    ax.grid(True, which="both", alpha=0.3)
    if title:
        ax.set_title(title)
    leg = ax.legend(fontsize=8)
    return _finish(PlotHandles(fig, (ax,), tuple(lines), {"legend": leg}), path, dpi)
