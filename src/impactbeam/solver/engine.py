"""The exact event-driven solver (paper section 2): Python side of the one compiled engine.

:func:`integrate` packs the problem (the states' modes, shapes at the
contactors, load weights and transfer matrices of eq. 12) into arrays,
runs the compiled loop of :mod:`~impactbeam.solver._loop`, and supplies it
with what it asks for: a state the first time it is visited (states are
built lazily, so ``n`` contactors cost what the visited states cost, not
``2**n``), a transfer matrix the first time a switch between two states
occurs, larger record arrays, and, at checkpoints, progress reports and the
chance for Ctrl-C to stop the run. It returns the exact piecewise solution,
:class:`~impactbeam.solver.solution.Solution`; nothing is sampled here.

Packed problems are cached across runs on what they depend on (beam,
contactor positions, stiffnesses, damping, load distribution, mode count,
projection), not on gaps, sides or the load's time history, so a parameter
study over those reuses every mode and transfer matrix.
"""

from __future__ import annotations

import contextlib
import math
import threading
import weakref
from collections import OrderedDict
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

from ..model.beam import Beam, Contactor
from ..model.loading import Excitation, piece_arrays
from ..model.starting import InitialCondition, Preload
from ..modal import mode_set
from . import _codes as _loop, kernels
from ..model import Damping, SolverOptions
from .solution import Solution
from ..exceptions import SimulationError
from .blocks import classical_slot, slot_arrays
from .initial import initial_coordinates
from .states import StateModel, StateSpace, _preload_key

__all__ = ["integrate", "pack", "pack_key"]

_BUDGET = 200_000  # scan steps between checkpoints (~20-50 ms compiled; 1,000 interpreted, ~0.1 s)
_CACHE: OrderedDict[tuple, _Packed] = OrderedDict()
_CACHE_SIZE = 64


def make_space(beam, contactors, damping, excitation, options: SolverOptions, points, preload=None) -> StateSpace:
    """The state space of ``options.basis``: the paper's per-state modes or the shared Ritz basis.

    The shared basis needs a static attachment shape per contactor: the
    polynomials of the paper's uniform beam (inertia relief when it can move
    as a rigid body), or the exact static solver for any other beam its
    supports hold. A stepped beam, one with masses or springs, or a
    Timoshenko beam that can move as a rigid body uses the paper's per-state
    modes (a warning says so).
    """
    if options.basis == "enriched" and (beam.is_uniform or not mode_set(beam, (), options.modes).n_rigid):
        from .ritz_space import RitzStateSpace

        if options.projection != "paper" and contactors:
            from .._warnings import emit_user_level_warning

            emit_user_level_warning(
                f'solver.projection = "{options.projection}" has no effect: the enriched basis is shared by every '
                'contact state, so a switch projects nothing (it applies with solver.basis = "paper")'
            )
        return RitzStateSpace(beam, contactors, damping, excitation, options.modes, points, preload)  # type: ignore[return-value]
    if options.basis == "enriched" and contactors:
        from .._warnings import emit_user_level_warning

        emit_user_level_warning(
            "solver.basis: the enriched basis needs a static attachment shape, and this beam (stepped, with "
            "masses or springs, or Timoshenko) can move as a rigid body; using the paper's per-state modes "
            '(solver.basis = "paper"), which need more modes for stiff contactors'
        )
    return StateSpace(beam, contactors, damping, excitation, options.modes, points, preload)




def _grow(a: np.ndarray, n: int) -> np.ndarray:
    out = np.zeros((n,) + a.shape[1:], dtype=a.dtype)
    out[: a.shape[0]] = a
    return out


