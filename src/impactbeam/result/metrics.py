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

from .timegrid import cuts, per_state

if TYPE_CHECKING:
    from .protocol import ResultLike
    from ..model.beam import Contactor

__all__ = ["compute_metrics", "warn_unresolved", "contact_forces", "contact_intervals", "response_point",
           "pushing_parts", "METRIC_UNITS", "METRIC_DISPLAY"]

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

    The exact solution computes them in one compiled call
    (:meth:`~impactbeam.solver.solution.Solution.metric_arrays`, the same
    code the batched runs of sweeps use, so a case gives the same bits alone
    or in a batch); another solution (the ``solve_ivp`` reference) answers
    the same extremum and integral queries itself, around the same compiled
    rules (:mod:`impactbeam.solver._metrics`). The minimum of ``u`` in a
    contact interval of the first contactor is read from that interval's
    peak compression (``u = -s w(a)`` there, so ``min u = -(peak
    compression + gap)``), and ``max_penetration`` is the largest compression
    of the first contactor over the run.

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
    if hasattr(sol, "metric_arrays"):
        scalars, rows, shallow = sol.metric_arrays(x, sign, impacts)
    else:
        scalars, rows, shallow = _queried_arrays(result, x, sign, impacts)
    out = metrics_dict(scalars)
    arrays = getattr(sol, "event_arrays", None)
    if arrays is not None:  # without making the Event tuples
        out["events"] = [{"time": t, "kind": "impact" if k else "rebound", "contactor": c}
                         for t, k, c in zip(arrays[0].tolist(), arrays[1].tolist(), arrays[2].tolist())]
    else:
        out["events"] = [{"time": e.time, "kind": e.kind, "contactor": e.contactor} for e in result.events]
    if impacts:
        if np.isfinite(scalars[0]):
            _clip_pulling(result, rows[0], rows[1], rows[3], rows[5], rows[6])
        out["impacts"] = _impact_table(result, rows) if np.isfinite(scalars[0]) else []
    from ..solver.engine import touch_scale_warning

    for text in touch_scale_warning(shallow, result.beam.length):  # with the table or without, as in a batch
        from .._warnings import emit_user_level_warning

        emit_user_level_warning(text)
    return out


def pushing_parts(result: ResultLike, ci: int, a: float, b: float) -> list[tuple[float, float]]:
    """The parts of the contact ``[a, b]`` of contactor ``ci`` where its force ``k d + c_d d'`` pushes.

    Split where the state jumps (:func:`~impactbeam.result.timegrid.cuts`) and at the force's sign
    changes, located on 513 points of the contact, then by Brent's method; a part keeps its own ends.

    Parameters
    ----------
    result : SimulationResult
    ci : int
        The contactor.
    a, b : float, [s]
        The contact's start and end.

    Returns
    -------
    list of (float, float)
        The parts ``(start, end)`` [s] where the force is positive, in order.
    """
    from scipy.optimize import brentq

    sol = result.solution
    known = sol.__dict__.setdefault("_pushing_parts", {})  # a solution does not change: the table and the
    if (ci, a, b) in known:                                  # statistics ask for the same contacts
        return known[(ci, a, b)]
    c = result.contactors[ci]
    r = float(getattr(sol, "dashpots", np.zeros(ci + 1))[ci]) / c.stiffness

    def g(t: Any) -> np.ndarray:  # F / k
        smp = sol.sample(np.array([c.position]), np.atleast_1d(np.asarray(t, dtype=float)))
        return c.direction * (smp.w[:, 0] + r * smp.w_t[:, 0]) - c.gap

    edges = cuts(result, a, b)  # where the state jumps
    t = np.linspace(a, float(np.nextafter(b, -np.inf)), 513)  # (a sample at b is of the next segment)
    v = g(t)
    roots = []
    for j in np.flatnonzero(np.sign(v[:-1]) * np.sign(v[1:]) < 0.0):
        if np.any((edges > t[j]) & (edges <= t[j + 1])):
            continue  # a jump of the state is not a root
        try:
            roots.append(brentq(lambda x: float(g(x)[0]), t[j], t[j + 1], xtol=1e-15 * max(abs(b), 1e-300)))
        except ValueError:  # the ends' signs differ only in the last bits of a vectorised sample: no root
            continue
    ends = np.unique(np.concatenate([edges, roots]))
    known[(ci, a, b)] = [(float(u), float(w)) for u, w in zip(ends[:-1], ends[1:]) if g(0.5 * (u + w))[0] > 0.0]
    return known[(ci, a, b)]


