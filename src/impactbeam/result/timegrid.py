"""Time grids and quadrature rules that resolve the exact solution, not the output grid.

The scans of the stress and its turning points (:func:`scan_times`), the
time averages of the statistics and the energy ledger (:func:`gauss_panels`,
:func:`gauss_rule`, :func:`cumulative_power`) all take their rule from here.

Between events the response is a sum of the visited states' coordinates
(paper eq. 10): oscillations ``e^{-a t} cos(w t)`` of frequencies up to
``omega_max``, and, in an over-damped coordinate (modal damping above
critical, a stiff dashpot, Rayleigh damping of the high modes), exponentials
``e^{-(a + w) t}`` that can decay much faster than one period of
``omega_max``. A grid of ``per_period`` samples per period of
``omega_max`` resolves the oscillations; a fast exponential started at an
event or a break of the load dies within a few of its time constants
``1/D``, between two samples of that grid, where a quadrature and a scan
for turning points would miss it. (Found on a stiff stop with a
coefficient of restitution engaged at t = 0: the tip's velocity falls by a
factor of ten within one step of the uniform grid, and the RMS velocity was
11 % off.)

So when the fastest decay rate ``D`` of the visited states exceeds
:data:`GRADED_ABOVE` samples' worth of the uniform step ``h`` (``D h >
0.1``), a scan also holds, after every event and every break of the load,
the offsets ``GRADE_FIRST / D * GRADE_RATIO^k``, until their spacing
reaches ``h`` (at ``11 h``: slower coordinates that ``h`` still resolves
poorly have decayed by then); its local steps are 0.09 of the distance to
the break. The Gauss panels are graded likewise, ``1/D, 2/D, 4/D, ...``
after each cut (:func:`gauss_panels`).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .protocol import ResultLike

__all__ = ["per_state", "solution_rates", "top_frequency", "scan_times", "graded_offsets", "gauss_panels", "gauss_rule",
           "cuts", "cumulative_power", "SAMPLES_PER_PERIOD", "GAUSS_NODES", "PANELS_PER_CALL"]

#: Samples per period of the highest retained frequency in the scans of the stress and of its turning points.
SAMPLES_PER_PERIOD = 8
#: The grid is graded after breaks when the fastest decay rate times the uniform step exceeds this.
GRADED_ABOVE = 0.1
#: First offset after a break, in units of ``1/D``, and the growth ratio of the offsets.
GRADE_FIRST, GRADE_RATIO = 0.02, 1.1
#: Nodes of each Gauss-Legendre panel (:func:`gauss_rule`).
GAUSS_NODES = 8
#: Panels per call of ``sample`` in the quadratures (65,536 nodes: ~10 MB of work arrays).
PANELS_PER_CALL = 8192


def solution_rates(result: ResultLike) -> tuple[float, float]:
    """Highest angular frequency and fastest decay rate of the visited states' coordinates.

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    (float, float)
        ``omega_max`` [rad/s] and ``D`` [1/s]: the largest ``a`` of an
        under-damped or critical coordinate, ``a + w`` of an over-damped one
        (0 for a solution without a packed model: the ``solve_ivp`` path).
    """
    packed = getattr(result.solution, "packed", None)
    if packed is None:
        from ..modal import mode_set

        return float(np.max(mode_set(result.beam, (), result.n_modes).omega)), 0.0  # type: ignore[attr-defined]
    from ..solver._elementary import REG_OVER

    n = packed.nslots
    fast = packed.dec[:n] + np.where(packed.reg[:n] == REG_OVER, packed.wdh[:n], 0.0)
    return float(np.max(packed.om[:n])), float(np.max(fast))


def top_frequency(result: ResultLike) -> float:
    """Highest angular frequency [rad/s] of the visited states' retained modes (:func:`solution_rates`).

    Parameters
    ----------
    result : SimulationResult
    """
    return solution_rates(result)[0]


def graded_offsets(decay: float, step: float) -> np.ndarray:
    """Offsets after a break that resolve ``e^{-decay t}`` (module docstring); empty when ``step`` does.

    Parameters
    ----------
    decay : float, [1/s]
        The fastest decay rate ``D``.
    step : float, [s]
        The uniform grid's step ``h``.

    Returns
    -------
    ndarray, [s]
    """
    if not decay * step > GRADED_ABOVE:
        return np.zeros(0)
    last = step * GRADE_RATIO / (GRADE_RATIO - 1.0)  # their spacing reaches the step there
    k = int(math.ceil(math.log(last * decay / GRADE_FIRST) / math.log(GRADE_RATIO)))
    return GRADE_FIRST / decay * GRADE_RATIO ** np.arange(k + 1)


def scan_times(result: ResultLike, lo: float, hi: float, *, breaks: bool = True,
               per_period: float = SAMPLES_PER_PERIOD) -> np.ndarray:
    """A time grid of ``[lo, hi]`` resolving the exact solution (module docstring).

    ``per_period`` samples per period of the highest retained frequency
    (default ``SAMPLES_PER_PERIOD``), plus, with ``breaks``, every event and
    every break of the load's time pieces (where a derivative of the
    response may jump; with per-state modes, whose switches move the state,
    the instant before each event too), and, when a visited state decays
    faster than that grid resolves, those instants and the graded offsets
    after each of them (with or without ``breaks``), sorted and unique.

    Parameters
    ----------
    result : SimulationResult
    lo, hi : float, [s]
    breaks : bool
        Add the events and the load's piece boundaries.
    per_period : float
        Samples per period of the highest retained frequency.

    Returns
    -------
    ndarray, [s]
    """
    omega, decay = solution_rates(result)
    dt = 2.0 * math.pi / max(omega, 1e-300) / per_period
    n = max(int(math.ceil((hi - lo) / dt)), 1)
    t = np.linspace(lo, hi, n + 1)
    graded = graded_offsets(decay, (hi - lo) / n)
    if not (breaks or graded.size):
        return t
    events = np.array([e.time for e in result.events], dtype=float)
    at = [np.array([lo]), events]
    pieces = getattr(result.solution, "pieces", None)
    if pieces is not None:
        at.append(np.asarray(pieces[0], dtype=float))
    starts = np.concatenate(at)
    extra = [starts]
    if per_state(result):  # the state jumps at an event (eq. 12): its value from the left too
        extra.append(np.nextafter(events, -np.inf))
    if graded.size:
        near = starts[(starts >= lo - graded[-1]) & (starts <= hi)]
        extra.append((near[:, None] + graded[None, :]).ravel())
    cat = np.concatenate([t, *extra])
    return np.unique(cat[(cat >= lo) & (cat <= hi)])


def per_state(result: ResultLike) -> bool:
    """Whether the run's states have their own modes (the paper's basis, or a beam free to move as a rigid
    body), whose switches move the state by the projection of eq. (12).

    Parameters
    ----------
    result : SimulationResult
        Of the exact engine or of the ``solve_ivp`` path.
    """
    sol = result.solution  # the exact solution's packed problem, or the solve_ivp path's integrator
    space = getattr(getattr(sol, "packed", None), "space", None) or getattr(getattr(sol, "ref", None), "space", None)
    return bool(getattr(space, "per_state", False))


def _jump_times(result: ResultLike) -> np.ndarray:
    """The events and, with per-state modes, the segment starts that are not breaks of the load; sorted, kept
    with the solution (a random record has ~10^6 segments, and every contact of it asks)."""
    memo = result.solution.__dict__
    if "_jump_times" not in memo:
        at = np.array([e.time for e in result.events], dtype=float)
        if per_state(result):
            starts = np.asarray(result.solution.segment_starts, dtype=float)
            pieces = getattr(result.solution, "pieces", None)
            at = np.concatenate([at, starts if pieces is None else np.setdiff1d(starts, pieces[0])])
        memo["_jump_times"] = np.unique(at)
    return memo["_jump_times"]


def cuts(result: ResultLike, lo: float, hi: float) -> np.ndarray:
    """Where an integration rule's panels must end in ``[lo, hi]``: the ends and every event.

    A derivative of the response jumps at an event (the contact force starts or, with a dashpot, jumps); with
    per-state modes the state itself jumps by the projection of eq. (12), also at a switch undone at its
    instant, which records no event: then every segment start that is not a break of the load is a cut too
    (a load's break moves no state; a random record has thousands).

    Parameters
    ----------
    result : SimulationResult
    lo, hi : float, [s]

    Returns
    -------
    ndarray, [s]
        Sorted and unique, ``lo`` first and ``hi`` last.
    """
    at = _jump_times(result)
    inside = at[np.searchsorted(at, lo, side="right"): np.searchsorted(at, hi, side="left")]
    return np.concatenate([[lo], inside, [hi]])


def gauss_panels(a: np.ndarray, b: np.ndarray, panel: float, decay: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Panels covering each interval ``[a_i, b_i]``: at most ``panel`` long, graded where a fast decay starts.

    When a visited state decays faster than a panel resolves (``decay * panel > 1``), each interval's first
    panels are ``1/decay, 2/decay, 4/decay, ...`` long (a transient started at its beginning, an event or a
    jump of the state, dies within them; :data:`GAUSS_NODES` nodes integrate ``e^{-decay t}`` on them to
    round-off); the rest are equal.

    Parameters
    ----------
    a, b : ndarray, [s]
        The intervals (``a_i < b_i``; they need not touch).
    panel : float, [s]
        Longest panel.
    decay : float, [1/s]
        Fastest decay rate of the solution (:func:`solution_rates`).

    Returns
    -------
    (ndarray, ndarray)
        Left and right ends of the panels, in the order of their left ends.
    """
    lead = (2.0 ** np.arange(int(math.ceil(math.log2(decay * panel))) + 1) - 1.0) / decay \
        if decay * panel > 1.0 else np.zeros(1)  # the graded panels' edges, the last panel / 2 or more long
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    g = np.searchsorted(lead, b - a, side="left")  # graded edges inside each interval (lead[0] = 0: one at least)
    g = np.where(a + lead[np.maximum(g - 1, 0)] < b, g, g - 1).clip(1)  # never a panel of zero length
    start = a + lead[g - 1]  # where the equal panels begin
    m = np.maximum(np.ceil((b - start) / panel), 1.0).astype(np.int64)
    # the graded panels [a + lead[k], a + lead[k + 1]], k < g - 1, then m equal panels on [start, b]
    gi = np.repeat(np.arange(a.size), g - 1)
    gk = np.arange(gi.size) - np.repeat(np.cumsum(g - 1) - (g - 1), g - 1)
    ui = np.repeat(np.arange(a.size), m)
    uk = (np.arange(ui.size) - np.repeat(np.cumsum(m) - m, m)).astype(float)
    span = (b - start)[ui]
    u_left = start[ui] + span * (uk / m[ui])
    u_right = np.where(uk + 1.0 == m[ui], b[ui], start[ui] + span * ((uk + 1.0) / m[ui]))
    left = np.concatenate([a[gi] + lead[gk], u_left])
    right = np.concatenate([a[gi] + lead[gk + 1], u_right])
    order = np.argsort(left, kind="stable")
    return left[order], right[order]


def gauss_rule(left: np.ndarray, right: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of the composite Gauss-Legendre rule on the panels ``[left_i, right_i]``.

    :data:`GAUSS_NODES` nodes per panel: exact for polynomials of degree 15, and within 1.3e-5 for a
    sinusoid of two periods per panel (``w^2`` of a mode at the panel's frequency).

    Parameters
    ----------
    left, right : ndarray, [s]

    Returns
    -------
    (ndarray, ndarray)
        Nodes [s] and weights [s], panel by panel.
    """
    xg, wg = np.polynomial.legendre.leggauss(GAUSS_NODES)
    half = 0.5 * (np.asarray(right) - np.asarray(left))[:, None]
    mid = 0.5 * (np.asarray(right) + np.asarray(left))[:, None]
    return (mid + half * xg[None, :]).ravel(), (half * wg[None, :]).ravel()


def cumulative_power(result: ResultLike, times: np.ndarray) -> np.ndarray:
    """The work of the load, the beam's damping and the dashpots from ``times[0]`` to each of ``times``.

    The powers of :meth:`~impactbeam.solver.solution.Solution.sample` (``energy=True``) are integrated on
    the exact solution, not on the output grid: Gauss panels (:func:`gauss_panels`) end at every output time,
    every cut (:func:`cuts`) and every break of the load (where the load's power jumps), so the ledger of
    ``result.energy`` is the same whatever the output step.

    Parameters
    ----------
    result : SimulationResult
    times : ndarray, [s]
        Increasing.

    Returns
    -------
    ndarray, (n_t, 3), [J]
        Input work, dissipated energy and dashpot work (NaN after a run that stopped early).
    """
    t = np.asarray(times, dtype=float)
    out = np.zeros((t.size, 3))
    if t.size < 2:
        return out
    lo, hi = float(t[0]), float(t[-1])
    omega, decay = solution_rates(result)
    breaks = [cuts(result, lo, hi), t]
    pieces = getattr(result.solution, "pieces", None)
    if pieces is not None:
        p = np.asarray(pieces[0], dtype=float)
        breaks.append(p[(p > lo) & (p < hi)])
    at = np.unique(np.concatenate(breaks))
    left, right = gauss_panels(at[:-1], at[1:], 2.0 * math.pi / max(omega, 1e-300), decay)
    after = np.searchsorted(t, left, side="right")  # each panel adds to the output times after its start
    origin = np.zeros(1)
    for a in range(0, left.size, PANELS_PER_CALL):
        nodes, weights = gauss_rule(left[a : a + PANELS_PER_CALL], right[a : a + PANELS_PER_CALL])
        power = result.solution.sample(origin, nodes, energy=True).energies[:, 2:5]
        per_panel = (weights[:, None] * power).reshape(-1, GAUSS_NODES, 3).sum(axis=1)
        np.add.at(out, after[a : a + PANELS_PER_CALL], per_panel)
    return np.cumsum(out, axis=0)