class _Packed:
    """The visited states of one problem in arrays for the compiled loop (grown on demand).

    Per slot, the arrays of :class:`~impactbeam.solver.blocks.SlotArrays`
    (see :mod:`~impactbeam.solver._loop`), the modal-frame frequencies
    ``omo``, shapes at the contactors ``Wc`` and load weights ``pw``, ``pre``.
    """

    _PER_SLOT = ("reg", "dec", "wdh", "om", "omo", "Wc", "pw", "pre", "LW", "CW", "RW", "gen", "G", "H", "Cd")

    def __init__(self, space: StateSpace, preserve: bool) -> None:
        self.space = space
        self.preserve = preserve
        nm = space.state(()).modes.count  # N, or N + attachment shapes in the shared Ritz basis
        self.n_modes = nm
        nc = len(space.contactors)
        cap = min(4, 1 << nc)
        self.reg = np.zeros((cap, nm), dtype=np.int64)
        self.dec = np.zeros((cap, nm))
        self.wdh = np.zeros((cap, nm))
        self.om = np.zeros((cap, nm))
        self.omo = np.zeros((cap, nm))
        self.Wc = np.zeros((cap, nc, nm))
        self.pw = np.zeros((cap, nm))
        self.pre = np.zeros((cap, nm))
        self.LW = np.zeros((cap, 4, nm))
        self.CW = np.zeros((cap, 2, nc, nm))
        self.RW = np.zeros((cap, 4, nc, nm))
        self.gen = np.zeros(cap, dtype=np.int64)
        self.G = np.zeros((cap, 2, 2 * nm, nm))
        self.H = np.zeros((cap, 2, nm, 2 * nm))
        self.Cd = np.zeros((cap, nm, nm))
        self.smask = np.full(cap, -1, dtype=np.int64)
        self.dash = np.ascontiguousarray(space.dashpots, dtype=float)
        self.models: list[StateModel] = []
        self.keys: list[tuple[int, ...]] = []
        self.Tm = np.zeros((4, nm, nm))
        self.tr_from = np.full(4, -1, dtype=np.int64)
        self.tr_to = np.full(4, -1, dtype=np.int64)
        self.ntr = 0
        self._rows: dict[bytes, np.ndarray] = {}
        self._metric_rows: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}
        self.add_state(0)

    @property
    def general(self) -> bool:
        """Whether any built state has a damping matrix its modes do not diagonalise."""
        return bool(np.any(self.gen[: self.nslots]))

    def rows(self, x: np.ndarray) -> np.ndarray:
        """Mode shapes of every built state at ``x``: (n_states, len(x), n_modes), cached."""
        x = np.ascontiguousarray(x, dtype=float)
        key = x.tobytes()
        hit = self._rows.get(key)
        if hit is None or hit.shape[0] < self.nslots:
            done = 0 if hit is None else hit.shape[0]
            new = [st.modes.shapes(x).T for st in self.models[done:]]
            hit = np.ascontiguousarray(np.stack(new if hit is None else [*hit, *new]))
            self._rows[key] = hit
        return hit

    def metric_rows(self, x: float, positions: tuple[float, ...]) -> tuple[np.ndarray, np.ndarray]:
        """Shapes at ``x`` (S, n) and at each of ``positions`` (n_c, S, n) in every built state, cached."""
        key = (x, positions, self.nslots)
        hit = self._metric_rows.get(key)
        if hit is None:
            Wm = self.rows(np.array([x], dtype=float))[:, 0, :]
            Wc = np.zeros((max(len(positions), 1),) + Wm.shape)
            for c, p in enumerate(positions):
                Wc[c] = self.rows(np.array([p], dtype=float))[:, 0, :]
            hit = self._metric_rows[key] = (np.ascontiguousarray(Wm), Wc)
        return hit

    @property
    def nslots(self) -> int:
        return len(self.models)

    def arrays(self) -> tuple[np.ndarray, ...]:
        """The per-slot arrays in the order of :data:`_PER_SLOT`."""
        return tuple(getattr(self, name) for name in self._PER_SLOT)

    def add_state(self, mask: int) -> int:
        """Build the state with engaged-contactor bit mask ``mask``; its slot."""
        key = tuple(i for i in range(len(self.space.contactors)) if (mask >> i) & 1)
        st = self.space.state(key)
        if st.modes.count != self.n_modes:
            raise RuntimeError(f"state {key}: {st.modes.count} modes instead of {self.n_modes}")
        s = self.nslots
        if s >= self.smask.size:
            n = 2 * self.smask.size
            for name in self._PER_SLOT:
                setattr(self, name, _grow(getattr(self, name), n))
            self.smask = np.concatenate([self.smask, np.full(n - s, -1, dtype=np.int64)])
        omega = st.modes.omega
        if st.damping_matrix is None:
            sa = classical_slot(omega, st.dyn.decay, st.W_contact, st.load_weights, st.preload_weights)
        else:
            try:
                sa = slot_arrays(omega, st.damping_matrix, st.W_contact, st.load_weights, st.preload_weights)
            except SimulationError as exc:
                what = f"contactors {', '.join(map(str, key))} engaged" if key else "no contactor engaged"
                raise SimulationError(f"the state with {what}: {exc}") from None
        for name in ("reg", "dec", "wdh", "om", "LW", "CW", "RW", "G", "H", "Cd"):
            getattr(self, name)[s] = getattr(sa, name)
        self.gen[s] = sa.gen
        self.omo[s] = omega
        self.Wc[s] = st.W_contact
        self.pw[s] = st.load_weights
        self.pre[s] = st.preload_weights
        self.smask[s] = mask
        self.models.append(st)
        self.keys.append(key)
        return s

    def add_transfer(self, frm: int, to: int) -> None:
        """The matrix carrying modal coordinates from slot ``frm`` to slot ``to`` (eq. 12)."""
        k = self.ntr
        if k >= self.tr_from.size:
            n = 2 * self.tr_from.size
            self.Tm = _grow(self.Tm, n)
            self.tr_from = np.concatenate([self.tr_from, np.full(n - k, -1, dtype=np.int64)])
            self.tr_to = np.concatenate([self.tr_to, np.full(n - k, -1, dtype=np.int64)])
        self.Tm[k] = self.space.transfer(self.keys[to], self.keys[frm], self.preserve)
        self.tr_from[k] = frm
        self.tr_to[k] = to
        self.ntr = k + 1


