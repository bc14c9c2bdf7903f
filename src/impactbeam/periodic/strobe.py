"""Stroboscopic (Poincaré) sampling of a harmonically forced run and its period.

Under the harmonic load ``u(t) = A sin(2 pi f (t - start) + phase)`` the
forcing period is ``T = 1/f``. A run of ``settle + record`` periods is
sampled exactly (closed form, no interpolation) at the strobe times
``t_k = start + k T``; the last ``record`` samples form the Poincaré section.

The response period ``n`` (in forcing periods) is the smallest ``n`` with
``|s_{k+jn} - s_k| <= tolerance * scale`` for every pair of recorded samples
``n`` apart or a multiple of ``n`` apart (the samples of each phase ``k mod
n`` lie within the tolerance of each other: a strobe drifting by less than
the tolerance per period, but more over the record, has not repeated), where
``s_k`` is the state sampled at the strobe time: deflection and velocity at
the contactors, the output points and along the beam, each group scaled by
its largest magnitude over the record. ``n`` is looked for up to
``record // 2`` (two repeats at least). None found means chaotic or
quasi-periodic motion, or a transient not yet decayed: the result says so
with a warning.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._warnings import emit_user_level_warning
from ..exceptions import ParameterError
from .forcing import harmonic_period, strobe_point
from .linear import linear_limit

if TYPE_CHECKING:
    from ..result import SimulationResult
    from ..scenario import Scenario
    from ..solver.solution import ModalState

__all__ = ["SteadyState", "steady_state", "analyse_steady_state", "detect_period", "strobe_point",
           "harmonic_period", "strobe_samples"]

#: Default relative tolerance of the period test (see the module docstring).
PERIOD_TOLERANCE = 1e-4


@dataclass(frozen=True, eq=False)
class SteadyState:
    """The recorded steady state of a harmonically forced run.

    Attributes
    ----------
    frequency : float, [Hz]
        Forcing frequency.
    period : int
        Response period in forcing periods (1, 2, 3, ...); 0 when none was
        found within the record (see ``warnings``).
    impacts_per_period : float
        Impacts (all contactors) in one response period; without a period,
        the mean number per forcing period over the record.
    strobe : ndarray, (record,), [m]
        ``w`` at ``point`` at ``t_k = start + k / f``, ``k = settle .. settle + record - 1``.
    strobe_velocity : ndarray, (record,), [m/s]
    times : ndarray, (record,), [s]
        The strobe times.
    max, min : float, [m]
        Extremes of ``w`` at ``point`` over the record (exact, closed form).
    mismatch : float
        The relative mismatch of the period test for ``period`` (the smallest
        over the candidates when none passed).
    point : float, [m]
        Where ``w`` is sampled: the first contactor, else the first output point.
    window : tuple of float, [s]
        The recorded interval (in the clock of the last run).
    settled_after : int
        Forcing periods run before the record (more than asked for when the
        period test failed and the run was extended, see :func:`steady_state`;
        0 when the beam provably never reaches a stop from its start: the
        record is then the exact linear steady state,
        :func:`~impactbeam.periodic.linear.linear_limit`).
    result : SimulationResult
        The run (dense output over settle and record).
    warnings : list of str
    """

    frequency: float
    period: int
    impacts_per_period: float
    strobe: np.ndarray
    strobe_velocity: np.ndarray
    times: np.ndarray
    max: float
    min: float
    mismatch: float
    point: float
    window: tuple[float, float]
    result: Any = field(repr=False)
    settled_after: int = 0
    warnings: list[str] = field(default_factory=list)

    @property
    def converged(self) -> bool:
        """True when a period was found."""
        return self.period > 0

    def to_dict(self) -> dict[str, Any]:
        """Plain numbers for JSON output."""
        return {
            "frequency": self.frequency, "period": self.period, "impacts_per_period": self.impacts_per_period,
            "strobe": [float(v) for v in self.strobe], "max": self.max, "min": self.min,
            "mismatch": self.mismatch, "warnings": list(self.warnings),
        }


def count(name: str, value: Any, minimum: int) -> int:
    """An integer >= ``minimum``; ParameterError naming ``name`` otherwise."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or int(value) < minimum:
        raise ParameterError(f"{name}: expected a whole number >= {minimum}, got {value!r}")
    return int(value)


