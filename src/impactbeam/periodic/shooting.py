"""Periodic orbits of a harmonically forced impacting beam by shooting on the stroboscopic map.

Under the harmonic excitation ``u(t) = A sin(2 pi f (t - start) + phase)``
the event-driven system is periodic in time with period ``1/f``. A periodic
response of period ``M/f`` (``M`` = ``multiple``) is a fixed point of the
stroboscopic map ``P``: the modal state ``x = (eta, eta_t)`` at a section
time ``t_s`` carried over ``M/f`` by the exact solver. Newton's method solves
``P(x) = x`` with the exact Jacobian ``DP`` of the event-driven map (the
homogeneous transition of each segment composed with the saltation matrix
of each impact and rebound, :mod:`impactbeam.periodic._saltation`), starting
from the state the plain simulation of the scenario has settled on.
The eigenvalues of ``DP`` at the fixed point are the Floquet multipliers;
the orbit is asymptotically stable when all lie inside the unit circle.

The map's state is written in the free state's modal coordinates. With the
shared Ritz basis (``solver.basis = "enriched"``) every state has the same
coordinates up to an orthogonal change of basis, so the map is exact
wherever the section lies; with the paper's per-state modes a section inside
a contact would add two lossy projections (paper eq. 12), so the section is
placed, within the forcing period, in the middle of the longest free flight
of the settled response (the multipliers do not depend on where the section
lies). The strobe values reported are those at ``t = start + k/f``, the
times of ``impactbeam bifurcation``.

References
----------
.. [1] W. Xu, E. K. Ervin, Shock and Vibration 20 (2013), section 2, eqs. (9)-(12).
.. [2] M. di Bernardo, C. J. Budd, A. R. Champneys, P. Kowalczyk,
   "Piecewise-smooth Dynamical Systems", Springer (2008), section 2.5
   (saltation matrices).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from .._warnings import emit_user_level_warning
from ..exceptions import ParameterError
from ._saltation import FlowJacobian, energy_weights, flow_jacobian, to_free

if TYPE_CHECKING:
    from ..scenario import Scenario
    from ..solver.solution import Solution

__all__ = ["PeriodicOrbit", "StroboscopicMap", "periodic_orbit"]

_MAX_BACKTRACK = 6  # halvings of a Newton step that does not lower the residual
_MAX_UPHILL = 3  # steps in a row that do not lower it (the best trial is taken) before giving up


@dataclass(frozen=True, eq=False)
class PeriodicOrbit:
    """A periodic response of period ``multiple / f`` and its Floquet multipliers.

    Attributes
    ----------
    converged : bool
        Whether Newton's relative residual reached ``tolerance``.
    multiple : int
        ``M``: the orbit repeats after ``M`` forcing periods.
    period : float, [s]
        ``M / f``.
    strobe_times : ndarray, (M,), [s]
        ``start + k/f`` for the ``M`` consecutive strobe times after the section.
    strobe : ndarray, (M,), [m]
        ``w`` at the first contactor (the first output point without one) at ``strobe_times``.
    multipliers : ndarray of complex, (2 n,)
        Eigenvalues of the Jacobian of the map at the orbit, by decreasing
        modulus; empty when that Jacobian is not finite (a saltation divides
        by a switch's normal velocity, zero at a grazing contact; a warning
        says so).
    stable : bool
        All multipliers strictly inside the unit circle (False without multipliers).
    impacts_per_period : int
        Impacts (contactors engaging) in one period ``M / f`` of the orbit.
    least_period : int
        The smallest number of forcing periods after which the orbit repeats
        (a divisor of ``M``; ``M`` when not converged).
    iterations : int
        Newton steps taken.
    residuals : tuple of float
        Relative residual ``|P(x) - x| / |x|`` (energy norm) at each iterate.
    section_time : float, [s]
        Time of the section at which ``state`` is given.
    state : ndarray, (2 n,)
        ``(eta, eta_t)`` at ``section_time``, in the free state's modal coordinates.
    jacobian : ndarray, (2 n, 2 n)
        ``DP`` at ``state`` (the monodromy matrix of the map).
    map : StroboscopicMap
        The map itself, to evaluate at other states (finite differences, continuation).
    warnings : tuple of str
    message : str
    """

    converged: bool
    multiple: int
    period: float
    strobe_times: np.ndarray
    strobe: np.ndarray
    multipliers: np.ndarray
    stable: bool
    impacts_per_period: int
    least_period: int
    iterations: int
    residuals: tuple[float, ...]
    section_time: float
    state: np.ndarray
    jacobian: np.ndarray
    map: StroboscopicMap
    warnings: tuple[str, ...] = ()
    message: str = ""

    def to_dict(self) -> dict[str, Any]:
        """The fields of ``impactbeam periodic --json`` (SI; multipliers as ``[re, im]`` pairs)."""
        return {
            "converged": self.converged,
            "multiple": self.multiple,
            "period": self.period,
            "strobe": [float(v) for v in self.strobe],
            "strobe_times": [float(v) for v in self.strobe_times],
            "multipliers": [[float(m.real), float(m.imag)] for m in self.multipliers],
            "stable": self.stable,
            "impacts_per_period": self.impacts_per_period,
            "least_period": self.least_period,
            "iterations": self.iterations,
            "residual": self.residuals[-1] if self.residuals else None,
            "message": self.message,
        }


class StroboscopicMap:
    """``x -> x(t_s + M/f)``: the exact solver run from state ``x`` at the section time ``t_s``.

    Parameters
    ----------
    scenario : Scenario
        With a harmonic excitation.
    multiple : int
        ``M``.
    phase : float
        Section within the forcing period: ``t_s = start + (K + phase)/f``, ``0 <= phase < 1``.
    n_modes : int
        Modes per state.
    """

    def __init__(self, scenario: Scenario, multiple: int, phase: float, n_modes: int) -> None:
        from ..solver.engine import pack

        exc = scenario.excitation
        self.scenario = scenario
        self.multiple = int(multiple)
        self.phase = float(phase)
        self.frequency = float(exc.frequency)
        self.period = self.multiple / self.frequency
        self.options = dataclasses.replace(scenario.solver, modes=int(n_modes), end_time=self.period)
        # the load seen from the section: u(t_s + tau) = A sin(2 pi f tau + phase_0 + 2 pi phase)
        self.excitation = dataclasses.replace(exc, start=0.0, phase=float(exc.phase) + 2.0 * math.pi * self.phase)
        self.contactors = tuple(scenario.contactors)
        self.packed = pack(scenario.beam, self.contactors, scenario.damping, self.excitation, self.options,
                           scenario.preload)
        #: weights of the energy norm |(omega eta, eta_t)|
        self.weights = energy_weights(self.packed.om[0])

    @property
    def size(self) -> int:
        """Dimension ``2 n`` of the map's state."""
        return 2 * int(self.packed.n_modes)

    def norm(self, x: np.ndarray) -> float:
        """Energy-like norm ``|(omega eta, eta_t)|`` (units m kg^0.5 / s)."""
        return float(np.linalg.norm(self.weights * x))

    def solve(self, x: np.ndarray, duration: float | None = None) -> Solution:
        """The exact solution from state ``x`` (free-state coordinates) at the section, over ``duration``."""
        from ..model.starting import InitialCondition
        from ..solver.engine import integrate

        x = np.asarray(x, dtype=float)
        if x.shape != (self.size,):
            raise ParameterError(f"state: expected {self.size} modal coordinates and rates, got shape {x.shape}")
        opt = self.options if duration is None else dataclasses.replace(self.options, end_time=float(duration))
        n = self.packed.n_modes
        sc = self.scenario
        return integrate(sc.beam, self.contactors, sc.damping, self.excitation, InitialCondition(), opt,
                         start=(x[:n].copy(), x[n:].copy()), preload=sc.preload)

    def _checked(self, x: np.ndarray) -> Solution:
        from ..exceptions import SimulationError

        sol = self.solve(x)
        if sol.status != 0:
            raise SimulationError(f"periodic orbit: the map could not be evaluated: {sol.message}")
        return sol

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """``P(x)``: the state one period ``M/f`` later, in free-state coordinates."""
        return flow_jacobian(self._checked(x)).final

    def jacobian(self, x: np.ndarray) -> FlowJacobian:
        """``P(x)`` with its exact Jacobian (segment transitions and saltation matrices)."""
        return flow_jacobian(self._checked(x))