def pack(
    beam: Beam,
    contactors: tuple[Contactor, ...],
    damping: Damping,
    excitation: Excitation,
    options: SolverOptions,
    preload: Preload | None = None,
) -> _Packed:
    """The packed problem, from the cache when its modes and transfers are already known."""
    key = pack_key(beam, contactors, damping, excitation, options, preload)
    hit = _CACHE.get(key)
    if hit is not None:
        _CACHE.move_to_end(key)
        return hit
    # gaps and sides enter the compiled loop directly: the states do not depend on them
    neutral = tuple(Contactor(c.position, c.stiffness, 0.0, "below", c.damping, c.restitution) for c in contactors)
    space = make_space(beam, neutral, damping, excitation, options, np.zeros(0), preload)
    packed = _Packed(space, options.projection == "contact")
    _CACHE[key] = packed
    if len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    return packed


def pack_key(
    beam: Beam,
    contactors: tuple[Contactor, ...],
    damping: Damping,
    excitation: Excitation,
    options: SolverOptions,
    preload: Excitation | None = None,
) -> tuple:
    """What a packed problem depends on: not the gaps, sides or the load's time history (cases that differ only
    in those share their states and transfer matrices, and run in one batch)."""
    return (
        beam, tuple((c.position, c.stiffness, c.damping, c.restitution) for c in contactors), damping,
        excitation.kind, excitation.position, options.modes, options.projection, options.basis,
        _preload_key(preload),
    )


class _Records:
    """Growing record arrays of segments, events and energy jumps."""

    def __init__(self, nm: int, n: int = 64) -> None:
        self.taken = False  # the solution holds views of these arrays: not to be reused
        self.seg_t0 = np.empty(n)
        self.seg_t1 = np.empty(n)
        self.seg_s = np.empty(n, dtype=np.int64)
        self.seg_k = np.empty(n, dtype=np.int64)
        self.seg_eta = np.empty((n, nm))
        self.seg_deta = np.empty((n, nm))
        self.ev_t = np.empty(n)
        self.ev_kind = np.empty(n, dtype=np.int64)
        self.ev_c = np.empty(n, dtype=np.int64)
        self.ev_v = np.empty(n)
        self.ev_d = np.empty(n)
        self.jumps = np.empty(n)

    def grow(self, ic: np.ndarray) -> None:
        if ic[_loop.I_NSEG] + 1 > self.seg_t0.size:
            n = 2 * self.seg_t0.size
            for name in ("seg_t0", "seg_t1", "seg_s", "seg_k", "seg_eta", "seg_deta"):
                setattr(self, name, _grow(getattr(self, name), n))
        if ic[_loop.I_NEV] + 1 > self.ev_t.size or ic[_loop.I_NJUMP] + 1 > self.jumps.size:
            n = 2 * max(self.ev_t.size, self.jumps.size)
            for name in ("ev_t", "ev_kind", "ev_c", "ev_v", "ev_d", "jumps"):
                setattr(self, name, _grow(getattr(self, name), n))