def detect_period(samples: np.ndarray, tolerance: float = PERIOD_TOLERANCE,
                  max_period: int | None = None) -> tuple[int, float]:
    """Smallest period of a sequence of strobe states.

    Parameters
    ----------
    samples : ndarray, (n_samples, n_components)
        Already scaled (each component of order one over the record).
    tolerance : float
        Largest mismatch accepted: ``max |s_{k+jn} - s_k|`` over the record, the largest spread of the samples
        of one phase (module docstring).
    max_period : int, optional
        Largest period tried; default ``(n_samples - 1) // 2``.

    Returns
    -------
    (period, mismatch)
        ``period`` 0 when none passed; ``mismatch`` of the period found, else
        the smallest over the candidates.
    """
    s = np.asarray(samples, dtype=float)
    if s.ndim == 1:
        s = s[:, None]
    top = (s.shape[0] - 1) // 2 if max_period is None else min(int(max_period), s.shape[0] - 1)
    if top < 1:
        return 0, math.inf
    mism = _spread_one(s)  # period 1 alone first: a settled linear response has it
    if mism <= tolerance:
        return 1, mism
    later = _spreads(s, top) if top > 1 else np.empty(0)  # the longer periods in one pass, the same numbers
    hit = np.flatnonzero(later <= tolerance)
    if hit.size:
        return int(hit[0]) + 2, float(later[hit[0]])
    tried = np.concatenate([[mism], later])
    tried = tried[~np.isnan(tried)]  # a run that stopped early samples NaN after its end: those lags never count
    return 0, float(np.min(tried)) if tried.size else math.inf


def _spreads(s: np.ndarray, top: int) -> np.ndarray:
    """The mismatch of each period ``n = 2 .. top`` (``top < len(s)``): the largest spread of the samples of one
    phase ``r`` (``s[r::n]``), any component, from one gather of the samples phase by phase (NaN kept)."""
    order, classes, periods = _phase_classes(s.shape[0], top)
    cols = np.ascontiguousarray(s.T)[:, order]  # components along rows: NumPy reduces long contiguous rows fast
    spread = (np.maximum.reduceat(cols, classes, axis=1) - np.minimum.reduceat(cols, classes, axis=1)).max(axis=0)
    return np.maximum.reduceat(spread, periods)