def _check(scenario: Scenario, multiple: Any) -> int:
    from ..simulation import _require_scenario

    _require_scenario(scenario)
    if isinstance(multiple, bool) or not isinstance(multiple, (int, np.integer)) and not (
        isinstance(multiple, float) and multiple.is_integer()
    ):
        raise ParameterError(f"multiple: expected a whole number of forcing periods (1, 2, ...), got {multiple!r}")
    if int(multiple) < 1:
        raise ParameterError(f"multiple: the orbit period is M forcing periods with M >= 1, got {int(multiple)}")
    exc = scenario.excitation
    if exc.kind == "none":
        raise ParameterError('excitation.kind: periodic orbits need a harmonic excitation; the scenario has none')
    if exc.shape != "harmonic":
        raise ParameterError(
            f'excitation.shape: periodic orbits need shape = "harmonic" (with frequency and amplitude), '
            f'got "{exc.shape}"'
        )
    return int(multiple)


def _section_phase(sol: Any, lo: float, hi: float, start: float, f: float,
                   prefer_free: bool) -> tuple[float, bool]:
    """Phase (fraction of the forcing period) of the middle of the longest event-free interval in ``[lo, hi]``,
    and whether that interval is free.

    With ``prefer_free`` only intervals of the free state count when there are any. An interval where a
    contactor is pressed into its stop while released does not count as free: a dashpot contactor in its
    released phase (the map's state, the modal coordinates, cannot tell it from an engaged contact), or,
    with the paper's basis, one a projection left on the wrong side until it turns back (a run started
    there would switch it at once).
    """
    times = [lo] + [ev.time for ev in sol.events if lo < ev.time < hi] + [hi]
    best, best_len, best_free = 0.5 * (lo + hi), -1.0, False
    every = list(range(len(sol.contactors)))
    for a, b in zip(times[:-1], times[1:]):
        mid = 0.5 * (a + b)
        j = int(sol.segment_index(np.array([mid]))[0])
        free = sol.engaged(j) == () and not _compressed(sol, every, mid)
        key_better = (free and not best_free) if prefer_free else False
        if key_better or ((free == best_free or not prefer_free) and b - a > best_len):
            best, best_len, best_free = mid, b - a, free
    return float((f * (best - start)) % 1.0), best_free


