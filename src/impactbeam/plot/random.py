"""Figures of random runs: input and response densities with chi-squared bands, impact and rainflow histograms.

* :func:`plot_input_psd`: the target one-sided density against Welch's
  estimate of the load the solver integrates (the held history), with the
  band that holds a Gaussian estimate of the target with probability
  ``confidence`` (:func:`impactbeam.statistics.welch_psd`);
* :func:`plot_response_psd`: Welch's estimate of the deflection (or the
  bending stress) at a point over the analysis window, with its interval of
  confidence for the true density;
* :func:`plot_impact_histogram`: the peak forces of the impacts (code_aster's
  ``IMPACT`` histogram), per contactor;
* :func:`plot_rainflow_histogram`: rainflow cycles of the exact bending
  stress at a point, counted per range class (log scale);
* :func:`plot_random`: the four as one double-column figure.

Journal style of :mod:`impactbeam.plot` (sizes, fonts, Okabe-Ito series),
``ax=`` to draw into given axes, :class:`PlotHandles` returned.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

from ..exceptions import ParameterError
from .figure import PlotHandles, _finish, _new_figure
from .style import SERIES_STYLES, _log_ticks, _styled, figure_size

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["plot_input_psd", "plot_response_psd", "plot_impact_histogram", "plot_rainflow_histogram", "plot_random"]

_UNIT2 = {"base_acceleration": ("g^2/Hz", 9.80665**-2), "point_force": ("N^2/Hz", 1.0),
          "distributed_force": ("(N/m)^2/Hz", 1.0)}


def _axes(ax: Any, size: Any, aspect: float = 0.75) -> tuple[Any, Any, bool]:
    if ax is None:
        fig, grid = _new_figure(figure_size(size, aspect))
        return fig, grid[0, 0], True
    return ax.figure, ax, False


@_styled
def plot_input_psd(excitation: Any, *, ax: Axes | None = None, confidence: float = 0.95, resolution: float = 1.0,
                   size: str | tuple[float, float] = "single", path: str | os.PathLike[str] | None = None,
                   dpi: int = 300) -> PlotHandles:
    """Target density and the estimate of the synthesised load, with the target's chi-squared band.

    Parameters
    ----------
    excitation : Excitation
        A random excitation (``scenario.excitation``).
    ax : Axes, optional
    confidence : float
        Probability of the band.
    resolution : float, [Hz]
        Bin width of the estimate (segment of ``1 / resolution`` s).
    size : {"single", "double"} or (width, height)
    path : path-like, optional
    dpi : int

    Returns
    -------
    PlotHandles
    """
    from ..statistics import welch_psd

    if getattr(excitation, "shape", None) != "random":
        raise ParameterError('excitation: plot_input_psd needs a random excitation (shape = "random")')
    fig, ax, own = _axes(ax, size)
    unit, scale = _UNIT2[excitation.kind]
    fs = 1.0 / float(excitation.times[1] - excitation.times[0])
    rate = 4.0 * fs  # above the hold's images near fs
    t = excitation.start + np.arange(int(excitation.duration * rate)) / rate
    est = welch_psd(excitation.history(t), rate, segment=int(rate / resolution), confidence=confidence)
    lo_f, hi_f = excitation.psd.band
    f = est["frequency"]
    keep = (f >= lo_f) & (f <= hi_f)
    target = excitation.psd(f[keep]) * excitation.scale**2 * scale
    lo, hi = est["band"]
    band = ax.fill_between(f[keep], lo * target, hi * target, color="0.85", lw=0,
                           label=f"{100 * confidence:.0f} % band ({est['dof']:.0f} dof)")
    (syn,) = ax.plot(f[keep], est["psd"][keep] * scale, color=SERIES_STYLES[1][0], lw=0.6, label="synthesised (Welch)")
    (tgt,) = ax.plot(f[keep], target, color="#000000", lw=1.2, label="target")
    ax.set_xscale("log")
    ax.set_yscale("log")
    _log_ticks(ax.xaxis)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"one-sided PSD [{unit}]")
    ax.grid(True, which="major", alpha=0.3)
    legend = ax.legend(frameon=False, loc="upper center", ncols=1)
    ax.set_ylim(top=ax.get_ylim()[1] * 3)  # room for the legend above the band
    return _finish(PlotHandles(fig, (ax,), (tgt, syn), {"band": band, "legend": legend}), path, dpi)


def _response_history(result: Any, x: float, quantity: str, lo: float, hi: float) -> tuple[np.ndarray, float]:
    from ..statistics.window import top_frequency

    rate = 4.0 * top_frequency(result) / (2 * np.pi)
    t = lo + np.arange(int((hi - lo) * rate)) / rate
    if quantity == "stress":
        vals = np.concatenate([result.bending_stress([x], t[a : a + 4096])[0] for a in range(0, t.size, 4096)])
    else:
        vals = result.solution.sample(np.array([x]), t).w[:, 0]
    return vals, rate


@_styled
def plot_response_psd(result: Any, x: float | None = None, *, quantity: str = "w", ax: Axes | None = None,
                      window: tuple[float, float] | None = None, confidence: float = 0.95, resolution: float = 1.0,
                      size: str | tuple[float, float] = "single", path: str | os.PathLike[str] | None = None,
                      dpi: int = 300) -> PlotHandles:
    """Welch estimate of the response density at a point, with its interval of confidence.

    Parameters
    ----------
    result : SimulationResult
    x : float, optional, [m]
        Position (default: the first output point).
    quantity : {"w", "stress"}
        Deflection [mm^2/Hz] or outer-fibre bending stress [MPa^2/Hz].
    ax : Axes, optional
    window : (float, float), optional, [s]
        Default: the analysis window (:func:`impactbeam.statistics.analysis_window`).
    confidence : float
    resolution : float, [Hz]
        Bin width.
    size : {"single", "double"} or (width, height)
    path : path-like, optional
    dpi : int

    Returns
    -------
    PlotHandles
    """
    from ..statistics import analysis_window, welch_psd

    if quantity not in ("w", "stress"):
        raise ParameterError(f'quantity: must be "w" or "stress", got {quantity!r}')
    x = float(result.points[0] if x is None else x)
    lo, hi = analysis_window(result, window)
    vals, rate = _response_history(result, x, quantity, lo, hi)
    est = welch_psd(vals, rate, segment=min(int(rate / resolution), vals.size), confidence=confidence)
    scale = 1e6 if quantity == "w" else 1e-12  # mm^2, MPa^2
    ex = getattr(getattr(result, "scenario", None), "excitation", None)
    f_top = 2.0 * ex.psd.band[1] if getattr(ex, "shape", None) == "random" else rate / 2
    keep = (est["frequency"] > 0) & (est["frequency"] <= f_top)  # up to twice the load's band
    f, p = est["frequency"][keep], est["psd"][keep] * scale
    lo_b, hi_b = est["band"]
    fig, ax, own = _axes(ax, size)
    band = ax.fill_between(f, p / hi_b, p / lo_b, color="0.85", lw=0, label=f"{100 * confidence:.0f} % interval")
    (line,) = ax.plot(f, p, color="#000000", lw=0.8, label=f"Welch, {est['dof']:.0f} dof")
    ax.set_xscale("log")
    ax.set_yscale("log")
    _log_ticks(ax.xaxis)
    ax.set_xlabel("frequency [Hz]")
    what = "w" if quantity == "w" else "bending stress"
    unit = "mm^2/Hz" if quantity == "w" else "MPa^2/Hz"
    ax.set_ylabel(f"PSD of {what} at x = {x * 1e3:.4g} mm [{unit}]")
    ax.grid(True, which="major", alpha=0.3)
    legend = ax.legend(frameon=False, loc="lower left")
    return _finish(PlotHandles(fig, (ax,), (line,), {"band": band, "legend": legend}), path, dpi)


@_styled
def plot_impact_histogram(run: Any, *, ax: Axes | None = None, bins: int = 20,
                          size: str | tuple[float, float] = "single", path: str | os.PathLike[str] | None = None,
                          dpi: int = 300) -> PlotHandles:
    """Histogram of the impacts' peak forces per contactor (probability density).

    Parameters
    ----------
    run : SimulationResult, SteadyState or ImpactStatistics
    ax : Axes, optional
    bins : int
        Classes over the range of the peak forces.
    size : {"single", "double"} or (width, height)
    path : path-like, optional
    dpi : int

    Returns
    -------
    PlotHandles
    """
    from ..statistics import ImpactStatistics, impact_statistics

    stats = run if isinstance(run, ImpactStatistics) else impact_statistics(run)
    fig, ax, own = _axes(ax, size)
    peaks = [np.array([r["peak_force"] for r in stats.impacts if r["contactor"] == c["contactor"]])
             for c in stats.contactors]
    drawn = []
    top = max((float(p.max()) for p in peaks if p.size), default=1.0)
    edges = np.linspace(0.0, top, bins + 1)
    for i, p in enumerate(peaks):
        if p.size:
            color, ls, _ = SERIES_STYLES[i % len(SERIES_STYLES)]
            _, _, patches = ax.hist(p, bins=edges, density=True, histtype="step", color=color, ls=ls,
                                    label=f"contactor {i} ({p.size} impacts)")
            drawn.append(patches[0])
    ax.set_xlabel("peak impact force [N]")
    ax.set_ylabel("probability density [1/N]")
    ax.grid(True, alpha=0.3)
    legend = ax.legend(frameon=False, loc="upper right") if drawn else None
    return _finish(PlotHandles(fig, (ax,), tuple(drawn), {"legend": legend}), path, dpi)


@_styled
def plot_rainflow_histogram(result: Any, x: float | None = None, *, ax: Axes | None = None, bins: int = 30,
                            window: tuple[float, float] | None = None, size: str | tuple[float, float] = "single",
                            path: str | os.PathLike[str] | None = None, dpi: int = 300) -> PlotHandles:
    """Rainflow cycles of the exact bending stress at a point, per range class (counts, log scale).

    Parameters
    ----------
    result : SimulationResult
    x : float, optional, [m]
        Position (default: the first ``[fatigue]`` point, else the clamped end x = 0).
    ax : Axes, optional
    bins : int
    window : (float, float), optional, [s]
    size : {"single", "double"} or (width, height)
    path : path-like, optional
    dpi : int

    Returns
    -------
    PlotHandles
    """
    from ..statistics import analysis_window, rainflow_cycles, stress_turning_points

    if x is None:
        fat = getattr(getattr(result, "scenario", None), "fatigue", None)
        x = fat.points[0] if fat is not None else 0.0
    lo, hi = analysis_window(result, window)
    _, values = stress_turning_points(result, float(x), lo, hi)
    rng, _, count = rainflow_cycles(values)
    fig, ax, own = _axes(ax, size)
    edges = np.linspace(0.0, float(rng.max(initial=0.0)) * 1e-6 or 1.0, bins + 1)
    _, _, patches = ax.hist(rng * 1e-6, bins=edges, weights=count, color="0.55", edgecolor="#000000", lw=0.4,
                            label=f"{count.sum():.1f} cycles in {hi - lo:.4g} s")
    ax.set_yscale("log")
    ax.set_xlabel(f"stress range at x = {float(x) * 1e3:.4g} mm [MPa]")
    ax.set_ylabel("cycles (half cycles count 1/2)")
    ax.grid(True, alpha=0.3)
    legend = ax.legend(frameon=False, loc="upper right")
    return _finish(PlotHandles(fig, (ax,), tuple(patches), {"legend": legend}), path, dpi)


@_styled
def plot_random(result: Any, *, x: float | None = None, path: str | os.PathLike[str] | None = None,
                dpi: int = 300) -> PlotHandles:
    """The four figures of a random run in one double-column figure (2 x 2).

    Parameters
    ----------
    result : SimulationResult
        A run with a random excitation.
    x : float, optional, [m]
        Point of the response density (default: the first output point).
    path : path-like, optional
    dpi : int

    Returns
    -------
    PlotHandles
    """
    ex = result.scenario.excitation if getattr(result, "scenario", None) is not None else None
    fig, grid = _new_figure(figure_size("double", 0.75), 2, 2)
    plot_input_psd(ex, ax=grid[0, 0])
    plot_response_psd(result, x, ax=grid[0, 1])
    plot_impact_histogram(result, ax=grid[1, 0])
    plot_rainflow_histogram(result, ax=grid[1, 1])
    return _finish(PlotHandles(fig, tuple(grid.ravel()), ()), path, dpi)
