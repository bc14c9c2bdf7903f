"""Figures of periodic motion: bifurcation diagrams, frequency-response curves and bifurcation maps.

Each function reads its object's attributes only (a
:class:`~impactbeam.periodic.bifurcation.BifurcationDiagram`, a
:class:`~impactbeam.periodic.frf.FrequencyResponse`, a map dataset), so this
package never imports the drivers that make them. The figures are in the
journal style of the package (:mod:`.style`: column widths, 8 pt fonts,
Okabe-Ito colours with distinct markers, legends outside the data) and are
bare figures on the Agg canvas, never pyplot's global state; each function
returns a :class:`~impactbeam.plot.figure.PlotHandles`.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from .figure import PlotHandles, _finish, _new_figure
from .style import _outside_legend, _styled, display_label, figure_size, surface_w

__all__ = ["plot_bifurcation", "plot_frequency_response", "plot_map"]

#: (colour, marker) of the two sweep directions: Okabe-Ito blue and vermilion, told apart without colour
#: by the marker (hollow circles / triangles up for the up sweep, dots / triangles down for the down sweep).
_SWEEP = {"up": "#0072B2", "down": "#D55E00"}


def _legend_handles(*axes: Any) -> tuple[list[Any], list[str]]:
    handles, labels = [], []
    for ax in axes:
        h, lab = ax.get_legend_handles_labels()
        handles += h
        labels += lab
    return handles, labels


@_styled
def plot_bifurcation(diagram: Any, path: str | os.PathLike[str] | None = None, *,
                     scale: float = 1e3, x_scale: float | None = None, xlabel: str | None = None,
                     size: str | tuple[float, float] = "double", dpi: int = 300) -> PlotHandles:
    """The classic diagram: strobe samples against the parameter, impacts per response period beneath.

    Up sweeps are hollow circles, down sweeps dots (the down sweep shows
    inside the up sweep's circles where the two agree). In the lower panel a
    value whose period was found is a dot (impacts per response period), one
    without a period a cross (the mean impacts per forcing period); all four
    marks are in the legend.

    Parameters
    ----------
    diagram : BifurcationDiagram
        From :func:`impactbeam.bifurcation`.
    path : str or path-like, optional
        Write the figure there (format from the suffix).
    scale : float
        Multiplies w (default 1e3: mm).
    x_scale : float, optional
        Multiplies the parameter (default: its display unit, e.g. mm for a gap).
    xlabel : str, optional
        Default: the parameter's name with its unit.
    size : {"single", "double"} or (width, height)
    dpi : int
        Resolution of raster files.

    Returns
    -------
    PlotHandles
        ``axes`` = (strobe panel, impacts panel); ``artists["legend"]``.
    """
    label, xs = display_label(diagram.parameter, diagram.unit)
    xs = xs if x_scale is None else x_scale
    fig, grid = _new_figure(figure_size(size, 0.62), 2, 1, sharex=True, height_ratios=(3, 1))
    ax, ax_n = grid[0, 0], grid[1, 0]
    vals = np.array([p.value for p in diagram.points]) * xs
    uniq = np.unique(vals)
    step = float(np.min(np.diff(uniq))) if uniq.size > 1 else 1.0
    lines = []
    for direction, offset in (("up", -0.12), ("down", 0.12)):
        pts = [p for p in diagram.points if p.direction == direction]
        if not pts:
            continue
        color = _SWEEP[direction]
        x = np.concatenate([np.full(p.state.strobe.size, p.value * xs) for p in pts])
        y = np.concatenate([p.state.strobe for p in pts]) * scale
        if direction == "up":
            lines.append(ax.scatter(x, y, s=9.0, facecolors="none", edgecolors=color, linewidths=0.6,
                                    label="strobe, sweep up"))
        else:
            lines.append(ax.scatter(x, y, s=1.5, color=color, linewidths=0, label="strobe, sweep down"))
        xi = np.array([p.value for p in pts]) * xs + offset * step
        found = np.array([bool(p.state.period) for p in pts])
        ipp = np.array([p.state.impacts_per_period for p in pts], dtype=float)
        ax_n.plot(xi[found], ipp[found], "o", ms=2.0, color=color, ls="none",
                  label=f"impacts per response period, {direction}")
        if (~found).any():
            ax_n.plot(xi[~found], ipp[~found], "x", ms=3.0, mew=0.8, color=color, ls="none",
                      label=f"no period found: impacts per forcing period, {direction}")
    unit = "mm" if scale == 1e3 else ("m" if scale == 1.0 else "")
    ax.set_ylabel(f"w at the strobe point [{unit}]" if unit else "w at the strobe point")
    ax_n.set_ylabel("impacts /\nperiod")
    ax_n.set_xlabel(xlabel if xlabel is not None else label)
    for a in (ax, ax_n):
        a.grid(True, alpha=0.3)
    handles, labels = _legend_handles(ax, ax_n)
    legend = fig.legend(handles, labels, loc="outside lower center", ncols=2, frameon=False, markerscale=1.5)
    fig.align_ylabels()
    return _finish(PlotHandles(fig, (ax, ax_n), tuple(lines), {"legend": legend}), path, dpi)


def _limits(lo: float, hi: float, pad: float = 0.08) -> tuple[float, float]:
    span = hi - lo if hi > lo else max(abs(hi), 1.0)
    return lo - pad * span, hi + pad * span


@_styled
def plot_frequency_response(fr: Any, path: str | os.PathLike[str] | None = None, *, ax: Any = None,
                            scale: float = 1e3, contactor: Any = None, size: str | tuple[float, float] = "double",
                            dpi: int = 300) -> PlotHandles:
    """max and min of ``w`` against the forcing frequency, up and down sweeps, with the linear FRF dashed.

    The axis is scaled to the simulated extremes (with a margin), not to the
    linear resonance: without contact the linear curve's peak is many times
    the impacting response, and an axis that holds it flattens the impacting
    branch. Where the linear curve leaves the axis its peak is written on the
    figure.

    Parameters
    ----------
    fr : FrequencyResponse
        From :func:`impactbeam.frequency_response`.
    path : str or path-like, optional
        Write the figure there (format from the suffix).
    ax : matplotlib Axes, optional
    scale : float
        Multiplies w (default 1e3: mm).
    contactor : Contactor, optional
        Draws its surface as a horizontal line at its ``w``: ``-gap`` for a
        contactor ``below`` the beam, ``+gap`` above (it should be the
        contactor at the strobe point ``fr.point``).
    size : {"single", "double"} or (width, height)
    dpi : int
        Resolution of raster files.

    Returns
    -------
    PlotHandles
        ``artists`` holds ``"surface"`` (the line, or None), ``"linear_peak"``
        (the note of an off-scale linear peak, or None) and ``"legend"``.
    """
    own = ax is None
    if own:
        fig, grid = _new_figure(figure_size(size, 0.55))
        ax = grid[0, 0]
    fig = ax.figure
    order = np.argsort(fr.frequency, kind="stable")
    fs = fr.frequency[order]
    lin = fr.linear[order] * scale
    if len(fr.linear_curve[0]):  # the curve on a fine grid: a resonance between swept values is not missed
        fs, lin = fr.linear_curve[0], fr.linear_curve[1] * scale
    (l_lin,) = ax.plot(fs, lin, color="#000000", ls="--", lw=0.8, label="linear FRF |H| A (no contact)")
    ax.plot(fs, -lin, color="#000000", ls="--", lw=0.8)
    lines = [l_lin]
    for direction, mk in (("up", "^"), ("down", "v")):
        m = fr.direction == direction
        if m.any():
            color = _SWEEP[direction]
            lines += ax.plot(fr.frequency[m], fr.max[m] * scale, mk, ms=2.5, color=color, ls="none",
                             label=f"max, sweep {direction}")
            lines += ax.plot(fr.frequency[m], fr.min[m] * scale, mk, ms=2.5, color=color, mfc="none", mew=0.6,
                             ls="none", label=f"min, sweep {direction}")
    art: dict[str, Any] = {"surface": None, "linear_peak": None}
    ys = [fr.max * scale, fr.min * scale]
    if contactor is not None:
        w_s = surface_w(contactor) * scale
        side = "+gap" if w_s > 0 else "-gap" if w_s < 0 else "0"
        art["surface"] = ax.axhline(w_s, color="0.45", lw=0.8, ls=":", label=f"contactor surface, w = {side}")
        ys.append(np.array([w_s]))
    finite = np.concatenate([y[np.isfinite(y)] for y in ys])
    lo, hi = _limits(float(finite.min()), float(finite.max())) if finite.size else (-1.0, 1.0)
    ax.set_ylim(lo, hi)
    k = int(np.argmax(lin)) if lin.size else 0
    if lin.size and lin[k] > hi:
        art["linear_peak"] = ax.annotate(
            f"linear peak {lin[k]:.3g} mm\nat {fs[k]:.4g} Hz (off scale)" if scale == 1e3 else
            f"linear peak {lin[k]:.3g} at {fs[k]:.4g} Hz (off scale)",
            xy=(fs[k], hi), xytext=(6, -4), textcoords="offset points", ha="left", va="top")
    ax.set_xlabel("forcing frequency [Hz]")
    where = f"x = {fr.point * 1e3:.4g} mm" if np.isfinite(fr.point) else "the strobe point"
    ax.set_ylabel(f"w at {where} [mm]" if scale == 1e3 else f"w at {where}")
    ax.grid(True, alpha=0.3)
    art["legend"] = _outside_legend(fig, ax, ncols=3) if own else ax.legend(fontsize="small", loc="best")
    return _finish(PlotHandles(fig, (ax,), tuple(lines), art), path, dpi)


@_styled
def plot_map(ds: Any, path: str | os.PathLike[str] | None = None, *, size: str | tuple[float, float] = "double",
             dpi: int = 300) -> PlotHandles:
    """Two panels over (x, y): the response period (0: none found) and the impacts per period.

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`impactbeam.bifurcation_map`.
    path : str or path-like, optional
        Write the figure there (format from the suffix).
    size : {"single", "double"} or (width, height)
    dpi : int
        Resolution of raster files.

    Returns
    -------
    PlotHandles
    """
    from matplotlib import colormaps

    fig, grid = _new_figure(figure_size(size, 0.42), 1, 2, sharey=True)
    axes = grid[0]
    xlabel, xs = display_label(ds.attrs["x_parameter"], ds["x"].attrs.get("units"))
    ylabel, ys = display_label(ds.attrs["y_parameter"], ds["y"].attrs.get("units"))
    x, y = ds["x"].values * xs, ds["y"].values * ys
    period = np.where(ds["done"].values[:, None], ds["period"].values, -1).astype(float)
    period[period < 0] = np.nan
    top = max(2, int(np.nanmax(period)) if np.isfinite(period).any() else 2)
    cmap = colormaps["tab10"].resampled(top + 1)
    m0 = axes[0].pcolormesh(x, y, period, shading="nearest", cmap=cmap, vmin=-0.5, vmax=top + 0.5)
    fig.colorbar(m0, ax=axes[0], label="period (0: none found)", ticks=range(top + 1))
    m1 = axes[1].pcolormesh(x, y, ds["impacts_per_period"].values, shading="nearest", cmap="viridis")
    fig.colorbar(m1, ax=axes[1], label="impacts per period")
    for ax in axes:
        ax.set_xlabel(xlabel)
    axes[0].set_ylabel(ylabel)
    return _finish(PlotHandles(fig, tuple(axes), (), {"period": m0, "impacts_per_period": m1}), path, dpi)