def _compressed(sol: Any, which: list[int], t: float) -> bool:
    """Whether any of the contactors ``which`` is pressed into its stop at ``t`` (its opening negative)."""
    if not which:
        return False
    cs = [sol.contactors[i] for i in which]
    w = sol.sample(np.array([c.position for c in cs]), np.array([t])).w[0]
    return any(c.gap_function(float(wi)) < 0.0 for c, wi in zip(cs, w))


def _settle(scenario: Scenario, multiple: int, settle_periods: float | None) -> tuple[Any, float, int]:
    """The plain simulation the search starts from, its end time and the modes per state."""
    from ..simulation import simulate

    exc = scenario.excitation
    f = float(exc.frequency)
    sc = scenario
    if settle_periods is not None:
        if not (isinstance(settle_periods, (int, float)) and math.isfinite(settle_periods) and settle_periods > 0):
            raise ParameterError(f"settle_periods: expected a positive number of forcing periods, got {settle_periods!r}")
        sc = scenario.with_values({"solver.end_time": float(exc.start + (settle_periods + multiple) / f)})
    end = float(sc.solver.end_time)
    if end - exc.start < multiple / f * (1.0 - 1e-12):
        raise ParameterError(
            f"solver.end_time: {end:g} s leaves less than {multiple} forcing period(s) after excitation.start "
            f"({exc.start:g} s); the search needs the settled response: give settle_periods or a longer end_time"
        )
    res = simulate(sc)
    if res.solution.status != 0:
        from ..exceptions import SimulationError

        raise SimulationError(f"periodic orbit: the settling run stopped early: {res.solution.message}")
    return res, end, int(res.n_modes)