def _clip_pulling(result: ResultLike, rc: np.ndarray, ra: np.ndarray, rbe: np.ndarray, force: np.ndarray,
                  impulse: np.ndarray) -> None:
    """Impulses of contacts with per-state modes: the integral of the force's positive part, segment by segment.

    The contact force never pulls (:meth:`~impactbeam.model.beam.Contactor.force`). With the shared basis an
    engaged contactor's force stays positive until its release and the state is continuous, so the table's
    closed form ``k int d dt + c_d [d]`` is its integral. With per-state modes
    (:func:`~impactbeam.result.timegrid.per_state`) every switch moves the state, and can leave a struck
    contactor on the wrong side: the impulse is summed over
    the parts where the force pushes (:func:`pushing_parts`), the dashpot's share ``c_d [d]`` within each
    (from the left of its end); a contact that never pushes gets 0. Contact ``i``: contactor ``rc[i]`` on
    ``[ra[i], rbe[i]]``, its peak force ``force[i]``; ``impulse`` is changed in place.
    """
    if not rc.size or not per_state(result):
        return
    sol = result.solution
    dash = getattr(sol, "dashpots", np.zeros(len(result.contactors)))
    for i in range(rc.size):
        total = 0.0
        c, cd = result.contactors[int(rc[i])], float(dash[int(rc[i])])
        for u, w in pushing_parts(result, int(rc[i]), float(ra[i]), float(rbe[i])) if force[i] > 0.0 else []:
            total += c.stiffness * (c.direction * sol.integrals([(c.position, u, w)])[0] - c.gap * (w - u))
            if cd > 0.0:  # c_d [d], the part's end from the left
                wl = sol.sample(np.array([c.position]), np.array([u, float(np.nextafter(w, -np.inf))])).w[:, 0]
                total += cd * c.direction * (wl[1] - wl[0])
        impulse[i] = max(total, 0.0)


def metrics_dict(scalars: np.ndarray) -> dict[str, Any]:
    """The scalar metrics as the dictionary of :func:`compute_metrics` (None for NaN, counts as int).

    Parameters
    ----------
    scalars : ndarray, (10,)
        In the order of :data:`METRIC_UNITS`.
    """
    out: dict[str, Any] = {}
    for key, v in zip(METRIC_UNITS, scalars.tolist()):
        out[key] = None if v != v else (int(v) if key in _COUNTS else v + 0.0)  # + 0.0: no "-0.0" for a 0
    return out


_COUNTS = ("n_impacts", "n_events")