_SPARE = threading.local()  # record arrays of this thread's last run, reused by its next one


@contextlib.contextmanager
def _records(nm: int, n_pieces: int) -> Iterator[_Records]:
    """Record arrays for a run: this thread's spare ones (grown by earlier runs), or new ones when in use.

    A run has at least one segment per load piece: records for a long load are made that large at
    once (an eighth more for the events), and the solution takes them without a copy (:func:`_solution`).
    """
    rec = getattr(_SPARE, "rec", None)
    need = n_pieces + n_pieces // 8 + 64
    if rec is None or rec.seg_eta.shape[1] != nm or (n_pieces > _TAKE and rec.seg_t0.size < need):
        rec = _Records(nm, need if n_pieces > _TAKE else 64)
    else:
        _SPARE.rec = None  # in use (a run started from a callback of this one gets its own)
    try:
        yield rec
    finally:
        _SPARE.rec = None if rec.taken else rec


_TAKE = 1 << 14  # segments from which the solution takes the record arrays instead of copying them


_PIECES: weakref.WeakKeyDictionary[Excitation, dict[float, tuple[np.ndarray, ...]]] = weakref.WeakKeyDictionary()


def _pieces(excitation: Excitation, end_time: float) -> tuple[np.ndarray, ...]:
    """The load pieces as arrays for the compiled loop, cached per (immutable) excitation and end time."""
    per_end = _PIECES.setdefault(excitation, {})
    if end_time not in per_end:
        per_end[end_time] = piece_arrays(excitation, end_time)
    return per_end[end_time]


def _call(K: kernels.Kernels, pk: _Packed, con: tuple[np.ndarray, ...], pcs: tuple[np.ndarray, ...],
          opt: SolverOptions, tol_h: float, fc: np.ndarray, ic: np.ndarray, carry: tuple[np.ndarray, ...],
          rec: _Records) -> int:
    try:
        return int(K.run(
            pk.reg, pk.dec, pk.wdh, pk.om, pk.omo, pk.Wc, pk.LW, pk.CW, pk.RW, pk.gen, pk.G, pk.H, pk.smask, pk.Tm,
            pk.tr_from, pk.tr_to, *con, pk.dash, *pcs,
            float(opt.end_time), tol_h, float(opt.event_tolerance), int(opt.max_events),
            _BUDGET // 200 if K.interpreted else _BUDGET,
            fc, ic, *carry, rec.seg_t0, rec.seg_t1, rec.seg_s, rec.seg_k, rec.seg_eta, rec.seg_deta,
            rec.ev_t, rec.ev_kind, rec.ev_c, rec.ev_v, rec.ev_d, rec.jumps,
        ))
    except SystemError as exc:  # a signal that arrived while numba converted the arguments
        if isinstance(exc.__cause__ or exc.__context__, KeyboardInterrupt):
            raise KeyboardInterrupt from None
        raise


