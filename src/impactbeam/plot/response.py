"""Figures of one or several simulation results: the response, the excitation, the contact force.

Every function takes an optional ``ax=`` (or ``axes=``), never touches the
global pyplot state when it creates its own figure (a bare
:class:`matplotlib.figure.Figure` on the Agg canvas, whatever the user's
backend), labels its axes with units and returns a :class:`PlotHandles`,
which Jupyter displays as the figure. Functions given ``path`` write the
figure atomically; the format follows the suffix (``.png``, ``.pdf``,
``.svg`` ...).

Conventions, for figures that go into a paper:

* widths of one journal column (``size="single"``, 3.5 in) or two
  (``"double"``, 7 in), fonts of 8 pt (9 pt titles) at print size;
* time in ms and deflections in mm, as in the metrics summaries;
* the response as ``u``, the quantity of the metrics (``u = -w`` for a
  contactor above the beam, ``w`` below: positive away from the contactor),
  or ``w`` or both, always labelled;
* series that differ in line style as well as colour (the Okabe-Ito
  palette), so they survive grey-scale printing and colour-blindness;
* legends outside the data area of figures drawn here.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from .figure import PlotHandles, _finish, _new_figure
from .style import (
    _EXCITATION_AXIS,
    _outside_legend,
    _response_label,
    surface_w,
    _side_legend,
    _style,
    _styled,
    figure_size,
)
from ..exceptions import ParameterError

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..result.protocol import ResultLike

__all__ = ["plot_result", "plot_response", "plot_excitation", "surface_distance"]

_MM = 1e3
_MS = 1e3


def _contact_point(result: ResultLike) -> tuple[float, np.ndarray, str]:
    """Position, sampled w and a label of the first contactor, else the first output point."""
    if len(result.contactors):
        c = result.contactors[0]
        return c.position, np.asarray(result.w_contact[:, 0]), "first contactor"
    return float(result.points[0]), np.asarray(result.w[:, 0]), "first output point"


def _w_at(result: ResultLike, x: float | None) -> tuple[float, np.ndarray]:
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
    result: ResultLike, *, x: float | None = None, side: Literal["above", "below"] = "above"
) -> np.ndarray:
    """The paper's plotted deflection: distance from the contactor surface [m], positive away.

    With a contactor this is its gap function ``g = c - s w(a, t)`` (``s = +1``
    for a contactor above, ``-1`` below; see the model page), i.e. ``u + c``
    with ``u`` the metrics' deflection positive away from the contactor:
    negative values mean contact, as in Figs. 4-8 of Xu & Ervin (2013).
    Without a contactor it is ``-s w(x, t)`` at ``x`` (default the first
    output point), oriented as if a contactor were on ``side`` with no gap.

    Parameters
    ----------
    result : SimulationResult
    x : float, optional, [m]
        Where to read ``w`` without a contactor.
    side : {"above", "below"}
        Orientation without a contactor.

    Returns
    -------
    ndarray, (n_t,), [m]
        At the result's output times.
    """
    if len(result.contactors):
        c = result.contactors[0]
        return c.gap - c.direction * np.asarray(result.w_contact[:, 0])
    _, w = _w_at(result, x)
    s = 1.0 if side == "above" else -1.0
    return -s * w


# --------------------------------------------------------------------------- one result


def _excitation_of(result: Any, excitation: Any) -> Any:
    if excitation is not None:
        return excitation
    sc = getattr(result, "scenario", None)  # when the result carries its scenario
    return getattr(sc, "excitation", None)


def _draw_excitation(ax: Axes, excitation: Any, t: np.ndarray, compact: bool = False) -> Any:
    label, scale = _EXCITATION_AXIS.get(excitation.kind, ("load", 1.0))
    if compact:  # the unit alone names the quantity in a one-column panel
        label = "load " + label[label.index("["):]
    (line,) = ax.plot(t * _MS, excitation.history(t) * scale, color="0.25", lw=1.0)
    ax.set_ylabel(label)
    ax.grid(True, alpha=0.3)
    return line


@_styled
def plot_result(
    result: ResultLike,
    path: str | os.PathLike[str] | None = None,
    *,
    ax: Axes | None = None,
    force: bool = True,
    quantity: Literal["u", "w", "both"] = "u",
    excitation: Any = None,
    size: str | tuple[float, float] = "double",
    title: str | None = None,
    dpi: int = 300,
) -> PlotHandles:
    """Response at the first contactor (or first output point) against time [ms].

    Panels, top to bottom: the excitation (when known), the response with
    the contact intervals shaded, impacts and rebounds marked at their exact
    times and the contactor surface dashed, and the contact force. With
    ``ax`` only the response is drawn there (the force on ``ax.twinx()``).

    Parameters
    ----------
    result : SimulationResult
    path : path-like, optional
        Write the figure there (atomically); the format follows the suffix.
    ax : Axes, optional
    force : bool
        Draw the contact force (only when there is a contactor).
    quantity : {"u", "w", "both"}
        ``"u"``: the metrics' deflection, positive away from the first
        contactor (``u = -w`` above the beam, ``w`` below); ``"w"``: the
        deflection from rest along +w; ``"both"``: the two, labelled.
    excitation : Excitation, optional
        Drawn in a top panel; default the result's scenario's, if it has one.
    size : {"single", "double"} or (width, height)
        One journal column (3.5 in) or two (7 in).
    title : str, optional
    dpi : int
        Resolution of raster files.

    Returns
    -------
    PlotHandles
        ``axes`` = (response[, force][, excitation]); ``artists`` holds
        ``contact_spans``, ``impacts``, ``rebounds``, ``surface``, ``legend``.
    """
    from ..result.metrics import contact_intervals

    if quantity not in ("u", "w", "both"):
        raise ParameterError(f'quantity: must be "u", "w" or "both", got {quantity!r}')
    x, w, where = _contact_point(result)
    has_c = len(result.contactors) > 0
    sign = -result.contactors[0].direction if has_c else 1.0  # u = sign * w
    show_force = force and has_c
    excitation = _excitation_of(result, excitation)
    show_ex = ax is None and excitation is not None and getattr(excitation, "kind", "none") != "none"
    ax_ex = ax_f = None
    if ax is None:
        heights = ([0.7] if show_ex else []) + [2.0] + ([0.9] if show_force else [])
        fig, grid = _new_figure(figure_size(size, 0.22 * sum(heights) + 0.12), len(heights), 1, sharex=True,
                                height_ratios=heights)
        axs = list(grid[:, 0])
        ax_ex = axs.pop(0) if show_ex else None
        ax_w = axs.pop(0)
        ax_f = axs.pop(0) if show_force else None
    else:
        fig = ax.figure
        ax_w = ax
        ax_f = ax.twinx() if show_force else None
    t = np.asarray(result.time)
    tm = t * _MS
    pos = f"x = {x * _MM:.4g} mm"
    lines = []
    if quantity in ("u", "both"):
        lines += ax_w.plot(tm, sign * w * _MM, color="#000000", lw=1.0, label="u" if has_c else "u = w")
    if quantity in ("w", "both"):
        lines += ax_w.plot(tm, w * _MM, color="#0072B2", ls="--", lw=1.0, label="w (from rest)")
    artists: dict[str, Any] = {"contact_spans": [], "impacts": None, "rebounds": None, "surface": None}
    if has_c:
        c = result.contactors[0]
        ysurf = -c.gap if quantity != "w" else surface_w(c)
        artists["surface"] = ax_w.axhline(ysurf * _MM, color="0.4", ls=(0, (4, 2)), lw=0.8, label="contactor surface")
        t_end = float(t[-1])
        for k, (a, b) in enumerate(contact_intervals(result, 0)):
            span = ax_w.axvspan(a * _MS, min(b, t_end) * _MS, color="0.85", lw=0, label="in contact" if k == 0 else None)
            artists["contact_spans"].append(span)
        ymul = sign if quantity != "w" else 1.0
        for kind, marker, face in (("impact", "v", "#D55E00"), ("rebound", "^", "none")):
            times = [e.time for e in result.events if e.kind == kind and e.contactor == 0]
            if times:
                wv = result.displacement([x], times)[0]
                (m,) = ax_w.plot(np.asarray(times) * _MS, ymul * wv * _MM, ls="none", marker=marker, ms=4,
                                 mfc=face, mec="#D55E00", mew=0.8, label=f"{kind}s")
                artists[f"{kind}s"] = m
        if ax_f is not None:
            (lf,) = ax_f.plot(tm, result.contact_force[:, 0], color="#D55E00", ls="-", lw=0.9, label="contact force")
            lines.append(lf)
            ax_f.set_ylabel("contact force F [N]" if size != "single" else "F [N]")
            if ax is None:
                ax_f.grid(True, alpha=0.3)
    if ax_ex is not None:
        artists["excitation"] = _draw_excitation(ax_ex, excitation, t, compact=size == "single")
    ylab = {"u": "u [mm]", "w": "w [mm]", "both": "u, w [mm]"}[quantity]
    if size != "single":
        ylab = "deflection " + ylab
    ax_w.set_ylabel(ylab)
    bottom = ax_f if (ax is None and ax_f is not None) else ax_w
    bottom.set_xlabel("time t [ms]")
    ax_w.grid(True, alpha=0.3)
    side = f", u positive away from the {where}" if has_c and quantity != "w" and size != "single" else ""
    heading = title if title is not None else f"{result.scenario_name}: response at {pos}{side}"
    if ax is None:
        artists["legend"] = _outside_legend(fig, ax_w, ncols=6 if size == "double" else 2)
        (ax_ex or ax_w).set_title(heading)
        fig.align_ylabels()
    else:
        artists["legend"] = _side_legend(ax_w)
        ax_w.set_title(heading)
    axes = tuple(a for a in (ax_w, ax_f, ax_ex) if a is not None)
    return _finish(PlotHandles(fig, axes, tuple(lines), artists), path, dpi)


# --------------------------------------------------------------------------- groups of histories


@_styled
def plot_response(
    results: ResultLike | Sequence[ResultLike],
    *,
    ax: Axes | None = None,
    labels: Sequence[str] | None = None,
    quantity: Literal["surface", "w"] = "surface",
    x: float | None = None,
    side: Literal["above", "below"] = "above",
    time_window: tuple[float, float] | None = None,
    reference: Sequence[tuple[float, str]] = (),
    title: str | None = None,
    size: str | tuple[float, float] = "double",
    path: str | os.PathLike[str] | None = None,
    dpi: int = 300,
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
        paper's plotted quantity; ``-w`` or ``w`` by ``side`` for a run
        without contactor); ``"w"``: deflection from rest at ``x``.
    x : float, optional, [m]
        Position for ``"w"`` or for a run without contactor (default: the
        first contactor, else the first output point).
    side : {"above", "below"}
        Orientation of a run without contactor under ``"surface"``.
    time_window : (float, float), optional, [s]
    reference : sequence of (value [m], label)
        Horizontal reference lines (e.g. published peak values).
    title : str, optional
    size : {"single", "double"} or (width, height)
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
    own = ax is None
    if own:
        fig, grid = _new_figure(figure_size(size, 0.5 if size == "double" else 0.8))
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
        lines.extend(ax.plot(t * _MS, y * _MM, lw=1.0, label=lab, **_style(i)))
    artists: dict[str, Any] = {"reference": []}
    for j, (val, lab) in enumerate(reference):
        artists["reference"].append(
            ax.axhline(val * _MM, color="0.45", ls=(0, (1 + 2 * j, 1.5)), lw=0.8, label=lab)
        )
    if quantity == "surface" and any(len(r.contactors) for r in runs):
        artists["surface"] = ax.axhline(0.0, color="0.4", lw=0.5)
    ax.set_ylabel(_response_label(runs, quantity, side))
    ax.set_xlabel("time t [ms]")
    ax.grid(True, alpha=0.3)
    if title:
        ax.set_title(title)
    artists["legend"] = _outside_legend(fig, ax, ncols=3 if size == "double" else 1) if own else _side_legend(ax)
    return _finish(PlotHandles(fig, (ax,), tuple(lines), artists), path, dpi)


@_styled
def plot_excitation(
    excitations: Sequence[Any],
    *,
    ax: Axes | None = None,
    labels: Sequence[str] | None = None,
    end_time: float = 0.03,
    n: int = 601,
    size: str | tuple[float, float] = "double",
    path: str | os.PathLike[str] | None = None,
    dpi: int = 300,
) -> PlotHandles:
    """Load histories against time [ms] (Fig. 4(a) of the paper).

    Parameters
    ----------
    excitations : sequence of Excitation
        Base accelerations are shown in g (9.80665 m/s^2), forces in N or N/m;
        the axis label follows the first excitation's kind.
    ax, labels, size, path, dpi
        As :func:`plot_response`.
    end_time : float, [s]
    n : int
        Samples.
    """
    own = ax is None
    if own:
        fig, grid = _new_figure(figure_size(size, 0.3 if size == "double" else 0.6))
        ax = grid[0, 0]
    else:
        fig = ax.figure
    t = np.linspace(0.0, end_time, n)
    lines = []
    ylabel, scale = _EXCITATION_AXIS.get(excitations[0].kind if excitations else "", ("load", 1.0))
    for i, ex in enumerate(excitations):
        lab = labels[i] if labels is not None else f"excitation {i}"
        lines.extend(ax.plot(t * _MS, ex.history(t) * scale, lw=1.0, label=lab, **_style(i)))
    ax.set_xlabel("time t [ms]")
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    leg = _outside_legend(fig, ax) if own else _side_legend(ax)
    return _finish(PlotHandles(fig, (ax,), tuple(lines), {"legend": leg}), path, dpi)

