"""The compiled loop's status codes and the layout of its carried state (no numba here).

:mod:`~impactbeam.solver._loop` returns a status code and keeps everything
it carries from one call to the next in two arrays, ``ic`` (integers) and
``fc`` (floats), at these indices; the Python side
(:mod:`~impactbeam.solver.engine`, :mod:`~impactbeam.solver.batch`) reads
them from here, so that importing it does not import numba.
"""

from __future__ import annotations

__all__ = ["DONE", "CHATTER", "NEED_STATE", "NEED_TRANSFER", "NEED_SPACE", "CHECKPOINT", "CASE_DONE",
           "I_SLOT", "I_PIECE", "I_JUST", "I_PENDING", "I_NSEG", "I_NEV", "I_NJUMP", "I_NSLOTS", "I_NTR",
           "I_WARN_C", "REQ_A", "REQ_B", "I_RESUME", "I_EVALS", "I_SAME", "I_WARN_N", "I_USED", "N_INT",
           "F_T", "F_LAST_T", "F_WARN_T", "F_WARN_MOVED", "F_WARN_SCALE", "F_TAU", "F_E_SUM", "F_E_PEAK", "N_FLOAT",
           "MOVED_WARN", "MOVED_FLOOR", "ENERGY_WARN", "TOUCH", "TOUCH_SCALE", "TOUCH_SCALE_COUNT", "touch_depth"]

DONE, CHATTER, NEED_STATE, NEED_TRANSFER, NEED_SPACE, CHECKPOINT = 0, 1, 2, 3, 4, 5
CASE_DONE = 6  # a batch finished a case and stops after each (a continuation)
# integer carry
I_SLOT, I_PIECE, I_JUST, I_PENDING, I_NSEG, I_NEV, I_NJUMP, I_NSLOTS, I_NTR = 0, 1, 2, 3, 4, 5, 6, 7, 8
I_WARN_C, REQ_A, REQ_B, I_RESUME, I_EVALS, I_SAME, I_WARN_N, I_USED = 9, 10, 11, 12, 13, 14, 15, 16
N_INT = 17
# float carry
F_T, F_LAST_T, F_WARN_T, F_WARN_MOVED, F_WARN_SCALE, F_TAU = 0, 1, 2, 3, 4, 5
F_E_SUM, F_E_PEAK = 6, 7  # the switches' |energy changes| summed, and the largest energy before or after one
N_FLOAT = 8
# a switch whose projection moves a contactor's deflection by more than MOVED_WARN of its scale (the larger of
# its gap and deflection, at least MOVED_FLOOR touch tolerances: 1e-6 L, for a zero gap at rest) is counted
# and warned about (engine.projection_warning), by the engine and the solve_ivp path alike
MOVED_WARN = 0.05
MOVED_FLOOR = 1e6
# switches whose projections change the N-mode model's energy by more than ENERGY_WARN of the largest energy at a
# switch, their changes' magnitudes summed, are warned about (engine.energy_warning): with per-state modes too
# few for a stiff stop, the projections (paper eq. 12) gain or lose energy at every impact, and the impact
# count and forces go wrong before any single switch moves a deflection by MOVED_WARN
ENERGY_WARN = 0.05
# the touch tolerance, as a fraction of the beam's length: a row within TOUCH L of its surface touches it (tol_h)
TOUCH = 1e-12
# an impact whose peak compression is at most TOUCH_SCALE touch tolerances is resolved only at that scale; the
# metrics count such impacts (_metrics.run_metrics) once a run has TOUCH_SCALE_COUNT contacts, and warn of them
# from TOUCH_SCALE_COUNT on (engine.touch_scale_warning), alone or in a batch
TOUCH_SCALE = 100
TOUCH_SCALE_COUNT = 10


def touch_depth(length: float) -> float:
    """The depth [m] below which an impact is resolved only at the touch tolerance's scale (beam ``length`` [m])."""
    return TOUCH_SCALE * TOUCH * float(length)