def integrate(
    beam: Beam,
    contactors: tuple[Contactor, ...],
    damping: Damping,
    excitation: Excitation,
    initial: InitialCondition,
    options: SolverOptions,
    progress: Callable[[float], None] | None = None,
    start: tuple[np.ndarray, np.ndarray] | None = None,
    preload: Preload | None = None,
) -> Solution:
    """Run the exact event-driven integration; see :func:`impactbeam.simulate`.

    Parameters
    ----------
    beam : Beam
    contactors : tuple of Contactor
    damping : Damping
    excitation : Excitation
    initial : InitialCondition
        The state at t = 0 (unless ``start`` is given).
    options : SolverOptions
    progress : callable, optional
        Called with the simulated time at every checkpoint.
    start : tuple of ndarray, optional
        Free-state modal displacement and velocity at t = 0 (replaces
        ``initial``); see :meth:`Solution.modal_state`.
    preload : Preload, optional
        The constant load of ``[preload]``, acting throughout.

    Returns
    -------
    Solution
        The exact piecewise modal solution with its events.
    """
    contactors = tuple(contactors)
    K = kernels.for_work(0)  # interpreted until the run proves long, unless the compiled kernels are loaded
    pk = pack(beam, contactors, damping, excitation, options, preload)
    nm = pk.n_modes
    con = (
        np.array([c.gap for c in contactors], dtype=float),
        np.array([c.direction for c in contactors], dtype=float),
        np.array([c.stiffness for c in contactors], dtype=float),
    )
    pcs = _pieces(excitation, options.end_time)
    tol_h = _loop.TOUCH * beam.length
    fc = np.zeros(_loop.N_FLOAT)
    fc[_loop.F_LAST_T] = -1.0
    ic = np.zeros(_loop.N_INT, dtype=np.int64)
    ic[[_loop.I_JUST, _loop.I_PENDING, _loop.I_WARN_C]] = -1
    if start is None:
        eta, deta = initial_coordinates(pk.space, beam, initial, preload, contactors=contactors,
                                        preserve_contacts=pk.preserve)
    else:
        eta, deta = (np.array(v, dtype=float) for v in start)
        if eta.shape != (nm,) or deta.shape != (nm,):
            raise ValueError(f"start: expected two arrays of {nm} modal coordinates")
    eta = np.ascontiguousarray(eta, dtype=float)
    deta = np.ascontiguousarray(deta, dtype=float)
    nc1 = max(len(contactors), 1)
    # slot coordinates, the state in the modal frame at a pending switch, toggles, released phases and the
    # place of a scan stopped at a checkpoint
    carry = (eta, deta, eta.copy(), deta.copy(), np.zeros(nc1, dtype=np.int64), np.zeros(nc1, dtype=np.int64),
             np.zeros(3 * max(2 * len(contactors), 1)))
    with _records(nm, int(pcs[0].size)) as rec:
        return _run_loop(K, pk, contactors, options, pcs, con, tol_h, fc, ic, carry, rec, progress, excitation)


def _run_loop(K, pk, contactors, options, pcs, con, tol_h, fc, ic, carry, rec, progress, excitation) -> Solution:
    """The loop of :func:`integrate` with the arrays it supplies; the solution copied out of ``rec``."""
    while True:
        ic[_loop.I_NSLOTS] = pk.nslots
        ic[_loop.I_NTR] = pk.ntr
        status = _call(K, pk, con, pcs, options, tol_h, fc, ic, carry, rec)
        if status == _loop.NEED_STATE:
            pk.add_state(int(ic[_loop.REQ_A]))
        elif status == _loop.NEED_TRANSFER:
            pk.add_transfer(int(ic[_loop.REQ_A]), int(ic[_loop.REQ_B]))
        elif status == _loop.NEED_SPACE:
            rec.grow(ic)
        elif status == _loop.CHECKPOINT:
            if progress is not None:
                progress(float(fc[_loop.F_T] + (fc[_loop.F_TAU] if ic[_loop.I_RESUME] else 0.0)))
            if K.interpreted:  # a long run: the compiled kernels (when cached) take over, the same results sooner
                K = kernels.active()
        else:
            break
    if progress is not None:
        progress(float(fc[_loop.F_T]))
    return _solution(pk, contactors, options, pcs, con, fc, ic, rec, status, excitation, take=True)


