"""Compiled batches: many cases of one packed problem in one call, metrics included.

The cases of a batch share their packed problem (beam, contactor positions,
stiffnesses and dashpots, damping, load distribution, modes, basis: the
states and transfer matrices, built once); each has its own gaps and sides,
load pieces (padded into arrays), end time, event tolerance, event limit
and initial modal state. :func:`run_batch` runs them one after the other
through the event loop of :func:`~impactbeam.solver._loop.run` and computes
each one's metrics with :func:`~impactbeam.solver._metrics.run_metrics` as it
ends: the same compiled code as a single run, so a case gives the same bits
alone or in a batch.

Like the loop it is resumable: it returns to Python when the loop lacks a
state, a transfer matrix or room (the case being run in ``bc[B_CASE]``, the
loop's own request in ``ic``), and after ``budget`` scan steps (progress,
Ctrl-C); called again with the same arrays it goes on where it stopped.
With ``bc[B_STOP_EACH]`` it also returns ``CASE_DONE`` after each case (a
continuation, whose next case starts from this one's final state).
"""

from __future__ import annotations

from ._closed import copy_into
from ._codes import CASE_DONE
from ._dense import dense_work
from ._jit import njit
from ._loop import (
    CHATTER, CHECKPOINT, DONE, F_E_PEAK, F_E_SUM, F_LAST_T, F_T, F_WARN_MOVED, F_WARN_SCALE, F_WARN_T, I_EVALS, I_JUST, I_NEV, I_NJUMP,
    I_NSEG, I_NSLOTS, I_NTR, I_PENDING, I_WARN_C, I_WARN_N, run,
)
from ._metrics import run_metrics

__all__ = ["run_batch", "start_case", "CASE_DONE", "B_CASE", "B_STARTED", "B_STOP_EACH", "B_STEPS", "N_BC"]

B_CASE, B_STARTED, B_STOP_EACH, B_STEPS = 0, 1, 2, 3
N_BC = 4


@njit(cache=True, nogil=True)
def start_case(k, eta0, deta0, fc, ic, eta, deta, own_e, own_d, toggles, phase, held):  # pragma: no cover
    """Set the loop's carry to the start of case ``k``: at t = 0, in its initial modal state.

    The counts of built states and transfer matrices (``ic[I_NSLOTS]``,
    ``ic[I_NTR]``) belong to the packed problem and are kept.
    """
    for i in range(fc.size):
        fc[i] = 0.0
    fc[F_LAST_T] = -1.0
    nslots = ic[I_NSLOTS]
    ntr = ic[I_NTR]
    for i in range(ic.size):
        ic[i] = 0
    ic[I_NSLOTS] = nslots
    ic[I_NTR] = ntr
    ic[I_JUST] = -1
    ic[I_PENDING] = -1
    ic[I_WARN_C] = -1
    copy_into(eta, eta0[k])
    copy_into(deta, deta0[k])
    copy_into(own_e, eta0[k])
    copy_into(own_d, deta0[k])
    for i in range(toggles.size):
        toggles[i] = 0
        phase[i] = 0
    for i in range(held.size):
        held[i] = 0.0


