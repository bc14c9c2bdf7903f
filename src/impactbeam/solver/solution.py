"""Dense output of the solver: the exact piecewise modal solution and its events.

Like SciPy's ``OdeSolution``, a solution is a list of segments, each with its
own closed form; it can be evaluated at any time, not only at output
samples. :class:`Solution` is what :func:`~impactbeam.solver.engine.integrate`
returns; :class:`PiecewiseSolution` is the interface that
:class:`~impactbeam.result.SimulationResult` and :mod:`~impactbeam.result.metrics`
use, which the ``solve_ivp`` reference path implements too.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from ..exceptions import ParameterError
from . import kernels
from ._codes import TOUCH, TOUCH_SCALE_COUNT, touch_depth

if TYPE_CHECKING:
    from ..model.beam import Contactor

__all__ = ["Event", "Samples", "PiecewiseSolution", "Solution", "ModalState"]


_WORK = threading.local()  # work arrays of the metrics, per thread, kernels and size


def _work(K: Any, nm: int) -> tuple:
    key = (id(K), nm)
    hit = getattr(_WORK, "arrays", None)
    if hit is None or hit[0] != key:
        hit = _WORK.arrays = (key, K.dense_work(nm))
    return hit[1]


class Event(NamedTuple):
    """An impact (contactor engages) or rebound (it releases) at an exact time.

    Attributes
    ----------
    time : float, [s]
    kind : {"impact", "rebound"}
    contactor : int
        Index of the contactor.
    velocity : float, [m/s]
        ``w_t`` at the contactor at the event.
    """

    time: float
    kind: str
    contactor: int
    velocity: float


@dataclass(frozen=True, eq=False)
class ModalState:
    """The state of the N-mode model at one instant, to start another run from.

    Attributes
    ----------
    time : float, [s]
        When the state was taken (informative: a run started from it begins at t = 0).
    eta, deta : ndarray
        Modal displacement and velocity in the free state's basis (the
        ``n_modes`` free modes, plus one attachment shape per contactor
        position with ``solver.basis = "enriched"``).
    basis : tuple
        What the free state's basis depends on (beam, contactor positions,
        mode count, basis kind); a run accepts the state only in the same basis.
    """

    time: float
    eta: np.ndarray
    deta: np.ndarray
    basis: tuple


def basis_signature(beam: Any, contactors: Any, modes: int, basis: str, excitation: Any = None) -> tuple:
    """What the free state's modal basis depends on (see :class:`ModalState`).

    Parameters
    ----------
    beam : Beam
    contactors : sequence of Contactor
        Their positions and stiffnesses enter the enriched basis (its
        attachment shapes, and the local shapes of a stiff stop).
    modes : int
        Retained modes per state.
    basis : {"enriched", "paper"}
    excitation : Excitation, optional
        A point force's position enters the enriched basis too (its second
        load-dependent vector when it acts at a stop).
    """
    if basis != "enriched":
        return (beam, (), int(modes), basis)
    stops = tuple((float(c.position), float(c.stiffness)) for c in contactors)
    load = None
    if excitation is not None and excitation.kind == "point_force" and excitation.position is not None:
        load = float(excitation.position)
    return (beam, stops, int(modes), basis, load)


@dataclass(frozen=True, eq=False)
class Samples:
    """Values of a solution at given times (rows = times).

    Attributes
    ----------
    w, w_t : ndarray, (n_t, n_x), [m], [m/s]
        Deflection and velocity.
    engaged : ndarray of bool, (n_t, n_c)
        Contactors engaged.
    eta, eta_t : ndarray or None, (n_t, n_modes)
        Modal coordinates in the basis of the state at each time (when asked for).
    energies : ndarray or None, (n_t, 5)
        Kinetic energy, modal strain energy, load power (excitation and
        preload), power dissipated by the beam's damping and by the engaged
        contactors' dashpots (when asked for).
    """

    w: np.ndarray
    w_t: np.ndarray
    engaged: np.ndarray
    eta: np.ndarray | None = None
    eta_t: np.ndarray | None = None
    energies: np.ndarray | None = None


class PiecewiseSolution:
    """What every solution offers (the exact one and the ``solve_ivp`` reference).

    Attributes
    ----------
    events : list of Event
    status : int
        0: reached ``end_time``; 1: stopped by the chattering guard.
    message : str
    warnings : tuple of str
        What the solver is unsure of (e.g. a lossy projection at a switch).
    energy_jumps : ndarray, [J]
        Change of mechanical energy at each switch (zero for a lossless one;
        a contactor's dashpot releasing with a penetration left loses its
        spring's energy there).
    t_end : float, [s]
        Where the solution ends (``end_time`` unless stopped).
    dashpots : ndarray, (n_contactors,), [N s/m]
        Each contactor's dashpot (``contactors.N.damping`` or from ``restitution``).
    """

    events: list[Event]
    dashpots: np.ndarray
    status: int
    message: str
    warnings: tuple[str, ...]
    energy_jumps: np.ndarray
    t_end: float
    contactors: tuple[Contactor, ...]
    n_modes: int

    event_penetrations: np.ndarray

    def release_losses(self) -> tuple[np.ndarray, np.ndarray]:
        """Times and energies [J] a contactor's dashpot takes at its switches.

        A contactor with a dashpot releases when ``k d + c d' = 0`` with a
        penetration ``d > 0`` left: the energy ``k d^2 / 2`` of its spring
        leaves the beam's mechanical energy there (the massless contact
        element relaxes through its dashpot); when it engages again before
        ``d`` returns to 0, ``k d^2 / 2`` comes back (a negative loss).
        Without a dashpot ``d = 0`` at every switch and nothing is lost.
        """
        times, losses = [], []
        for ev, d in zip(self.events, self.event_penetrations):
            c = self.dashpots[ev.contactor] if len(self.dashpots) else 0.0
            if c > 0.0 and d > 0.0:
                e = 0.5 * self.contactors[ev.contactor].stiffness * d * d
                times.append(ev.time)
                losses.append(e if ev.kind == "rebound" else -e)
        return np.asarray(times, dtype=float), np.asarray(losses, dtype=float)

    def check_times(self, t: Any, end_time: float, name: str = "t") -> np.ndarray:
        """Times as a float array; ParameterError outside ``[0, end_time]``.

        Parameters
        ----------
        t : float or array_like, [s]
        end_time : float, [s]
            End of the simulated interval.
        name : str
            The argument named in the error.
        """
        t = np.atleast_1d(np.asarray(t, dtype=float))
        if t.ndim != 1:
            raise ParameterError(f"{name}: expected a 1-D array of times, got shape {t.shape}")
        bad = ~np.isfinite(t) | (t < 0.0) | (t > end_time * (1.0 + 1e-12))
        if bad.any():
            raise ParameterError(
                f"{name}: {t[bad][0]:g} s is outside the simulated interval [0, {end_time:g}] s"
            )
        return t

    def sample(self, x: np.ndarray, t: np.ndarray, *, modal: bool = False, energy: bool = False) -> Samples:
        """Exact values at times ``t`` and positions ``x`` (NaN after ``t_end``).

        Parameters
        ----------
        x : ndarray, [m]
            Positions on the beam.
        t : ndarray, [s]
            Times, in any order.
        modal : bool
            Also the modal coordinates (in the basis of the state at each time).
        energy : bool
            Also the energy terms (kinetic, modal strain, load power, damping power).
        """
        raise NotImplementedError

    def extremum(self, x: float, lo: float, hi: float, sign: float = 1.0, offset: float = 0.0,
                 engaged: int | None = None, rate: float = 0.0) -> tuple[float, float]:
        """Maximum of ``sign (w(x, t) + rate w_t(x, t) + offset)`` over ``[lo, hi]`` and its time.

        With ``engaged = c`` only the times when contactor ``c`` is engaged count.
        Returns ``(-inf, nan)`` when no time qualifies.

        Parameters
        ----------
        x : float, [m]
            Position on the beam.
        lo, hi : float, [s]
            The time interval.
        sign : float
            +1 for the maximum of ``w + offset``, -1 for the minimum.
        offset : float, [m]
            Added to ``w``.
        engaged : int or None
            Only times when this contactor is engaged.
        rate : float, [s]
            Weight of the velocity (a dashpot's force over the spring's: ``c / k``).
        """
        raise NotImplementedError

    def integral(self, x: float, lo: float, hi: float) -> float:
        """``int_lo^hi w(x, t) dt`` [m s].

        Parameters
        ----------
        x : float, [m]
            Position on the beam.
        lo, hi : float, [s]
            The time interval.
        """
        raise NotImplementedError

    def extrema(self, queries: list[tuple]) -> np.ndarray:
        """Several :meth:`extremum` queries ``(x, lo, hi, sign, offset, engaged[, rate])``: array (n, 2).

        Parameters
        ----------
        queries : list of tuple
            Each ``(x, lo, hi, sign, offset, engaged[, rate])`` as for :meth:`extremum`.
        """
        return np.array([self.extremum(*q) for q in queries], dtype=float).reshape(len(queries), 2)

    def integrals(self, queries: list[tuple[float, float, float]]) -> np.ndarray:
        """Several :meth:`integral` queries ``(x, lo, hi)``.

        Parameters
        ----------
        queries : list of tuple
            Each ``(x, lo, hi)`` as for :meth:`integral`.
        """
        return np.array([self.integral(*q) for q in queries], dtype=float)


class Solution(PiecewiseSolution):
    """The exact piecewise solution of the N-mode model (closed form per segment).

    Segment ``j`` covers ``[t0[j], t1[j]]`` in state slot ``slot[j]`` (the set
    of engaged contactors ``engaged(j)``) under load piece ``piece[j]``,
    starting from the modal state ``eta0[j], deta0[j]`` in that state's basis.
    Built by :func:`~impactbeam.solver.engine.integrate`, not by users.

    Parameters
    ----------
    t0, t1, slot, piece : ndarray, (n_segments,)
        Start and end time [s], state slot and load piece of each segment.
    eta0, deta0 : ndarray, (n_segments, n_state_modes)
        Modal state at the start of each segment.
    packed : Packed
        The compiled model: every visited state's modes and coefficients.
    pieces : tuple of ndarray
        The load pieces (:func:`impactbeam.model.loading.time_pieces`).
    contactor_arrays : tuple of ndarray
        Positions, stiffnesses, gaps and sides of the contactors.
    contactors : tuple of Contactor
    events : list of Event or None
        None: made from ``event_arrays`` when first asked for.
    energy_jumps : ndarray, [J]
        Change of mechanical energy at each switch.
    event_penetrations : ndarray, [m]
        The switching contactor's penetration ``s w(a) - gap`` at each event.
    status : int
        0: reached ``end_time``; 1: stopped by the chattering guard.
    message : str
    warnings : tuple of str
    t_end : float, [s]
        Where the solution ends.
    evaluations : int
        Closed-form evaluations the run took.
    n_modes : int
        Coordinates of the state bases.
    event_arrays : tuple of ndarray, optional
        The events as arrays: times [s], kinds (1 impact, 0 rebound),
        contactors and velocities [m/s] (default: from ``events``).
    excitation : Excitation, optional
        The run's load (default: the packed problem's, which runs that differ
        only in their loads' time histories share).
    """

    def __init__(self, *, t0, t1, slot, piece, eta0, deta0, packed, pieces, contactor_arrays, contactors,
                 events, energy_jumps, event_penetrations, status, message, warnings, t_end, evaluations,
                 n_modes, event_arrays=None, excitation=None) -> None:
        self.t0 = t0
        self.t1 = t1
        self.slot = slot
        self.piece = piece
        self.eta0 = eta0
        self.deta0 = deta0
        self.packed = packed
        self.pieces = pieces
        self.contactor_arrays = contactor_arrays
        self.contactors = contactors
        self._events = events
        self.energy_jumps = energy_jumps
        self.event_penetrations = event_penetrations
        self.status = status
        self.message = message
        self.warnings = warnings
        self.t_end = t_end
        self.evaluations = evaluations
        self.n_modes = n_modes
        self.excitation = packed.space.excitation if excitation is None else excitation
        self.dashpots = packed.dash
        self._atol = TOUCH * float(packed.space.beam.length)
        self._rows: dict[bytes, np.ndarray] = {}  # mode shapes at a few positions (metrics, dense queries)
        if event_arrays is None:  # times, kinds (1 impact, 0 rebound), contactors, velocities
            event_arrays = (np.array([e.time for e in events], dtype=float),
                            np.array([e.kind == "impact" for e in events], dtype=np.int64),
                            np.array([e.contactor for e in events], dtype=np.int64),
                            np.array([e.velocity for e in events], dtype=float))
        self.event_arrays = event_arrays

    @property
    def events(self) -> list[Event]:  # type: ignore[override]
        """The events, made from :attr:`event_arrays` on first access."""
        if self._events is None:
            t, kind, c, v = self.event_arrays
            self._events = [Event(ti, "impact" if ki else "rebound", ci, vi)
                            for ti, ki, ci, vi in zip(t.tolist(), kind.tolist(), c.tolist(), v.tolist())]
        return self._events

    @property
    def n_segments(self) -> int:
        return int(self.t0.size)

    @property
    def segment_starts(self) -> np.ndarray:
        """Start times of the segments [s] (``t0``)."""
        return self.t0

    def engaged(self, j: int) -> tuple[int, ...]:
        """Engaged contactors of segment ``j``.

        Parameters
        ----------
        j : int
            Segment index.
        """
        return self.packed.keys[int(self.slot[j])]

    def _model(self) -> tuple:
        """The model arrays of :func:`~impactbeam.solver._dense.extremum` and ``integral``."""
        pk = self.packed
        return (pk.reg, pk.dec, pk.wdh, pk.om, pk.LW, pk.CW, pk.gen, pk.G, pk.smask, *self.contactor_arrays,
                self.pieces[0], *self.pieces[2:])

    def rows(self, x: np.ndarray) -> np.ndarray:
        """Mode shapes of every visited state at ``x``: shape (n_states, len(x), n_modes) (cached per ``x``).

        Parameters
        ----------
        x : ndarray, [m]
            Positions on the beam.
        """
        x = np.asarray(x, dtype=float)
        if x.size > 64:
            return self.packed.rows(x)
        key = x.tobytes()
        if key not in self._rows:
            self._rows[key] = self.packed.rows(x)
        return self._rows[key]

    def segment_index(self, t: np.ndarray) -> np.ndarray:
        """Segment holding each time (an event time belongs to the segment it starts).

        Parameters
        ----------
        t : ndarray, [s]
            Times.
        """
        idx = np.searchsorted(self.t0, t, side="right") - 1
        return np.minimum(np.maximum(idx, 0, out=idx), max(self.n_segments - 1, 0), out=idx)

    def sample(self, x: np.ndarray, t: np.ndarray, *, modal: bool = False, energy: bool = False) -> Samples:
        x = np.atleast_1d(np.asarray(x, dtype=float))
        t = np.atleast_1d(np.asarray(t, dtype=float))
        nt, nx, nm = t.size, x.size, self.n_modes
        idx = self.segment_index(t)
        w = np.empty((nt, nx))
        w_t = np.empty((nt, nx))
        eta = np.empty((nt, nm)) if modal else np.empty((0, nm))
        eta_t = np.empty((nt, nm)) if modal else np.empty((0, nm))
        en = np.empty((nt, 5)) if energy else np.empty((0, 5))
        if nt and self.n_segments:
            pk = self.packed
            kernels.for_work(nt).sample(t, idx, self.rows(x), w, w_t, eta, eta_t, en, modal, energy,
                          self.t0, self.slot, self.piece, self.eta0, self.deta0, pk.reg, pk.dec, pk.wdh, pk.om,
                          pk.omo, pk.Wc, pk.LW, pk.CW, pk.gen, pk.G, pk.Cd, pk.pw, pk.pre, pk.smask,
                          *self.contactor_arrays, pk.dash, self.pieces[0], *self.pieces[2:])
        masks = self.packed.smask[self.slot[idx]] if self.n_segments else np.zeros(nt, dtype=np.int64)
        nc = len(self.contactors)
        engaged = ((masks[:, None] >> np.arange(nc)[None, :]) & 1).astype(bool)
        after = t > self.t_end * (1.0 + 1e-15) if self.status else np.zeros(nt, dtype=bool)
        if after.any() or not self.n_segments:
            bad = after if self.n_segments else np.ones(nt, dtype=bool)
            for arr in (w, w_t, eta if modal else None, eta_t if modal else None, en if energy else None):
                if arr is not None:
                    arr[bad] = np.nan
        return Samples(w, w_t, engaged, eta if modal else None, eta_t if modal else None, en if energy else None)

    def metric_arrays(self, x: float, sign: float, table: bool) -> tuple[np.ndarray, tuple[np.ndarray, ...]]:
        """The metrics in one compiled call (:func:`~impactbeam.solver._metrics.run_metrics`).

        Parameters
        ----------
        x : float, [m]
            Where ``u = sign w`` is read.
        sign : float
            +1 or -1.
        table : bool
            Also the per-impact table's peak forces, integrals and end compressions.

        Returns
        -------
        scalars : ndarray, (10,)
            In the order of :data:`~impactbeam.solver._metrics.SCALARS`, NaN where undefined.
        rows : tuple of ndarray
            Contactor, start, end, clipped end, peak compression, peak force
            [N], impulse [N s] and the compression at both ends (NaN without
            a dashpot), one entry per contact interval (the last five with
            ``table`` only).
        shallow : ndarray, (4 + n_contactors,)
            The impacts resolved only at the touch tolerance's scale
            (:func:`~impactbeam.solver._metrics.count_shallow`; zeros below
            ``TOUCH_SCALE_COUNT`` contacts).
        """
        K = kernels.for_work(self.n_segments + self.event_arrays[0].size)
        pk = self.packed
        ev_t, ev_kind, ev_c = self.event_arrays[:3]
        nev = ev_t.size
        n = nev + len(self.contactors) + 1
        rows = (np.zeros(n, dtype=np.int64), *np.zeros((8, n)))
        out = np.empty(K.N_SCALARS)
        shallow = np.zeros(4 + len(self.contactors))
        Wm, Wc = self.metric_rows(x)
        pcs = self.pieces
        n_rows = K.run_metrics(
            self.t0, self.t1, self.slot, self.piece, self.eta0, self.deta0, ev_t, ev_kind, ev_c,
            self.event_penetrations, nev, self.energy_jumps, float(self.t_end), pk.reg, pk.dec, pk.wdh, pk.om, pk.LW,
            pk.CW, pk.gen, pk.G, pk.smask, *self.contactor_arrays, pk.dash, pcs[0], *pcs[2:], Wm, Wc, float(sign),
            self._atol, 1e-14, bool(table), touch_depth(pk.space.beam.length), TOUCH_SCALE_COUNT, shallow, out, *rows,
            _work(K, self.n_modes),
        )
        return out, tuple(r[:n_rows] for r in rows), shallow

    def metric_rows(self, x: float) -> tuple[np.ndarray, np.ndarray]:
        """Shapes at ``x`` (S, n) and at each contactor (n_c, S, n) in every built state slot.

        Cached by the packed problem, for every run that shares it.

        Parameters
        ----------
        x : float, [m]
            The metric point.
        """
        return self.packed.metric_rows(x, tuple(c.position for c in self.contactors))

    def _row_table(self, xs: list[float]) -> tuple[np.ndarray, np.ndarray]:
        """Distinct positions of ``xs`` with their shapes in every visited state, and each x's row."""
        ux: dict[float, int] = {}
        row = np.array([ux.setdefault(x, len(ux)) for x in xs], dtype=np.int64)
        R = self.rows(np.fromiter(ux, dtype=float, count=len(ux)))  # (S, p, nm)
        return np.ascontiguousarray(R.transpose(1, 0, 2)), row

    def extrema(self, queries: list[tuple]) -> np.ndarray:
        n = len(queries)
        out = np.empty((2, n))
        out[0] = -np.inf
        out[1] = np.nan
        if n and self.n_segments:
            Wr, row = self._row_table([q[0] for q in queries])
            lo, hi, sign, offset, cond = (np.array(v) for v in zip(*(q[1:6] for q in queries)))
            cond = np.array([-1 if c is None else c for c in cond], dtype=np.int64)
            rate = np.array([q[6] if len(q) > 6 else 0.0 for q in queries], dtype=float)
            kernels.for_work(n * self.n_segments).extremum(
                lo.astype(float), np.minimum(hi.astype(float), self.t_end), sign.astype(float),
                offset.astype(float), rate, row, cond, self._atol, 1e-14, Wr, out[0], out[1],
                self.t0, self.t1, self.slot, self.piece, self.eta0, self.deta0, *self._model(),
            )
        return out.T

    def extremum(self, x: float, lo: float, hi: float, sign: float = 1.0, offset: float = 0.0,
                 engaged: int | None = None, rate: float = 0.0) -> tuple[float, float]:
        v, t = self.extrema([(x, lo, hi, sign, offset, engaged, rate)])[0]
        return float(v), float(t)

    def integrals(self, queries: list[tuple[float, float, float]]) -> np.ndarray:
        n = len(queries)
        out = np.zeros(n)
        if n and self.n_segments:
            Wr, row = self._row_table([q[0] for q in queries])
            lo = np.array([q[1] for q in queries], dtype=float)
            hi = np.minimum(np.array([q[2] for q in queries], dtype=float), self.t_end)
            kernels.for_work(n * self.n_segments).integral(lo, hi, row, Wr, out, self.t0, self.t1, self.slot, self.piece, self.eta0,
                            self.deta0, *self._model())
        return out

    def integral(self, x: float, lo: float, hi: float) -> float:
        return float(self.integrals([(x, lo, hi)])[0])

    def modal_state(self, t: float, basis: tuple = ()) -> ModalState:
        """The exact modal state at time ``t`` carried into the free state's basis.

        With the shared (enriched) basis the change of basis is exact; with
        the paper's per-state modes it is the projection of eq. (12), the one
        a switch into the free state makes. ``basis`` is stored in the result
        (see :func:`basis_signature`).

        Parameters
        ----------
        t : float, [s]
            A time of the solution.
        basis : tuple
            What the free state's basis depends on (:func:`basis_signature`).
        """
        t = float(self.check_times(t, self.t_end)[0])
        smp = self.sample(np.zeros(1), np.array([t]), modal=True)
        j = int(self.segment_index(np.array([t]))[0])
        key = self.engaged(j)
        eta, deta = smp.eta[0], smp.eta_t[0]  # type: ignore[index]
        if key:
            T = self.packed.space.transfer((), key, self.packed.preserve)
            eta, deta = T @ eta, T @ deta
        return ModalState(t, np.array(eta, dtype=float), np.array(deta, dtype=float), basis)
