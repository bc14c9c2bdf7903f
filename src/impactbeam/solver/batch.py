"""Batched runs: many cases of one packed problem through one compiled call (:mod:`~impactbeam.solver._batch`).

:func:`integrate_batch` packs the problem once (its states and transfer
matrices are shared by every case, and cached across batches as for single
runs), lays the cases' own inputs out as arrays (gaps, sides, load pieces
padded to the longest, end times, event tolerances and limits, initial modal
states) and runs them in the compiled loop, which returns to Python only
for what it lacks (a state, a transfer matrix, room) or at checkpoints.
Each case's metrics are computed in the same compiled pass, by the code a
single run's :meth:`~impactbeam.solver.solution.Solution.metric_arrays` uses:
the same bits alone or in a batch.

A case whose state cannot be built (a damping the blocks refuse) is marked
failed with its message and the batch goes on.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from ..model import Damping, SolverOptions
from ..model.beam import Beam, Contactor
from ..model.loading import Excitation
from ..model.starting import InitialCondition, Preload
from . import _codes as _loop, kernels
from .engine import _BUDGET, _pieces, _Records, _solution, pack, run_warnings, stop_message
from .initial import initial_coordinates
from .solution import Solution

__all__ = ["BatchResult", "integrate_batch"]


@dataclass
class BatchResult:
    """The outcome of :func:`integrate_batch`, one entry per case.

    Attributes
    ----------
    scalars : ndarray, (n_cases, 10)
        The metrics in the order of :data:`impactbeam.result.metrics.METRIC_UNITS` (NaN where undefined).
    status : ndarray of int, (n_cases,)
        0 end time reached, 1 stopped by the chattering guard, -1 failed.
    t_stop : ndarray, (n_cases,), [s]
        Where each run ended.
    messages : list of str
        The solver's message (its stop, or why the case failed).
    warnings : list of list of str
        The solver's warnings per case.
    errors : list of Exception or None
        The exception of each failed case.
    """

    scalars: np.ndarray
    status: np.ndarray
    t_stop: np.ndarray
    messages: list[str]
    warnings: list[list[str]] = field(default_factory=list)
    errors: list[BaseException | None] = field(default_factory=list)


def _padded(per_case: list[tuple[np.ndarray, ...]]) -> tuple[list[np.ndarray], np.ndarray]:
    """Load pieces of every case as (n_cases, n_max) arrays (zero beyond a case's count) and the counts."""
    counts = np.array([p[0].size for p in per_case], dtype=np.int64)
    width = max(int(counts.max()), 1)
    out = [np.zeros((len(per_case), width)) for _ in range(7)]
    for k, pcs in enumerate(per_case):
        for arr, col in zip(out, pcs):
            arr[k, : col.size] = col
    return out, counts


def _rows_at(pk, x: float) -> np.ndarray:
    return np.ascontiguousarray(pk.rows(np.array([x], dtype=float))[:, 0, :])


def _starts(pk, beam: Beam, contactor_sets: Sequence[tuple[Contactor, ...]], initial: InitialCondition,
            preload: Preload | None, starts: tuple[np.ndarray, np.ndarray] | None) -> tuple[np.ndarray, np.ndarray]:
    """Each case's free-state (eta, deta) at t = 0: ``starts``, or ``initial`` for its gaps (an equilibrium
    depends on them), computed once per distinct contactor set."""
    n, nm = len(contactor_sets), pk.n_modes
    if starts is not None:
        return np.array(starts[0], dtype=float).reshape(n, nm), np.array(starts[1], dtype=float).reshape(n, nm)
    eta0, deta0 = np.empty((n, nm)), np.empty((n, nm))
    known: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}
    for i, cs in enumerate(contactor_sets):
        key = tuple(cs)
        if key not in known:
            known[key] = initial_coordinates(pk.space, beam, initial, preload, contactors=key,
                                             preserve_contacts=pk.preserve)
        eta0[i], deta0[i] = known[key]
    return eta0, deta0


