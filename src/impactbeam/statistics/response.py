"""Mean, RMS and standard deviation of the deflection and velocity over the analysis window.

The time averages ``(1/T) int w dt`` and ``(1/T) int w^2 dt`` are the
trapezoid rule on a uniform grid of ``RMS_SAMPLES_PER_PERIOD = 4`` samples per
period of the highest retained frequency of the exact solution. ``w^2``
holds frequencies up to twice the highest one, at most the grid's Nyquist
frequency, so no product of two modes aliases onto the mean (a term exactly
at the Nyquist frequency alternates in sign on the grid and averages out);
what is left is the end correction of the trapezoid rule, of order one
sample's share, ``1/n``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from .window import analysis_window, scan_times

if TYPE_CHECKING:
    from ..result.protocol import ResultLike

__all__ = ["response_statistics", "time_average"]

_CHUNK = 65536
#: Samples per period of the highest retained frequency for the time averages (module docstring).
RMS_SAMPLES_PER_PERIOD = 4.0


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
    t = scan_times(result, lo, hi, breaks=False, per_period=RMS_SAMPLES_PER_PERIOD)
    dt = np.diff(t)
    acc = {k: np.zeros(np.size(x)) for k in ("mean", "mean_square", "velocity_mean", "velocity_mean_square")}
    for a in range(0, t.size - 1, _CHUNK):
        b = min(a + _CHUNK, t.size - 1)
        s = result.solution.sample(np.asarray(x, dtype=float), t[a : b + 1])
        h = dt[a:b, None]
        for key, v in (("mean", s.w), ("mean_square", s.w**2), ("velocity_mean", s.w_t),
                       ("velocity_mean_square", s.w_t**2)):
            acc[key] += np.sum(0.5 * (v[1:] + v[:-1]) * h, axis=0)
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