@njit(cache=True, nogil=True)
def run_batch(reg, dec, wdh, om, omo, Wc, LW, CW, RW, gen, G, H, smask, Tm, tr_from, tr_to, kst, dash,
              gaps, sides, pt0, pt1, pconst, pslope, pamp, pOm, pphase, npieces, T_end, xtol, max_events,
              eta0, deta0, tol_h, budget, Wm, Wcp, sign, atol, bc, fc, ic, eta, deta, own_e, own_d, toggles, phase,
              held, seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, ev_t, ev_kind, ev_c, ev_v, ev_d, jumps,
              out, out_status, out_t, out_warn, depth, min_count, out_shallow, rc, ra, rb, rbe, peaks, fpeaks, ints, d0,
              d1):
    # pragma: no cover - compiled
    """Run (or resume) cases ``bc[B_CASE]`` ... of the batch; a status code (module docstring).

    Per case ``k``: ``gaps[k], sides[k]``; load pieces ``p*[k, :npieces[k]]``;
    ``T_end[k]``, ``xtol[k]``, ``max_events[k]``; initial modal state
    ``eta0[k], deta0[k]`` (free state); ``u = sign[k] w`` at the metric
    point, whose shapes are ``Wm`` (and ``Wcp[c]`` at contactor ``c``).
    Results: ``out[k]`` the scalar metrics (:data:`~impactbeam.solver._metrics.SCALARS`),
    ``out_status[k]`` (0 end time reached, 1 chattering guard), ``out_t[k]``
    where the run stopped, ``out_warn[k]`` the loop's projection warning
    (count, contactor, time, moved, scale) and the number of switches,
    ``out_shallow[k]`` the impacts at most ``depth`` deep
    (:func:`~impactbeam.solver._metrics.count_shallow`, from ``min_count`` contacts on).
    ``DONE`` when every case is done.
    """
    n_cases = gaps.shape[0]
    work = dense_work(eta.size)
    steps = 0
    while bc[B_CASE] < n_cases:
        k = bc[B_CASE]
        if bc[B_STARTED] == 0:
            start_case(k, eta0, deta0, fc, ic, eta, deta, own_e, own_d, toggles, phase, held)
            bc[B_STARTED] = 1
        n = npieces[k]
        before = ic[I_EVALS]
        st = run(reg, dec, wdh, om, omo, Wc, LW, CW, RW, gen, G, H, smask, Tm, tr_from, tr_to, gaps[k], sides[k],
                 kst, dash, pt0[k, :n], pt1[k, :n], pconst[k, :n], pslope[k, :n], pamp[k, :n], pOm[k, :n],
                 pphase[k, :n], T_end[k], tol_h, xtol[k], max_events[k], budget - steps, fc, ic, eta, deta, own_e,
                 own_d, toggles, phase, held, seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, ev_t, ev_kind, ev_c,
                 ev_v, ev_d, jumps)
        steps += ic[I_EVALS] - before
        if st == CHECKPOINT:
            if steps >= budget:
                return CHECKPOINT
            continue
        if st != DONE and st != CHATTER:
            return st  # the loop lacks a state, a transfer or room: Python supplies it
        nseg = ic[I_NSEG]
        nev = ic[I_NEV]
        t_stop = fc[F_T]
        out_status[k] = 0 if st == DONE else 1
        out_t[k] = t_stop
        out_warn[k, 0] = ic[I_WARN_N]
        out_warn[k, 1] = ic[I_WARN_C]
        out_warn[k, 2] = fc[F_WARN_T]
        out_warn[k, 3] = fc[F_WARN_MOVED]
        out_warn[k, 4] = fc[F_WARN_SCALE]
        out_warn[k, 5] = ic[I_NJUMP]
        out_warn[k, 6] = fc[F_E_SUM]
        out_warn[k, 7] = fc[F_E_PEAK]
        t_end = T_end[k] if st == DONE else t_stop
        run_metrics(seg_t0[:nseg], seg_t1[:nseg], seg_s[:nseg], seg_k[:nseg], seg_eta[:nseg], seg_deta[:nseg],
                    ev_t[:nev], ev_kind[:nev], ev_c[:nev], ev_d[:nev], nev, jumps[:ic[I_NJUMP]], t_end, reg, dec,
                    wdh, om, LW, CW, gen, G, smask, gaps[k], sides[k], kst, dash, pt0[k, :n], pconst[k, :n],
                    pslope[k, :n], pamp[k, :n], pOm[k, :n], pphase[k, :n], Wm, Wcp, sign[k], atol, 1e-14, False,
                    depth, min_count, out_shallow[k], out[k], rc, ra, rb, rbe, peaks, fpeaks, ints, d0, d1, work)
        bc[B_CASE] = k + 1
        bc[B_STARTED] = 0
        if bc[B_STOP_EACH]:
            return CASE_DONE
        if steps >= budget and bc[B_CASE] < n_cases:
            return CHECKPOINT
    return DONE
