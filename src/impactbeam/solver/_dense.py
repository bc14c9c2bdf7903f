"""Compiled evaluation of the exact piecewise solution: samples, extrema and integrals.

The solver records each segment's start time, state slot, load piece and
modal state (:class:`~impactbeam.solver.solution.Solution`); these kernels
rebuild a segment's closed form (:func:`~impactbeam.solver._closed.segment_setup`)
and evaluate it.

* :func:`sample` evaluates modal coordinates, deflections at given rows of
  shapes, energies and powers at arbitrary times.
* :func:`extremum` finds the maximum of ``sign (W eta + offset)`` over a time
  interval by branch and bound: on a sub-interval with end values ``u0, u1``,
  slopes ``d0, d1`` and the curvature bound ``M`` of
  :func:`~impactbeam.solver._closed.curvature_bound`, no value exceeds
  ``max(u0, u1, A(s_x))`` where ``A(s) = u0 + d0 s + M s^2/2`` meets its
  mirror from the right end at ``s_x``. With the bound ``M3`` of
  :func:`~impactbeam.solver._closed.jerk_bound` and the curvatures ``c0, c1``
  at the ends, ``u''`` stays below ``(c0 + c1 + M3 L)/2`` (used for ``M`` when
  smaller) and ``u`` below the cubic ``u0 + d0 s + c0 s^2/2 + M3 s^3/6`` on
  the left half (its mirror on the right), which is what drops the many
  near-equal peaks of a steady-state record early. Sub-intervals that cannot
  beat the best value found (to ``atol``) are dropped, the others are split, and an
  interior maximum (slope ``+`` to ``-``, ``u''`` proven negative) is refined
  by Newton's method on the velocity with the curvature each evaluation
  gives, as is a best point the bisection left (the intervals around it
  dropped because they could beat it by ``atol`` at most: on a flat maximum
  that left its time loose by up to a microsecond). The result is the maximum of
  the N-mode solution to ``atol``, not of any sampled grid.
* :func:`integral` integrates ``W eta`` in closed form
  (:func:`~impactbeam.solver._closed.integral_of`), e.g. impulses.
"""

from __future__ import annotations

import math

import numpy as np
from ._jit import njit

from ._closed import (
    NP, alpha_at, copy_into, curvature_bound, integral_of, jerk_bound, load_phase, particular_at, particular_spread,
    project, segment_setup, state_at, workspace,
)
from ._elementary import ROW_C, ROW_S, kernel_work, kernels_at
from ._events import newton_step, secant_start
from ._loop import load_value, to_modal

__all__ = ["sample", "extremum", "extremum_query", "integral", "integral_query", "first_segment", "dense_work",
           "row_ceiling"]

ONE_ROW = np.int64(1)  # an int64 value, not a literal: one compiled specialisation of project


@njit(cache=True, nogil=True, _nrt=False)
def first_segment(t1, lo):  # pragma: no cover - compiled
    """``max(searchsorted(t1, lo) - 1, 0)``: the segment before the first one ending at or after ``lo``.

    (A binary search written out: numba's ``searchsorted`` compiles slowly.)
    """
    left = 0
    right = t1.size
    while left < right:
        mid = (left + right) >> 1
        if t1[mid] < lo:
            left = mid + 1
        else:
            right = mid
    return max(left - 1, 0)


@njit(cache=True, nogil=True, _nrt=False)
def _setup(j, seg_t0, seg_s, seg_k, seg_eta, seg_deta, reg, dec, om, LW, CW, smask, gap, side, kst,
           pt0, pconst, pslope, pamp, pOm, pphase, ws):  # pragma: no cover - compiled
    """Closed form of segment ``j`` (:func:`~impactbeam.solver._closed.segment_setup`) into the workspace ``ws``."""
    h0, dh0, P, lA, lB, lD, lE, AL = ws
    return segment_setup(seg_s[j], seg_k[j], seg_t0[j], seg_eta[j], seg_deta[j], reg, dec, om, LW[:, 0], LW[:, 1],
                         CW[:, 0], CW[:, 1], LW[:, 2], LW[:, 3], smask, gap, side, kst, pt0, pconst, pslope, pamp,
                         pOm, pphase, h0, dh0, P, lA, lB, lD, lE, AL)