@functools.lru_cache(maxsize=32)
def _phase_classes(n_samples: int, top: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The sample indices of each phase ``r`` of each period ``n = 2 .. top`` in turn, where each phase's and
    each period's indices start."""
    order, classes, periods = [], [], []
    at = 0
    for n in range(2, top + 1):
        periods.append(len(classes))
        for r in range(n):
            idx = np.arange(r, n_samples, n)
            classes.append(at)
            order.append(idx)
            at += idx.size
    out = (np.concatenate(order), np.array(classes), np.array(periods))
    for a in out:
        a.flags.writeable = False
    return out


def _spread_one(s: np.ndarray) -> float:
    """The mismatch of period 1: the largest spread (max - min) of the record, any component (NaN kept).

    Every pair of samples, not only neighbours: a strobe that drifts by less than the tolerance per period but
    more over the record has not repeated.
    """
    return float(np.max(s.max(axis=0) - s.min(axis=0)))


#: A period above 1 whose shorter-lag mismatches shrink by more than this fraction from the first to the
#: last whole repetitions of the record is a transient decaying onto a shorter period (:func:`still_settling`).
DECAY = 0.05


def still_settling(samples: np.ndarray, period: int, tolerance: float) -> bool:
    """Whether a shorter period than ``period`` (or 1 when none) is being approached.

    For each ``m`` below ``period`` (all ``m`` up to a quarter of the record
    when ``period`` is 0) the mismatch ``d_k = |s_{k+m} - s_k|`` is compared
    between the first and the second half of the record. A period ``n > 1``
    repeats ``d_k`` every ``n`` samples, so its means over whole repetitions
    in the two halves are equal; a transient decaying onto a shorter period,
    which the strobe aliases into a longer one (a multiplier ``mu`` near a
    root of unity, ``|mu|`` near 1: ``mu^n`` is near 1 before the transient
    has decayed), shrinks them. True when the second half's mean is below
    ``1 - DECAY`` of the first's, the first half's largest still above
    ``tolerance`` (its mean may be below: a transient decaying onto period 1
    at 75 Hz on the harmonic specimen passed for period 5, its lag-1 mean
    falling from 2.7e-5 to 1.7e-7 of the scale over the record; without a
    period: the second half's largest below half the first's).
    """
    s = np.asarray(samples, dtype=float)
    top = period - 1 if period else max(1, (s.shape[0] - 1) // 4)
    for m in range(1, top + 1):
        d = np.max(np.abs(s[m:] - s[:-m]), axis=1)
        if period:  # whole repetitions of the period in each half
            h = (d.size // 2) // period * period
            if h < period:
                break
            early, late = float(np.mean(d[:h])), float(np.mean(d[d.size - h:]))
            if float(np.max(d[:h])) > tolerance and late < (1.0 - DECAY) * early:
                return True
            continue
        h = d.size // 2
        if h < 2:
            break
        early, late = float(np.max(d[:h])), float(np.max(d[h:]))
        if early > tolerance and late < 0.5 * early:
            return True
    return False


def _probe_points(scenario: Scenario) -> np.ndarray:
    """Contactors, output points and five stations along the beam."""
    return _probes(scenario.beam.length, tuple(c.position for c in scenario.contactors),
                   tuple(scenario.output_points))


@functools.lru_cache(maxsize=64)
def _probes(length: float, contactors: tuple[float, ...], outputs: tuple[float, ...]) -> np.ndarray:
    """:func:`_probe_points` of these positions (read only: a bifurcation diagram asks for them at every run)."""
    pts = list(contactors) + list(outputs) + list(np.linspace(0.2, 1.0, 5) * length)
    out = np.unique(np.asarray(pts, dtype=float))
    out.flags.writeable = False
    return out


def strobe_samples(sol: Any, scenario: Scenario, times: np.ndarray) -> tuple[Any, np.ndarray]:
    """The solution at the probe points at ``times`` (:meth:`~impactbeam.solver.solution.Solution.sample`)
    and those samples as :func:`detect_period` takes them (displacements and velocities, each scaled)."""
    smp = sol.sample(_probe_points(scenario), times)
    return smp, _scaled(smp.w, smp.w_t)


def _scaled(w: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Displacements and velocities each divided by the largest magnitude of their group."""
    sw = float(np.max(np.abs(w))) or 1.0
    sv = float(np.max(np.abs(v))) or 1.0
    return np.hstack([w / sw, v / sv])


def analyse_steady_state(
    result: SimulationResult,
    scenario: Scenario,
    *,
    settle_periods: int,
    record_periods: int,
    tolerance: float = PERIOD_TOLERANCE,
    max_period: int | None = None,
    start: float | None = None,
    settled_after: int | None = None,
) -> SteadyState:
    """Strobe samples, period and extremes of the record of a finished run.

    Parameters
    ----------
    result : SimulationResult
        A run of ``settle_periods + record_periods`` forcing periods from ``start``.
    scenario : Scenario
        Its scenario (harmonic load).
    settle_periods, record_periods : int
        Periods discarded, then recorded.
    tolerance : float
        Relative tolerance of the period test.
    max_period : int, optional
        Longest period looked for (default ``record_periods // 2``).
    start : float, optional, [s]
        When the harmonic load begins in this run (default ``excitation.start``).
    settled_after : int, optional
        Periods run before the record in all (default ``settle_periods``).

    Returns
    -------
    SteadyState
    """
    return _record_analysis(result, scenario, settle_periods, record_periods, tolerance, max_period, start,
                            settled_after).steady_state()


@dataclasses.dataclass(frozen=True)
class _RecordAnalysis:
    """The record of a run analysed but for its extremes (:func:`analyse_steady_state` adds them).

    A run whose period is not found is extended (:func:`settle_and_record`):
    its extremes are never used, and searching them (every segment of the
    record) cost as much as a fifth of a bifurcation diagram.
    """

    result: SimulationResult
    frequency: float
    period: int
    impacts_per_period: float
    strobe_point: float
    at_point: tuple[np.ndarray, np.ndarray]  # w and w_t at strobe_point at the strobe times
    times: np.ndarray
    window: tuple[float, float]
    mismatch: float
    settled_after: int
    warnings: list[str]

    def steady_state(self) -> SteadyState:
        """The steady state, its extremes over the record searched now."""
        sol = self.result.solution
        x0, (lo, hi) = self.strobe_point, self.window
        w, w_t = self.at_point
        ext = sol.extrema([(x0, lo, hi, 1.0, 0.0, None), (x0, lo, hi, -1.0, 0.0, None)])
        return SteadyState(
            frequency=self.frequency, period=self.period, impacts_per_period=self.impacts_per_period,
            strobe=w[:-1].copy(), strobe_velocity=w_t[:-1].copy(), times=self.times[:-1].copy(),
            max=float(ext[0, 0]), min=float(-ext[1, 0]), mismatch=self.mismatch, point=x0, window=self.window,
            result=self.result, settled_after=self.settled_after, warnings=self.warnings,
        )


def _record_analysis(result: SimulationResult, scenario: Scenario, settle_periods: int, record_periods: int,
                     tolerance: float, max_period: int | None, start: float | None,
                     settled_after: int | None) -> _RecordAnalysis:
    """Strobe samples and period of the record (the part of :func:`analyse_steady_state` that decides)."""
    T = harmonic_period(scenario)
    t_load = scenario.excitation.start if start is None else float(start)
    sol = result.solution
    k = np.arange(settle_periods, settle_periods + record_periods + 1)
    times = np.minimum(t_load + k * T, sol.t_end)
    probes = _probe_points(scenario)
    smp, scaled = strobe_samples(sol, scenario, times)
    x0 = strobe_point(scenario)
    j0 = int(np.searchsorted(probes, x0))  # one of the probes: its samples are the strobe's
    lo, hi = float(times[0]), float(times[-1])
    warns: list[str] = []
    if result.status != 0:
        warns.append(f"the run stopped early ({result.message}); the steady state is incomplete")
    n, mism = detect_period(scaled, tolerance, max_period)
    before = settle_periods if settled_after is None else settled_after
    settling = still_settling(scaled, n, tolerance)
    ev_t, ev_impact = _event_arrays(result)
    free = not smp.engaged.any() and not np.any((ev_t >= lo) & (ev_t <= hi))
    if free and n > 1:  # no contact over the record: a linear system, whose steady state has period 1
        settling = True
    if settling:
        n = 0
    n_imp = int(np.count_nonzero(ev_impact & (ev_t >= lo) & (ev_t < hi)))
    if n:
        reps = record_periods // n
        in_reps = int(np.count_nonzero(ev_impact & (ev_t >= lo) & (ev_t < lo + reps * n * T)))
        ipp = in_reps / reps
    else:
        ipp = n_imp / record_periods
        top = max_period if max_period is not None else record_periods // 2
        why = ("the strobe samples are still converging (a decaying transient)" if settling else
               "chaotic or quasi-periodic motion, a period longer than the record can show (raise record_periods), "
               "or not settled")
        warns.append(
            f"no period up to {top} forcing periods within tolerance {tolerance:g} at f = {1 / T:.6g} Hz "
            f"(smallest mismatch {mism:.3g}): {why} after {before} periods; "
            "impacts_per_period is the mean per forcing period"
        )
    return _RecordAnalysis(result, 1.0 / T, n, float(ipp), x0, (smp.w[:, j0], smp.w_t[:, j0]), times, (lo, hi),
                           float(mism), before, warns)


def _event_arrays(result: SimulationResult) -> tuple[np.ndarray, np.ndarray]:
    """Event times and whether each is an impact (from the solution's arrays when it keeps them)."""
    arrays = getattr(result.solution, "event_arrays", None)
    if arrays is not None:
        return arrays[0], arrays[1] == 1
    t = np.array([e.time for e in result.events], dtype=float)
    return t, np.array([e.kind == "impact" for e in result.events], dtype=bool)


def run_periods(scenario: Scenario, periods: int, *, start_state: ModalState | None = None,
                progress: Callable[[float], None] | None = None) -> tuple[SimulationResult, float]:
    """Simulate ``periods`` forcing periods from the load's start; the run and the load's start time.

    From ``start_state`` the run begins at t = 0 with the load switched on
    at once (``start`` = 0, same ``phase``): the state came from the end of a
    run that ended a whole number of periods after its load began, so the
    phase of the load carries on.
    """
    from ..simulation import simulate

    T = harmonic_period(scenario)
    ex = scenario.excitation
    if start_state is not None and ex.start != 0.0:
        ex = dataclasses.replace(ex, start=0.0)
    end = ex.start + periods * T
    sc = dataclasses.replace(scenario, excitation=ex, solver=dataclasses.replace(scenario.solver, end_time=end))
    return simulate(sc, start=start_state, progress=progress), ex.start


def steady_state(
    scenario: Scenario,
    *,
    settle_periods: int = 100,
    record_periods: int = 50,
    start_state: ModalState | None = None,
    tolerance: float = PERIOD_TOLERANCE,
    max_period: int | None = None,
    max_settle_periods: int | None = None,
) -> SteadyState:
    """Run a harmonically forced scenario to its steady state and analyse it.

    Parameters
    ----------
    scenario : Scenario
        With ``[excitation] shape = "harmonic"``; ``solver.end_time`` is
        replaced by ``start + (settle_periods + record_periods) / f``. With
        ``solver.modes = "auto"`` the first run chooses the count, and a run
        extended from its final state keeps it (``result.n_modes``).
    settle_periods, record_periods : int
        Forcing periods discarded as transient, then recorded. No period is
        discarded when the beam provably never reaches a stop from the start:
        the record is then the linear steady state itself (``settled_after =
        0``; :func:`~impactbeam.periodic.linear.linear_limit`).
    start_state : ModalState, optional
        Begin from this state (e.g. ``previous.result.final_state()``) with the
        load on from t = 0, instead of the scenario's initial condition.
    tolerance : float
        Relative tolerance of the period test (module docstring).
    max_period : int, optional
        Longest period looked for (default ``record_periods // 2``).
    max_settle_periods : int, optional
        When no period is found, the run goes on from its final state for
        ``settle_periods + record_periods`` more periods, and again, until a
        period is found or this many periods have settled (default
        ``10 * settle_periods``; a lightly damped beam forced off resonance
        keeps its free transient for hundreds of periods).

    Returns
    -------
    SteadyState
        With ``period = 0`` and a warning when no period was found.

    Examples
    --------
    >>> ss = steady_state(sc, settle_periods=100, record_periods=50)  # doctest: +SKIP
    >>> ss.period, ss.impacts_per_period, ss.strobe[:2]               # doctest: +SKIP
    """
    settle = count("settle_periods", settle_periods, 0)
    record = count("record_periods", record_periods, 2)
    limit = 10 * settle if max_settle_periods is None else count("max_settle_periods", max_settle_periods, 0)
    if start_state is not None and scenario.solver.modes == "auto":
        raise ParameterError('start_state: a start from a modal state needs a fixed solver.modes (the basis the '
                             'state belongs to), got "auto"')
    ss = settle_and_record(scenario, settle, record, start_state, tolerance, max_period, limit)
    for text in ss.warnings:
        emit_user_level_warning(text)
    return ss


def with_modes_of(scenario: Scenario, result: SimulationResult) -> Scenario:
    """``scenario`` with ``solver.modes = "auto"`` replaced by the count ``result`` chose (else unchanged).

    A run that goes on from another's modal state needs that state's basis,
    so the count "auto" chose for the first run is kept for the rest.
    """
    if scenario.solver.modes != "auto":
        return scenario
    return dataclasses.replace(scenario, solver=dataclasses.replace(scenario.solver, modes=int(result.n_modes)))


def settle_and_record(scenario: Scenario, settle: int, record: int, start_state: ModalState | None,
                      tolerance: float, max_period: int | None, limit: int) -> SteadyState:
    """Run, analyse, and extend the run while no period is found (see :func:`steady_state`).

    :func:`settle_and_analyse`, with the extremes of the record searched.
    """
    return settle_and_analyse(scenario, settle, record, start_state, tolerance, max_period, limit).steady_state()


def settle_and_analyse(scenario: Scenario, settle: int, record: int, start_state: ModalState | None,
                       tolerance: float, max_period: int | None, limit: int) -> _RecordAnalysis:
    """The record of :func:`settle_and_record` analysed, its extremes not yet searched (``.steady_state()`` does).

    When the beam provably never touches a stop from its start, the record is
    run from the linear steady state it tends to (:func:`~impactbeam.periodic.
    linear.linear_limit`): exact, with ``settled_after = 0``. With
    ``solver.modes = "auto"`` the first run chooses the count; an extension
    carries the modal state, so it runs with that count (:func:`with_modes_of`).
    A bifurcation diagram searches the extremes of one value while the next
    one runs.
    """
    steady = linear_limit(scenario, start_state)
    if steady is not None:
        res, t_load = run_periods(scenario, record, start_state=steady)
        return _record_analysis(res, scenario, 0, record, tolerance, max_period, t_load, 0)
    res, t_load = run_periods(scenario, settle + record, start_state=start_state)
    scenario = with_modes_of(scenario, res)
    done = settle
    while True:
        rec = _record_analysis(res, scenario, settle, record, tolerance, max_period, t_load, done)
        if rec.period or res.status != 0 or done + settle + record > limit:
            return rec
        res, t_load = run_periods(scenario, settle + record, start_state=res.final_state())
        done += settle + record
