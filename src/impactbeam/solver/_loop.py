"""The compiled event loop of paper section 2, resumable.

:func:`run` walks from event to event: on each segment (one state, one load
piece) it prepares the closed form (:mod:`~impactbeam.solver._closed`),
judges the contactors at the segment start, scans for the first switching
event (:mod:`~impactbeam.solver._events`), records the segment and, at an
event, switches the state and carries the state across with the state's
transfer matrix (paper eq. 12, or the exact change of basis of a shared Ritz
basis), in the states' own modal frames.

Each state slot holds its coordinates ``z`` (:mod:`~impactbeam.solver.blocks`):
its modal coordinates when its modes diagonalise its damping (``gen = 0``),
else one coordinate per block of its first-order system, with the maps
``G`` (coordinates to the modal frame) and ``H`` (back). The packed arrays,
per slot ``s``:

* ``reg, dec, wdh, om``: regime, decay, damped frequency and frequency of
  each coordinate; ``omo``: the state's modal frequencies (energies);
* ``Wc[s, c]``: mode shapes at the contactors (modal frame);
* ``LW[s] = (bu, au, bp, ap)``: loads per unit of the excitation's time law
  (``bu`` on the second, ``au`` on the first equation of a coordinate) and
  of the preload; ``CW[s] = (Bc, Ac)``: loads per unit point force at each
  contactor (its gap force);
* ``RW[s] = (RV, RU, QV, QU)``: each contactor's deflection (``RV . z + RU .
  (z' - alpha)``) and velocity (``QV``, ``QU``) rows;
* ``G[s]``, ``H[s]``, ``Cd[s]``: the maps of a general state and its damping
  matrix in the modal frame (energies).

A contactor with a dashpot (``dash[c] > 0``) switches on its force ``k d +
c d'``: engaged it stays while that force is positive; released with a
penetration left (``phase[c] = 1``) it engages again if the force turns
positive before the penetration returns to 0, which ends that phase.

It never needs Python in between, but it returns to Python when it lacks
something, with a status code; Python supplies it and calls :func:`run` again,
which resumes where it stopped (all loop variables live in ``fc``/``ic`` and
the arrays passed in):

* ``NEED_STATE``: the state with engaged-contactor bit mask ``ic[REQ_A]`` is
  not built (states are built on demand, so memory and time do not grow like
  ``2**n_contactors``);
* ``NEED_TRANSFER``: the transfer matrix from slot ``ic[REQ_A]`` to slot
  ``ic[REQ_B]`` is missing;
* ``NEED_SPACE``: a record array is full;
* ``CHECKPOINT``: the budget of one call is spent (progress reports, Ctrl-C
  and the move from the interpreted to the compiled kernels are handled by
  Python there; a scan stopped inside a segment resumes exactly where it
  was, so the solution does not depend on the budget or on any return to
  Python). The budget counts scan steps, and :data:`PASS_COST` for each
  switch and each segment's set-up, so that a run of switches with few scan
  steps between them (a contact bouncing as it settles) returns too;
* ``DONE`` / ``CHATTER``: the run ended, at ``end_time`` or at the
  chattering guard (``max_events`` events, or endless switching at one
  instant).
"""

from __future__ import annotations

import math

import numpy as np
from ._jit import njit

from ._closed import (
    NP, alpha_at, copy_into, curvature_bound, kernels_into, load_phase, particular_at, project, segment_setup, state_at,
    state_from, workspace,
)
from ._elementary import kernel_work
from ._events import departure, scan

from ._codes import (  # noqa: E402 - status codes and the carry's layout, shared with the Python side
    CHATTER, CHECKPOINT, DONE, F_E_PEAK, F_E_SUM, F_LAST_T, F_T, F_TAU, F_WARN_MOVED, F_WARN_SCALE, F_WARN_T,
    I_EVALS, I_JUST, I_NEV, I_NJUMP, I_NSEG, I_NSLOTS, I_NTR, I_PENDING, I_PIECE, I_RESUME, I_SAME, I_SLOT, I_USED,
    I_WARN_C, I_WARN_N, MOVED_FLOOR, MOVED_WARN, NEED_SPACE, NEED_STATE, NEED_TRANSFER, REQ_A, REQ_B,
)

