"""Event-driven exact integration of the piecewise-linear modal model (paper section 2).

Between events the state (set of engaged contactors) and the load form are
fixed and every mode has a closed-form response
(:mod:`~impactbeam.solver.closed_form`). The integrator walks from event to
event: it evaluates the closed form on the sampling grid (which also yields
the output), detects a crossing of a contactor's opening
``g = gap - s w(a)`` between two grid points (or a grazing dip below zero
between them, found from the exact derivative), locates it with Brent's
method on the closed form, switches the state there and projects the modal
displacement and velocity onto the new modes (paper eqs. 11-12).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ..beam import Beam, Contactor
from ..loading import Excitation, InitialCondition, TimePiece, time_pieces
from ..modes import mode_set
from . import kernels
from .closed_form import ClosedFormSegment, LoadForm
from .options import Damping, SolverOptions
from .states import StateModel, StateSpace

__all__ = ["Event", "Segment", "RawSolution", "integrate"]

_CHUNK = 2048


@dataclass(frozen=True)
class Event:
    """An impact (contactor engages) or rebound (it releases) at an exact time."""

    time: float
    kind: str  # "impact" | "rebound"
    contactor: int
    velocity: float  # w_t at the contactor [m/s]


@dataclass(frozen=True, eq=False)
class Segment:
    """Closed-form modal response on ``[t0, t1]`` in one state (dense output)."""

    t0: float
    t1: float
    engaged: tuple[int, ...]
    solution: ClosedFormSegment
    piece: TimePiece


@dataclass(eq=False)
class RawSolution:
    """What :func:`integrate` returns; :class:`~impactbeam.result.SimulationResult` wraps it."""

    time: np.ndarray
    w: np.ndarray  # (time, point)
    w_t: np.ndarray
    w_contact: np.ndarray  # (time, contactor)
    w_t_contact: np.ndarray
    state_code: np.ndarray  # (time,) index into state_keys
    state_keys: list[tuple[int, ...]]
    kinetic: np.ndarray
    modal_strain: np.ndarray  # 1/2 sum omega^2 eta^2 (includes engaged springs at zero gap)
    load_power: np.ndarray  # u(t) sum p_n eta'_n
    damping_power: np.ndarray  # sum 2 xi omega eta'^2
    eta: np.ndarray  # (time, mode) in the basis of the state at that time
    eta_t: np.ndarray
    events: list[Event]
    segments: list[Segment]
    space: StateSpace
    status: int
    message: str
    switch_energy_jumps: list[float]


def initial_coordinates(
    beam: Beam, initial: InitialCondition, n_modes: int
) -> tuple[np.ndarray, np.ndarray]:
    """Free-state modal displacement and velocity at t = 0."""
    ms = mode_set(beam, (), n_modes)
    eta = np.zeros(ms.count)
    deta = np.zeros(ms.count)
    if initial.tip_displacement:
        x0 = beam.length if initial.position is None else initial.position
        # flexibility at x0 from a converged modal sum (terms fall as n^-4)
        big = mode_set(beam, (), max(120, n_modes))
        flex = float(np.sum(big.static_coordinates(x0) * big.shapes([x0])[:, 0]))
        eta = ms.static_coordinates(x0, initial.tip_displacement / flex)
    if initial.modal_displacement is not None:
        v = np.asarray(initial.modal_displacement)
        eta[: min(v.size, eta.size)] += v[: eta.size]
    if initial.modal_velocity is not None:
        v = np.asarray(initial.modal_velocity)
        deta[: min(v.size, deta.size)] += v[: deta.size]
    return eta, deta


def make_space(beam, contactors, damping, excitation, options: SolverOptions, points) -> StateSpace:
    """The state space of ``options.basis``: the paper's per-state modes or the shared Ritz basis."""
    if options.basis == "enriched":
        from .ritz import RitzStateSpace

        return RitzStateSpace(beam, contactors, damping, excitation, options.modes, points)  # type: ignore[return-value]
    return StateSpace(beam, contactors, damping, excitation, options.modes, points)