def _queried_arrays(result: ResultLike, x: float, sign: float, table: bool) -> tuple[np.ndarray, tuple]:
    """:meth:`~impactbeam.solver.solution.Solution.metric_arrays` for any solution, through its queries."""
    from ..solver import kernels
    from ..solver._codes import TOUCH_SCALE_COUNT, touch_depth

    K = kernels.for_work(len(result.events))
    sol = result.solution
    t_end = sol.t_end
    con = result.contactors
    nc = len(con)
    ev_t = np.array([e.time for e in result.events], dtype=float)
    ev_kind = np.array([e.kind == "impact" for e in result.events], dtype=np.int64)
    ev_c = np.array([e.contactor for e in result.events], dtype=np.int64)
    nev = ev_t.size
    n = nev + nc + 1
    rc, ra, rb, rbe = np.zeros(n, dtype=np.int64), np.zeros(n), np.zeros(n), np.zeros(n)
    n_rows = int(K.contact_rows(ev_t, ev_kind, ev_c, nev, nc, float(t_end), rc, ra, rb, rbe)) if nc else 0
    rc, ra, rb, rbe = rc[:n_rows], ra[:n_rows], rb[:n_rows], rbe[:n_rows]
    queries: list[tuple] = [(x, 0.0, t_end, sign, 0.0, None)]
    if not nc:
        queries.append((x, 0.0, t_end, -sign, 0.0, None))
    else:  # the largest compression of the first contactor over the run
        c0 = con[0]
        queries.append((c0.position, 0.0, t_end, c0.direction, -c0.direction * c0.gap, 0))
    ext = sol.extrema(queries)
    top, t_top = float(ext[0, 0]), float(ext[0, 1])
    peaks = np.full(n_rows, np.nan)
    contact = np.full(5, np.nan)
    peak_after = np.nan
    counted = False
    if nc:
        K.first_contact(ev_t, ev_kind, ev_c, nev, t_top, contact)
        a, b = contact[3], contact[4]
        counted = n_rows >= TOUCH_SCALE_COUNT and np.isfinite(top)  # every peak, for count_shallow
        want = [i for i in range(n_rows) if table or counted or (rc[i] == 0 and ra[i] == a)]
        if want:
            peaks[want] = sol.extrema([_peak_query(result, int(rc[i]), ra[i], rbe[i]) for i in want])[:, 0]
        if np.isfinite(top) and np.isfinite(a) and a < t_end and not np.any((rc == 0) & (ra == a)):
            peak_after = float(sol.extrema([_peak_query(result, 0, a, min(b, t_end))])[0, 0])
    energy = 0.0
    if np.isfinite(top):
        dash = np.asarray(getattr(sol, "dashpots", np.zeros(nc)), dtype=float)
        kst = np.array([c.stiffness for c in con], dtype=float)
        jumps = np.ascontiguousarray(result.energy_jumps, dtype=float)
        pen = np.ascontiguousarray(getattr(sol, "event_penetrations", np.zeros(nev)), dtype=float)
        energy = (-K.pairwise_sum(jumps, jumps.size)
                  - K.release_loss_sum(ev_c, ev_kind, pen, nev, dash, kst, np.empty(max(nev, 1))))
    shallow = np.zeros(4 + nc)
    if nc and counted:
        K.count_shallow(rc, ra, peaks, n_rows, touch_depth(result.beam.length), shallow)
    out = np.empty(K.N_SCALARS)
    low, deepest = (float(ext[1, 0]), np.nan) if not nc else (np.nan, float(ext[1, 0]))
    K.assemble(out, nev, top, t_top, low, energy, deepest, n_rows, rc, ra, peaks, contact, con[0].gap if nc else 0.0,
               peak_after)
    fpeaks, ints, d0, d1 = peaks.copy(), np.zeros(n_rows), np.full(n_rows, np.nan), np.full(n_rows, np.nan)
    if table and n_rows:
        dash = getattr(sol, "dashpots", np.zeros(nc))
        ints = sol.integrals([(con[c].position, a, be) for c, a, be in zip(rc, ra, rbe)])
        forced = [i for i in range(n_rows) if dash[rc[i]] > 0.0]
        if forced:
            fq = [_peak_query(result, int(rc[i]), ra[i], rbe[i]) + (dash[rc[i]] / con[rc[i]].stiffness,)
                  for i in forced]
            fpeaks[forced] = sol.extrema(fq)[:, 0]
            for i in forced:
                c = con[rc[i]]
                w = sol.sample(np.array([c.position]), np.array([ra[i], rbe[i]])).w[:, 0]
                d0[i], d1[i] = c.direction * w - c.gap
        fpeaks, ints = _forces(result, rc, ra, rbe, fpeaks, np.asarray(ints, dtype=float), d0, d1)
    return out, (rc, ra, rb, rbe, peaks, fpeaks, ints, d0, d1), shallow


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
    ints = sol.integrals([(c.position, a, b) for c, (_, a, b) in zip(cs, intervals)])
    rate = np.array([dash[ci] / c.stiffness for c, (ci, _, _) in zip(cs, intervals)])
    queries = [_peak_query(result, ci, a, b) + (r,) for (ci, a, b), r in zip(intervals, rate)]
    ask = [i for i in range(n) if compressions is None or rate[i] > 0.0]
    peaks = np.full(n, np.nan) if compressions is None else np.asarray(compressions, dtype=float).copy()
    if ask:
        peaks[ask] = sol.extrema([queries[i] for i in ask])[:, 0]
    d0, d1 = np.full(n, np.nan), np.full(n, np.nan)
    forced = np.flatnonzero(rate > 0.0)
    if forced.size:  # the compressions at the ends, for the dashpot's share c [d]: one evaluation for all
        xs = np.unique([cs[i].position for i in forced])
        # the end from the left: a sample at an event time is of the segment it starts (after the switch's
        # projection, which with per-state modes moves the state)
        ts = np.array([t for i in forced for t in (intervals[i][1], np.nextafter(intervals[i][2], -np.inf))])
        w = sol.sample(xs, ts).w
        col = np.searchsorted(xs, [cs[i].position for i in forced])
        for j, i in enumerate(forced):
            d0[i], d1[i] = cs[i].direction * w[2 * j: 2 * j + 2, col[j]] - cs[i].gap
    ci, a, b = (np.array(v) for v in zip(*intervals))
    force, impulse = _forces(result, ci.astype(np.int64), a.astype(float), b.astype(float), peaks,
                             np.asarray(ints, dtype=float), d0, d1)
    _clip_pulling(result, ci.astype(np.int64), a.astype(float), b.astype(float), force, impulse)
    return force, impulse