@njit(cache=True, nogil=True, _nrt=False)
def slot_row(gen, G, r, rate, v, u):  # pragma: no cover - compiled
    """The modal-frame row ``r . (eta + rate eta')`` as coefficients ``(v, u)`` on a slot's ``(z, z' - alpha)``."""
    nm = r.size
    if gen == 0:
        for n in range(nm):
            v[n] = r[n]
            u[n] = rate * r[n]
        return
    for n in range(nm):
        sv = 0.0
        su = 0.0
        for m in range(nm):
            sv += r[m] * (G[0, m, n] + rate * G[0, nm + m, n])
            su += r[m] * (G[1, m, n] + rate * G[1, nm + m, n])
        v[n] = sv
        u[n] = su


@njit(cache=True, nogil=True)
def sample(tq, segidx, rows, out_rows, out_drows, out_eta, out_deta, energies, want_modal, want_energy,
           seg_t0, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om, omo, Wc, LW, CW, gen, G, Cd, pw, pre,
           smask, gap, side, kst, dash, pt0, pconst, pslope, pamp, pOm, pphase):  # pragma: no cover - compiled
    """Evaluate the solution at times ``tq`` (segment ``segidx[i]`` each).

    ``rows[s]`` (shape (S, r, n)) holds the mode shapes of state slot ``s`` at
    the requested points; ``out_rows[i, j]`` and ``out_drows[i, j]`` receive
    ``w`` and ``w_t`` there. With ``want_modal`` the modal coordinates go to
    ``out_eta``/``out_deta`` (in the slot's modal frame); with ``want_energy``
    ``energies[i]`` receives (kinetic, modal strain, external load power
    (excitation and preload), power dissipated by the beam's damping, power
    dissipated by the engaged contactors' dashpots).
    """
    nm = seg_eta.shape[1]
    vectors = (np.empty(nm), np.empty(nm), np.empty(nm), np.empty(nm), np.empty(nm), kernel_work(nm))
    _sample(tq, segidx, rows, out_rows, out_drows, out_eta, out_deta, energies, want_modal, want_energy, seg_t0,
            seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om, omo, Wc, LW, CW, gen, G, Cd, pw, pre, smask, gap,
            side, kst, dash, pt0, pconst, pslope, pamp, pOm, pphase, workspace(nm), vectors)


