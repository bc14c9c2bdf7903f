"""The compiled event loop of paper section 2, resumable.

:func:`run` walks from event to event: on each segment (one state, one load
piece) it prepares the closed form (:mod:`~impactbeam.solver._closed`),
judges the contactors at the segment start, scans for the first switching
event (:mod:`~impactbeam.solver._events`), records the segment and, at an
event, switches the state and carries the modal coordinates across with the
state's transfer matrix (paper eq. 12, or the exact change of basis of a
shared Ritz basis).

It never needs Python in between, but it returns to Python when it lacks
something, with a status code; Python supplies it and calls :func:`run` again,
which resumes where it stopped (all loop variables live in ``fc``/``ic``):

* ``NEED_STATE``: the state with engaged-contactor bit mask ``ic[REQ_A]`` is
  not built (states are built on demand, so memory and time do not grow like
  ``2**n_contactors``);
* ``NEED_TRANSFER``: the transfer matrix from slot ``ic[REQ_A]`` to slot
  ``ic[REQ_B]`` is missing;
* ``NEED_SPACE``: a record array is full;
* ``CHECKPOINT``: the evaluation budget of one call is spent (progress
  reports and Ctrl-C are handled by Python there);
* ``DONE`` / ``CHATTER``: the run ended, at ``end_time`` or at the
  chattering guard (``max_events`` events, or endless switching at one
  instant).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from ._closed import curvature_bound, project, segment_setup, state_at, workspace
from ._events import departure, scan

DONE, CHATTER, NEED_STATE, NEED_TRANSFER, NEED_SPACE, CHECKPOINT = 0, 1, 2, 3, 4, 5
# integer carry
I_SLOT, I_PIECE, I_JUST, I_PENDING, I_NSEG, I_NEV, I_NJUMP, I_NSLOTS, I_NTR = 0, 1, 2, 3, 4, 5, 6, 7, 8
I_WARN_C, REQ_A, REQ_B, I_SKIP, I_EVALS, I_SAME, I_WARN_N = 9, 10, 11, 12, 13, 14, 15
N_INT = 16
# float carry
F_T, F_LAST_T, F_WARN_T, F_WARN_MOVED, F_WARN_SCALE = 0, 1, 2, 3, 4
N_FLOAT = 5
KMAX = 5  # highest derivative used to judge a tangency


@njit(cache=True, nogil=True)
def _dot(x, y):  # pragma: no cover - compiled
    s = 0.0
    for n in range(x.size):
        s += x[n] * y[n]
    return s


@njit(cache=True, nogil=True)
def _energy(mask, eta, deta, om, Wc, gap, side, kst):  # pragma: no cover - compiled
    """Mechanical energy: beam, end supports and engaged contactors (with their gaps)."""
    E = 0.0
    for n in range(eta.size):
        E += 0.5 * (deta[n] * deta[n] + om[n] * om[n] * eta[n] * eta[n])
    for i in range(gap.size):
        if (mask >> i) & 1:
            wc = _dot(Wc[i], eta)
            g = gap[i] - side[i] * wc
            E += 0.5 * kst[i] * (g * g - wc * wc)
    return E


@njit(cache=True, nogil=True)
def _find(keys, n, key):  # pragma: no cover - compiled
    for i in range(n):
        if keys[i] == key:
            return i
    return -1


@njit(cache=True, nogil=True)
def _switch(fc, ic, eta, deta, smask, om, Wc, Tm, tr_from, tr_to, gap, side, kst,
            ev_t, ev_kind, ev_c, ev_v, jumps, tol_h, work):  # pragma: no cover - compiled
    """Switch contactor ``ic[I_PENDING]`` at ``fc[F_T]``; a status code if something is missing, else -1."""
    c = ic[I_PENDING]
    s = ic[I_SLOT]
    new_mask = smask[s] ^ (1 << c)
    ns = _find(smask, ic[I_NSLOTS], new_mask)
    if ns < 0:
        ic[REQ_A] = new_mask
        return NEED_STATE
    k = -1
    for i in range(ic[I_NTR]):
        if tr_from[i] == s and tr_to[i] == ns:
            k = i
            break
    if k < 0:
        ic[REQ_A] = s
        ic[REQ_B] = ns
        return NEED_TRANSFER
    nev = ic[I_NEV]
    if nev + 1 > ev_t.size or ic[I_NJUMP] + 1 > jumps.size:
        return NEED_SPACE
    t = fc[F_T]
    nc = gap.size
    nm = eta.size
    E_before = _energy(smask[s], eta, deta, om[s], Wc[s], gap, side, kst)
    if nev > 0 and ev_t[nev - 1] == t and ev_c[nev - 1] == c:
        ic[I_NEV] = nev - 1  # an impact and a rebound at one instant cancel (grazing touch)
    else:
        ev_t[nev] = t
        ev_kind[nev] = 1 if (new_mask >> c) & 1 else 0
        ev_c[nev] = c
        ev_v[nev] = _dot(Wc[s, c], deta)
        ic[I_NEV] = nev + 1
    wb = work[0, :nc]
    for i in range(nc):
        wb[i] = _dot(Wc[s, i], eta)
    e1 = work[1, :nm]
    d1 = work[2, :nm]
    T = Tm[k]
    for n in range(nm):
        e1[n] = _dot(T[n], eta)
        d1[n] = _dot(T[n], deta)
    eta[:] = e1
    deta[:] = d1
    lossy = False
    for i in range(nc):
        moved = abs(_dot(Wc[ns, i], eta) - wb[i])
        scale = max(max(gap[i], abs(wb[i])), 1e6 * tol_h)  # floor 1e-6 L: zero gap at rest
        if moved > 0.05 * scale:
            if not (ic[I_WARN_N] or lossy) or moved / scale > fc[F_WARN_MOVED] / fc[F_WARN_SCALE]:
                fc[F_WARN_T] = t
                fc[F_WARN_MOVED] = moved
                fc[F_WARN_SCALE] = scale
                ic[I_WARN_C] = i
            lossy = True
    if lossy:
        ic[I_WARN_N] += 1
    jumps[ic[I_NJUMP]] = _energy(new_mask, eta, deta, om[ns], Wc[ns], gap, side, kst) - E_before
    ic[I_NJUMP] += 1
    ic[I_SLOT] = ns
    ic[I_JUST] = c
    ic[I_PENDING] = -1
    return -1


@njit(cache=True, nogil=True)
def _judge_start(ic, fc, g, V, base, dec, om, eta, deta, lA, lB, lD, Om, phi, toggles, tol_h, dvec, mag):
    # pragma: no cover - compiled
    """Contactor to switch at the segment start (inconsistent or departing into its stop), or -1."""
    just = ic[I_JUST]
    for c in range(g.size):
        if g[c] > tol_h:
            continue
        bad = g[c] < -tol_h and c != just
        if not bad:
            bad = departure(V[c], base[c], dec, om, eta, deta, lA, lB, lD, Om, phi, dvec, mag) < 0
        if bad:
            t = fc[F_T]
            if t != fc[F_LAST_T]:
                toggles[:] = 0
                fc[F_LAST_T] = t
            toggles[c] += 1
            if toggles[c] <= 2:
                return c
    return -1


@njit(cache=True, nogil=True)
def run(reg, dec, wdh, om, Wc, pw, smask, Tm, tr_from, tr_to, gap, side, kst,
        pt0, pt1, pconst, pslope, pamp, pOm, pphase,
        T_end, tol_h, xtol, max_events, budget, fc, ic, eta, deta, toggles,
        seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, ev_t, ev_kind, ev_c, ev_v, jumps):
    # pragma: no cover - compiled
    """Run (or resume) the event loop; returns a status code (module docstring)."""
    nm = eta.size
    nc = gap.size
    h0, dh0, P, lA, lB, lD = workspace(nm)
    V = np.empty((nc, nm))
    base = np.empty(nc)
    VH = np.empty((nc, nm))
    VD = np.empty((nc, nm))
    PV = np.empty((nc, 7))
    g = np.empty(nc)
    dg = np.empty(nc)
    gb = np.empty(nc)
    dgb = np.empty(nc)
    M = np.empty(nc)
    dvec = np.empty(KMAX + 1)
    mag = np.empty(KMAX + 1)
    stack = np.empty((96, 6))
    work = np.empty((3, max(nm, nc)))
    evals = 0
    while True:
        if ic[I_PENDING] >= 0:
            t = fc[F_T]
            if t != fc[F_LAST_T]:
                fc[F_LAST_T] = t
                toggles[:] = 0
                ic[I_SAME] = 0
            st = _switch(fc, ic, eta, deta, smask, om, Wc, Tm, tr_from, tr_to, gap, side, kst,
                         ev_t, ev_kind, ev_c, ev_v, jumps, tol_h, work)
            if st >= 0:
                return st
            ic[I_SAME] += 1
            if ic[I_NEV] >= max_events or ic[I_SAME] > 4 * nc + 8:
                return CHATTER
            continue
        t = fc[F_T]
        kp = ic[I_PIECE]
        if t >= T_end or kp >= pt0.size:
            return DONE
        s = ic[I_SLOT]
        Om, phi = segment_setup(s, kp, t, eta, deta, reg, dec, om, pw, Wc, smask, gap, side, kst,
                                pt0, pconst, pslope, pamp, pOm, pphase, h0, dh0, P, lA, lB, lD)
        mask = smask[s]
        for c in range(nc):
            o = -1.0 if (mask >> c) & 1 else 1.0
            base[c] = o * gap[c]
            for n in range(nm):
                V[c, n] = -o * side[c] * Wc[s, c, n]
            g[c] = base[c] + _dot(V[c], eta)
            dg[c] = _dot(V[c], deta)
        if ic[I_SKIP] == 0 and nc > 0:
            c_bad = _judge_start(ic, fc, g, V, base, dec[s], om[s], eta, deta, lA, lB, lD, Om, phi,
                                 toggles, tol_h, dvec, mag)
            if c_bad >= 0:
                ic[I_PENDING] = c_bad
                continue
        if ic[I_NSEG] + 1 > seg_t0.size:
            return NEED_SPACE
        t_end = min(pt1[kp], T_end)
        tau_end = t_end - t
        project(V, base, h0, dh0, P, VH, VD, PV, nc)
        curvature_bound(V, dec[s], om[s], h0, dh0, PV, Om, tau_end, M)
        wmax = 0.0
        for n in range(nm):
            wmax = max(wmax, om[s, n])
        dmin = math.pi / (4.0 * wmax) if wmax > 0.0 else tau_end
        tau_e, ch, used = scan(0.0, tau_end, g, dg, gb, dgb, M, dmin, xtol, tol_h, budget - evals, stack,
                               reg[s], dec[s], wdh[s], om[s], VH, VD, base, PV, Om, phi, V, h0, dh0)
        evals += used
        ic[I_EVALS] += used
        te = t + tau_e if ch != -1 else t_end
        if te > t or ch >= 0:
            i = ic[I_NSEG]
            seg_t0[i] = t
            seg_t1[i] = te
            seg_s[i] = s
            seg_k[i] = kp
            seg_eta[i, :] = eta
            seg_deta[i, :] = deta
            ic[I_NSEG] = i + 1
            state_at(te - t, reg[s], dec[s], wdh[s], om[s], h0, dh0, P, Om, phi, eta, deta)
        fc[F_T] = te
        ic[I_SKIP] = 0
        if ch >= 0:
            ic[I_PENDING] = ch
        elif ch == -2:
            ic[I_JUST] = -1
            ic[I_SKIP] = 1
            return CHECKPOINT
        else:
            ic[I_JUST] = -1
            if te >= pt1[kp]:
                ic[I_PIECE] = kp + 1
        if evals >= budget:
            return CHECKPOINT