KMAX = 5  # highest derivative used to judge a tangency
# what a switch or a segment's set-up counts in the budget of a call, in scan steps: about their cost relative to a
# step's (interpreted, 16 modes: ~3 ms against ~0.1 ms), so that a call returns after about the same time either way
PASS_COST = 32
ROW_MAIN, ROW_PHASE = 0, 1  # a contactor's switching row; the end of its released phase


@njit(cache=True, nogil=True, _nrt=False)
def _dot(x, y):  # pragma: no cover - compiled
    s = 0.0
    for n in range(x.size):
        s += x[n] * y[n]
    return s


@njit(cache=True, nogil=True, _nrt=False)
def _zero(x):  # pragma: no cover - compiled
    for i in range(x.size):
        x[i] = 0


@njit(cache=True, nogil=True, _nrt=False)
def energy(mask, e, d, omo, Wc, gap, side, kst):  # pragma: no cover - compiled
    """Mechanical energy from the modal frame: beam, end supports and engaged contactors (with their gaps)."""
    E = 0.0
    for n in range(e.size):
        E += 0.5 * (d[n] * d[n] + omo[n] * omo[n] * e[n] * e[n])
    for i in range(gap.size):
        if (mask >> i) & 1:
            wc = _dot(Wc[i], e)
            g = gap[i] - side[i] * wc
            E += 0.5 * kst[i] * (g * g - wc * wc)
    return E


@njit(cache=True, nogil=True, _nrt=False)
def to_modal(gen, G, z, dz, alpha, e, d):  # pragma: no cover - compiled
    """Modal-frame displacement ``e`` and velocity ``d`` of a slot's coordinates ``z, z'``."""
    nm = z.size
    if gen == 0:
        copy_into(e, z)
        copy_into(d, dz)
        return
    for m in range(nm):
        se = 0.0
        sd = 0.0
        for n in range(nm):
            r = dz[n] - alpha[n]
            se += G[0, m, n] * z[n] + G[1, m, n] * r
            sd += G[0, nm + m, n] * z[n] + G[1, nm + m, n] * r
        e[m] = se
        d[m] = sd


@njit(cache=True, nogil=True, _nrt=False)
def _find(keys, n, key):  # pragma: no cover - compiled
    for i in range(n):
        if keys[i] == key:
            return i
    return -1


@njit(cache=True, nogil=True, _nrt=False)
def load_value(kp, t, pt0, pconst, pslope, pamp, pOm, pphase):  # pragma: no cover - compiled
    """The excitation's time law ``u(t)`` in piece ``kp``."""
    tp = t - pt0[kp]
    u = pconst[kp] + pslope[kp] * tp
    if pamp[kp] != 0.0:
        u += pamp[kp] * math.sin(pOm[kp] * tp + pphase[kp])
    return u