def _solution(pk, contactors, options, pcs, con, fc, ic, rec, status, excitation, take: bool = False) -> Solution:
    """The solution in ``rec``: copied, or with ``take`` (records no later run writes) its large arrays taken.

    ``excitation`` is the run's own load (the packed problem, shared by runs that differ in their loads' time
    histories, holds the one it was built with)."""
    nseg, nev, njump = int(ic[_loop.I_NSEG]), int(ic[_loop.I_NEV]), int(ic[_loop.I_NJUMP])
    t_stop = float(fc[_loop.F_T])
    code = 1 if status == _loop.CHATTER else 0
    message = stop_message(code, t_stop, nev)
    moved = None
    if ic[_loop.I_WARN_N]:
        moved = (int(ic[_loop.I_WARN_N]), njump, options.modes, int(ic[_loop.I_WARN_C]),
                 float(fc[_loop.F_WARN_MOVED]), float(fc[_loop.F_WARN_SCALE]), float(fc[_loop.F_WARN_T]))
    warnings = run_warnings(code, t_stop, nev, float(options.end_time), moved,
                            (float(fc[_loop.F_E_SUM]), float(fc[_loop.F_E_PEAK]), njump, options.modes),
                            (excitation, pk.space.state(()).modes.omega, options.modes))
    rec.taken = take and nseg > _TAKE and 2 * nseg > rec.seg_t0.size  # large and mostly used: no copy

    def out(a: np.ndarray) -> np.ndarray:
        return a[:nseg] if rec.taken else a[:nseg].copy()

    return Solution(
        t0=out(rec.seg_t0), t1=out(rec.seg_t1), slot=out(rec.seg_s), piece=out(rec.seg_k), eta0=out(rec.seg_eta),
        deta0=out(rec.seg_deta), packed=pk, pieces=pcs, contactor_arrays=con, contactors=contactors, events=None,
        energy_jumps=rec.jumps[:njump].copy(), event_penetrations=rec.ev_d[:nev].copy(), status=code,
        message=message, warnings=tuple(warnings),
        t_end=t_stop if code else float(options.end_time), evaluations=int(ic[_loop.I_EVALS]),
        n_modes=pk.n_modes, excitation=excitation,
        event_arrays=(rec.ev_t[:nev].copy(), rec.ev_kind[:nev].copy(), rec.ev_c[:nev].copy(), rec.ev_v[:nev].copy()),
    )



def stop_message(status: int, t_stop: float, n_events: int) -> str:
    """The solution's message: the end time reached (status 0), or where the chattering guard stopped it (1)."""
    if status == 1:
        return (
            f"Stopped at t = {t_stop:.9g} s after {n_events} events (solver.max_events or endless switching at one "
            "instant): chattering contact; the solution ends there."
        )
    return "The simulation reached end_time."


def run_warnings(status: int, t_stop: float, n_events: int, end_time: float,
                 moved: tuple | None = None, energy: tuple | None = None,
                 spectrum: tuple | None = None, shallow: tuple | None = None) -> list[str]:
    """The warnings of a run, for the single run, the batch and the ``solve_ivp`` path alike.

    The projection's (``moved``: the arguments of :func:`projection_warning`,
    None when no switch moved a contactor's deflection that much), the
    projections' energy changes (``energy``: the arguments of
    :func:`energy_warning`), a random load reaching above the retained modes
    (``spectrum``: the arguments of :func:`spectrum_warning`), impacts
    resolved only at the touch tolerance's scale (``shallow``: the arguments
    of :func:`touch_scale_warning`; the batch's, a single run's metrics give
    theirs), and a stop by the chattering guard (``status`` 1), whose results
    cover only ``[0, t_stop]``.
    """
    out = [] if moved is None else [projection_warning(*moved)]
    if energy is not None and energy[0] > _loop.ENERGY_WARN * energy[1]:
        out.append(energy_warning(*energy))
    if spectrum is not None:
        out.extend(spectrum_warning(*spectrum))
    if shallow is not None:
        out.extend(touch_scale_warning(*shallow))
    if status == 1:
        out.append(f"{stop_message(status, t_stop, n_events)} The results cover 0 to {t_stop:.6g} s of the "
                   f"{end_time:.6g} s asked: metrics are of that part, later samples are NaN.")
    return out