def space_initial_coordinates(space, beam: Beam, initial: InitialCondition, n_modes: int):
    """Free-state (eta, deta) at t = 0 in the basis of ``space``."""
    if hasattr(space, "initial_coordinates"):
        return space.initial_coordinates(initial)
    return initial_coordinates(beam, initial, n_modes)


def _segment(st: StateModel, piece: TimePiece, t: float, eta: np.ndarray, deta: np.ndarray) -> ClosedFormSegment:
    tau = t - piece.t0
    p = st.load_weights
    a = p * (piece.const + piece.slope * tau) + st.gap_force
    b = p * piece.slope if piece.slope else None
    d = p * piece.amp if piece.amp else None
    return ClosedFormSegment(st.dyn, LoadForm(a, b, d, piece.Omega, piece.phase + piece.Omega * tau), eta, deta)


class _Integrator:
    def __init__(
        self,
        beam: Beam,
        contactors: tuple[Contactor, ...],
        damping: Damping,
        excitation: Excitation,
        initial: InitialCondition,
        options: SolverOptions,
        points: np.ndarray,
        progress: Callable[[float], None] | None,
    ) -> None:
        self.opt = options
        self.contactors = contactors
        self.space = make_space(beam, contactors, damping, excitation, options, points)
        self.pieces = time_pieces(excitation, options.end_time)
        self.gap = np.array([c.gap for c in contactors])
        self.side = np.array([c.direction for c in contactors])
        self.tol_h = 1e-12 * beam.length
        self.progress = progress
        dt = options.time_step
        # scan step: at most 1/8 of the shortest period of any state (the all-engaged one is stiffest)
        all_eng = tuple(range(len(contactors)))
        wmax = max(self.space.state(()).omega_max, self.space.state(all_eng).omega_max if contactors else 0.0)
        self.sub = max(1, math.ceil(dt * wmax / (2.0 * math.pi) * 8.0)) if wmax > 0 else 1
        self.h = dt / self.sub
        self.n_out = int(math.floor(options.end_time / dt * (1.0 + 1e-12))) + 1
        self.time = np.arange(self.n_out) * dt
        n_p = points.size
        n_c = len(contactors)
        nm = self.space.state(()).modes.count
        # filled segment by segment; rows never reached (a run stopped early) become NaN at the end
        self.w = np.empty((self.n_out, n_p))
        self.w_t = np.empty((self.n_out, n_p))
        self.wc = np.empty((self.n_out, n_c))
        self.wtc = np.empty((self.n_out, n_c))
        self.code = np.full(self.n_out, -1, dtype=np.int16)
        self.kin = np.empty(self.n_out)
        self.strain = np.empty(self.n_out)
        self.lpow = np.empty(self.n_out)
        self.dpow = np.empty(self.n_out)
        self.eta = np.empty((self.n_out, nm))
        self.eta_t = np.empty((self.n_out, nm))
        self.keys: list[tuple[int, ...]] = []
        self.events: list[Event] = []
        self.segments: list[Segment] = []
        self.jumps: list[float] = []
        self.projection_warning: str | None = None

    # ------------------------------------------------------------------ helpers
    def _code(self, engaged: tuple[int, ...]) -> int:
        if engaged not in self.keys:
            self.keys.append(engaged)
        return self.keys.index(engaged)

    def _orient(self, engaged: tuple[int, ...]) -> np.ndarray:
        o = np.ones(len(self.contactors))
        o[list(engaged)] = -1.0
        return o

    def _h(self, st: StateModel, orient: np.ndarray, eta: np.ndarray, deta: np.ndarray):
        wc = st.W_contact @ eta
        dwc = st.W_contact @ deta
        g = self.gap[:, None] - self.side[:, None] * wc
        dg = -self.side[:, None] * dwc
        return orient[:, None] * g, orient[:, None] * dg, wc, dwc

    def _energy(self, st: StateModel, eta: np.ndarray, deta: np.ndarray) -> float:
        """Total mechanical energy (beam + supports + engaged contactors) of one modal state."""
        wc = st.W_contact @ eta
        E = 0.5 * float(deta @ deta) + 0.5 * float(np.sum(st.modes.omega**2 * eta**2))
        for i in st.engaged:
            c = self.contactors[i]
            g = c.gap - c.direction * wc[i]
            E += 0.5 * c.stiffness * (g**2 - wc[i] ** 2)
        return E

    def _desired_switch(self, st, seg: ClosedFormSegment, orient, tau1: float, just: int | None) -> int | None:
        """Contactor whose state is inconsistent at the start of a segment, if any.

        For the contactor ``just`` switched at this instant only the direction of
        motion is judged: the projection onto the new truncated mode set (eq. 12)
        moves ``w(a)`` slightly, so its opening may start a hair on the wrong side.
        """
        if not self.contactors:
            return None
        e0, d0 = seg.state_at(0.0)
        h0, dh0, _, _ = self._h(st, orient, e0[:, None], d0[:, None])
        if just is None and np.all(h0[:, 0] > self.tol_h):
            return None  # every contactor clearly on its consistent side
        e1, d1 = seg.state_at(tau1)
        h1, dh1, _, _ = self._h(st, orient, e1[:, None], d1[:, None])
        h = np.concatenate([h0, h1], axis=1)
        dh = np.concatenate([dh0, dh1], axis=1)
        for c in range(len(self.contactors)):
            if c == just:
                if dh[c, 0] * tau1 < -self.tol_h:
                    return c
                continue
            if h[c, 0] < -self.tol_h:
                return c  # already on the wrong side (e.g. released inside the contactor)
            if abs(h[c, 0]) <= self.tol_h:
                if dh[c, 0] * tau1 < -self.tol_h:
                    return c
                if abs(dh[c, 0]) * tau1 <= self.tol_h and h[c, 1] < -self.tol_h:
                    return c
        return None

    # ------------------------------------------------------------------ event location
    def _locate(self, st, seg, orient, c: int, lo: float, hi: float, hlo: float, dlo: float, dhi: float) -> float | None:
        o, s, gap = orient[c], self.side[c], self.gap[c]
        f = seg.projector(-o * s * st.W_contact[c], o * gap)

        def h(t: float) -> float:
            return f(t)[0]

        def dh(t: float) -> float:
            return f(t)[1]

        tol = self.opt.event_tolerance
        hh = h(hi)
        if hlo <= self.tol_h:
            # starting on the contact surface: move to the maximum of h first
            if dlo > 0 and dh(hi) < 0:
                lo = brentq(dh, lo, hi, xtol=tol)
                hlo = h(lo)
            if hlo <= 0:
                return None
        if hh > 0:
            # grazing: both ends open, the derivative changes sign
            if not (dlo < 0 < dhi):
                return None
            tmin = brentq(dh, lo, hi, xtol=tol)
            if h(tmin) > 0:
                return None
            hi = tmin
            if h(hi) == 0:
                return hi
        return float(brentq(h, lo, hi, xtol=tol, rtol=4 * np.finfo(float).eps, maxiter=200))

    def _release_in_tension(self, st, seg, orient, c: int, lo: float, hi: float) -> float:
        """Where a contactor on the wrong side of its state turns back (largest tension or penetration)."""
        f = seg.projector(-orient[c] * self.side[c] * st.W_contact[c], orient[c] * self.gap[c])
        return float(brentq(lambda t: f(t)[1], lo, hi, xtol=self.opt.event_tolerance))

    # ------------------------------------------------------------------ main loop
    def _run_from(self, eta: np.ndarray, deta: np.ndarray) -> RawSolution:
        opt = self.opt
        T = opt.end_time
        engaged: tuple[int, ...] = ()
        t = 0.0
        k_piece = 0
        status, message = 0, "The simulation reached end_time."
        toggles_at_t: dict[int, int] = {}
        last_t = -1.0
        just: int | None = None
        while t < T and k_piece < len(self.pieces):
            piece = self.pieces[k_piece]
            st = self.space.state(engaged)
            orient = self._orient(engaged)
            seg = _segment(st, piece, t, eta, deta)
            t_end = min(piece.t1, T)
            # consistency at the start of the segment (zero gap at rest, grazing, release)
            c_bad = self._desired_switch(st, seg, orient, min(self.h, t_end - t) if t_end > t else self.h, just)
            if c_bad is not None:
                if t != last_t:
                    toggles_at_t, last_t = {}, t
                toggles_at_t[c_bad] = toggles_at_t.get(c_bad, 0) + 1
                if toggles_at_t[c_bad] <= 2:
                    engaged, eta, deta = self._switch(st, engaged, c_bad, t, eta, deta)
                    just = c_bad
                    if len(self.events) >= opt.max_events:
                        status, message = 1, self._chatter_message(t)
                        break
                    continue
            te, c_hit = self._advance(st, seg, orient, t, t_end)
            self.segments.append(Segment(t, te, engaged, seg, piece))
            eta, deta = seg.state_at(te - t)
            t = te
            if self.progress is not None:
                self.progress(t)
            just = c_hit
            if c_hit is not None:
                engaged, eta, deta = self._switch(st, engaged, c_hit, t, eta, deta)
                if len(self.events) >= opt.max_events:
                    status, message = 1, self._chatter_message(t)
                    break
            elif t >= piece.t1:
                k_piece += 1
        if self.projection_warning is not None:
            message = f"{message} Warning: {self.projection_warning}"
        unset = self.code < 0
        if unset.any():
            for arr in (self.w, self.w_t, self.wc, self.wtc, self.kin, self.strain, self.lpow, self.dpow, self.eta, self.eta_t):
                arr[unset] = np.nan
        return RawSolution(
            self.time, self.w, self.w_t, self.wc, self.wtc, self.code, self.keys, self.kin, self.strain,
            self.lpow, self.dpow, self.eta, self.eta_t, self.events, self.segments, self.space, status,
            message, self.jumps,
        )

    def _chatter_message(self, t: float) -> str:
        return (
            f"Stopped at t = {t:.9g} s after {len(self.events)} events (solver.max_events): "
            "chattering contact; later samples are NaN."
        )

    def _switch(self, st, engaged, c, t, eta, deta):
        new = tuple(sorted(set(engaged) ^ {c}))
        kind = "impact" if c in new else "rebound"
        E_before = self._energy(st, eta, deta)
        vel = float(st.W_contact[c] @ deta)
        if self.events and self.events[-1].time == t and self.events[-1].contactor == c:
            self.events.pop()  # an impact and a rebound at one instant cancel (grazing touch)
        else:
            self.events.append(Event(t, kind, c, vel))
        P = self.space.transfer(new, engaged, self.opt.projection == "contact")
        w_before = st.W_contact @ eta
        eta, deta = P @ eta, P @ deta
        moved = np.abs(self.space.state(new).W_contact @ eta - w_before)
        # floor 1e-6 L: with zero gap the deflection at the event is round-off
        scale = np.maximum(np.maximum(self.gap, np.abs(w_before)), 1e6 * self.tol_h)
        worst = int(np.argmax(moved / scale))
        if moved[worst] > 0.05 * scale[worst] and self.projection_warning is None:
            self.projection_warning = (
                f"At t = {t:.6g} s the projection onto {self.opt.modes} modes moved the deflection at "
                f"contactor {worst} by {moved[worst]:.3g} m ({100 * moved[worst] / scale[worst]:.0f} % of its gap "
                "or deflection): the contactor is too stiff for this number of modes; add modes."
            )
        self.jumps.append(self._energy(self.space.state(new), eta, deta) - E_before)
        return new, eta, deta

    def _advance(self, st: StateModel, seg: ClosedFormSegment, orient, t0: float, t_end: float):
        """Scan [t0, t_end] for the first event; store the output; return (end time, contactor hit or None)."""
        hit_tau, hit_c = None, None
        if self.contactors:
            hit_tau, hit_c = self._scan(st, seg, orient, t0, t_end)
        t1 = t_end if hit_tau is None else t0 + hit_tau
        self._output(st, seg, t0, t1)
        return t1, hit_c

    def _scan(self, st: StateModel, seg: ClosedFormSegment, orient, t0: float, t_end: float):
        h = self.h
        k = math.ceil(t0 / h - 1e-9)
        k_last = math.floor(t_end / h + 1e-9)
        V = (orient * -self.side)[:, None] * st.W_contact  # h = orient (gap - s w) = orient*gap + V @ eta
        if kernels.AVAILABLE and st.dyn.all_under:
            ld = seg.load
            tau, c = kernels.scan(
                t0, h, k, k_last, t_end, st.dyn.mu, V * seg._A[None, :], V * seg._B[None, :],
                orient * self.gap, V @ seg._particular_coefficients(), ld.Omega, ld.phi, ld.d is not None,
                orient < 0, self.tol_h, self.opt.event_tolerance,
            )
            return (None, None) if c < 0 else (float(tau), int(c))
        base = (orient * self.gap)[:, None]
        hv, dv = seg.evaluate_grid(0.0, h, 1, V)
        hp, dhp = hv[:, 0] + base[:, 0], dv[:, 0]
        tau_prev = 0.0
        n_chunk = 256
        while True:
            n = max(0, min(n_chunk, k_last + 1 - k))
            tau0 = k * h - t0
            if n:
                H, dH = seg.evaluate_grid(tau0, h, n, V)
                H = H + base
                taus = tau0 + h * np.arange(n)
            else:
                H = np.zeros((V.shape[0], 0))
                dH = H
                taus = np.zeros(0)
            last = k + n > k_last
            if last and (t_end - t0) > (taus[-1] if n else 0.0) + 1e-15:
                He, dHe = seg.evaluate_grid(t_end - t0, h, 1, V)
                H = np.concatenate([H, He + base], axis=1)
                dH = np.concatenate([dH, dHe], axis=1)
                taus = np.append(taus, t_end - t0)
            if taus.size:
                Hprev = np.concatenate([hp[:, None], H[:, :-1]], axis=1)
                dHprev = np.concatenate([dhp[:, None], dH[:, :-1]], axis=1)
                tprev = np.concatenate([[tau_prev], taus[:-1]])
                start_touch = np.abs(Hprev) <= self.tol_h
                cross = (H <= 0.0) & ((Hprev > 0.0) | (start_touch & (dHprev > 0)))
                dtau = taus - tprev
                graze = (Hprev > 0) & (H > 0) & (dHprev < 0) & (dH > 0)
                graze &= (Hprev < np.abs(dHprev) * dtau) | (H < np.abs(dH) * dtau)
                # a contactor left on the wrong side of its state by the projection of
                # eq. 12 (engaged but open: in tension; free but penetrated) switches
                # where its opening turns back before reaching the right side: a
                # one-sided spring cannot pull, and a free beam cannot pass the stop
                tension = (Hprev <= 0.0) & (H < 0.0) & (dHprev > 0.0) & (dH <= 0.0)
                cand = (cross | graze | tension) & (dtau > 0.0)  # tau = 0 may be both ends of the first interval
                if cand.any():
                    for j in np.nonzero(cand.any(axis=0))[0]:
                        best = None
                        for c in np.nonzero(cand[:, j])[0]:
                            if tension[c, j] and not cross[c, j]:
                                r = self._release_in_tension(st, seg, orient, int(c), tprev[j], taus[j])
                            else:
                                r = self._locate(
                                    st, seg, orient, int(c), tprev[j], taus[j], Hprev[c, j], dHprev[c, j], dH[c, j]
                                )
                            if r is not None and (best is None or r < best[0]):
                                best = (r, int(c))
                        if best is not None:
                            return best
                hp, dhp = H[:, -1], dH[:, -1]
                tau_prev = taus[-1]
            if last:
                return None, None
            k += n
            n_chunk = min(2 * n_chunk, 8192)

    def _output(self, st: StateModel, seg: ClosedFormSegment, t0: float, t1: float) -> None:
        """Exact output at the sampling times in [t0, t1) (t1 included at the end of the run)."""
        dt = self.opt.time_step
        i0 = max(0, math.ceil(t0 / dt - 1e-9))
        i1 = self.n_out if t1 >= self.opt.end_time else min(self.n_out, math.ceil(t1 / dt - 1e-9))
        code = self._code(st.engaged)
        if i1 <= i0:
            return
        if kernels.AVAILABLE and st.dyn.all_under:
            ld = seg.load
            n = st.modes.count
            kernels.output(
                t0, dt, i0, i1, st.dyn.mu, seg._A, seg._B, seg._particular_coefficients(), ld.Omega, ld.phi,
                ld.d is not None, ld.a - st.gap_force, ld.b if ld.b is not None else np.zeros(n),
                ld.d if ld.d is not None else np.zeros(n), st.modes.omega, 2.0 * st.dyn.decay, st.W_out,
                st.W_contact, self.w, self.w_t, self.wc, self.wtc, self.kin, self.strain, self.lpow, self.dpow,
                self.eta, self.eta_t,
            )
            self.code[i0:i1] = code
            return
        om = st.modes.omega[:, None]
        damp2 = (2.0 * st.dyn.decay)[:, None]
        for a in range(i0, i1, 8192):
            b = min(a + 8192, i1)
            tau0 = a * dt - t0
            eta, deta = seg.evaluate_grid(tau0, dt, b - a)
            sl = slice(a, b)
            self.w[sl] = (st.W_out @ eta).T
            self.w_t[sl] = (st.W_out @ deta).T
            if self.contactors:
                self.wc[sl] = (st.W_contact @ eta).T
                self.wtc[sl] = (st.W_contact @ deta).T
            self.code[sl] = code
            self.kin[sl] = 0.5 * np.einsum("ij,ij->j", deta, deta)
            oe = om * eta
            self.strain[sl] = 0.5 * np.einsum("ij,ij->j", oe, oe)
            f = seg.force(tau0 + dt * np.arange(b - a)) - st.gap_force[:, None]
            self.lpow[sl] = np.einsum("ij,ij->j", f, deta)
            self.dpow[sl] = np.einsum("ij,ij->j", damp2 * deta, deta)
            n = eta.shape[0]
            self.eta[sl, :n] = eta.T
            self.eta_t[sl, :n] = deta.T


def integrate(
    beam: Beam,
    contactors: tuple[Contactor, ...],
    damping: Damping,
    excitation: Excitation,
    initial: InitialCondition,
    options: SolverOptions,
    points: np.ndarray,
    progress: Callable[[float], None] | None = None,
) -> RawSolution:
    """Run the event-driven exact integration; see :func:`impactbeam.simulate`.

    Problems whose every state is under-damped (up to 3 contactors, no progress
    callback) run in the compiled loop of :mod:`~impactbeam.solver.fast`, which is
    tested to reproduce this Python loop; everything else runs here.
    """
    from . import fast

    if fast.supported(beam, contactors, damping, excitation, options, points, progress):
        return fast.integrate_fast(beam, contactors, damping, excitation, initial, options, points)
    integ = _Integrator(beam, contactors, damping, excitation, initial, options, points, progress)
    eta, deta = space_initial_coordinates(integ.space, beam, initial, options.modes)
    return integ._run_from(eta, deta)
