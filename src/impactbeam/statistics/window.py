"""The part of a run that the statistics describe, and the time grid that resolves its solution.

A random load starts the beam from rest: the response is stationary only
after the free state's slowest mode has forgotten that start. The statistics
of a run with a random excitation therefore begin ``settling`` seconds after
the load does, with

.. math:: t_{settle} = \\ln(10^3) / \\min_n(\\xi_n \\omega_n),

the time over which the transient's mean square, which decays as
``exp(-2 xi omega t)``, falls below 1e-3 of its initial value for every mode
(single-mode estimate; a run much shorter than a few ``t_settle`` is
reported). Any other run is described whole: ``[0, t_end]``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from .._warnings import emit_user_level_warning
from ..result.timegrid import scan_times, top_frequency

if TYPE_CHECKING:
    from ..result.protocol import ResultLike

# scan_times and top_frequency: from result.timegrid (their one copy), kept here for the statistics
__all__ = ["analysis_window", "settling_time", "scan_times", "top_frequency", "SETTLE_DECADES"]

#: Decades by which the start-up transient's mean square has decayed when the statistics begin.
SETTLE_DECADES = 3.0


def _excitation(result: ResultLike) -> Any:
    """The run's load: the solution's own (the packed problem's may be another run's of the same structure)."""
    own = getattr(result.solution, "excitation", None)
    return own if own is not None else getattr(getattr(result, "scenario", None), "excitation", None)


def settling_time(result: ResultLike) -> float:
    """``ln(10^3) / min(xi_n omega_n)`` of the free state's retained modes [s] (module docstring).

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    float
        inf when a mode is undamped (or the solution has no free-state model).
    """
    packed = getattr(result.solution, "packed", None)
    if packed is None:
        return math.inf
    decay = np.asarray(packed.space.state(()).dyn.decay, dtype=float)
    elastic = decay[np.asarray(packed.space.state(()).modes.omega) > 0]
    slowest = float(np.min(elastic)) if elastic.size else 0.0
    return SETTLE_DECADES * math.log(10.0) / slowest if slowest > 0 else math.inf


def analysis_window(result: ResultLike, window: tuple[float, float] | None = None) -> tuple[float, float]:
    """``(lo, hi)`` [s] of the statistics: given, or the stationary part of a random run, else the whole run.

    Parameters
    ----------
    result : SimulationResult
    window : (float, float), optional
        An explicit window inside ``[0, t_end]``.

    Returns
    -------
    (float, float)
    """
    t_end = float(result.solution.t_end)
    if window is not None:
        lo, hi = float(window[0]), min(float(window[1]), t_end)
        if not (0.0 <= lo < hi):
            from ..exceptions import ParameterError

            raise ParameterError(f"window: expected 0 <= start < end <= {t_end:g} s, got {window!r}")
        return lo, hi
    ex = _excitation(result)
    if ex is None or getattr(ex, "shape", None) != "random" or not ex.active:
        return 0.0, t_end
    settle = settling_time(result)
    start = float(ex.start)
    if not start + settle < start + 0.5 * (t_end - start):
        emit_user_level_warning(
            f"statistics: the run lasts {t_end - start:.3g} s after the random load starts, less than twice the "
            f"settling time of the slowest mode ({settle:.3g} s); the statistics include the start from rest "
            "(simulate longer for stationary values)"
        )
        return start, t_end
    return start + settle, t_end