def touch_scale_warning(shallow: np.ndarray, length: float) -> list[str]:
    """The warning of impacts resolved only at the touch tolerance's scale (or none).

    A contactor that bounces with every rebound smaller than the last (a
    restitution or dashpot stop at a small gap, a beam settling onto it)
    makes a sequence of impacts without end in theory; the engine follows it
    down to the touch tolerance (``TOUCH`` of the beam's ``length``), so the
    impacts of its tail, each at most ``TOUCH_SCALE`` touch tolerances deep,
    are as many as that tolerance makes them. With the paper's basis, a
    struck contactor the projection of eq. (12) leaves on the wrong side
    makes contacts that never press the stop at all. ``shallow`` is what
    :func:`~impactbeam.solver._metrics.count_shallow` counted; from
    ``TOUCH_SCALE_COUNT`` such impacts on they are warned about.
    """
    n = int(shallow[0])
    if n < _loop.TOUCH_SCALE_COUNT:
        return []
    which = ", ".join(str(c) for c in np.flatnonzero(np.asarray(shallow[4:]) > 0.0))
    return [
        f"metrics: {n} of {int(shallow[1])} impacts (contactor {which}, between t = {shallow[2]:.6g} and "
        f"{shallow[3]:.6g} s) are at most "
        f"{_loop.touch_depth(length):.2g} m deep ({_loop.TOUCH_SCALE} touch tolerances), contacts resolved only at "
        f"the scale of the touch tolerance ({_loop.TOUCH:g} of the beam length): a contact settling onto its stop by "
        "ever smaller bounces (a dashpot or restitution stop at a small gap) makes such impacts without end, as many "
        "as that tolerance resolves, and with the paper's basis a projection can leave a struck contactor on the "
        "wrong side (see the projection's warning); n_impacts and the impact table count them"
    ]


def spectrum_warning(excitation: Any, omega: np.ndarray, modes: int) -> list[str]:
    """The warning of a random load whose density reaches above the highest retained free mode (or none).

    The modes between that mode and the top of the band are excited at
    resonance and are not in the model: the response, its impacts and the
    fatigue damage lack their part (a tip force on a cantilever with 2 modes
    under a density up to 5 kHz: damage 4.7 times low). ``omega`` are the
    free state's frequencies [rad/s]; the ``modes``-th lowest is the highest
    retained mode (the enriched basis adds functions above it).
    """
    psd = getattr(excitation, "psd", None)
    if excitation is None or excitation.shape != "random" or psd is None or not excitation.active:
        return []
    elastic = np.sort(np.asarray(omega, dtype=float))
    elastic = elastic[elastic > 0.0]
    if not elastic.size:
        return []
    f_mode = float(elastic[min(int(modes), elastic.size) - 1]) / (2.0 * math.pi)
    f_top = psd.band[1]
    if f_top <= f_mode:
        return []
    return [f"excitation.psd reaches {f_top:.4g} Hz, above the highest of the {modes} retained modes "
            f"({f_mode:.4g} Hz): the modes in between respond to the load at resonance and are not in the model, "
            "so the response, its impacts and the fatigue damage lack their part; use more modes (solver.modes) "
            "or a density that ends below the modes kept"]


def energy_warning(changed: float, peak: float, switches: int, modes: int) -> str:
    """The warning of switches whose projections changed the model's energy by more than ``ENERGY_WARN`` in all.

    ``changed`` is the sum of the magnitudes of the energy changes at the
    ``switches`` switches, ``peak`` the largest energy before or after one.
    """
    return (
        f"the projections onto {modes} modes at the {switches} switches changed the model's energy by "
        f"{changed:.3g} J in all ({100 * changed / peak:.0f} % of the largest energy at a switch, {peak:.3g} J; "
        f"more than {100 * _loop.ENERGY_WARN:g} %): too few per-state modes for these contactors' stiffness, "
        "the impacts (their forces, penetrations, even their count) are not converged; add modes."
    )


def projection_warning(count: int, switches: int, modes: int, contactor: int, moved: float, scale: float,
                       when: float) -> str:
    """The warning of switches whose projection moved a contactor's deflection by more than ``MOVED_WARN``."""
    return (
        f"{count} of {switches} switches: the projection onto {modes} modes moved the deflection at a "
        f"contactor by more than {100 * _loop.MOVED_WARN:g} % of its gap or deflection (worst: contactor "
        f"{contactor} by {moved:.3g} m, {100 * moved / scale:.0f} %, at t = "
        f"{when:.6g} s): the contactor is too stiff for this number of modes; add modes."
    )
