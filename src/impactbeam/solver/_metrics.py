"""Compiled response metrics of one run, from its segment records and events.

The definitions are those of :mod:`impactbeam.result.metrics` (the project's
public contract), computed here once for the single-run path
(:meth:`~impactbeam.solver.solution.Solution.metric_arrays`) and the batched
path (:mod:`~impactbeam.solver._batch`), so that a case gives the same bits
alone or in a batch:

* :func:`contact_rows`: every contact interval of every contactor whose
  clipped length ``min(end, t_end) - start`` is positive, contactor by
  contactor in time order (the per-impact table's rows);
* :func:`assemble`: the scalar metrics from the extremum of ``u``, the
  largest compression of the first contactor over the run, the peak
  compression of the first contact after the maximum, the contact intervals
  of the first contactor and the energy jumps;
* :func:`run_metrics`: both, with the extrema and integrals in closed form
  (:mod:`~impactbeam.solver._dense`); with ``table`` also each row's peak
  force, impulse integral and end penetrations.

The scalar metrics do not depend on whether the table is computed (the peak
``min_response`` reads is the same query as that row's in the table); a
solution that is not the exact one (the ``solve_ivp`` reference) uses
:func:`contact_rows`, :func:`first_contact` and :func:`assemble` around its
own extrema (:func:`impactbeam.result.metrics.compute_metrics`).
"""

from __future__ import annotations

import math

import numpy as np

from ._dense import extremum_query, integral_query, sample_row
from ._jit import njit

__all__ = ["N_SCALARS", "SCALARS", "contact_rows", "assemble", "run_metrics", "impact_forces", "pairwise_sum",
           "release_loss_sum", "count_shallow"]

#: Order of the scalar metrics in the arrays of this module (NaN where undefined).
SCALARS = ("max_response", "t_max", "first_impact_time", "n_impacts", "free_duration", "contact_duration",
           "min_response", "max_penetration", "n_events", "energy_residual")
N_SCALARS = 10
MAX_RESPONSE, T_MAX, FIRST_IMPACT, N_IMPACTS, FREE_DURATION, CONTACT_DURATION = 0, 1, 2, 3, 4, 5
MIN_RESPONSE, MAX_PENETRATION, N_EVENTS, ENERGY_RESIDUAL = 6, 7, 8, 9
IMPACT = 1  # ev_kind of an impact (0: a rebound)