@njit(cache=True, nogil=True, _nrt=False)
def _sample(tq, segidx, rows, out_rows, out_drows, out_eta, out_deta, energies, want_modal, want_energy,
            seg_t0, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om, omo, Wc, LW, CW, gen, G, Cd, pw, pre,
            smask, gap, side, kst, dash, pt0, pconst, pslope, pamp, pOm, pphase, ws, vectors):
    # pragma: no cover - compiled
    """The loop of :func:`sample` on the scratch arrays it made; no reference counting (:mod:`._jit`)."""
    nm = seg_eta.shape[1]
    h0, dh0, P = ws[0], ws[1], ws[2]
    AL = ws[7]
    z, dz, e, d, alpha, kw = vectors
    cur = -1
    Om = 0.0
    phi = 0.0
    for i in range(tq.size):
        j = segidx[i]
        s = seg_s[j]
        kp = seg_k[j]
        if j != cur:
            Om, phi = _setup(j, seg_t0, seg_s, seg_k, seg_eta, seg_deta, reg, dec, om, LW, CW, smask, gap, side,
                             kst, pt0, pconst, pslope, pamp, pOm, pphase, ws)
            cur = j
        tau = tq[i] - seg_t0[j]
        state_at(tau, reg[s], dec[s], wdh[s], om[s], h0, dh0, P, Om, phi, z, dz, kw)
        if gen[s]:
            alpha_at(AL, tau, Om, phi, alpha)
        to_modal(gen[s], G[s], z, dz, alpha, e, d)
        for r in range(out_rows.shape[1]):
            acc = 0.0
            dacc = 0.0
            for n in range(nm):
                acc += rows[s, r, n] * e[n]
                dacc += rows[s, r, n] * d[n]
            out_rows[i, r] = acc
            out_drows[i, r] = dacc
        if want_modal:
            copy_into(out_eta[i], e)
            copy_into(out_deta[i], d)
        if want_energy:
            u = load_value(kp, tq[i], pt0, pconst, pslope, pamp, pOm, pphase)
            kin = 0.0
            strain = 0.0
            lp = 0.0
            dp = 0.0
            for n in range(nm):
                kin += d[n] * d[n]
                strain += omo[s, n] * omo[s, n] * e[n] * e[n]
                lp += (pw[s, n] * u + pre[s, n]) * d[n]
            if gen[s]:
                for n in range(nm):
                    acc = 0.0
                    for m in range(nm):
                        acc += Cd[s, n, m] * d[m]
                    dp += d[n] * acc
            else:
                for n in range(nm):
                    dp += 2.0 * dec[s, n] * d[n] * d[n]
            cp = 0.0
            mask = smask[s]
            for c in range(gap.size):
                if (mask >> c) & 1 and dash[c] > 0.0:
                    vc = 0.0
                    for n in range(nm):
                        vc += Wc[s, c, n] * d[n]
                    cp += dash[c] * vc * vc
            energies[i, 0] = 0.5 * kin
            energies[i, 1] = 0.5 * strain
            energies[i, 2] = lp
            energies[i, 3] = dp - cp
            energies[i, 4] = cp


@njit(cache=True, nogil=True, _nrt=False)
def sample_row(t, Wq, seg_t0, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om, LW, CW, gen, G, smask, gap, side,
               kst, pt0, pconst, pslope, pamp, pOm, pphase, work):  # pragma: no cover - compiled
    """``Wq[s] . eta(t)``: one row at one time, as :func:`sample` evaluates it (``work`` from :func:`dense_work`).

    The segment is the last one starting at or before ``t`` (an event time
    belongs to the segment it starts).
    """
    ws, alpha, e, d, z, dz = work[0], work[9], work[10], work[11], work[13], work[14]
    h0, dh0, P = ws[0], ws[1], ws[2]
    AL = ws[7]
    left = 0
    right = seg_t0.size
    while left < right:  # searchsorted(seg_t0, t, "right")
        mid = (left + right) >> 1
        if seg_t0[mid] <= t:
            left = mid + 1
        else:
            right = mid
    j = min(max(left - 1, 0), seg_t0.size - 1)
    s = seg_s[j]
    Om, phi = _setup(j, seg_t0, seg_s, seg_k, seg_eta, seg_deta, reg, dec, om, LW, CW, smask, gap, side, kst, pt0,
                     pconst, pslope, pamp, pOm, pphase, ws)
    tau = t - seg_t0[j]
    nm = seg_eta.shape[1]
    state_at(tau, reg[s], dec[s], wdh[s], om[s], h0, dh0, P, Om, phi, z, dz, work[15])
    if gen[s]:
        alpha_at(AL, tau, Om, phi, alpha)
    to_modal(gen[s], G[s], z, dz, alpha, e, d)
    acc = 0.0
    for n in range(nm):
        acc += Wq[s, n] * e[n]
    return acc


@njit(cache=True, nogil=True, _nrt=False)
def _upper(t0, u0, d0, t1, u1, d1, M):  # pragma: no cover - compiled
    """Upper bound of a function on [t0, t1] from end values, slopes and ``|u''| <= M``."""
    L = t1 - t0
    U = max(u0, u1)
    den = d0 - d1 + M * L
    if den > 0.0:
        sx = -(u0 - u1 + d1 * L - 0.5 * M * L * L) / den
        if 0.0 < sx < L:
            U = max(U, u0 + d0 * sx + 0.5 * M * sx * sx)
    return U


