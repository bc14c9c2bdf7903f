"""Response metrics of a simulation (the paper's Table 2 quantities and more).

Definitions (the project's public contract for ``simulate --json``). On ``u = w`` at the first contactor for a
contactor ``below`` (``u = -w`` for one ``above``; ``u = w`` at the first output
point without contactor), so that ``u`` is positive away from the contactor:

* ``max_response``: max of ``u``; ``t_max`` its time;
* ``free_duration``: the free interval containing ``t_max``;
* ``contact_duration``, ``min_response``: the first contact interval after
  ``t_max`` and the minimum of ``u`` in it;
* ``max_penetration``: the largest compression of the first contactor over the run;
* ``n_impacts``: contact intervals begun; ``first_impact_time``: the first one's start;
* ``energy_residual``: the energy balance residual of the N-mode solution,
  ``total(0) + input work - dissipated - total(end)``, which within segments
  is zero exactly, so it is minus the sum of the energy changes at the
  switches, less what the contactors' dashpots dissipate at a release
  (:meth:`~impactbeam.solver.solution.PiecewiseSolution.release_losses`).

Every extremum is the maximum of the exact N-mode solution (branch and bound
on the closed form, :mod:`impactbeam.solver._dense`), to 1e-12 of the beam
length, and impulses are integrals in closed form: nothing depends on the
output time step.

Per impact (``impacts``): contactor, start, end, duration, peak force and
impulse of the contact force ``k d + c d'`` (``d`` the compression, ``c`` the
contactor's dashpot).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .protocol import ResultLike
    from ..model.beam import Contactor

__all__ = ["compute_metrics", "contact_forces", "contact_intervals", "response_point", "METRIC_UNITS", "METRIC_DISPLAY"]

#: Units of the scalar metrics (for labelled outputs).
METRIC_UNITS = {
    "max_response": "m",
    "t_max": "s",
    "first_impact_time": "s",
    "n_impacts": "1",
    "free_duration": "s",
    "contact_duration": "s",
    "min_response": "m",
    "max_penetration": "m",
    "n_events": "1",
    "energy_residual": "J",
}


#: How summaries show the Table-2 metrics: (key, label, scale, unit), lengths in mm, times in ms.
METRIC_DISPLAY = (
    ("max_response", "max response", 1e3, "mm"),
    ("t_max", "at time", 1e3, "ms"),
    ("free_duration", "free duration", 1e3, "ms"),
    ("contact_duration", "contact duration", 1e3, "ms"),
    ("min_response", "min response", 1e3, "mm"),
    ("first_impact_time", "first impact", 1e3, "ms"),
    ("n_impacts", "impacts", 1.0, ""),
    ("max_penetration", "max penetration", 1e3, "mm"),
    ("max_bending_stress", "max bending stress", 1e-6, "MPa"),
    ("max_bending_stress_time", "at time", 1e3, "ms"),
    ("max_bending_stress_position", "at x", 1e3, "mm"),
)


def contact_intervals(result: ResultLike, contactor: int = 0) -> list[tuple[float, float]]:
    """Contact intervals ``(start, end)`` of one contactor; ``end`` is inf if still engaged.

    Parameters
    ----------
    result : SimulationResult
    contactor : int
        Index of the contactor.

    Returns
    -------
    list of (float, float), [s]
    """
    out: list[tuple[float, float]] = []
    start: float | None = None
    for ev in result.events:
        if ev.contactor != contactor:
            continue
        if ev.kind == "impact":
            start = ev.time
        elif start is not None:
            out.append((start, ev.time))
            start = None
    if start is not None:
        out.append((start, math.inf))
    return out


def response_point(contactors: Sequence[Contactor], points: Sequence[float]) -> tuple[float, float]:
    """Where the metrics read the response, and the sign of ``u = sign * w`` there.

    The one rule for ``u`` (module docstring): at the first contactor,
    ``u = -s w`` with ``s`` its :attr:`~impactbeam.model.beam.Contactor.direction`
    (positive away from it); without contactors ``u = w`` at the first output point.

    Parameters
    ----------
    contactors : sequence of Contactor
    points : sequence of float, [m]
        The output points.

    Returns
    -------
    x : float, [m]
    sign : float
        +1 or -1.
    """
    if contactors:
        c0 = contactors[0]
        return c0.position, -c0.direction
    return float(points[0]), 1.0


def _metric_point(result: ResultLike) -> tuple[float, float]:
    """Position of the metrics and the sign making ``u`` positive away from the contactor."""
    return response_point(result.contactors, result.points)


def compute_metrics(result: ResultLike, *, impacts: bool = True) -> dict[str, Any]:
    """The metrics dictionary of :meth:`SimulationResult.metrics`.

    All extrema of one call are found in one batch of the compiled kernel
    (:meth:`~impactbeam.solver.solution.Solution.extrema`); with the
    per-impact table, the minimum of ``u`` in a contact interval of the first
    contactor is read from that interval's peak compression
    (``u = -s w(a)`` there, so ``min u = -(peak compression + gap)``).

    Parameters
    ----------
    result : SimulationResult
    impacts : bool
        Include the per-impact table (``"impacts"``).

    Returns
    -------
    dict
        Keys of :data:`METRIC_UNITS` (SI values, None where undefined), the
        events and, with ``impacts``, the per-impact table.
    """
    sol = result.solution
    x, sign = _metric_point(result)
    t_end = sol.t_end
    out: dict[str, Any] = {k: None for k in METRIC_UNITS}
    out["events"] = [{"time": e.time, "kind": e.kind, "contactor": e.contactor} for e in result.events]
    out["n_events"] = len(result.events)
    rows = _contact_rows(result) if impacts else []
    queries: list[tuple] = [(x, 0.0, t_end, sign, 0.0, None)]
    if not result.contactors:
        queries.append((x, 0.0, t_end, -sign, 0.0, None))
    elif not impacts:  # with the table, the largest compression is the largest of its peaks
        c0 = result.contactors[0]
        queries.append((c0.position, 0.0, t_end, c0.direction, -c0.direction * c0.gap, 0))
    first_peak = len(queries)
    queries += [_peak_query(result, ci, a, be) for ci, a, _, be in rows]
    ext = sol.extrema(queries)
    peaks = ext[first_peak:, 0]
    if not np.isfinite(ext[0, 0]):
        if impacts:
            out["impacts"] = []
        return out
    out["max_response"] = float(ext[0, 0])
    t_max = float(ext[0, 1])
    out["t_max"] = t_max
    out["energy_residual"] = -float(np.sum(result.energy_jumps)) - float(np.sum(sol.release_losses()[1]))
    if not result.contactors:
        out["min_response"] = -float(ext[1, 0])
    else:
        deepest = ext[1, 0] if not impacts else max((p for (ci, *_), p in zip(rows, peaks) if ci == 0), default=-np.inf)
        out["max_penetration"] = max(float(deepest), 0.0) if np.isfinite(deepest) else 0.0
        _contact_metrics(result, out, t_max, rows, peaks)
    if impacts:
        out["impacts"] = _impact_table(result, rows, peaks)
    return out


def _contact_metrics(result: ResultLike, out: dict[str, Any], t_max: float, rows: list, peaks) -> None:
    """Impact count, first impact, free and contact durations and the minimum in contact."""
    sol = result.solution
    c0 = result.contactors[0]
    iv = contact_intervals(result, 0)
    out["n_impacts"] = len(iv)
    out["first_impact_time"] = iv[0][0] if iv else None
    prev_end, nxt_start = 0.0, None
    for a, b in iv:
        if b <= t_max:
            prev_end = b
        elif a >= t_max:
            nxt_start = a
            break
    out["free_duration"] = (nxt_start - prev_end) if nxt_start is not None else None
    after = [(a, b) for a, b in iv if a >= t_max]
    if not after:
        return
    a, b = after[0]
    if math.isfinite(b):
        out["contact_duration"] = b - a
    if a >= sol.t_end:
        return
    known = [p for (ci, ra, _, _), p in zip(rows, peaks) if ci == 0 and ra == a]
    if known:
        peak = float(known[0])
    else:  # the same query as the per-impact table's, so both paths give the same bits
        peak = float(sol.extrema([_peak_query(result, 0, a, min(b, sol.t_end))])[0, 0])
    if np.isfinite(peak):
        out["min_response"] = -(peak + c0.gap)


def _contact_rows(result: ResultLike) -> list[tuple[int, float, float, float]]:
    """(contactor, start, end, end clipped to the solution) of every contact interval."""
    t_end = result.solution.t_end
    rows = []
    for ci in range(len(result.contactors)):
        for a, b in contact_intervals(result, ci):
            if min(b, t_end) > a:
                rows.append((ci, a, b, min(b, t_end)))
    return rows


def _peak_query(result: ResultLike, ci: int, a: float, be: float) -> tuple:
    """Extremum query for the largest compression ``s w(a) - gap`` of contactor ``ci`` on ``[a, be]``."""
    c = result.contactors[ci]
    return (c.position, a, be, c.direction, -c.direction * c.gap, ci)


def contact_forces(result: ResultLike, intervals: Sequence[tuple[int, float, float]],
                   compressions: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Peak force and impulse of the contact force over intervals, in closed form.

    The force of contactor ``c`` while engaged is ``k d + c_d d'`` with the
    compression ``d = s w(a) - gap`` and ``c_d`` its dashpot (0 without,
    :attr:`~impactbeam.solver.solution.PiecewiseSolution.dashpots`): the peak
    is the exact maximum of that force on the interval, the impulse its
    integral ``k int d dt + c_d [d]``.

    Parameters
    ----------
    result : SimulationResult
    intervals : sequence of (int, float, float)
        ``(contactor, start, end)`` [s], each inside one contact of that contactor.
    compressions : ndarray, optional
        The largest compression on each interval, when already known (the
        peak force of a contactor without dashpot is ``k`` times it).

    Returns
    -------
    peaks, impulses : ndarray, [N], [N s]
    """
    sol = result.solution
    n = len(intervals)
    if not n:
        return np.zeros(0), np.zeros(0)
    dash = getattr(sol, "dashpots", np.zeros(len(result.contactors)))
    cs = [result.contactors[ci] for ci, _, _ in intervals]
    k = np.array([c.stiffness for c in cs])
    ints = sol.integrals([(c.position, a, b) for c, (_, a, b) in zip(cs, intervals)])
    impulses = k * (np.array([c.direction for c in cs]) * ints - np.array([c.gap * (b - a) for c, (_, a, b)
                                                                           in zip(cs, intervals)]))
    rate = np.array([dash[ci] for ci, _, _ in intervals]) / k
    queries = [_peak_query(result, ci, a, b) + (r,) for (ci, a, b), r in zip(intervals, rate)]
    ask = [i for i in range(n) if compressions is None or rate[i] > 0.0]
    peaks = np.full(n, np.nan) if compressions is None else np.asarray(compressions, dtype=float).copy()
    if ask:
        peaks[ask] = sol.extrema([queries[i] for i in ask])[:, 0]
    forced = np.flatnonzero(rate > 0.0)
    if forced.size:  # the dashpot's share of the impulse: c [d] over each interval, one evaluation for all
        xs = np.unique([cs[i].position for i in forced])
        ts = np.array([t for i in forced for t in intervals[i][1:]])
        w = sol.sample(xs, ts).w
        col = np.searchsorted(xs, [cs[i].position for i in forced])
        for j, i in enumerate(forced):
            d = cs[i].direction * w[2 * j: 2 * j + 2, col[j]] - cs[i].gap
            impulses[i] += dash[intervals[i][0]] * float(d[1] - d[0])
    return k * np.maximum(peaks, 0.0), impulses


def _impact_table(result: ResultLike, rows: list, peaks) -> list[dict[str, Any]]:
    """Duration, peak force and impulse of every contact interval (exact, closed form; :func:`contact_forces`)."""
    if not rows:
        return []
    force_peaks, impulses = contact_forces(result, [(ci, a, be) for ci, a, _, be in rows], peaks)
    out = []
    for (ci, a, b, be), peak, impulse in zip(rows, force_peaks, impulses):
        out.append(
            {
                "contactor": ci,
                "start": a,
                "end": b if math.isfinite(b) else None,
                "duration": (b - a) if math.isfinite(b) else None,
                "peak_force": float(peak),
                "impulse": float(impulse),
            }
        )
    out.sort(key=lambda d: (d["start"], d["contactor"]))
    return out
