"""Compiled fast path of the exact solver for all-under-damped problems.

:func:`integrate_fast` returns the same :class:`~impactbeam.solver.engine.RawSolution`
as :func:`impactbeam.solver.engine.integrate` (same events, samples, state
codes, energies, status and message, to round-off) but runs the whole event
loop of paper section 2 (closed-form segments, eq. 10; event location; the
projection of eqs. 11-12) in one numba function,
:func:`~impactbeam.solver.kernels.run`. :func:`supported` tells when it
applies: numba is available, at most three contactors, every state (all
``2**n_contactors`` of them) has only under-damped modes (no rigid-body,
critically or over-damped mode) and no progress callback is requested.

The per-problem data (the states' modes, shapes at the contactors and output
points, load weights, gap forces and the transfer matrices of eq. 12) are
packed once and cached, like the states of
:class:`~impactbeam.solver.states.StateSpace`. Dense output
(``segments[i].solution``) is built lazily, on first access, with the same
:class:`~impactbeam.solver.closed_form.ClosedFormSegment` the Python engine
would have built.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..beam import Beam, Contactor
from ..loading import Excitation, InitialCondition, time_pieces
from . import kernels
from .engine import Event, RawSolution, Segment, _segment, make_space, space_initial_coordinates
from .options import Damping, SolverOptions
from .states import StateModel, StateSpace

__all__ = ["MAX_CONTACTORS", "integrate_fast", "supported"]

MAX_CONTACTORS = 3
_CACHE: dict[tuple, _Packed | None] = {}
_CACHE_SIZE = 64


class _Packed:
    """The states of one problem packed into arrays for :func:`kernels.run`."""

    def __init__(self, space: StateSpace, states: dict[tuple[int, ...], StateModel], projection: str) -> None:
        nc = len(space.contactors)
        S = 1 << nc
        nm = space.state(()).modes.count
        npt = space.points.size
        self.space = space
        self.states = states
        self.keys = [tuple(i for i in range(nc) if (s >> i) & 1) for s in range(S)]
        self.om = np.empty((S, nm))
        self.xi = np.empty((S, nm))
        self.dec = np.empty((S, nm))
        self.wd = np.empty((S, nm))
        self.mu = np.empty((S, nm), dtype=complex)
        self.Wc = np.empty((S, nc, nm))
        self.Wo = np.empty((S, npt, nm))
        self.pw = np.empty((S, nm))
        self.gf = np.empty((S, nm))
        self.Tm = np.zeros((S, S, nm, nm))
        for s, key in enumerate(self.keys):
            st = states[key]
            self.om[s] = st.modes.omega
            self.xi[s] = st.dyn.xi
            self.dec[s] = st.dyn.decay
            self.wd[s] = st.dyn.wd
            self.mu[s] = st.dyn.mu
            self.Wc[s] = st.W_contact
            self.Wo[s] = st.W_out
            self.pw[s] = st.load_weights
            self.gf[s] = st.gap_force
        preserve = projection == "contact"
        for s in range(S):
            for c in range(nc):
                new = s ^ (1 << c)
                self.Tm[new, s] = space.transfer(self.keys[new], self.keys[s], preserve)
        self.gap = np.array([c.gap for c in space.contactors], dtype=float)
        self.side = np.array([c.direction for c in space.contactors], dtype=float)
        self.kst = np.array([c.stiffness for c in space.contactors], dtype=float)
        all_eng = tuple(range(nc))
        self.wmax = max(states[()].omega_max, states[all_eng].omega_max if nc else 0.0)
        self.tables: dict[tuple[float, float], tuple[np.ndarray, ...]] = {}

    def grid_tables(self, h: float, dt: float) -> tuple[np.ndarray, ...]:
        """Block tables ``exp(mu m h)``, ``exp(mu m dt)`` per state (filled by the kernel on first use)."""
        tab = self.tables.get((h, dt))
        if tab is None:
            S, nm = self.om.shape
            shape = (S, nm, kernels.BLOCK)
            tab = (np.empty(shape), np.empty(shape), np.empty(shape), np.empty(shape), np.zeros(S, dtype=np.bool_))
            if len(self.tables) >= 8:
                self.tables.pop(next(iter(self.tables)))
            self.tables[(h, dt)] = tab
        return tab


def _pack(
    beam: Beam,
    contactors: tuple[Contactor, ...],
    damping: Damping,
    excitation: Excitation,
    options: SolverOptions,
    points: np.ndarray,
) -> _Packed | None:
    """Packed states of the problem, or None when the fast path does not apply (cached)."""
    contactors = tuple(contactors)
    pts = np.asarray(points, dtype=float)
    key = (beam, contactors, damping, excitation.kind, excitation.position, options.modes,
           tuple(pts.tolist()), options.projection, options.basis)
    if key in _CACHE:
        return _CACHE[key]
    packed: _Packed | None = None
    nm = options.modes
    ok = kernels.AVAILABLE and len(contactors) <= MAX_CONTACTORS and pts.size > 0
    # quick rejection before any mode is computed: xi >= 1 is never under-damped
    ok = ok and float(np.max(damping.ratios(False, nm))) < 1.0
    ok = ok and (not contactors or float(np.max(damping.ratios(True, nm))) < 1.0)
    if ok:
        space = make_space(beam, contactors, damping, excitation, options, pts)
        nm = space.state(()).modes.count
        states = {}
        for s in range(1 << len(contactors)):
            eng = tuple(i for i in range(len(contactors)) if (s >> i) & 1)
            st = space.state(eng)
            if not st.dyn.all_under or st.modes.count != nm:
                ok = False
                break
            states[eng] = st
        if ok:
            packed = _Packed(space, states, options.projection)
    if len(_CACHE) >= _CACHE_SIZE:
        _CACHE.pop(next(iter(_CACHE)))
    _CACHE[key] = packed
    return packed


def supported(
    beam: Beam,
    contactors: Sequence[Contactor],
    damping: Damping,
    excitation: Excitation,
    options: SolverOptions,
    points: np.ndarray,
    progress: Callable[[float], None] | None = None,
) -> bool:
    """True when :func:`integrate_fast` applies to this problem.

    It applies when numba is installed, there are at most
    :data:`MAX_CONTACTORS` contactors, no ``progress`` callback is given, and
    every state (each subset of engaged contactors) has only under-damped
    modes with the requested count. The check builds the states (cached).
    """
    if progress is not None:
        return False
    return _pack(beam, tuple(contactors), damping, excitation, options, np.asarray(points, dtype=float)) is not None


class LazySegments(Sequence):
    """The segments of a run; each :class:`~impactbeam.solver.engine.Segment` is built on first access.

    Building a segment's :class:`~impactbeam.solver.closed_form.ClosedFormSegment`
    repeats exactly what the Python engine does at the segment's start
    (``engine._segment``) from the stored start time, state, load piece and
    modal coordinates.
    """

    def __init__(self, t0, t1, keys, states, pieces, piece_index, eta0, deta0) -> None:
        self._t0 = t0
        self._t1 = t1
        self._keys = keys
        self._states = states
        self._pieces = pieces
        self._piece_index = piece_index
        self._eta0 = eta0
        self._deta0 = deta0
        self._built: list[Segment | None] = [None] * len(t0)

    def __len__(self) -> int:
        return len(self._built)

    def _get(self, i: int) -> Segment:
        seg = self._built[i]
        if seg is None:
            eng = self._keys[i]
            piece = self._pieces[self._piece_index[i]]
            t0 = float(self._t0[i])
            sol = _segment(self._states[eng], piece, t0, self._eta0[i].copy(), self._deta0[i].copy())
            seg = Segment(t0, float(self._t1[i]), eng, sol, piece)
            self._built[i] = seg
        return seg

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, slice):
            return [self._get(j) for j in range(*i.indices(len(self)))]
        n = len(self)
        j = int(i)
        if j < 0:
            j += n
        if not 0 <= j < n:
            raise IndexError("segment index out of range")
        return self._get(j)

    @property
    def starts(self) -> np.ndarray:
        """Start times of all segments without building them."""
        return self._t0.copy()


def _output_arrays(n_out: int, npt: int, nc: int, nm: int) -> list[np.ndarray]:
    """The float output arrays (time, w, w_t, w_contact, w_t_contact, four energies, eta, eta_t).

    They are C-contiguous views of one buffer: one allocation instead of
    eleven lets the C allocator hand the same memory back on the next run
    instead of mapping (and page-faulting) fresh pages for each array, which
    costs about as much as the whole Case 3 integration.
    """
    widths = (1, npt, npt, nc, nc, 1, 1, 1, 1, nm, nm)
    buf = np.empty(n_out * sum(widths))
    out = []
    off = 0
    for k, width in enumerate(widths):
        a = buf[off : off + n_out * width]
        out.append(a if width == 1 and k in (0, 5, 6, 7, 8) else a.reshape(n_out, width))
        off += n_out * width
    return out


def integrate_fast(
    beam: Beam,
    contactors: tuple[Contactor, ...],
    damping: Damping,
    excitation: Excitation,
    initial: InitialCondition,
    options: SolverOptions,
    points: np.ndarray,
    progress: Callable[[float], None] | None = None,
) -> RawSolution:
    """Run the exact integration in compiled code; see :func:`impactbeam.solver.engine.integrate`.

    Raises
    ------
    ValueError
        If :func:`supported` is False for these inputs.
    """
    contactors = tuple(contactors)
    pts = np.asarray(points, dtype=float)
    pk = _pack(beam, contactors, damping, excitation, options, pts)
    if pk is None or progress is not None:
        raise ValueError("integrate_fast: this problem is not supported by the compiled path; use engine.integrate")
    nm = pk.om.shape[1]
    nc = len(contactors)
    npt = pts.size
    T = options.end_time
    dt = options.time_step
    wmax = pk.wmax
    sub = max(1, math.ceil(dt * wmax / (2.0 * math.pi) * 8.0)) if wmax > 0 else 1
    h = dt / sub
    n_out = math.floor(T / dt * (1.0 + 1e-12)) + 1
    pieces = time_pieces(excitation, T)
    pt0 = np.array([p.t0 for p in pieces])
    pt1 = np.array([p.t1 for p in pieces])
    pconst = np.array([p.const for p in pieces])
    pslope = np.array([p.slope for p in pieces])
    pamp = np.array([p.amp for p in pieces])
    pOm = np.array([p.Omega for p in pieces])
    pphase = np.array([p.phase for p in pieces])
    eta0, deta0 = space_initial_coordinates(pk.space, beam, initial, options.modes)
    time, w, w_t, wc, wtc, kin, strain, lpow, dpow, eta, eta_t = _output_arrays(n_out, npt, nc, nm)
    time[:] = np.arange(n_out) * dt
    code = np.full(n_out, -1, dtype=np.int16)
    Rs_r, Rs_i, Ro_r, Ro_i, built = pk.grid_tables(h, dt)
    (status, t_stop, nseg, seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, nev, ev_t, ev_kind, ev_c, ev_v,
     njump, jumps, nkeys, key_order, warn, warn_t, warn_c, warn_moved, warn_scale) = kernels.run(
        pk.om, pk.xi, pk.dec, pk.wd, pk.mu, pk.Wc, pk.Wo, pk.pw, pk.gf, pk.Tm, pk.gap, pk.side, pk.kst,
        pt0, pt1, pconst, pslope, pamp, pOm, pphase,
        float(T), float(dt), float(h), int(n_out), float(1e-12 * beam.length), float(options.event_tolerance),
        int(options.max_events), np.ascontiguousarray(eta0, dtype=float), np.ascontiguousarray(deta0, dtype=float),
        Rs_r, Rs_i, Ro_r, Ro_i, built,
        w, w_t, wc, wtc, code, kin, strain, lpow, dpow, eta, eta_t,
    )
    events = [
        Event(float(ev_t[i]), "impact" if ev_kind[i] else "rebound", int(ev_c[i]), float(ev_v[i])) for i in range(nev)
    ]
    if status == 1:
        message = (
            f"Stopped at t = {t_stop:.9g} s after {nev} events (solver.max_events): "
            "chattering contact; later samples are NaN."
        )
    else:
        message = "The simulation reached end_time."
    if warn:
        projection_warning = (
            f"At t = {warn_t:.6g} s the projection onto {options.modes} modes moved the deflection at "
            f"contactor {warn_c} by {warn_moved:.3g} m ({100 * warn_moved / warn_scale:.0f} % of its gap "
            "or deflection): the contactor is too stiff for this number of modes; add modes."
        )
        message = f"{message} Warning: {projection_warning}"
    unset = code < 0
    if unset.any():
        for arr in (w, w_t, wc, wtc, kin, strain, lpow, dpow, eta, eta_t):
            arr[unset] = np.nan
    keys = [pk.keys[int(s)] for s in key_order[:nkeys]]
    seg_keys = [pk.keys[int(s)] for s in seg_s[:nseg]]
    segments = LazySegments(
        seg_t0[:nseg], seg_t1[:nseg], seg_keys, pk.states, pieces, seg_k[:nseg], seg_eta[:nseg], seg_deta[:nseg]
    )
    space = make_space(beam, contactors, damping, excitation, options, pts)
    space._states.update(pk.states)
    return RawSolution(
        time, w, w_t, wc, wtc, code, keys, kin, strain, lpow, dpow, eta, eta_t, events, segments,  # type: ignore[arg-type]
        space, int(status), message, [float(x) for x in jumps[:njump]],
    )