@njit(cache=True, nogil=True, _nrt=False)
def _cubic_max(u, d, c, m, h):  # pragma: no cover - compiled
    """Maximum of ``u + d s + c s^2/2 + m s^3/6`` over ``0 <= s <= h`` (``m >= 0``)."""
    top = max(u, u + h * (d + h * (0.5 * c + h * m / 6.0)))
    if d > 0.0 and c < 0.0:
        disc = c * c - 2.0 * m * d
        if disc >= 0.0:
            s = 2.0 * d / (math.sqrt(disc) - c)  # the smaller root of the slope: a local maximum
            if s < h:
                top = max(top, u + s * (d + s * (0.5 * c + s * m / 6.0)))
    return top


@njit(cache=True, nogil=True, _nrt=False)
def _cubic_upper(u0, d0, c0, u1, d1, c1, L, M3):  # pragma: no cover - compiled
    """Upper bound on ``[t0, t0 + L]`` from value, slope and curvature at both ends and a bound ``M3`` on ``|u'''|``.

    Taylor's theorem from each end over its half: ``u(t0 + s) <= u0 + d0 s +
    c0 s^2/2 + M3 s^3/6``, and the mirror image from ``t0 + L``.
    """
    h = 0.5 * L
    return max(_cubic_max(u0, d0, c0, M3, h), _cubic_max(u1, -d1, c1, M3, h))


@njit(cache=True, nogil=True, _nrt=False)
def _row3(tau, reg, a, w, om, VH, VD, base, PV, Om, phi, kw):  # pragma: no cover - compiled
    """Row 0 and its first two derivatives at ``tau`` (the second from the equation of motion).

    ``kw``: the scratch of :func:`~impactbeam.solver._elementary.kernels_at`.
    """
    p = PV[0]
    sn, cs = load_phase(tau, Om, phi)
    u, du = particular_at(p, tau, Om, sn, cs)
    ddu = 2.0 * p[2] + 6.0 * p[3] * tau
    if Om != 0.0:
        ddu += -Om * Om * (p[4] * sn + p[5] * cs) + p[6] * (-2.0 * Om * sn - Om * Om * tau * cs)
        ddu += p[7] * (2.0 * Om * cs - Om * Om * tau * sn)
    u += base[0]
    kernels_at(tau, reg, a, w, kw)
    kc = kw[ROW_C]
    ks = kw[ROW_S]
    for n in range(om.size):
        eC = kc[n]
        eS = ks[n]
        an = a[n]
        o2 = om[n] * om[n]
        vh = VH[0, n]
        vd = VD[0, n]
        u += (eC + an * eS) * vh + eS * vd
        du += -o2 * eS * vh + (eC - an * eS) * vd
        ddu += o2 * (an * eS - eC) * vh + ((2.0 * an * an - o2) * eS - 2.0 * an * eC) * vd
    return u, du, ddu