def _forces(result: ResultLike, contactor: np.ndarray, start: np.ndarray, end: np.ndarray, peaks: np.ndarray,
            ints: np.ndarray, d0: np.ndarray, d1: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Peak forces and impulses of contact intervals ``(contactor, start, end)``, by the compiled rule.

    :func:`~impactbeam.solver._metrics.impact_forces`: ``k max(peak, 0)`` and
    ``k (s int w - gap T) + c_d [d]``. ``peaks`` are the maxima of ``d + (c_d / k) d'`` (of ``d`` without
    dashpot), ``ints`` the integrals of ``w`` at the contactor, ``d0, d1`` the
    compressions at the ends (read only with a dashpot).
    """
    from ..solver import kernels

    con = result.contactors
    n = len(peaks)
    force = np.array(peaks, dtype=float)
    impulse = np.array(ints, dtype=float)
    kernels.for_work(n).impact_forces(
        np.asarray(contactor, dtype=np.int64), np.asarray(start, dtype=float), np.asarray(end, dtype=float), force,
        impulse, np.asarray(d0, dtype=float), np.asarray(d1, dtype=float), n,
        np.array([c.direction for c in con], dtype=float), np.array([c.gap for c in con], dtype=float),
        np.array([c.stiffness for c in con], dtype=float),
        np.asarray(getattr(result.solution, "dashpots", np.zeros(len(con))), dtype=float))
    return force, impulse


def _impact_table(result: ResultLike, rows: tuple) -> list[dict[str, Any]]:
    """Duration, peak force and impulse of every contact interval (exact, closed form), by start time.

    ``rows`` as :meth:`~impactbeam.solver.solution.Solution.metric_arrays`
    returns them (the peak forces and impulses already by :func:`_forces`'s rule).
    """
    rc, ra, rb, _, _, force, impulse, _, _ = rows
    order = np.lexsort((rc, ra))  # by start, then contactor
    return [
        {"contactor": ci, "start": a, "end": b if b != math.inf else None,
         "duration": (b - a) if b != math.inf else None, "peak_force": peak, "impulse": imp}
        for ci, a, b, peak, imp in zip(rc[order].tolist(), ra[order].tolist(), rb[order].tolist(),
                                       force[order].tolist(), impulse[order].tolist())
    ]


def response_size(metrics: dict[str, Any]) -> float:
    """The larger of ``|max_response|`` and ``|min_response|`` (0 where undefined): what :func:`warn_unresolved` weighs.

    Parameters
    ----------
    metrics : dict
        Metrics of :func:`compute_metrics` (or :func:`metrics_dict`).
    """
    return max((abs(v) for v in (metrics.get("max_response"), metrics.get("min_response")) if v is not None),
               default=0.0)


#: A response smaller than this fraction of the beam's length is not resolved by the extrema (:func:`warn_unresolved`).
UNRESOLVED = 1e-9


def warn_unresolved(result: ResultLike, metrics: dict[str, Any], driven: bool | None = None) -> None:
    """Warn when the response is too small for the extrema's absolute tolerance (1e-12 of the length).

    Parameters
    ----------
    result : SimulationResult
    metrics : dict
        Its metrics (:func:`compute_metrics`).
    driven : bool, optional
        Whether a load or a starting motion drives the run (default: read
        from the result's scenario, else whether the response is not 0).
    """
    peak = response_size(metrics)
    sc = getattr(result, "scenario", None)
    if driven is None:
        driven = peak > 0.0 if sc is None else (sc.excitation.active or not sc.initial.at_rest)
    length = result.beam.length
    if driven and peak < UNRESOLVED * length and result.contactors:
        # u may only have moved towards the stop, without reaching it (max_response the start's 0,
        # min_response undefined): the least u over the run then says how large the response is
        x, sign = response_point(result.contactors, result.points)
        sol = result.solution
        peak = max(peak, float(sol.extrema([(x, 0.0, sol.t_end, -sign, 0.0, None)])[0, 0]))
    if driven and peak < UNRESOLVED * length:
        from .._warnings import emit_user_level_warning

        emit_user_level_warning(
            f"metrics: the response is only ~{peak:.2g} m, below 1e-9 of the beam length; the extrema behind "
            f"max_response, t_max and min_response are located to {1e-12 * length:.2g} m "
            "(1e-12 L), so they are not resolved: scale the load up (the model is linear until contact) or "
            "read the response from displacement()"
        )