@njit(cache=True, nogil=True, _nrt=False)
def _switch(fc, ic, eta, deta, own_e, own_d, smask, gen, omo, Wc, LW, CW, H, Tm, tr_from, tr_to,
            gap, side, kst, dash, phase, u_now, ev_t, ev_kind, ev_c, ev_v, ev_d, jumps, tol_h, work):
    # pragma: no cover - compiled
    """Switch contactor ``ic[I_PENDING]`` at ``fc[F_T]``; a status code if something is missing, else -1.

    ``own_e, own_d`` hold the state in the current slot's modal frame.
    """
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
    E_before = energy(smask[s], own_e, own_d, omo[s], Wc[s], gap, side, kst)
    engaging = (new_mask >> c) & 1
    wb = work[0, :nc]
    for i in range(nc):
        wb[i] = _dot(Wc[s, i], own_e)
    pen = side[c] * wb[c] - gap[c]
    # a contact under way at the start: its spring's energy is the initial state's, neither a change the switch
    # makes nor a dashpot's re-engagement (its penetration is recorded as 0: no release loss to book)
    start_up = engaging and t == 0.0 and pen > 0.0
    if nev > 0 and ev_t[nev - 1] == t and ev_c[nev - 1] == c:
        ic[I_NEV] = nev - 1  # an impact and a rebound at one instant cancel (grazing touch)
    else:
        ev_t[nev] = t
        ev_kind[nev] = 1 if engaging else 0
        ev_c[nev] = c
        ev_v[nev] = _dot(Wc[s, c], own_d)
        ev_d[nev] = 0.0 if start_up else pen
        ic[I_NEV] = nev + 1
    phase[c] = 1 if (not engaging and dash[c] > 0.0 and pen > tol_h) else 0
    spring = 0.5 * kst[c] * pen * pen if pen > 0.0 else 0.0  # the switching spring's energy
    if start_up:
        E_before += spring
    e1 = work[1, :nm]
    d1 = work[2, :nm]
    T = Tm[k]
    for n in range(nm):
        e1[n] = _dot(T[n], own_e)
        d1[n] = _dot(T[n], own_d)
    copy_into(own_e, e1)
    copy_into(own_d, d1)
    if gen[ns] == 0:
        copy_into(eta, own_e)
        copy_into(deta, own_d)
    else:  # the new state's coordinates: z = H0 x, z' = H1 x + alpha(t)
        for n in range(nm):
            al = LW[ns, 1, n] * u_now + LW[ns, 3, n]
            for i in range(nc):
                if (new_mask >> i) & 1 and gap[i] != 0.0:
                    al += side[i] * kst[i] * gap[i] * CW[ns, 1, i, n]
            se = 0.0
            sd = 0.0
            for m in range(nm):
                se += H[ns, 0, n, m] * own_e[m] + H[ns, 0, n, nm + m] * own_d[m]
                sd += H[ns, 1, n, m] * own_e[m] + H[ns, 1, n, nm + m] * own_d[m]
            eta[n] = se
            deta[n] = sd + al
    lossy = False
    for i in range(nc):
        moved = abs(_dot(Wc[ns, i], own_e) - wb[i])
        scale = max(max(gap[i], abs(wb[i])), MOVED_FLOOR * tol_h)  # floor 1e-6 L: zero gap at rest
        if moved > MOVED_WARN * scale:
            if not (ic[I_WARN_N] or lossy) or moved / scale > fc[F_WARN_MOVED] / fc[F_WARN_SCALE]:
                fc[F_WARN_T] = t
                fc[F_WARN_MOVED] = moved
                fc[F_WARN_SCALE] = scale
                ic[I_WARN_C] = i
            lossy = True
    if lossy:
        ic[I_WARN_N] += 1
    E_after = energy(new_mask, own_e, own_d, omo[ns], Wc[ns], gap, side, kst)
    jumps[ic[I_NJUMP]] = E_after - E_before
    # the projection's change: the jump less the spring energy a dashpot contactor's engagement adds or release
    # removes while penetrated (its release losses, metrics.release_loss_sum; not the modes': engine.energy_warning)
    booked = 0.0 if (start_up or dash[c] <= 0.0) else (spring if engaging else -spring)
    fc[F_E_SUM] += abs(E_after - E_before - booked)
    fc[F_E_PEAK] = max(fc[F_E_PEAK], E_before, E_after)
    ic[I_NJUMP] += 1
    ic[I_SLOT] = ns
    ic[I_JUST] = c
    ic[I_PENDING] = -1
    return -1


@njit(cache=True, nogil=True, _nrt=False)
def contactor_rows(s, mask, RW, gap, side, kst, dash, phase, V, U, base, rowc, rowk):  # pragma: no cover
    """The switching rows of slot ``s`` (positive while the state holds); their number.

    Free: the opening ``gap - s w`` (a released dashpot contactor: ``-F/k``,
    and its penetration, whose return to 0 ends that phase). Engaged: the
    penetration ``s w - gap``, or ``F / k = d + (c/k) d'`` with a dashpot.
    """
    nm = V.shape[1]
    nr = 0
    for c in range(gap.size):
        eng = (mask >> c) & 1
        sg = side[c] if eng else -side[c]
        r = dash[c] / kst[c] if (eng or phase[c]) else 0.0
        for n in range(nm):
            V[nr, n] = sg * (RW[s, 0, c, n] + r * RW[s, 2, c, n])
            U[nr, n] = sg * (RW[s, 1, c, n] + r * RW[s, 3, c, n])
        base[nr] = -gap[c] if eng else gap[c]
        rowc[nr] = c
        rowk[nr] = ROW_MAIN
        nr += 1
        if not eng and phase[c]:
            for n in range(nm):
                V[nr, n] = side[c] * RW[s, 0, c, n]
                U[nr, n] = side[c] * RW[s, 1, c, n]
            base[nr] = -gap[c]
            rowc[nr] = c
            rowk[nr] = ROW_PHASE
            nr += 1
    return nr