@njit(cache=True, nogil=True, _nrt=False)
def _concave_peak(t0, t1, d0, d1, xtol, reg, a, w, om, VH, VD, base, PV, Om, phi, kw):  # pragma: no cover
    """The maximum of row 0 on ``[t0, t1]`` where ``u'' < 0`` and ``u'`` goes from ``d0 > 0`` to ``d1 < 0``.

    Newton's method on ``u'`` (:func:`~impactbeam.solver._events.newton_step`)
    with the ``u''`` each evaluation of :func:`_row3` already gives, from the
    secant point of the slopes. Returns the last point evaluated and the value
    there: within the tolerance of the maximum's time, so the value's error
    is of the order of ``|u''|`` times its square.
    """
    lo = t0
    hi = t1
    t = secant_start(t0, t1, d0, d1)
    u = -np.inf
    for _ in range(200):
        u, du, ddu = _row3(t, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
        if du == 0.0:
            break
        tn, lo, hi, done = newton_step(t, du, ddu, lo, hi, xtol)
        if done:
            break
        t = tn
    return t, u


@njit(cache=True, nogil=True, _nrt=False)
def _push(stack, i, t0, u0, d0, c0, t1, u1, d1, c1):  # pragma: no cover - compiled
    """Row ``i`` of the branch-and-bound stack: an interval with value, slope and curvature at both ends."""
    row = stack[i]
    row[0], row[1], row[2], row[3], row[4], row[5], row[6], row[7] = t0, u0, d0, c0, t1, u1, d1, c1


@njit(cache=True, nogil=True, _nrt=False)
def _segment_max(ta, tb, M, M3, best, atol, xtol, stack, reg, a, w, om, VH, VD, base, PV, Om, phi, kw):
    # pragma: no cover - compiled
    """Branch and bound for the maximum of row 0 on ``[ta, tb]`` (module docstring).

    ``M`` bounds ``|u''|`` and ``M3`` the third derivative: a sub-interval is
    done when its upper bound cannot beat ``best``, when ``u`` is proven
    monotone on it (the maximum is then at an end), or when ``u`` is proven
    concave on it (``u'' < 0`` at both ends and ``|u''(t0)| + |u''(t1)| >= M3 L``;
    the maximum is then the root of ``u'``, :func:`_concave_peak`, or an end).
    The half where ``u'`` turns from + to - is searched first. A best point
    left by the bisection is refined to the root of ``u'`` that the slopes
    around it bracket, when that is higher. Returns the new best value and
    its time, NaN when ``best`` was not beaten.
    """
    tbest = np.nan
    ua, da, ca = _row3(ta, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
    ub, db, cb = _row3(tb, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
    # the interval the best point was found in (its midpoint or an end), the slopes at its ends and there
    n0, nd0, n1, nd1, ndt = ta, da, tb, db, 0.0
    if ua > best:
        best = ua
        tbest = ta
        ndt = da
    if ub > best:
        best = ub
        tbest = tb
        ndt = db
    _push(stack, 0, ta, ua, da, ca, tb, ub, db, cb)
    top = 1
    while top > 0:
        top -= 1
        t0 = stack[top, 0]
        u0 = stack[top, 1]
        d0 = stack[top, 2]
        c0 = stack[top, 3]
        t1 = stack[top, 4]
        u1 = stack[top, 5]
        d1 = stack[top, 6]
        c1 = stack[top, 7]
        L = t1 - t0
        # u'' lies within M3 (t - t0) of c0 and M3 (t1 - t) of c1: local bounds, tighter than M on short intervals
        m_abs = min(M, 0.5 * (abs(c0) + abs(c1) + M3 * L))
        m_up = max(0.0, min(m_abs, 0.5 * (c0 + c1 + M3 * L)))
        if (min(_upper(t0, u0, d0, t1, u1, d1, m_up), _cubic_upper(u0, d0, c0, u1, d1, c1, L, M3)) <= best + atol
                or L <= xtol):
            continue
        if (d0 > 0.0 and d1 > 0.0 and d0 + d1 >= m_abs * L) or (d0 < 0.0 and d1 < 0.0 and -(d0 + d1) >= m_abs * L):
            continue  # monotone: the ends hold the maximum
        concave = c0 < 0.0 and c1 < 0.0 and -(c0 + c1) >= M3 * L
        if concave and not (d0 > 0.0 and d1 < 0.0):
            continue  # concave with no interior stationary point: the ends hold the maximum
        if concave:  # the one interior maximum: the root of u' by Newton's method with u''
            tm, um = _concave_peak(t0, t1, d0, d1, xtol, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
            if um > best:
                best = um
                tbest = tm
                n1 = n0  # already the root of u': nothing to refine
            continue
        tm = 0.5 * (t0 + t1)
        um, dm, cm = _row3(tm, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
        if um > best:
            best = um
            tbest = tm
            n0, nd0, n1, nd1, ndt = t0, d0, t1, d1, dm
        if top + 2 > stack.shape[0]:
            continue
        # the half where u' turns from + to - (the right one when u'(tm) > 0) is searched first: its maximum
        # is then known before the other half's bound is tested, which usually drops that half unsplit
        if dm > 0.0:
            _push(stack, top, t0, u0, d0, c0, tm, um, dm, cm)
            _push(stack, top + 1, tm, um, dm, cm, t1, u1, d1, c1)
        else:
            _push(stack, top, tm, um, dm, cm, t1, u1, d1, c1)
            _push(stack, top + 1, t0, u0, d0, c0, tm, um, dm, cm)
        top += 2
    if not np.isnan(tbest) and n1 > n0:
        # a point of the bisection, the intervals around it dropped when they could beat it by atol at most:
        # the stationary point its slopes bracket, when that is higher (else a flat maximum's time is only
        # defined to where the function is within atol of its top: up to a microsecond on a slow response)
        tm, um = tbest, best
        if ndt > 0.0 and nd1 < 0.0:
            tm, um = _concave_peak(tbest, n1, ndt, nd1, xtol, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
        elif ndt < 0.0 and nd0 > 0.0:
            tm, um = _concave_peak(n0, tbest, nd0, ndt, xtol, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
        if um > best:
            best = um
            tbest = tm
    return best, tbest


@njit(cache=True, nogil=True)
def dense_work(nm):  # pragma: no cover - compiled
    """Work arrays of :func:`extremum_query` and :func:`integral_query` for ``nm`` coordinates."""
    return (workspace(nm), np.empty((1, nm)), np.empty((1, nm)), np.zeros(1), np.empty((1, nm)), np.empty((1, nm)),
            np.empty((1, NP)), np.empty(1), np.empty(1), np.zeros(nm), np.empty(nm), np.empty(nm),
            np.empty((128, 8)), np.empty(nm), np.empty(nm), kernel_work(nm))


@njit(cache=True, nogil=True, _nrt=False)
def row_ceiling(VH, VD, PV, base, reg, a, wd, L):  # pragma: no cover - compiled
    """An upper bound of row 0 of a projection on ``[0, L]``, and the magnitude it is made of.

    A homogeneous contribution ``f`` (value ``VH``, slope ``VD`` at 0, decay
    ``a >= 0``) never exceeds ``sqrt(VH^2 + ((VD + a VH) / w_d)^2)`` when
    under-damped, nor ``|VH| + |VD + a VH| L`` otherwise (``e^{-a tau}`` times
    cos/sin, 1/tau or cosh/sinh, each bounded so); the particular part by
    :func:`~impactbeam.solver._closed.particular_spread`.
    """
    p = PV[0]
    spread = particular_spread(p, L)
    up = base[0] + p[0] + spread
    mag = abs(base[0]) + abs(p[0]) + spread
    for n in range(wd.size):
        if a[n] < 0.0:
            return np.inf, np.inf  # a growing coordinate: no ceiling (never so: damping dissipates)
        vh = VH[0, n]
        vd = VD[0, n] + a[n] * vh
        if reg[n] == 0:
            r = vd / wd[n]
            amp = math.sqrt(vh * vh + r * r)
        else:
            amp = abs(vh) + abs(vd) * L
        up += amp
        mag += amp
    return up, mag


@njit(cache=True, nogil=True, _nrt=False)
def extremum_query(lo, hi, sign, offset, rate, Wq, cond, atol, xtol, seg_t0, seg_t1, seg_s, seg_k, seg_eta,
                   seg_deta, reg, dec, wdh, om, LW, CW, gen, G, smask, gap, side, kst, pt0, pconst, pslope, pamp,
                   pOm, pphase, work):  # pragma: no cover - compiled
    """Maximum of ``sign (Wq[s] . (eta + rate eta') + offset)`` over ``[lo, hi]`` and its time.

    ``eta`` are the modal coordinates in slot ``s``'s frame (``rate``: a
    velocity term, e.g. a dashpot's force). Only segments whose state has
    contactor ``cond`` engaged count (``cond < 0``: all); ``(-inf, nan)``
    when none qualifies. ``work`` from :func:`dense_work`.

    A segment whose ceiling (:func:`row_ceiling`, less a round-off margin)
    cannot reach the best value found so far is skipped: its branch and bound
    could not have changed that value, so the result is the same to the bit,
    only sooner.
    """
    ws, V, U, base, VH, VD, PV, M, M3, alpha, e, d, stack, _, _, kw = work
    h0, dh0, P = ws[0], ws[1], ws[2]
    AL = ws[7]
    nm = seg_eta.shape[1]
    best = -np.inf
    tbest = np.nan
    j0 = first_segment(seg_t1, lo)
    # a first lower bound from the segment starts inside the interval (no closed form needed)
    for j in range(j0, seg_t0.size):
        if seg_t0[j] > hi:
            break
        s = seg_s[j]
        if seg_t0[j] >= lo and (cond < 0 or ((smask[s] >> cond) & 1) == 1):
            if gen[s]:
                Om, phi = _setup(j, seg_t0, seg_s, seg_k, seg_eta, seg_deta, reg, dec, om, LW, CW, smask,
                                 gap, side, kst, pt0, pconst, pslope, pamp, pOm, pphase, ws)
                alpha_at(AL, 0.0, Om, phi, alpha)
            to_modal(gen[s], G[s], seg_eta[j], seg_deta[j], alpha, e, d)
            v = 0.0
            for n in range(nm):
                v += Wq[s, n] * (e[n] + rate * d[n])
            v = sign * (v + offset)
            if v > best:
                best = v
                tbest = seg_t0[j]
    for j in range(j0, seg_t0.size):
        if seg_t0[j] > hi:
            break
        a0 = max(seg_t0[j], lo)
        a1 = min(seg_t1[j], hi)
        if a1 < a0:
            continue
        s = seg_s[j]
        if cond >= 0 and ((smask[s] >> cond) & 1) == 0:
            continue
        Om, phi = _setup(j, seg_t0, seg_s, seg_k, seg_eta, seg_deta, reg, dec, om, LW, CW, smask, gap, side,
                         kst, pt0, pconst, pslope, pamp, pOm, pphase, ws)
        slot_row(gen[s], G[s], Wq[s], rate, V[0], U[0])
        for n in range(nm):
            V[0, n] *= sign
            U[0, n] *= sign
        base[0] = sign * offset
        project(V, U, base, dec[s], om[s], h0, dh0, P, AL, Om, VH, VD, PV, ONE_ROW)
        L = a1 - seg_t0[j]
        up, mag = row_ceiling(VH, VD, PV, base, reg[s], dec[s], wdh[s], L)
        if up + 1e-9 * mag < best:
            continue  # no value of this segment reaches best: its search would change nothing
        curvature_bound(VH, VD, dec[s], om[s], PV, Om, L, M)
        jerk_bound(VH, VD, dec[s], om[s], PV, Om, L, M3)
        best, tloc = _segment_max(a0 - seg_t0[j], L, M[0], M3[0], best, atol, xtol,
                                  stack, reg[s], dec[s], wdh[s], om[s], VH, VD, base, PV, Om, phi, kw)
        if not np.isnan(tloc):
            tbest = tloc + seg_t0[j]
    return best, tbest


@njit(cache=True, nogil=True)
def extremum(lo, hi, sign, offset, rate, row, cond_bit, atol, xtol, Wr, out_val, out_t,
             seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om, LW, CW, gen, G, smask, gap, side,
             kst, pt0, pconst, pslope, pamp, pOm, pphase):  # pragma: no cover - compiled
    """:func:`extremum_query` for each query ``q``, on the rows ``Wr[row[q]]``: values and times into ``out_*``.

    It makes the work arrays (so it counts references: a kernel without
    reference counting never frees the arrays it makes) and hands them to
    :func:`_extremum`.
    """
    _extremum(lo, hi, sign, offset, rate, row, cond_bit, atol, xtol, Wr, out_val, out_t, seg_t0, seg_t1, seg_s,
              seg_k, seg_eta, seg_deta, reg, dec, wdh, om, LW, CW, gen, G, smask, gap, side, kst, pt0, pconst, pslope,
              pamp, pOm, pphase, dense_work(seg_eta.shape[1]))


@njit(cache=True, nogil=True, _nrt=False)
def _extremum(lo, hi, sign, offset, rate, row, cond_bit, atol, xtol, Wr, out_val, out_t,
              seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om, LW, CW, gen, G, smask, gap, side,
              kst, pt0, pconst, pslope, pamp, pOm, pphase, work):  # pragma: no cover - compiled
    """The loop of :func:`extremum` on the work arrays it made."""
    for q in range(lo.size):
        out_val[q], out_t[q] = extremum_query(
            lo[q], hi[q], sign[q], offset[q], rate[q], Wr[row[q]], cond_bit[q], atol, xtol, seg_t0, seg_t1, seg_s,
            seg_k, seg_eta, seg_deta, reg, dec, wdh, om, LW, CW, gen, G, smask, gap, side, kst, pt0, pconst, pslope,
            pamp, pOm, pphase, work)


@njit(cache=True, nogil=True, _nrt=False)
def integral_query(lo, hi, Wq, seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om, LW, CW, gen, G,
                   smask, gap, side, kst, pt0, pconst, pslope, pamp, pOm, pphase, work):  # pragma: no cover
    """``int_lo^hi Wq[s] . eta dt`` over the segments, in closed form (``work`` from :func:`dense_work`)."""
    ws, V, U, base, VH, VD, PV = work[0], work[1], work[2], work[3], work[4], work[5], work[6]
    h0, dh0, P = ws[0], ws[1], ws[2]
    AL = ws[7]
    base[0] = 0.0
    total = 0.0
    j0 = first_segment(seg_t1, lo)
    for j in range(j0, seg_t0.size):
        if seg_t0[j] > hi:
            break
        a0 = max(seg_t0[j], lo)
        a1 = min(seg_t1[j], hi)
        if a1 <= a0:
            continue
        s = seg_s[j]
        Om, phi = _setup(j, seg_t0, seg_s, seg_k, seg_eta, seg_deta, reg, dec, om, LW, CW, smask, gap, side,
                         kst, pt0, pconst, pslope, pamp, pOm, pphase, ws)
        slot_row(gen[s], G[s], Wq[s], 0.0, V[0], U[0])
        project(V, U, base, dec[s], om[s], h0, dh0, P, AL, Om, VH, VD, PV, ONE_ROW)
        # the row from a0: its homogeneous part restarted there, the particular part shifted
        total += integral_of(VH, VD, PV, reg[s], dec[s], wdh[s], om[s], Om, phi, a1 - seg_t0[j])
        if a0 > seg_t0[j]:
            total -= integral_of(VH, VD, PV, reg[s], dec[s], wdh[s], om[s], Om, phi, a0 - seg_t0[j])
    return total


@njit(cache=True, nogil=True)
def integral(lo, hi, row, Wr, out, seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om, LW, CW, gen,
             G, smask, gap, side, kst, pt0, pconst, pslope, pamp, pOm, pphase):  # pragma: no cover - compiled
    """``out[q] = int_lo[q]^hi[q] Wr[row[q], s] . eta dt`` over the segments, in closed form (work arrays made
    here, as in :func:`extremum`)."""
    _integral(lo, hi, row, Wr, out, seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om, LW, CW, gen,
              G, smask, gap, side, kst, pt0, pconst, pslope, pamp, pOm, pphase, dense_work(seg_eta.shape[1]))


@njit(cache=True, nogil=True, _nrt=False)
def _integral(lo, hi, row, Wr, out, seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, reg, dec, wdh, om, LW, CW, gen,
              G, smask, gap, side, kst, pt0, pconst, pslope, pamp, pOm, pphase, work):  # pragma: no cover - compiled
    """The loop of :func:`integral` on the work arrays it made."""
    for q in range(lo.size):
        out[q] = integral_query(lo[q], hi[q], Wr[row[q]], seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, reg, dec,
                                wdh, om, LW, CW, gen, G, smask, gap, side, kst, pt0, pconst, pslope, pamp, pOm,
                                pphase, work)