@njit(cache=True, nogil=True, _nrt=False)
def pairwise_sum(x, n):  # pragma: no cover - compiled
    """``numpy.sum(x[:n])`` to the bit: NumPy's pairwise summation (blocks of 128, eight accumulators)."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += x[i]
        return res
    if n <= 128:
        r0, r1, r2, r3 = x[0], x[1], x[2], x[3]
        r4, r5, r6, r7 = x[4], x[5], x[6], x[7]
        i = 8
        while i < n - (n % 8):
            r0 += x[i]
            r1 += x[i + 1]
            r2 += x[i + 2]
            r3 += x[i + 3]
            r4 += x[i + 4]
            r5 += x[i + 5]
            r6 += x[i + 6]
            r7 += x[i + 7]
            i += 8
        res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
        while i < n:
            res += x[i]
            i += 1
        return res
    n2 = n // 2
    n2 -= n2 % 8
    return pairwise_sum(x, n2) + pairwise_sum(x[n2:], n - n2)


@njit(cache=True, nogil=True, _nrt=False)
def release_loss_sum(ev_c, ev_kind, ev_d, nev, dash, kst, work):  # pragma: no cover - compiled
    """Sum of the energies the contactors' dashpots take at their switches (``release_losses``), NumPy's order.

    ``k d^2 / 2`` at a release with a penetration ``d > 0`` left, its negative
    at a re-engagement; ``work`` holds at least ``nev`` floats.
    """
    m = 0
    for i in range(nev):
        c = ev_c[i]
        if dash.size and dash[c] > 0.0 and ev_d[i] > 0.0:
            e = 0.5 * kst[c] * ev_d[i] * ev_d[i]
            work[m] = -e if ev_kind[i] == IMPACT else e
            m += 1
    return pairwise_sum(work, m)


@njit(cache=True, nogil=True, _nrt=False)
def contact_rows(ev_t, ev_kind, ev_c, nev, n_contactors, t_end, rc, ra, rb, rbe):  # pragma: no cover - compiled
    """Contact intervals with a positive clipped length: contactor, start, end (inf: still engaged), clipped end.

    Contactor by contactor, each in time order; returns their number (the
    arrays hold at least ``nev + n_contactors`` entries).
    """
    n = 0
    for ci in range(n_contactors):
        start = 0.0
        open_ = False
        for i in range(nev):
            if ev_c[i] != ci:
                continue
            if ev_kind[i] == IMPACT:
                start = ev_t[i]
                open_ = True
            elif open_:
                b = ev_t[i]
                be = min(b, t_end)
                if be > start:
                    rc[n], ra[n], rb[n], rbe[n] = ci, start, b, be
                    n += 1
                open_ = False
        if open_:
            be = min(np.inf, t_end)
            if be > start:
                rc[n], ra[n], rb[n], rbe[n] = ci, start, np.inf, be
                n += 1
    return n


@njit(cache=True, nogil=True, _nrt=False)
def first_contact(ev_t, ev_kind, ev_c, nev, t_max, out):  # pragma: no cover - compiled
    """Contact intervals of contactor 0: ``out = (count, first start, free duration, start and end of the
    first interval beginning at or after t_max)`` (NaN where there is none)."""
    count = 0
    first = np.nan
    prev_end = 0.0
    nxt = np.nan
    a_after = np.nan
    b_after = np.nan
    start = 0.0
    open_ = False
    for i in range(nev + 1):
        closed = False
        b = np.inf
        if i < nev:
            if ev_c[i] != 0:
                continue
            if ev_kind[i] == IMPACT:
                start = ev_t[i]
                open_ = True
                continue
            if open_:
                b = ev_t[i]
                closed = True
        elif open_:
            closed = True  # still engaged at the end: (start, inf)
        if not closed:
            continue
        open_ = False
        if count == 0:
            first = start
        count += 1
        if np.isnan(nxt):
            if b <= t_max:
                prev_end = b
            elif start >= t_max:
                nxt = start
        if np.isnan(a_after) and start >= t_max:
            a_after = start
            b_after = b
    out[0] = count
    out[1] = first
    out[2] = nxt - prev_end
    out[3] = a_after
    out[4] = b_after


@njit(cache=True, nogil=True, _nrt=False)
def assemble(out, nev, top, t_top, low, energy_residual, deepest, n_rows, rc, ra, peaks, contact, gap0, peak_after):
    # pragma: no cover - compiled
    """The scalar metrics (order :data:`SCALARS`, NaN for undefined) from what the queries found.

    ``top, t_top``: the maximum of ``u`` and its time; ``low``: the maximum
    of ``-u`` (no contactor, else unused); ``deepest``: the largest
    compression of the first contactor over the run (while engaged);
    ``peaks[i]``: the peak compression of row ``i`` (NaN where not computed);
    ``contact``: :func:`first_contact` at ``t_top``; ``peak_after``: the peak
    compression over the first contact interval after ``t_top`` when no row
    holds it (NaN otherwise, or when there is none). No contactor: ``rc`` is
    empty and ``gap0`` unused.
    """
    for i in range(out.size):
        out[i] = np.nan
    out[N_EVENTS] = nev
    if not math.isfinite(top):
        return
    out[MAX_RESPONSE] = top
    out[T_MAX] = t_top
    out[ENERGY_RESIDUAL] = energy_residual
    if np.isnan(contact[0]):
        out[MIN_RESPONSE] = -low
        return
    out[MAX_PENETRATION] = max(deepest, 0.0) if math.isfinite(deepest) else 0.0
    out[N_IMPACTS] = contact[0]
    out[FIRST_IMPACT] = contact[1]
    out[FREE_DURATION] = contact[2]
    a = contact[3]
    b = contact[4]
    if np.isnan(a):
        return
    if math.isfinite(b):
        out[CONTACT_DURATION] = b - a
    peak = peak_after
    for i in range(n_rows):
        if rc[i] == 0 and ra[i] == a and not np.isnan(peaks[i]):
            peak = peaks[i]
            break
    if math.isfinite(peak):
        out[MIN_RESPONSE] = -(peak + gap0)


@njit(cache=True, nogil=True, _nrt=False)
def count_shallow(rc, ra, peaks, n_rows, depth, shallow):  # pragma: no cover - compiled
    """The contacts whose peak compression ``peaks[i]`` is at most ``depth``, in place of ``shallow``.

    ``shallow[0]`` their number, ``shallow[1]`` the number of rows,
    ``shallow[2]`` and ``shallow[3]`` the first and last of their starts,
    ``shallow[4 + c]`` 1 where contactor ``c`` has one (0 elsewhere); a NaN
    peak is not counted. The rule behind
    :func:`impactbeam.solver.engine.touch_scale_warning`.
    """
    for j in range(shallow.size):
        shallow[j] = 0.0
    first = math.inf
    last = -math.inf
    for i in range(n_rows):
        p = peaks[i]
        if math.isfinite(p) and p <= depth:
            shallow[0] += 1.0
            first = min(first, ra[i])
            last = max(last, ra[i])
            shallow[4 + rc[i]] = 1.0
    shallow[1] = n_rows
    if shallow[0] > 0.0:
        shallow[2] = first
        shallow[3] = last


@njit(cache=True, nogil=True, _nrt=False)
def impact_forces(rc, ra, rbe, fpeaks, ints, d0, d1, n, side, gap, kst, dash):  # pragma: no cover - compiled
    """Peak force and impulse of contact intervals, in place of ``fpeaks`` and ``ints``.

    The rule of :func:`impactbeam.result.metrics.contact_forces`. Row ``i``
    of contactor ``c = rc[i]`` on ``[ra[i], rbe[i]]``: ``fpeaks[i]``, the
    largest ``d + (c_d / k) d'`` (``d = s w - gap`` the compression),
    becomes the peak force ``k max(fpeaks[i], 0)``; ``ints[i] = int w dt``
    becomes the impulse ``k (s int w dt - gap (rbe - ra)) + c_d (d1 - d0)``,
    the dashpot's share from the compressions ``d0, d1`` at the ends (read
    only when ``c_d > 0``).
    """
    for i in range(n):
        c = rc[i]
        k = kst[c]
        p = fpeaks[i]
        if 0.0 > p:
            p = 0.0
        fpeaks[i] = k * p
        imp = k * (side[c] * ints[i] - gap[c] * (rbe[i] - ra[i]))
        if dash[c] > 0.0:
            imp += dash[c] * (d1[i] - d0[i])
        ints[i] = imp


@njit(cache=True, nogil=True)
def run_metrics(seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, ev_t, ev_kind, ev_c, ev_d, nev, jumps, t_end,
                reg, dec, wdh, om, LW, CW, gen, G, smask, gap, side, kst, dash, pt0, pconst, pslope, pamp, pOm,
                pphase, Wm, Wc, sign, atol, xtol, table, depth, min_count, shallow, out, rc, ra, rb, rbe, peaks, fpeaks,
                ints, d0, d1, work):
    # pragma: no cover - compiled
    """The metrics of one run (module docstring); returns the number of rows.

    ``Wm[s]``: the shapes at the metric point in slot ``s``; ``Wc[c, s]``:
    at contactor ``c``; ``sign``: ``u = sign w`` there. The segment and
    event arrays hold exactly the run's records. ``out`` receives the
    scalars; the row arrays (at least ``nev + n_contactors`` long) the
    per-impact table: contactor, start, end, clipped end, peak compression
    ``s w - gap``, and with ``table`` the peak force (``fpeaks``) and the
    impulse (``ints``) of :func:`impact_forces` and the compression at both
    ends of dashpot contactors (``d0, d1``; NaN for the others). ``shallow``
    receives :func:`count_shallow` of the rows at most ``depth`` deep when
    there are ``min_count`` rows or more (zeros otherwise): a row the table
    does not hold is sampled at its middle first and searched only when that
    sample is not deeper. ``work`` from
    :func:`~impactbeam.solver._dense.dense_work`, its last array resized to
    ``nev`` floats by the caller's ``scratch``.
    """
    nc = gap.size
    top, t_top = extremum_query(0.0, t_end, sign, 0.0, 0.0, Wm, -1, atol, xtol, seg_t0, seg_t1, seg_s, seg_k,
                                seg_eta, seg_deta, reg, dec, wdh, om, LW, CW, gen, G, smask, gap, side, kst, pt0,
                                pconst, pslope, pamp, pOm, pphase, work)
    low = np.nan
    deepest = np.nan
    contact = np.full(5, np.nan)
    n_rows = 0
    peak_after = np.nan
    if nc == 0 and math.isfinite(top):
        low, _ = extremum_query(0.0, t_end, -sign, 0.0, 0.0, Wm, -1, atol, xtol, seg_t0, seg_t1, seg_s, seg_k,
                                seg_eta, seg_deta, reg, dec, wdh, om, LW, CW, gen, G, smask, gap, side, kst, pt0,
                                pconst, pslope, pamp, pOm, pphase, work)
    if nc > 0:
        n_rows = contact_rows(ev_t, ev_kind, ev_c, nev, nc, t_end, rc, ra, rb, rbe)
        first_contact(ev_t, ev_kind, ev_c, nev, t_top, contact)
        a = contact[3]
        for i in range(n_rows):  # the table's peaks; without it only the one min_response reads
            c = rc[i]
            peaks[i] = np.nan
            if table or (c == 0 and ra[i] == a):
                peaks[i], _ = extremum_query(ra[i], rbe[i], side[c], -side[c] * gap[c], 0.0, Wc[c], c, atol, xtol,
                                             seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om, LW, CW,
                                             gen, G, smask, gap, side, kst, pt0, pconst, pslope, pamp, pOm, pphase,
                                             work)
        if math.isfinite(top):
            # the largest compression over the run: one search over the engaged segments (the best value so far
            # prunes the later, shallower contacts), not the largest of the peaks, so it is the same with or
            # without the table
            deepest, _ = extremum_query(0.0, t_end, side[0], -side[0] * gap[0], 0.0, Wc[0], 0, atol, xtol, seg_t0,
                                        seg_t1, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om, LW, CW, gen, G,
                                        smask, gap, side, kst, pt0, pconst, pslope, pamp, pOm, pphase, work)
        if math.isfinite(top) and not np.isnan(a) and a < t_end:
            known = False
            for i in range(n_rows):
                if rc[i] == 0 and ra[i] == a:
                    known = True
            if not known:  # an interval of no length: the compression where it starts
                peak_after, _ = extremum_query(a, min(contact[4], t_end), side[0], -side[0] * gap[0], 0.0, Wc[0], 0,
                                               atol, xtol, seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, reg, dec,
                                               wdh, om, LW, CW, gen, G, smask, gap, side, kst, pt0, pconst, pslope,
                                               pamp, pOm, pphase, work)
    energy = 0.0
    if math.isfinite(top):
        scratch = np.empty(max(nev, 1))
        energy = -pairwise_sum(jumps, jumps.size) - release_loss_sum(ev_c, ev_kind, ev_d, nev, dash, kst, scratch)
    assemble(out, nev, top, t_top, low, energy, deepest, n_rows, rc, ra, peaks, contact, gap[0] if nc else 0.0,
             peak_after)
    if table:
        for i in range(n_rows):
            c = rc[i]
            fpeaks[i] = peaks[i]
            d0[i] = np.nan
            d1[i] = np.nan
            ints[i] = integral_query(ra[i], rbe[i], Wc[c], seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, reg, dec,
                                     wdh, om, LW, CW, gen, G, smask, gap, side, kst, pt0, pconst, pslope, pamp, pOm,
                                     pphase, work)
            if dash[c] > 0.0:
                fpeaks[i], _ = extremum_query(ra[i], rbe[i], side[c], -side[c] * gap[c], dash[c] / kst[c], Wc[c], c,
                                              atol, xtol, seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, reg, dec,
                                              wdh, om, LW, CW, gen, G, smask, gap, side, kst, pt0, pconst, pslope,
                                              pamp, pOm, pphase, work)
                d0[i] = side[c] * sample_row(ra[i], Wc[c], seg_t0, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om,
                                             LW, CW, gen, G, smask, gap, side, kst, pt0, pconst, pslope, pamp, pOm,
                                             pphase, work) - gap[c]
                d1[i] = side[c] * sample_row(rbe[i], Wc[c], seg_t0, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh,
                                             om, LW, CW, gen, G, smask, gap, side, kst, pt0, pconst, pslope, pamp,
                                             pOm, pphase, work) - gap[c]
        impact_forces(rc, ra, rbe, fpeaks, ints, d0, d1, n_rows, side, gap, kst, dash)
    for j in range(shallow.size):
        shallow[j] = 0.0
    if n_rows >= min_count and math.isfinite(top):
        deep = np.empty(n_rows)
        for i in range(n_rows):
            p = peaks[i]
            c = rc[i]
            if np.isnan(p):  # not in the table: deeper than depth at its middle, or searched
                p = side[c] * sample_row(0.5 * (ra[i] + rbe[i]), Wc[c], seg_t0, seg_s, seg_k, seg_eta, seg_deta, reg,
                                         dec, wdh, om, LW, CW, gen, G, smask, gap, side, kst, pt0, pconst, pslope,
                                         pamp, pOm, pphase, work) - gap[c]
                if p <= depth:
                    p, _ = extremum_query(ra[i], rbe[i], side[c], -side[c] * gap[c], 0.0, Wc[c], c, atol, xtol,
                                          seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om, LW, CW,
                                          gen, G, smask, gap, side, kst, pt0, pconst, pslope, pamp, pOm, pphase, work)
            deep[i] = p
        count_shallow(rc, ra, deep, n_rows, depth, shallow)
    return n_rows