def periodic_orbit(
    scenario: Scenario,
    *,
    multiple: int = 1,
    settle_periods: float | None = None,
    guess: PeriodicOrbit | None = None,
    tolerance: float = 1e-11,
    max_iterations: int = 20,
) -> PeriodicOrbit:
    """Periodic response of period ``multiple / f`` by Newton's method on the stroboscopic map.

    Parameters
    ----------
    scenario : Scenario
        With ``[excitation] shape = "harmonic"``.
    multiple : int
        ``M >= 1``: look for an orbit repeating after ``M`` forcing periods.
    settle_periods : float, optional
        Simulate this many forcing periods after ``excitation.start`` before
        the search (default: the scenario's ``solver.end_time``). The last
        ``M`` periods of that run give the starting state and the section.
    guess : PeriodicOrbit, optional
        Start from this orbit's state and section instead of a simulation
        (continuation in a parameter: pass the orbit found at a nearby value).
    tolerance : float
        Newton stops when ``|P(x) - x| <= tolerance |x|`` in the energy norm.
    max_iterations : int
        Newton steps at most.

    Returns
    -------
    PeriodicOrbit
        With ``converged = False`` (and an
        :class:`~impactbeam.exceptions.ImpactBeamWarning`) when Newton did not
        reach ``tolerance``.

    Raises
    ------
    ParameterError
        ``multiple < 1`` or not whole, no harmonic excitation, a run too short
        to settle, or a ``guess`` of another model.
    SimulationError
        The settling run stopped early (chattering contact).

    Notes
    -----
    Each Newton step solves ``(DP - I) dx = -(P(x) - x)`` with the exact
    Jacobian ``DP`` (module docstring), halving a step that does not lower
    the residual. Convergence is quadratic as long as no event is grazing; a
    grazing contact (normal velocity below ``1e-4`` of the orbit's scale) is
    warned about, since the map is not differentiable there. The
    multipliers are the eigenvalues of ``DP`` at the orbit; they do not
    depend on the section. Unstable orbits are found from a ``guess`` near
    them (e.g. between two coexisting stable orbits past a fold).

    Examples
    --------
    >>> sc = ib.load_scenario("harmonic.toml")  # doctest: +SKIP
    >>> orbit = ib.periodic_orbit(sc, multiple=1, settle_periods=30)  # doctest: +SKIP
    >>> orbit.converged, orbit.stable, abs(orbit.multipliers[0])  # doctest: +SKIP
    (True, True, 0.9294...)
    """
    M = _check(scenario, multiple)
    exc = scenario.excitation
    f = float(exc.frequency)
    if not (isinstance(max_iterations, int) and max_iterations >= 0):
        raise ParameterError(f"max_iterations: expected a whole number >= 0, got {max_iterations!r}")
    if not (isinstance(tolerance, (int, float)) and tolerance > 0):
        raise ParameterError(f"tolerance: expected a positive number, got {tolerance!r}")
    if guess is not None:
        pmap = StroboscopicMap(scenario, M, guess.map.phase, guess.map.options.modes)
        if guess.state.shape != (pmap.size,):
            raise ParameterError("guess: its modal state does not fit this scenario's basis (other modes or contactors)")
        x, k0 = np.array(guess.state, dtype=float), round(f * (guess.section_time - exc.start) - guess.map.phase)
    else:
        res, end, n_modes = _settle(scenario, M, settle_periods)
        sol = res.solution
        # per-state modes (solver.basis = "paper", or a beam that can move as a rigid body)
        per_state = sol.packed.space.per_state
        prefer_free = per_state or bool(np.any(sol.packed.dash > 0.0))
        phase, free = _section_phase(sol, end - M / f, end, float(exc.start), f, prefer_free)
        pmap = StroboscopicMap(scenario, M, phase, n_modes)
        k0 = math.ceil(f * (end - exc.start) - M - phase - 1e-9)
        t_s = exc.start + (k0 + phase) / f
        smp = sol.sample(np.array([scenario.beam.length]), np.array([t_s]), modal=True)
        j = int(sol.segment_index(np.array([t_s]))[0])
        x = to_free(sol.packed, int(sol.slot[j])) @ np.concatenate([smp.eta[0], smp.eta_t[0]])
        notes: list[str] = []
        released = [i for i in range(len(scenario.contactors)) if i not in sol.engaged(j)]
        if not free and (per_state or _compressed(sol, released, t_s)):  # (the shared basis: exact in contact)
            notes.append(f"periodic orbit: the settling run has no free flight in its last {M} forcing period(s), "
                         "so the section lies inside a contact, where the map's start (modal coordinates of the "
                         "free state) loses what the paper's per-state modes or a dashpot's released phase carry: "
                         "the orbit and its multipliers are those of that map, which may differ slightly from the "
                         "simulation's (1e-6 of the amplitude in the cases seen)")
        settled = _settled_period(sol, scenario, end)
        if settled and M % settled:
            notes.append(f"periodic orbit: the settling run repeats after {settled} forcing period(s), not after "
                         f"multiple = {M}: an orbit found from its state is another one than the simulation settles "
                         f"on (they coexist); multiple = {settled} looks for the settled one")
        return _newton(scenario, pmap, x, k0, tolerance, max_iterations, tuple(notes))
    return _newton(scenario, pmap, x, k0, tolerance, max_iterations)


