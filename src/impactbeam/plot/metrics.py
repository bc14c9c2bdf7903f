"""The metrics drawn where they are read: a response with every metric and impact-table column marked.

:func:`plot_metrics` is the figure of the metrics page of the documentation
(Case 3): ``u`` at the first contactor with the contactor's surface, the
contact intervals and each metric of :meth:`SimulationResult.metrics` marked
at its value, and beneath it the contact force with the columns of the impact
table (``start``, ``end``, ``duration``, ``peak_force``, ``impulse``) marked
on one contact.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

from ..exceptions import ParameterError
from .figure import PlotHandles, _finish, _new_figure
from .style import _styled, figure_size

if TYPE_CHECKING:
    from ..result.protocol import ResultLike

__all__ = ["plot_metrics"]

_MM = 1e3
_MS = 1e3
_MARK = "#D55E00"  # Okabe-Ito vermilion: the marks
_SPAN = "#0072B2"  # Okabe-Ito blue: the durations


def _span(ax: Any, t0: float, t1: float, y: float, text: str, color: str = _SPAN, dy: float = 4.0) -> Any:
    """A double-headed arrow from ``t0`` to ``t1`` [ms] at height ``y`` [mm], labelled above its middle."""
    arrow = ax.annotate("", xy=(t1, y), xytext=(t0, y),
                        arrowprops={"arrowstyle": "<->", "color": color, "lw": 0.8, "shrinkA": 0, "shrinkB": 0})
    ax.annotate(text, xy=(0.5 * (t0 + t1), y), xytext=(0, dy), textcoords="offset points", ha="center",
                va="bottom", color=color)
    return arrow


def _label(ax: Any, x: float, y: float, text: str, dx: float, dy: float, ha: str = "left") -> Any:
    """A text at an offset [pt] from a point, with a thin leader line to it."""
    return ax.annotate(text, xy=(x, y), xytext=(dx, dy), textcoords="offset points", ha=ha, va="center",
                       color=_MARK, arrowprops={"arrowstyle": "-", "color": _MARK, "lw": 0.5})


def _deepest(result: ResultLike, x: float, sign: float, a: float, b: float) -> float:
    """Time [s] of the least ``u = sign w(x)`` in ``[a, b]`` on the exact solution (a fine grid)."""
    t = np.linspace(a, b, 2001)
    return float(t[np.argmin(sign * result.displacement([x], t)[0])])


@_styled
def plot_metrics(
    result: ResultLike,
    path: str | os.PathLike[str] | None = None,
    *,
    time_window: tuple[float, float] | None = None,
    size: str | tuple[float, float] = "double",
    title: str | None = None,
    dpi: int = 300,
) -> PlotHandles:
    """The response ``u`` with each metric marked at its value, and the contact force with the impact table.

    ``u`` is the metrics' deflection at the first contactor, positive away
    from it (``u = -w`` for a contactor above the beam, ``w`` below), so the
    beam touches the contactor when ``u = -gap``. Marked on ``u``:
    ``max_response`` at ``t_max``, ``first_impact_time``, ``free_duration``
    (the free interval around ``t_max``), ``contact_duration`` and
    ``min_response`` (the first contact after ``t_max``), ``max_penetration``
    (the deepest compression of the run, below the surface) and
    ``n_impacts``. On the force panel, the columns of
    :meth:`SimulationResult.impacts` for the first contact after ``t_max``:
    ``start``, ``end``, ``duration``, ``peak_force`` and ``impulse`` (the
    shaded area).

    Parameters
    ----------
    result : SimulationResult
        A run with at least one contactor and a contact after its peak.
    path : path-like, optional
        Write the figure there (atomically); the format follows the suffix.
    time_window : (float, float), optional, [s]
        Default: from 0 to a little past the second contact after the peak.
    size : {"single", "double"} or (width, height)
    title : str, optional
    dpi : int
        Resolution of raster files.

    Returns
    -------
    PlotHandles
        ``axes`` = (response, force); ``artists`` holds one entry per metric
        and per impact-table column (``"max_response"``, ``"t_max"``, ...,
        ``"impulse"``), and ``"surface"``, ``"contact_spans"``.

    Raises
    ------
    ParameterError
        The run has no contactor, or no contact after its peak.
    """
    from ..result.metrics import contact_intervals

    if not len(result.contactors):
        raise ParameterError("plot_metrics: the run has no contactor, so there are no contact metrics to mark")
    m = result.metrics()
    if m["contact_duration"] is None or m["min_response"] is None:
        raise ParameterError("plot_metrics: the run has no complete contact after its peak (contact_duration is null)")
    c = result.contactors[0]
    sign = -c.direction
    t = np.asarray(result.time)
    u = sign * np.asarray(result.w_contact[:, 0])
    force = np.asarray(result.contact_force[:, 0])
    iv = contact_intervals(result, 0)
    after = [(a, b) for a, b in iv if a >= m["t_max"]]
    ca, cb = after[0]
    if time_window is None:
        end = after[1][1] if len(after) > 1 else cb
        time_window = (0.0, min(float(t[-1]), end + 0.25 * (end - ca)))
    t0, t1 = time_window
    sel = (t >= t0) & (t <= t1)
    fig, grid = _new_figure(figure_size(size, 0.62), 2, 1, sharex=True, height_ratios=[2.2, 1.0])
    ax, axf = grid[0, 0], grid[1, 0]
    (line,) = ax.plot(t[sel] * _MS, u[sel] * _MM, color="#000000", lw=1.0, label="u")
    art: dict[str, Any] = {"contact_spans": []}
    gap_mm = -c.gap * _MM
    art["surface"] = ax.axhline(gap_mm, color="0.4", ls=(0, (4, 2)), lw=0.8)
    for a, b in iv:
        if b > t0 and a < t1:
            for axis in (ax, axf):
                art["contact_spans"].append(axis.axvspan(max(a, t0) * _MS, min(b, t1) * _MS, color="0.88", lw=0))
    top, bottom = m["max_response"] * _MM, m["min_response"] * _MM
    height = top - bottom
    tm = m["t_max"] * _MS
    (art["max_response"],) = ax.plot([tm], [top], "o", ms=4, color=_MARK)
    _label(ax, tm, top, f"max_response = {top:.4f} mm", 16, 8)
    art["t_max"] = ax.axvline(tm, color=_MARK, lw=0.6, ls=":")
    ax.annotate("t_max", xy=(tm, bottom - 0.02 * height), xytext=(2, 0), textcoords="offset points",
                ha="left", va="top", color=_MARK)
    tf = m["first_impact_time"] * _MS
    art["first_impact_time"] = ax.axvline(tf, color=_MARK, lw=0.6, ls="--")
    ax.annotate("first_impact_time", xy=(tf, top), xytext=(2, 0), textcoords="offset points", ha="left",
                va="top", color=_MARK, rotation=90)
    prev_end = max([b for a, b in iv if b <= m["t_max"]], default=0.0) * _MS
    art["free_duration"] = _span(ax, prev_end, ca * _MS, 0.55 * top, "free_duration")
    ax.annotate("contactor surface, u = -gap", xy=(cb * _MS, gap_mm), xytext=(10, -3), textcoords="offset points",
                ha="left", va="top", color="0.3")
    art["contact_duration"] = _span(ax, ca * _MS, cb * _MS, bottom - 0.12 * height, "contact_duration", dy=-11)
    t_min = _deepest(result, c.position, sign, ca, cb) * _MS
    (art["min_response"],) = ax.plot([t_min], [bottom], "v", ms=4, color=_MARK)
    _label(ax, t_min, bottom, f"min_response = {bottom:.4f} mm", 24, -10)
    rows = [r for r in m["impacts"] if r["contactor"] == 0]
    deepest = max(rows, key=lambda r: r["peak_force"])
    t_pen = _deepest(result, c.position, sign, deepest["start"], deepest["end"] or float(t[-1])) * _MS
    pen = m["max_penetration"] * _MM
    art["max_penetration"] = ax.annotate("", xy=(t_pen, gap_mm - pen), xytext=(t_pen, gap_mm), arrowprops={
        "arrowstyle": "|-|", "color": _SPAN, "lw": 0.8, "mutation_scale": 2.0, "shrinkA": 0, "shrinkB": 0})
    ax.annotate(f"max_penetration = {pen:.4f} mm", xy=(t_pen, gap_mm - 0.5 * pen), xytext=(-6, 0),
                textcoords="offset points", ha="right", va="center", color=_SPAN)
    shown = sum(1 for a, _ in iv if t0 <= a <= t1)
    art["n_impacts"] = ax.text(0.995, 0.97, f"n_impacts = {m['n_impacts']} in {t[-1] * _MS:g} ms "
                               f"({shown} shown)", transform=ax.transAxes, ha="right", va="top")
    ax.set_ylim(bottom - 0.3 * height, top + 0.2 * height)
    ax.set_ylabel("u [mm] (positive away\nfrom the contactor)")
    ax.grid(True, alpha=0.3)
    # force panel: the impact table's columns on the first contact after the peak
    row = next(r for r in rows if r["start"] == ca)
    axf.plot(t[sel] * _MS, force[sel], color=_MARK, lw=0.9)
    inside = (t >= ca) & (t <= cb)
    art["impulse"] = axf.fill_between(t[inside] * _MS, force[inside], color=_MARK, alpha=0.25, lw=0)
    fmax = row["peak_force"]
    art["start"] = axf.axvline(ca * _MS, color=_SPAN, lw=0.6, ls=":")
    art["end"] = axf.axvline(cb * _MS, color=_SPAN, lw=0.6, ls=":")
    (art["peak_force"],) = axf.plot([t_min], [fmax], "o", ms=3.5, color=_MARK)
    _label(axf, t_min, fmax, f"peak_force = {fmax:.3f} N", 14, -2)
    art["duration"] = _span(axf, ca * _MS, cb * _MS, 1.15 * fmax, "start, end, duration", dy=2)
    axf.annotate(f"impulse = {row['impulse'] * 1e3:.3f} mN s (area)", xy=(cb * _MS, 0.3 * fmax), xytext=(6, 0),
                 textcoords="offset points", ha="left", va="center", color=_MARK)
    axf.set_ylim(0.0, 1.6 * fmax)
    axf.set_ylabel("contact force F [N]")
    axf.set_xlabel("time t [ms]")
    axf.grid(True, alpha=0.3)
    ax.set_xlim(t0 * _MS, t1 * _MS)
    x_mm = c.position * _MM
    ax.set_title(title if title is not None else
                 f"{result.scenario_name}: the metrics on u at the first contactor (x = {x_mm:.4g} mm)")
    fig.align_ylabels()
    return _finish(PlotHandles(fig, (ax, axf), (line,), art), path, dpi)
