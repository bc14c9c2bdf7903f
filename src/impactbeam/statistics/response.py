"""Mean, RMS and standard deviation of the deflection and velocity over the analysis window.

The time averages ``(1/T) int w dt`` and ``(1/T) int w^2 dt`` (and those
of ``w_t``) are integrated by the composite Gauss-Legendre rule
(:func:`~impactbeam.result.timegrid.gauss_rule`): the window is cut at every
event (where a derivative of the response jumps, and with per-state modes
the state itself, eq. 12; :func:`~impactbeam.result.timegrid.cuts`), and
each piece into panels of at most one period of the highest retained
frequency of the visited states, 8 nodes each. A
mode's square oscillates twice per such panel, which the rule integrates
within 1.3e-5; a transient is integrated as well as a steady oscillation (a
trapezoid rule on 4 samples per period, exact for a stationary record, was
3e-3 off on short transient runs and 17 % on a fast over-damped one). Where a
visited state decays faster than a panel resolves, the panels after each cut
are graded (:func:`~impactbeam.result.timegrid.gauss_panels`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ..result.timegrid import PANELS_PER_CALL, cuts, gauss_panels, gauss_rule, solution_rates
from .window import analysis_window

if TYPE_CHECKING:
    from ..result.protocol import ResultLike

__all__ = ["response_statistics", "time_average"]



def time_average(result: ResultLike, x: np.ndarray, lo: float, hi: float) -> dict[str, np.ndarray]:
    """Time averages of ``w``, ``w^2``, ``w_t`` and ``w_t^2`` at positions ``x`` over ``[lo, hi]``.

    Parameters
    ----------
    result : SimulationResult
    x : ndarray, [m]
    lo, hi : float, [s]

    Returns
    -------
    dict
        ``mean``, ``mean_square`` [m, m^2], ``velocity_mean``, ``velocity_mean_square``, arrays over ``x``.
    """
    omega, decay = solution_rates(result)
    at = cuts(result, lo, hi)
    left, right = gauss_panels(at[:-1], at[1:], 2.0 * math.pi / max(omega, 1e-300), decay)
    acc = {k: np.zeros(np.size(x)) for k in ("mean", "mean_square", "velocity_mean", "velocity_mean_square")}
    for a in range(0, left.size, PANELS_PER_CALL):
        t, wt = gauss_rule(left[a : a + PANELS_PER_CALL], right[a : a + PANELS_PER_CALL])
        s = result.solution.sample(np.asarray(x, dtype=float), t)
        for key, v in (("mean", s.w), ("mean_square", s.w**2), ("velocity_mean", s.w_t),
                       ("velocity_mean_square", s.w_t**2)):
            acc[key] += wt @ v
    span = hi - lo
    return {k: v / span for k, v in acc.items()}


def response_statistics(result: ResultLike, window: tuple[float, float] | None = None) -> dict[str, Any]:
    """Deflection and velocity statistics at the output points over the analysis window.

    Parameters
    ----------
    result : SimulationResult
    window : (float, float), optional, [s]
        Default :func:`~impactbeam.statistics.window.analysis_window`.

    Returns
    -------
    dict
        ``window`` [s], ``points`` [m], and per point ``mean`` [m], ``rms`` [m]
        (root mean square about zero), ``std`` [m] (about the mean),
        ``rms_velocity`` [m/s], ``mean_square``, ``velocity_mean_square``.
    """
    lo, hi = analysis_window(result, window)
    x = np.asarray(result.points, dtype=float)
    avg = time_average(result, x, lo, hi)
    ms, vms, mean = avg["mean_square"], avg["velocity_mean_square"], avg["mean"]
    return {
        "window": [lo, hi], "points": x.tolist(), "mean": mean.tolist(), "rms": np.sqrt(ms).tolist(),
        "std": np.sqrt(np.maximum(ms - mean**2, 0.0)).tolist(), "rms_velocity": np.sqrt(vms).tolist(),
        "mean_square": ms.tolist(), "velocity_mean_square": vms.tolist(),
    }
