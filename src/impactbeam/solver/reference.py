"""Independent reference integrator: the same modal model by :func:`scipy.integrate.solve_ivp`.

``simulate(..., method="ivp")`` runs this path. It integrates the same
piecewise-linear modal equations as the exact solver (paper eq. 9),

.. math:: \\ddot\\eta_n + 2\\xi_n\\omega_n\\dot\\eta_n + \\omega_n^2\\eta_n
          = p_n u(t) + f^{gap}_n,

in each state (the set of engaged contactors, with the same mode sets from
:class:`~impactbeam.solver.states.StateSpace`), but by a general-purpose
Runge-Kutta method (DOP853, ``rtol = 1e-10``) instead of the closed form,
with the time history ``u(t)`` written out from the fields of the
:class:`~impactbeam.model.loading.Excitation` rather than taken from the exact
solver's closed-form load pieces. Contact changes are terminal
``solve_ivp`` events on each contactor's opening ``g = c - s w(a)`` with a
direction (downward crossing while open: impact; upward crossing while
engaged: rebound); the integration restarts in the new state after the
projection of the displacement and velocity (paper eq. 12). The integration
is also restarted at every break of the load history (pulse start and end,
table samples), so no step straddles a discontinuity of the load or of its
derivative.

It exists so the tests can check the exact solver against an integrator
that shares none of its propagation or event-location code. It is about
two orders of magnitude slower.

A contactor the projection of eq. (12) leaves on the wrong side of its new
state (its row below ``-1e-12 L``) is judged at the restart by the engine's
rule: it switches at once unless it is the contactor just switched and is
moving back towards its side; then it switches where its row turns back
(a terminal event on the row's slope), unless the row reaches 0 first. A
row touching 0 at a restart (two zero-gap stops crossed at one instant)
switches at once when its slope points to the wrong side.

Limitations (those of :func:`scipy.integrate.solve_ivp`): events are found
from sign changes between accepted steps, so a graze that dips below the
surface and back within one step is missed; the step is bounded by
``max_step`` (1/4 of the shortest modal period of any state) to make that
unlikely. Event times are located on the DOP853 dense output, accurate to
about the integration tolerance, not to 1e-13 s.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp

from ..model.beam import Beam, Contactor
from ..exceptions import SimulationError
from ..model.loading import Excitation
from ..model.starting import InitialCondition, Preload
from ._codes import MOVED_FLOOR, MOVED_WARN, TOUCH
from .engine import make_space
from .initial import initial_coordinates
from .reference_dense import IvpDense, IvpSegment, IvpSolution
from .solution import Event
from ..model import Damping, SolverOptions
from .states import StateModel

__all__ = ["integrate_ivp", "IvpSegment", "IvpDense", "IvpSolution", "RTOL"]

#: Relative tolerance of the reference integration.
RTOL = 1e-10


def _load_breaks(excitation: Excitation, end_time: float) -> list[float]:
    """Times in (0, end_time) where the load history or its derivative jumps."""
    if not excitation.active:
        return []
    s = excitation.start
    if excitation.shape == "half_sine":
        assert excitation.duration is not None
        cand = [s, s + excitation.duration]
    elif excitation.shape in ("step", "harmonic"):
        cand = [s]
    else:
        assert excitation.times is not None
        cand = list(s + excitation.times)
    return sorted({float(t) for t in cand if 0.0 < t < end_time})


def _history_on(excitation: Excitation, a: float, b: float):
    """Scalar ``u(t)`` on the interval [a, b] between two breaks of the history.

    Written from the fields of :class:`Excitation` (amplitude, start,
    duration, table), not from the exact solver's load pieces; the form is
    fixed on the interval, so a Runge-Kutta stage at either end sees the
    value of this interval (:meth:`Excitation.history` is right-continuous
    at the breaks, which is wrong for a stage at ``b``).
    """
    if not excitation.active:
        return lambda t: 0.0
    s = excitation.scale
    start = excitation.start
    tau_mid = 0.5 * (a + b) - start
    if excitation.shape == "half_sine":
        dur = float(excitation.duration)  # type: ignore[arg-type]
        if not 0.0 <= tau_mid <= dur:
            return lambda t: 0.0
        amp, om = s * excitation.amplitude, math.pi / dur
        return lambda t: amp * math.sin(om * (t - start))
    if excitation.shape == "step":
        val = s * excitation.amplitude if tau_mid >= 0.0 else 0.0
        return lambda t: val
    if excitation.shape == "harmonic":
        if tau_mid < 0.0:
            return lambda t: 0.0
        amp, om, ph = s * excitation.amplitude, 2.0 * math.pi * float(excitation.frequency), excitation.phase
        return lambda t: amp * math.sin(om * (t - start) + ph)
    tk, vk = excitation.times, excitation.values
    assert tk is not None and vk is not None
    if not tk[0] <= tau_mid <= tk[-1]:
        return lambda t: 0.0
    k = int(np.searchsorted(tk, tau_mid, side="right")) - 1
    k = min(max(k, 0), tk.size - 2)
    v0 = s * float(vk[k])
    if excitation.hold == "constant":
        return lambda t: v0
    t0 = start + float(tk[k])
    slope = s * float(vk[k + 1] - vk[k]) / float(tk[k + 1] - tk[k])
    return lambda t: v0 + slope * (t - t0)


class _Reference:
    def __init__(
        self,
        beam: Beam,
        contactors: tuple[Contactor, ...],
        damping: Damping,
        excitation: Excitation,
        options: SolverOptions,
        preload: Preload | None = None,
    ) -> None:
        self.beam = beam
        self.contactors = contactors
        self.excitation = excitation
        self.opt = options
        self.space = make_space(beam, contactors, damping, excitation, options, np.zeros(0), preload)
        self.dash = np.asarray(self.space.dashpots, dtype=float)
        self.gap = np.array([c.gap for c in contactors], dtype=float)
        self.side = np.array([c.direction for c in contactors], dtype=float)
        self.stiff = np.array([c.stiffness for c in contactors], dtype=float)
        self.tol = TOUCH * beam.length  # the touch tolerance of the engine (tol_h)
        T = options.end_time
        all_eng = tuple(range(len(contactors)))
        states = [self.space.state(())] + ([self.space.state(all_eng)] if contactors else [])
        wmax = max(st.omega_max for st in states)
        self.max_step = 0.25 * 2.0 * math.pi / wmax if wmax > 0 else math.inf
        self.max_step = min(self.max_step, T)

    # -------------------------------------------------------------- pieces of the model
    def gap_force(self, st: StateModel) -> np.ndarray:
        """Modal weights of the constant force ``s k c`` of each engaged gapped contactor.

        Contactor ``above`` (s = +1) engaged pushes with ``-k (w - c) = -k w + k c``;
        the ``-k w`` part is in the contact-state modes, ``+k c`` remains.
        """
        f = np.zeros(st.modes.count)
        for i in st.engaged:
            f += self.side[i] * self.stiff[i] * self.gap[i] * st.W_contact[i]
        return f

    def first_order(self, st: StateModel) -> tuple[np.ndarray, np.ndarray]:
        """``(A, f)`` of the state's first-order system ``y' = A y + b u(t) + f``, ``y = (eta, eta')``."""
        n = st.modes.count
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -np.diag(st.modes.omega**2)
        A[n:, n:] = -self.damping_matrix(st)
        return A, np.concatenate([np.zeros(n), self.gap_force(st) + st.preload_weights])

    def damping_matrix(self, st: StateModel) -> np.ndarray:
        """The state's damping in its modal frame (the beam's model and the engaged dashpots)."""
        return st.damping_matrix if st.damping_matrix is not None else np.diag(2.0 * st.dyn.decay)

    def events(self, st: StateModel, engaged: tuple[int, ...], phase: list[bool]) -> tuple[list, list]:
        """Terminal event functions, positive while the state holds, and what each row is.

        Engaged: the penetration ``d = s w - gap``, or with a dashpot the force
        over the stiffness ``d + (c/k) d'``; free: the opening ``gap - s w``,
        or after a release that left a penetration ``-(d + (c/k) d')`` and
        the penetration itself (whose return to 0 ends that phase).
        """
        n = st.modes.count
        evs, rows = [], []

        def make(Wc, base, sign, r):
            def ev(tt, y):
                return base + sign * (float(Wc @ y[:n]) + r * float(Wc @ y[n:]))

            ev.terminal = True
            ev.direction = -1.0
            return ev

        for c in range(len(self.contactors)):
            Wc, g0, s0 = st.W_contact[c], self.gap[c], self.side[c]
            r = self.dash[c] / self.stiff[c]
            if c in engaged:
                evs.append(make(Wc, -g0, s0, r))
            else:
                evs.append(make(Wc, g0, -s0, r if phase[c] else 0.0))
            rows.append((c, "main"))
            if c not in engaged and phase[c]:
                evs.append(make(Wc, -g0, s0, 0.0))
                rows.append((c, "phase"))
        return evs, rows

    def _judge_start(self, evs: list, rows: list, t: float, y0: np.ndarray, rhs, just: int | None,
                     judged: dict[int, int], t_stop: float) -> tuple[list[int], list[int], list[int]]:
        """Rows on the wrong side at a restart: to switch at once, where they turn back, or let run from below 0.

        The last are within the touch tolerance below 0 (or at 0, the beam still under no load until
        ``t_stop``); they count once deeper than it (:meth:`_shifted`).

        The engine's rule (:mod:`~impactbeam.solver._loop`): a row below
        ``-1e-12 L`` switches at once, unless it belongs to the contactor just
        switched (``just``) and is moving back towards its side, or this rule
        already switched its contactor twice at this instant (``judged``); those
        switch where their slope turns negative while they are still at or below 0. A row within
        ``1e-12 L`` of 0 (touching) switches at once when its slope points to the wrong side.
        """
        tol = self.tol
        # at rest in equilibrium under a load that is 0 over the whole piece: every row stays where it is
        still = all(not np.any(rhs(tt, y0)) for tt in (t, t + (t_stop - t) / 3.0, t + 2.0 * (t_stop - t) / 3.0))
        wrong, turns, below = [], [], []
        for r, ev in enumerate(evs):
            h = ev(t, y0)
            if h > tol:
                continue
            slope = self._slope(ev, rhs, t, y0)
            if h >= -tol:  # touching (a zero gap at a crossing, a contactor just switched): its slope decides
                if slope < 0.0 and judged.get(rows[r][0], 0) < 2:
                    wrong.append(r)
                elif h < 0.0 or (h == 0.0 and still):
                    below.append(r)  # (at 0 and still too: solve_ivp takes a row that stays at 0 for a crossing)
                continue
            back = rows[r][0] == just and rows[r][1] == "main" and slope >= 0.0
            if not back and judged.get(rows[r][0], 0) < 2:
                wrong.append(r)
            else:
                turns.append(r)
        return wrong, turns, below

    def _pulls_at_start(self, st: StateModel, engaged: tuple[int, ...], c: int, eta: np.ndarray,
                        deta: np.ndarray) -> bool:
        """Free dashpot contactor ``c`` penetrated at t = 0 with a pulling force ``k d + c d'``: starts released.

        The engine's rule (``_loop._released_at_start``).
        """
        if c in engaged or self.dash[c] <= 0.0:
            return False
        pen = self.side[c] * float(st.W_contact[c] @ eta) - self.gap[c]
        rate = self.side[c] * float(st.W_contact[c] @ deta)
        return pen > self.tol and pen + self.dash[c] / self.stiff[c] * rate < 0.0

    def _shifted(self, ev):
        """The terminal event ``ev`` moved by the touch tolerance: it fires where the row passes ``-tol``."""
        tol = self.tol

        def deeper(tt, y):
            return ev(tt, y) + tol

        deeper.terminal = True
        deeper.direction = -1.0
        return deeper

    @staticmethod
    def _slope(ev, rhs, tt: float, y: np.ndarray) -> float:
        """The time derivative of the affine row ``ev`` along the flow: its linear part applied to ``y'``."""
        return ev(tt, rhs(tt, y)) - ev(tt, np.zeros_like(y))

    @classmethod
    def _slope_event(cls, ev, rhs):
        """Terminal event on :meth:`_slope` of the row ``ev``, crossing down."""

        def slope(tt, y):
            return cls._slope(ev, rhs, tt, y)

        slope.terminal = True
        slope.direction = -1.0
        return slope

    def energy(self, st: StateModel, eta: np.ndarray, deta: np.ndarray) -> float:
        """Kinetic + strain (beam, supports) + engaged contactor springs ``1/2 k g^2``."""
        E = 0.5 * float(deta @ deta) + 0.5 * float(np.sum((st.modes.omega * eta) ** 2))
        wc = st.W_contact @ eta
        for i in st.engaged:
            g = self.gap[i] - self.side[i] * wc[i]
            # the modal strain already holds 1/2 k w^2 of the engaged spring
            E += 0.5 * self.stiff[i] * (g**2 - wc[i] ** 2)
        return E

    def atol(self, st: StateModel, y0: np.ndarray) -> np.ndarray:
        """Absolute tolerance per component: 1e-3 rtol of a characteristic modal amplitude."""
        n = st.modes.count
        om = st.modes.omega
        om_el = om[om > 0]
        w_ref = float(om_el.min()) if om_el.size else 2.0 * math.pi / self.opt.end_time
        u_max = 0.0
        if self.excitation.active:
            tt = np.linspace(0.0, self.opt.end_time, 2001)
            u_max = float(np.max(np.abs(self.excitation.history(tt))))
            if self.excitation.shape == "table":
                u_max = max(u_max, float(np.max(np.abs(self.excitation.values))) * abs(self.excitation.scale))
        U = max(
            float(np.max(np.abs(y0[:n]), initial=0.0)),
            float(np.max(np.abs(y0[n:]), initial=0.0)) / w_ref,
            u_max * float(np.max(np.abs(st.load_weights), initial=0.0)) / w_ref**2,
            float(np.sum(self.stiff * self.gap * np.max(np.abs(st.W_contact), axis=1))) / w_ref**2
            if self.contactors
            else 0.0,
            float(np.max(np.abs(st.preload_weights), initial=0.0)) / w_ref**2,
            1e-300,
        )
        a = RTOL * 1e-3 * U
        return np.concatenate([np.full(n, a), np.full(n, a * w_ref)])

    # -------------------------------------------------------------- main loop
    def run(self, eta: np.ndarray, deta: np.ndarray) -> IvpSolution:
        T = self.opt.end_time
        breaks = _load_breaks(self.excitation, T) + [T]
        engaged: tuple[int, ...] = ()
        t = 0.0
        k_break = 0
        events: list[Event] = []
        segments: list[IvpSegment] = []
        jumps: list[float] = []
        e_peak = 0.0  # the largest energy before or after a switch
        changed = 0.0  # the projections' energy changes, their magnitudes summed (engine.energy_warning)
        status, message = 0, "The simulation reached end_time."
        nc = len(self.contactors)
        same_instant: dict[int, int] = {}
        phase = [False] * nc  # released with a penetration left (dashpot contactors)
        pens: list[float] = []
        last_t = -1.0
        atol_state: dict[tuple[int, ...], np.ndarray] = {}
        just: int | None = None  # the contactor switched at the current restart
        judged: dict[int, int] = {}  # switches made at once by _judge_start at the instant judged_t
        judged_t = -1.0
        moved = _Moved(self.gap, self.tol)
        while t < T:
            while breaks[k_break] <= t:
                k_break += 1
            t_stop = breaks[k_break]
            a_int = breaks[k_break - 1] if k_break > 0 else 0.0
            st = self.space.state(engaged)
            n = st.modes.count
            u = _history_on(self.excitation, a_int, t_stop)
            A, fvec = self.first_order(st)  # y' = A y + b u(t) + f, y = (eta, eta')
            bvec = np.concatenate([np.zeros(n), st.load_weights])

            def rhs(tt, y, A=A, bvec=bvec, fvec=fvec, u=u):
                return A @ y + bvec * u(tt) + fvec

            evs, rows = self.events(st, engaged, phase)
            y0 = np.concatenate([eta, deta])
            if engaged not in atol_state:
                atol_state[engaged] = self.atol(st, y0)
            if t != judged_t:
                judged, judged_t = {}, t
            wrong, turns, below = self._judge_start(evs, rows, t, y0, rhs, just, judged, t_stop)
            if wrong and rows[wrong[0]][1] == "phase":
                phase[rows[wrong[0]][0]] = False  # the penetration left by a release is gone: a plain opening
                continue
            if wrong and t == 0.0 and self._pulls_at_start(st, engaged, rows[wrong[0]][0], eta, deta):
                phase[rows[wrong[0]][0]] = True  # penetrated but pulling: released, as after a rebound
                continue
            for r in below:
                evs[r] = self._shifted(evs[r])
            turned: dict[int, int] = {}  # event index -> the row on the wrong side it watches turn back
            for r in turns:
                turned[len(evs)] = r
                evs.append(self._slope_event(evs[r], rhs))
                rows.append((rows[r][0], "turn"))
            if wrong:
                sol = None
            else:
                sol = solve_ivp(
                    rhs, (t, t_stop), y0, method="DOP853", rtol=RTOL, atol=atol_state[engaged],
                    dense_output=True, events=evs or None, max_step=self.max_step,
                )
                if sol.status == -1:
                    raise SimulationError(f"solve_ivp failed at t = {t:.9g} s: {sol.message}")
            hit: tuple[float, int] | None = None
            if sol is None:
                hit = (t, wrong[0])
                judged[rows[wrong[0]][0]] = judged.get(rows[wrong[0]][0], 0) + 1
            elif sol.status == 1:
                for r, te in enumerate(sol.t_events):
                    if te.size and (hit is None or te[0] < hit[0]):
                        hit = (float(te[0]), r)
            t1 = hit[0] if hit is not None else float(sol.t[-1])
            y1 = sol.sol(t1) if sol is not None and sol.sol is not None else y0
            if sol is not None:
                segments.append(IvpSegment(t, t1, engaged, IvpDense(sol.sol, t, t1, y0, y1)))
            eta, deta = y1[:n].copy(), y1[n:].copy()
            t = t1
            just = None
            if hit is not None and hit[1] in turned:  # turned back: a switch if still on the wrong side
                r = turned[hit[1]]
                hit = (t, r) if evs[r](t, y1) <= 0.0 else None  # else it reached its side first: a restart
            if hit is not None and rows[hit[1]][1] == "phase":
                phase[rows[hit[1]][0]] = False  # the penetration left by a release is gone
            elif hit is not None:
                c = rows[hit[1]][0]
                if t != last_t:
                    same_instant, last_t = {}, t
                same_instant[c] = same_instant.get(c, 0) + 1
                new = tuple(sorted(set(engaged) ^ {c}))
                kind = "impact" if c in new else "rebound"
                E_before = self.energy(st, eta, deta)
                pen = self.side[c] * float(st.W_contact[c] @ eta) - self.gap[c]
                start_up = kind == "impact" and t == 0.0 and pen > 0.0  # the engine's rules (_loop._switch)
                if events and events[-1].time == t and events[-1].contactor == c:
                    events.pop()  # an impact and a rebound at one instant cancel (grazing touch)
                    pens.pop()
                else:
                    events.append(Event(t, kind, c, float(st.W_contact[c] @ deta)))
                    pens.append(0.0 if start_up else pen)
                phase[c] = kind == "rebound" and self.dash[c] > 0.0 and pen > self.tol
                spring = 0.5 * self.stiff[c] * pen * pen if pen > 0.0 else 0.0
                if start_up:
                    E_before += spring
                P = self.space.transfer(new, engaged, self.opt.projection == "contact")
                w_before = st.W_contact @ eta
                eta, deta = P @ eta, P @ deta
                engaged = new
                just = c
                moved.record(t, w_before, self.space.state(new).W_contact @ eta)
                E_after = self.energy(self.space.state(new), eta, deta)
                jumps.append(E_after - E_before)
                booked = 0.0 if (start_up or self.dash[c] <= 0.0) else (spring if kind == "impact" else -spring)
                changed += abs(E_after - E_before - booked)
                e_peak = max(e_peak, E_before, E_after)
                if len(events) >= self.opt.max_events or same_instant[c] > 4:
                    status = 1
                    why = "solver.max_events" if len(events) >= self.opt.max_events else (
                        f"contactor {c} switched {same_instant[c]} times at one instant")
                    message = (
                        f"Stopped at t = {t:.9g} s after {len(events)} events ({why}): "
                        "chattering contact; the solution ends there."
                    )
                    break
        changes = (changed, e_peak, len(jumps), self.opt.modes)  # engine.energy_warning's
        return IvpSolution(self, segments, events, np.asarray(jumps, dtype=float), status, message,
                           t if status else T, np.asarray(pens, dtype=float), moved.worst(len(jumps), self.opt.modes),
                           changes)


class _Moved:
    """The switches whose projection moved a contactor's deflection by more than ``MOVED_WARN`` of its scale.

    The engine's rule (:func:`~impactbeam.solver.engine.projection_warning`): the scale is the larger of the
    contactor's gap and its deflection before the switch, at least ``MOVED_FLOOR`` touch tolerances.
    """

    def __init__(self, gap: np.ndarray, tol: float) -> None:
        self.gap, self.tol = gap, tol
        self.count = 0
        self.top: tuple[float, int, float, float] | None = None  # t, contactor, moved, scale of the worst

    def record(self, t: float, before: np.ndarray, after: np.ndarray) -> None:
        lossy = False
        for i in range(self.gap.size):
            shift = abs(float(after[i] - before[i]))
            scale = max(self.gap[i], abs(float(before[i])), MOVED_FLOOR * self.tol)
            if shift > MOVED_WARN * scale:
                if self.top is None or shift / scale > self.top[2] / self.top[3]:
                    self.top = (t, i, shift, scale)
                lossy = True
        self.count += lossy

    def worst(self, switches: int, modes: int) -> tuple | None:
        """The arguments of :func:`~impactbeam.solver.engine.projection_warning`, or None."""
        if self.top is None:
            return None
        t, i, shift, scale = self.top
        return (self.count, switches, modes, i, shift, scale, t)


def integrate_ivp(
    beam: Beam,
    contactors: tuple[Contactor, ...],
    damping: Damping,
    excitation: Excitation,
    initial: InitialCondition,
    options: SolverOptions,
    preload: Preload | None = None,
) -> IvpSolution:
    """Integrate the modal model with :func:`scipy.integrate.solve_ivp` and terminal events.

    Parameters
    ----------
    beam : Beam
    contactors : tuple of Contactor
    damping : Damping
        The beam's damping model; contactor dashpots come with the contactors.
    excitation : Excitation
    initial : InitialCondition
    options : SolverOptions
        ``modes``, ``time_step`` (output sampling only), ``end_time``,
        ``max_events`` (chattering guard, status 1).
    preload : Preload, optional
        The constant load of ``[preload]``, acting throughout.

    Returns
    -------
    IvpSolution
        The dense output (the interface of the exact solver's
        :class:`~impactbeam.solver.solution.Solution`), so
        :class:`~impactbeam.result.SimulationResult` and its metrics work
        unchanged.

    Raises
    ------
    SimulationError
        If ``solve_ivp`` fails (step size underflow).

    Notes
    -----
    DOP853 with ``rtol = 1e-10`` and an absolute tolerance of 1e-13 of a
    characteristic modal amplitude; ``max_step`` is a quarter of the
    shortest modal period. See the module docstring for what is shared with
    the exact solver (mode sets, modal load weights, projection matrices)
    and what is not (propagation, load evaluation, event detection and
    location).
    """
    ref = _Reference(beam, tuple(contactors), damping, excitation, options, preload)
    eta, deta = initial_coordinates(ref.space, beam, initial, preload, contactors=tuple(contactors),
                                    preserve_contacts=options.projection == "contact")
    return ref.run(eta, deta)