def integrate_batch(
    beam: Beam,
    contactor_sets: Sequence[tuple[Contactor, ...]],
    damping: Damping,
    excitations: Sequence[Excitation],
    initial: InitialCondition,
    options: Sequence[SolverOptions],
    *,
    point: float,
    sign: np.ndarray | float,
    starts: tuple[np.ndarray, np.ndarray] | None = None,
    preload: Preload | None = None,
    progress: Callable[[int], None] | None = None,
    case_done: Callable[[int, Solution], tuple[np.ndarray, np.ndarray] | None] | None = None,
) -> BatchResult:
    """Run the cases of one packed problem and compute their metrics (module docstring).

    Parameters
    ----------
    beam, damping
        The beam and damping every case shares.
    contactor_sets : sequence of tuple of Contactor
        One per case: the same positions, stiffnesses and dashpots; gaps and sides free.
    excitations : sequence of Excitation
        One per case; the same ``kind`` and ``position`` (load distribution).
    initial : InitialCondition
        The state at t = 0 of every case (unless ``starts``).
    options : sequence of SolverOptions
        One per case; the same ``modes``, ``basis`` and ``projection``.
    point : float, [m]
        Where the metrics read ``u = sign w``.
    sign : float or ndarray, (n_cases,)
    starts : tuple of ndarray, optional
        Initial modal displacements and velocities (n_cases, n) in the free state's basis.
    preload : Preload, optional
        A constant load acting throughout.
    progress : callable, optional
        ``progress(cases_done)`` at checkpoints.
    case_done : callable, optional
        ``case_done(k, solution)`` after case ``k`` (its exact solution), before the next one starts; it may
        return ``(eta, deta)``, the next case's initial state (a continuation).

    Returns
    -------
    BatchResult
    """
    K = kernels.batched()
    n = len(excitations)
    contactors = tuple(contactor_sets[0])
    pk = pack(beam, contactors, damping, excitations[0], options[0], preload)
    nm = pk.n_modes
    nc = len(contactors)
    gaps = np.array([[c.gap for c in cs] for cs in contactor_sets], dtype=float).reshape(n, nc)
    sides = np.array([[c.direction for c in cs] for cs in contactor_sets], dtype=float).reshape(n, nc)
    kst = np.array([c.stiffness for c in contactors], dtype=float)
    pieces = [_pieces(ex, opt.end_time) for ex, opt in zip(excitations, options)]
    (pt0, pt1, pconst, pslope, pamp, pOm, pphase), npieces = _padded(pieces)
    T_end = np.array([opt.end_time for opt in options], dtype=float)
    xtol = np.array([opt.event_tolerance for opt in options], dtype=float)
    max_events = np.array([opt.max_events for opt in options], dtype=np.int64)
    eta0, deta0 = _starts(pk, beam, contactor_sets, initial, preload, starts)
    sign_arr = np.ascontiguousarray(np.broadcast_to(np.asarray(sign, dtype=float), (n,)))
    bc = np.zeros(K.N_BC, dtype=np.int64)
    bc[K.B_STOP_EACH] = case_done is not None
    fc = np.zeros(_loop.N_FLOAT)
    ic = np.zeros(_loop.N_INT, dtype=np.int64)
    nc1 = max(nc, 1)
    carry = (np.zeros(nm), np.zeros(nm), np.zeros(nm), np.zeros(nm), np.zeros(nc1, dtype=np.int64),
             np.zeros(nc1, dtype=np.int64), np.zeros(3 * max(2 * nc, 1)))
    rec = _Records(nm)
    out = np.full((n, K.N_SCALARS), np.nan)
    status = np.full(n, -1, dtype=np.int64)
    t_stop = np.zeros(n)
    warn = np.zeros((n, 8))
    shallow = np.zeros((n, 4 + nc))
    failed: dict[int, BaseException] = {}

    def table_rows() -> tuple[np.ndarray, ...]:
        m = rec.ev_t.size + nc + 1
        return (np.zeros(m, dtype=np.int64), *(np.zeros(m) for _ in range(8)))

    rows = table_rows()
    Wm = Wcp = np.zeros((0, nm))
    tol_h = _loop.TOUCH * beam.length
    atol = 1e-12 * float(pk.space.beam.length)
    while True:
        if Wm.shape[0] != pk.nslots:  # the shapes at the metric point and the contactors, in every built state
            Wm = _rows_at(pk, point)
            Wcp = np.stack([_rows_at(pk, c.position) for c in contactors]) if nc else np.zeros((1,) + Wm.shape)
        ic[_loop.I_NSLOTS] = pk.nslots
        ic[_loop.I_NTR] = pk.ntr
        st = int(K.run_batch(
            pk.reg, pk.dec, pk.wdh, pk.om, pk.omo, pk.Wc, pk.LW, pk.CW, pk.RW, pk.gen, pk.G, pk.H, pk.smask, pk.Tm,
            pk.tr_from, pk.tr_to, kst, pk.dash, gaps, sides, pt0, pt1, pconst, pslope, pamp, pOm, pphase, npieces,
            T_end, xtol, max_events, eta0, deta0, tol_h, _BUDGET, Wm, Wcp, sign_arr, atol, bc, fc, ic, *carry,
            rec.seg_t0, rec.seg_t1, rec.seg_s, rec.seg_k, rec.seg_eta, rec.seg_deta, rec.ev_t, rec.ev_kind,
            rec.ev_c, rec.ev_v, rec.ev_d, rec.jumps, out, status, t_stop, warn, _loop.touch_depth(beam.length),
            _loop.TOUCH_SCALE_COUNT, shallow, *rows,
        ))
        k = int(bc[K.B_CASE])
        if st == _loop.NEED_STATE or st == _loop.NEED_TRANSFER:
            try:
                if st == _loop.NEED_STATE:
                    pk.add_state(int(ic[_loop.REQ_A]))
                else:
                    pk.add_transfer(int(ic[_loop.REQ_A]), int(ic[_loop.REQ_B]))
            except Exception as exc:  # this case fails (as it would alone); the batch goes on
                failed[k] = exc
                bc[K.B_CASE] = k + 1
                bc[K.B_STARTED] = 0
        elif st == _loop.NEED_SPACE:
            rec.grow(ic)
            if rows[0].size < rec.ev_t.size + nc + 1:
                rows = table_rows()
        elif st == _loop.CASE_DONE:
            j = k - 1
            con = (gaps[j].copy(), sides[j].copy(), kst)
            sol = _solution(pk, tuple(contactor_sets[j]), options[j], pieces[j], con, fc, ic, rec,
                            _loop.CHATTER if status[j] == 1 else _loop.DONE, excitations[j])
            nxt = case_done(j, sol)  # type: ignore[misc]
            if nxt is not None and k < n:
                eta0[k] = nxt[0]
                deta0[k] = nxt[1]
        elif st == _loop.CHECKPOINT:
            if progress is not None:
                progress(k)
        else:
            break
    messages = []
    warnings: list[list[str]] = []
    free_omega = pk.space.state(()).modes.omega  # the spectrum warning's (run_warnings), one structure
    errors: list[BaseException | None] = [failed.get(k) for k in range(n)]
    for k in range(n):
        if k in failed:
            status[k] = -1
            messages.append(_message(failed[k]))
            warnings.append([])
            continue
        messages.append(stop_message(int(status[k]), float(t_stop[k]), int(out[k, 8])))
        moved = None
        if warn[k, 0]:
            moved = (int(warn[k, 0]), int(warn[k, 5]), options[k].modes, int(warn[k, 1]), float(warn[k, 3]),
                     float(warn[k, 4]), float(warn[k, 2]))
        warnings.append(run_warnings(int(status[k]), float(t_stop[k]), int(out[k, 8]), float(options[k].end_time),
                                     moved, (float(warn[k, 6]), float(warn[k, 7]), int(warn[k, 5]), options[k].modes),
                                     (excitations[k], free_omega, options[k].modes),
                                     (shallow[k], beam.length)))
    return BatchResult(out, status, t_stop, messages, warnings, errors)


def _message(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text or type(exc).__name__
