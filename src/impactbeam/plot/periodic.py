"""Figures of periodic motion: bifurcation diagrams, frequency-response curves and bifurcation maps.

Each function reads its object's attributes only (a
:class:`~impactbeam.periodic.bifurcation.BifurcationDiagram`, a
:class:`~impactbeam.periodic.frf.FrequencyResponse`, a map dataset), so this
package never imports the drivers that make them.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

__all__ = ["plot_bifurcation", "plot_frequency_response", "plot_map"]


def plot_bifurcation(diagram: Any, path: str | os.PathLike[str] | None = None, *,
                     axes: Any = None, scale: float = 1e3) -> Any:
    """The classic diagram: strobe samples against the parameter, impacts per period beneath.

    Up and down sweeps are drawn in two colours. Returns the figure; with
    ``path`` it is also written (and closed).

    Parameters
    ----------
    diagram : BifurcationDiagram
        From :func:`impactbeam.bifurcation`.
    path : str or path-like, optional
        Write the figure there (format from the suffix).
    axes : sequence of two matplotlib Axes, optional
        The strobe panel and the impacts-per-period panel.
    scale : float
        Multiplies w (default 1e3: mm).
    """
    import matplotlib.pyplot as plt

    from .style import display_label

    xlabel, xs = display_label(diagram.parameter, diagram.unit)
    if axes is None:
        fig, axes = plt.subplots(2, 1, sharex=True, figsize=(7.0, 5.6), height_ratios=(3, 1), layout="constrained")
    fig = axes[0].figure
    colors = {"up": "tab:blue", "down": "tab:orange"}
    offset = {"up": -0.12, "down": 0.12}
    vals = np.array([p.value for p in diagram.points]) * xs
    step = float(np.min(np.diff(np.unique(vals)))) if np.unique(vals).size > 1 else 1.0
    for direction in ("up", "down"):
        pts = [p for p in diagram.points if p.direction == direction]
        if not pts:
            continue
        x = np.concatenate([np.full(p.state.strobe.size, p.value * xs) for p in pts])
        y = np.concatenate([p.state.strobe for p in pts]) * scale
        if direction == "up":  # hollow circles, so the down sweep's dots show inside where they agree
            axes[0].scatter(x, y, s=10.0, facecolors="none", edgecolors=colors[direction], linewidths=0.6,
                            label="sweep up")
        else:
            axes[0].scatter(x, y, s=2.0, color=colors[direction], linewidths=0, label="sweep down")
        xi = np.array([p.value for p in pts]) * xs + offset[direction] * step
        axes[1].plot(xi, [p.state.impacts_per_period if p.state.period else np.nan for p in pts], "o", ms=2.5,
                     color=colors[direction])
        bad = [p for p in pts if not p.state.period]
        if bad:
            axes[1].plot([p.value * xs for p in bad], [p.state.impacts_per_period for p in bad], "x", ms=3,
                         color=colors[direction], label=f"{direction}: no period")
    axes[0].set_ylabel("w at strobe point [mm]" if scale == 1e3 else "w at strobe point")
    axes[0].legend(loc="best", fontsize="small", markerscale=2)
    axes[1].set_ylabel("impacts / period")
    axes[1].set_xlabel(xlabel)
    if path is not None:
        from .figure import save_and_close

        save_and_close(fig, path)
    return fig


def plot_frequency_response(fr: Any, path: str | os.PathLike[str] | None = None, *,
                            ax: Any = None, scale: float = 1e3, gap: float | None = None) -> Any:
    """max and min of ``w`` against frequency, up and down sweeps, the linear FRF dashed.

    Returns the figure; with ``path`` it is written (atomically) and closed.

    Parameters
    ----------
    fr : FrequencyResponse
        From :func:`impactbeam.frequency_response`.
    path : str or path-like, optional
        Write the figure there (format from the suffix).
    ax : matplotlib Axes, optional
    scale : float
        Multiplies w (default 1e3: mm).
    gap : float, optional, [m]
        Draws the contactor's surface as a horizontal line at this w.
    """
    import matplotlib.pyplot as plt

    if ax is None:
        fig, ax = plt.subplots(figsize=(7.0, 4.4), layout="constrained")
    fig = ax.figure
    order = np.argsort(fr.frequency, kind="stable")
    fs = fr.frequency[order]
    ax.plot(fs, fr.linear[order] * scale, "k--", lw=0.8, label="linear FRF |H| A (no contact)")
    ax.plot(fs, -fr.linear[order] * scale, "k--", lw=0.8)
    for direction, color, mk in (("up", "tab:blue", "^"), ("down", "tab:orange", "v")):
        m = fr.direction == direction
        if m.any():
            ax.plot(fr.frequency[m], fr.max[m] * scale, mk, ms=3, color=color, label=f"max, sweep {direction}")
            ax.plot(fr.frequency[m], fr.min[m] * scale, mk, ms=3, color=color, mfc="none",
                    label=f"min, sweep {direction}")
    if gap is not None:
        ax.axhline(gap * scale, color="0.5", lw=0.8, ls=":", label="gap")
    ax.set_xlabel("forcing frequency [Hz]")
    ax.set_ylabel("w at the strobe point [mm]" if scale == 1e3 else "w at the strobe point")
    ax.legend(fontsize="small", loc="best")
    if path is not None:
        from .figure import save_and_close

        save_and_close(fig, path)
    return fig


def plot_map(ds: Any, path: str | os.PathLike[str] | None = None) -> Any:
    """Two panels over (x, y): the response period (0: none found) and the impacts per period.

    Returns the figure; with ``path`` it is written (atomically) and closed.

    Parameters
    ----------
    ds : xarray.Dataset
        From :func:`impactbeam.bifurcation_map`.
    path : str or path-like, optional
        Write the figure there (format from the suffix).
    """
    import matplotlib.pyplot as plt

    from .style import display_label

    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.0), sharey=True, layout="constrained")
    xlabel, xs = display_label(ds.attrs["x_parameter"], ds["x"].attrs.get("units"))
    ylabel, ys = display_label(ds.attrs["y_parameter"], ds["y"].attrs.get("units"))
    x, y = ds["x"].values * xs, ds["y"].values * ys
    period = np.where(ds["done"].values[:, None], ds["period"].values, -1).astype(float)
    period[period < 0] = np.nan
    top = max(2, int(np.nanmax(period)) if np.isfinite(period).any() else 2)
    cmap = plt.get_cmap("tab10", top + 1)
    m0 = axes[0].pcolormesh(x, y, period, shading="nearest", cmap=cmap, vmin=-0.5, vmax=top + 0.5)
    fig.colorbar(m0, ax=axes[0], label="period (0: none found)", ticks=range(top + 1))
    m1 = axes[1].pcolormesh(x, y, ds["impacts_per_period"].values, shading="nearest", cmap="viridis")
    fig.colorbar(m1, ax=axes[1], label="impacts per period")
    for ax in axes:
        ax.set_xlabel(xlabel)
    axes[0].set_ylabel(ylabel)
    if path is not None:
        from .figure import save_and_close

        save_and_close(fig, path)
    return fig