#: Forcing periods at the end of the settling run whose strobe :func:`_settled_period` reads.
_SETTLED_RECORD = 24


def _settled_period(sol: Solution, scenario: Scenario, end: float) -> int:
    """Period, in forcing periods, of the settling run's strobe over its last periods; 0 when none is found.

    The strobe samples and the period test of :mod:`~impactbeam.periodic.strobe`, on the last
    :data:`_SETTLED_RECORD` periods (fewer when the run is shorter; none below four).
    """
    from .strobe import PERIOD_TOLERANCE, detect_period, strobe_samples

    exc = scenario.excitation
    f = float(exc.frequency)
    done = int(math.floor(f * (end - exc.start) + 1e-9))
    n = min(done, _SETTLED_RECORD)
    if n < 4:
        return 0
    times = exc.start + np.arange(done - n, done + 1) / f
    return detect_period(strobe_samples(sol, scenario, times)[1], PERIOD_TOLERANCE, n // 2)[0]


def _residual(pmap: StroboscopicMap, x: np.ndarray, fj: FlowJacobian) -> float:
    return pmap.norm(fj.final - x) / max(pmap.norm(x), np.finfo(float).tiny)


def _evaluate(pmap: StroboscopicMap, x: np.ndarray) -> tuple[FlowJacobian | None, float]:
    """The map with its Jacobian at ``x`` and the relative residual; ``(None, inf)`` when the run failed."""
    from ..exceptions import SimulationError

    try:
        fj = pmap.jacobian(x)
    except SimulationError:  # chattering contact from this state: a bad trial step
        return None, math.inf
    return fj, _residual(pmap, x, fj)


#: Why the multipliers of a state can be missing: the saltation of a contact with no normal velocity is infinite.
_NOT_FINITE = ("the map's Jacobian is not finite at this state (a saltation divided by a switch's normal velocity, "
               "which is zero at a grazing contact)")


def _newton(scenario: Scenario, pmap: StroboscopicMap, x: np.ndarray, k0: int, tol: float, max_it: int,
            notes: tuple[str, ...] = ()) -> PeriodicOrbit:
    """Newton's iteration on ``P(x) = x``; the orbit.

    A step that does not lower the residual is halved up to ``_MAX_BACKTRACK``
    times; when none of those lowers it the best trial is taken (Newton's
    residual need not fall monotonically far from the orbit), and after
    ``_MAX_UPHILL`` such steps in a row the search stops.
    """
    fj = pmap.jacobian(x)
    res = _residual(pmap, x, fj)
    residuals = [res]
    it = 0
    eye = np.eye(pmap.size)
    stalled = ""
    uphill = 0
    while res > tol and it < max_it:
        if not np.all(np.isfinite(fj.matrix)):
            stalled = _NOT_FINITE
            break
        try:
            dx = np.linalg.solve(fj.matrix - eye, x - fj.final)
        except np.linalg.LinAlgError:
            stalled = "a multiplier is exactly 1 (the fixed point is not isolated)"
            break
        best: tuple[float, float, FlowJacobian | None] = (math.inf, 0.0, None)
        lam = 1.0
        for _ in range(_MAX_BACKTRACK + 1):
            fj_new, res_new = _evaluate(pmap, x + lam * dx)
            if res_new < best[0]:
                best = (res_new, lam, fj_new)
            if res_new < res:
                break
            lam *= 0.5
        res_new, lam, fj_new = best
        uphill = uphill + 1 if res_new >= res else 0
        if fj_new is None or uphill > _MAX_UPHILL:
            stalled = f"{uphill} step(s) in a row along Newton's direction did not lower the residual"
            break
        x, fj, res = x + lam * dx, fj_new, res_new
        residuals.append(res)
        it += 1
    return _report(scenario, pmap, x, fj, k0, it, tuple(residuals), tol, stalled, notes)


def _least_period(pmap: StroboscopicMap, sol: Solution, x: np.ndarray) -> int:
    """Smallest ``d`` dividing ``M`` with ``x(d/f) = x`` to 1e-8 (energy norm): the orbit's least period."""
    M = pmap.multiple
    scale = pmap.norm(x)
    for d in range(1, M):
        if M % d:
            continue
        tau = np.array([d / pmap.frequency])
        smp = sol.sample(np.array([0.0]), tau, modal=True)
        j = int(sol.segment_index(tau)[0])
        xd = to_free(sol.packed, int(sol.slot[j])) @ np.concatenate([smp.eta[0], smp.eta_t[0]])
        if pmap.norm(xd - x) <= 1e-8 * scale:
            return d
    return M


def _report(scenario: Scenario, pmap: StroboscopicMap, x: np.ndarray, fj: FlowJacobian, k0: int, it: int,
            residuals: tuple[float, ...], tol: float, stalled: str = "", before: tuple[str, ...] = ()) -> PeriodicOrbit:
    exc = scenario.excitation
    f, M = pmap.frequency, pmap.multiple
    converged = residuals[-1] <= tol
    notes: list[str] = list(before)
    if not converged:
        notes.append(
            f"periodic orbit: Newton did not converge in {it} iteration(s) (relative residual {residuals[-1]:.3g} "
            f"> tolerance {tol:.3g}) for multiple = {M}{': ' + stalled if stalled else ''}; the response may "
            "not be periodic with this period, "
            "or the start was too far: try settle_periods, another multiple, or a guess from a nearby orbit"
        )
    for t, ratio in fj.grazing[:1]:
        notes.append(
            f"periodic orbit: a contact {t:.6g} s after the section is grazing (normal velocity {ratio:.2g} of "
            "the orbit's scale): the map is not smooth there, so the multipliers hold only for very small "
            "perturbations and Newton may converge slowly"
        )
    finite = bool(np.all(np.isfinite(fj.matrix)))
    if not finite:
        notes.append(f"periodic orbit: {_NOT_FINITE}: no multipliers are given and the orbit is not called stable")
    for text in notes:
        emit_user_level_warning(text)
    mult = np.linalg.eigvals(fj.matrix) if finite else np.empty(0, dtype=complex)
    mult = mult[np.argsort(-np.abs(mult), kind="stable")]
    sol = pmap.solve(x)
    t_s = exc.start + (k0 + pmap.phase) / f
    tau = (np.arange(1, M + 1) - pmap.phase) / f
    if scenario.contactors:
        where = scenario.contactors[0].position
    else:
        where = scenario.output_points[0]
    strobe = sol.sample(np.array([where]), tau).w[:, 0]
    impacts = sum(1 for ev in sol.events if ev.kind == "impact" and ev.time > 0.0)
    least = _least_period(pmap, sol, x) if converged else M
    rho = float(np.abs(mult).max()) if mult.size else 0.0
    stable = bool(converged and finite and rho < 1.0)
    msg = (f"converged in {it} Newton step(s), relative residual {residuals[-1]:.2g}; largest multiplier "
           f"modulus {rho:.6g} ({'stable' if stable else 'unstable' if converged else 'not converged'})")
    if converged and not finite:
        msg = (f"converged in {it} Newton step(s), relative residual {residuals[-1]:.2g}; multipliers not defined "
               "(the map's Jacobian is not finite)")
    if not converged:
        msg = f"not converged after {it} Newton step(s): relative residual {residuals[-1]:.2g}"
    elif least < M:
        msg += f"; the orbit repeats already after {least} forcing period(s)"
    return PeriodicOrbit(
        converged=converged, multiple=M, period=pmap.period, strobe_times=t_s + tau, strobe=strobe,
        multipliers=mult, stable=stable, impacts_per_period=impacts, least_period=least, iterations=it,
        residuals=residuals,
        section_time=t_s, state=x, jacobian=fj.matrix, map=pmap, warnings=tuple(notes), message=msg,
    )