@njit(cache=True, nogil=True, _nrt=False)
def _released_at_start(t, c, mask, g, dg, dash, kst, tol_h):  # pragma: no cover - compiled
    """Whether free dashpot contactor ``c``, penetrated at t = 0, starts released (its force ``k d + c d'`` pulls).

    ``g, dg``: its opening ``-d`` and slope ``-d'`` in the free state. The law
    never pulls, so such a contact is not under way: it starts as after a
    release that left a penetration (``phase``), and engages if its force
    turns to pushing before the penetration is gone.
    """
    if t != 0.0 or (mask >> c) & 1 or dash[c] <= 0.0 or g >= -tol_h:
        return False
    return g + dash[c] / kst[c] * dg > 0.0


@njit(cache=True, nogil=True, _nrt=False)
def _judge_start(ic, fc, g, nr, rowc, V, U, base, dec, om, eta, deta, lA, lB, lD, lE, AL, Om, phi, toggles,
                 tol_h, dvec, mag, dwork):  # pragma: no cover - compiled
    """Row to act on at the segment start (inconsistent, or departing into its stop), or -1."""
    just = ic[I_JUST]
    for r in range(nr):
        if g[r] > tol_h:
            continue
        c = rowc[r]
        bad = g[r] < -tol_h and c != just
        if not bad:
            bad = departure(V[r], U[r], base[r], dec, om, eta, deta, lA, lB, lD, lE, AL, Om, phi, dvec, mag,
                            dwork) < 0
        if bad:
            t = fc[F_T]
            if t != fc[F_LAST_T]:
                _zero(toggles)
                fc[F_LAST_T] = t
            toggles[c] += 1
            if toggles[c] <= 2:
                return r
    return -1


@njit(cache=True, nogil=True, _nrt=False)
def _openings(PV, VH, VD, base, nr, Om, phi, tol_h, g, dg):  # pragma: no cover - compiled
    """The first ``nr`` rows' values ``g`` and slopes ``dg`` at the segment start; True if one is within ``tol_h``."""
    touching = False
    sn, cs = load_phase(0.0, Om, phi)
    for r in range(nr):
        pv, pd = particular_at(PV[r], 0.0, Om, sn, cs)
        g[r] = base[r] + pv
        dg[r] = pd
        for n in range(VH.shape[1]):
            g[r] += VH[r, n]
            dg[r] += VD[r, n]
        touching = touching or g[r] <= tol_h
    return touching


@njit(cache=True, nogil=True)
def run(reg, dec, wdh, om, omo, Wc, LW, CW, RW, gen, G, H, smask, Tm, tr_from, tr_to, gap, side, kst, dash,
        pt0, pt1, pconst, pslope, pamp, pOm, pphase,
        T_end, tol_h, xtol, max_events, budget, fc, ic, eta, deta, own_e, own_d, toggles, phase, held,
        seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, ev_t, ev_kind, ev_c, ev_v, ev_d, jumps):
    # pragma: no cover - compiled
    """Run (or resume) the event loop; returns a status code (module docstring).

    A scan stopped by the budget (``CHECKPOINT`` inside a segment) keeps its
    place, openings and bounds in ``fc[F_TAU]``, ``ic[I_USED]`` and ``held``
    (``3 * max(2 n_c, 1)`` floats) and resumes from there: the solution does
    not depend on where the run returned to Python.
    """
    nm = eta.size
    nrm = 2 * gap.size
    h0, dh0, P, lA, lB, lD, lE, AL = workspace(nm)
    vectors = (h0, dh0, lA, lB, lD, lE, np.empty(nm), np.empty(nrm), np.empty(nrm), np.empty(nrm), np.empty(nrm),
               np.empty(nrm), np.empty(nrm), np.empty(KMAX + 1), np.empty(KMAX + 1), np.empty(nm), np.empty(nm))
    matrices = (P, AL, np.empty((nrm, nm)), np.empty((nrm, nm)), np.empty((nrm, nm)), np.empty((nrm, nm)),
                np.empty((nrm, nm)), np.empty((nrm, nm)), np.empty((nrm, NP)), np.empty((96, 6)),
                np.empty((3, max(nm, gap.size))), np.empty((2, KMAX + 2)), kernel_work(nm))
    rows = (np.empty(nrm, dtype=np.int64), np.empty(nrm, dtype=np.int64))
    return _walk(reg, dec, wdh, om, omo, Wc, LW, CW, RW, gen, G, H, smask, Tm, tr_from, tr_to, gap, side, kst, dash,
                 pt0, pt1, pconst, pslope, pamp, pOm, pphase, T_end, tol_h, xtol, max_events, budget, fc, ic, eta,
                 deta, own_e, own_d, toggles, phase, held, seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, ev_t,
                 ev_kind, ev_c, ev_v, ev_d, jumps, vectors, matrices, rows)


@njit(cache=True, nogil=True, _nrt=False)
def _walk(reg, dec, wdh, om, omo, Wc, LW, CW, RW, gen, G, H, smask, Tm, tr_from, tr_to, gap, side, kst, dash,
          pt0, pt1, pconst, pslope, pamp, pOm, pphase,
          T_end, tol_h, xtol, max_events, budget, fc, ic, eta, deta, own_e, own_d, toggles, phase, held,
          seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, ev_t, ev_kind, ev_c, ev_v, ev_d, jumps,
          vectors, matrices, rows):  # pragma: no cover - compiled
    """The loop of :func:`run`, on the scratch arrays it made; no reference counting (:mod:`._jit`)."""
    nm = eta.size
    nc = gap.size
    nrm = 2 * nc
    h0, dh0, lA, lB, lD, lE, alpha, base, g, dg, gb, dgb, M, dvec, mag, kc, ks = vectors
    P, AL, V, U, VH, VD, WH, WD, PV, stack, work, dwork, kw = matrices
    rowc, rowk = rows
    evals = 0
    k_slot = -1  # the slot and segment length of the kernels in kc, ks: equal lengths (a sampled load) share them
    k_tau = -1.0
    while True:
        if ic[I_PENDING] >= 0:
            t = fc[F_T]
            if t != fc[F_LAST_T]:
                fc[F_LAST_T] = t
                _zero(toggles)
                ic[I_SAME] = 0
            u_now = load_value(ic[I_PIECE], t, pt0, pconst, pslope, pamp, pOm, pphase) if ic[I_PIECE] < pt0.size else 0.0
            st = _switch(fc, ic, eta, deta, own_e, own_d, smask, gen, omo, Wc, LW, CW, H, Tm, tr_from, tr_to,
                         gap, side, kst, dash, phase, u_now, ev_t, ev_kind, ev_c, ev_v, ev_d, jumps, tol_h, work)
            if st >= 0:
                return st
            ic[I_SAME] += 1
            if ic[I_NEV] >= max_events or ic[I_SAME] > 4 * nc + 8:
                return CHATTER
            evals += PASS_COST
            if evals >= budget:
                return CHECKPOINT
            continue
        t = fc[F_T]
        kp = ic[I_PIECE]
        if t >= T_end or kp >= pt0.size:
            return DONE
        s = ic[I_SLOT]
        reg_s, dec_s, wdh_s, om_s = reg[s], dec[s], wdh[s], om[s]
        Om, phi = segment_setup(s, kp, t, eta, deta, reg, dec, om, LW[:, 0], LW[:, 1], CW[:, 0], CW[:, 1],
                                LW[:, 2], LW[:, 3], smask, gap, side, kst, pt0, pconst, pslope, pamp, pOm, pphase,
                                h0, dh0, P, lA, lB, lD, lE, AL)
        nr = contactor_rows(s, smask[s], RW, gap, side, kst, dash, phase, V, U, base, rowc, rowk)
        t_end = min(pt1[kp], T_end)
        tau_end = t_end - t
        project(V, U, base, dec_s, om_s, h0, dh0, P, AL, Om, VH, VD, PV, nr)
        resume = ic[I_RESUME] == 1
        touching = _openings(PV, VH, VD, base, nr, Om, phi, tol_h, g, dg)
        if touching and not resume:
            r_bad = _judge_start(ic, fc, g, nr, rowc, V, U, base, dec_s, om_s, eta, deta, lA, lB, lD, lE, AL,
                                 Om, phi, toggles, tol_h, dvec, mag, dwork)
            if r_bad >= 0:
                c = rowc[r_bad]
                if rowk[r_bad] == ROW_PHASE:
                    phase[c] = 0  # the penetration left by a release is gone: a plain opening from here
                    continue
                if _released_at_start(t, c, smask[s], g[r_bad], dg[r_bad], dash, kst, tol_h):
                    phase[c] = 1  # penetrated at the start but pulling: released, as after a rebound
                    continue
                alpha_at(AL, 0.0, Om, phi, alpha)
                to_modal(gen[s], G[s], eta, deta, alpha, own_e, own_d)
                ic[I_PENDING] = c
                continue
        if ic[I_NSEG] + 1 > seg_t0.size:
            return NEED_SPACE
        tau0 = 0.0
        used0 = 0
        if resume:  # the scan of this segment stopped at a checkpoint: on from where it was
            tau0 = fc[F_TAU]
            used0 = ic[I_USED]
            for r in range(nr):
                g[r] = held[r]
                dg[r] = held[nrm + r]
                M[r] = held[2 * nrm + r]
            ic[I_RESUME] = 0
        else:
            curvature_bound(VH[:nr], VD[:nr], dec_s, om_s, PV[:nr], Om, tau_end, M[:nr])
        wmax = 0.0
        for n in range(nm):
            wmax = max(wmax, om_s[n])
        dmin = math.pi / (4.0 * wmax) if wmax > 0.0 else tau_end
        ready = s == k_slot and tau_end == k_tau
        tau_e, ch, used, ready = scan(tau0, tau_end, g[:nr], dg[:nr], gb[:nr], dgb[:nr], M[:nr], dmin, xtol, tol_h,
                                      used0, budget - evals, stack, reg_s, dec_s, wdh_s, om_s, VH[:nr], VD[:nr],
                                      base[:nr], PV[:nr], Om, phi, WH[:nr], WD[:nr], kc, ks, ready, kw)
        if ch == -1 and not ready:  # the segment's end reached without a scan step there
            kernels_into(tau_end, reg_s, dec_s, wdh_s, kc, ks, kw)
            ready = True
        if ready:
            k_slot = s
            k_tau = tau_end
        evals += used - used0
        ic[I_EVALS] += used - used0
        if ch == -2:  # budget spent inside the segment: keep the scan's place and report
            fc[F_TAU] = tau_e
            ic[I_USED] = used
            for r in range(nr):
                held[r] = g[r]
                held[nrm + r] = dg[r]
                held[2 * nrm + r] = M[r]
            ic[I_RESUME] = 1
            return CHECKPOINT
        te = t + tau_e if ch != -1 else t_end
        if te > t or ch >= 0:
            i = ic[I_NSEG]
            seg_t0[i] = t
            seg_t1[i] = te
            seg_s[i] = s
            seg_k[i] = kp
            copy_into(seg_eta[i], eta)  # a view costs nothing here: no reference counting
            copy_into(seg_deta[i], deta)
            ic[I_NSEG] = i + 1
            if ch == -1:  # te - t = tau_end: its kernels are at hand (computed once for equal lengths)
                state_from(tau_end, kc, ks, dec_s, om_s, h0, dh0, P, Om, phi, eta, deta)
            else:
                state_at(te - t, reg_s, dec_s, wdh_s, om_s, h0, dh0, P, Om, phi, eta, deta, kw)
        fc[F_T] = te
        if ch >= 0:
            c = rowc[ch]
            if rowk[ch] == ROW_PHASE:
                phase[c] = 0
                ic[I_JUST] = -1
            else:
                alpha_at(AL, te - t, Om, phi, alpha)
                to_modal(gen[s], G[s], eta, deta, alpha, own_e, own_d)
                ic[I_PENDING] = c
        else:
            ic[I_JUST] = -1
            if te >= pt1[kp]:
                if gen[s] != 0 and kp + 1 < pt0.size:
                    # a block's first equation carries the load (alpha, au u(t)): where the next piece makes
                    # u jump, the coordinates' rates jump with alpha, the state they stand for (to_modal)
                    # staying continuous
                    du = (load_value(kp + 1, te, pt0, pconst, pslope, pamp, pOm, pphase)
                          - load_value(kp, te, pt0, pconst, pslope, pamp, pOm, pphase))
                    if du != 0.0:
                        for n in range(nm):
                            deta[n] += LW[s, 1, n] * du
                ic[I_PIECE] = kp + 1
        evals += PASS_COST
        if evals >= budget:
            return CHECKPOINT
