"""The simulation API: a scenario (or model objects) in, a :class:`~impactbeam.result.SimulationResult` out.

:func:`simulate` checks what the model cannot represent, runs the exact
solver of :mod:`impactbeam.solver` (or the independent ``solve_ivp``
reference), and wraps the exact solution in a result; ``solver.modes =
"auto"`` repeats that with more modes until the metrics settle. This module
sits above the layers it joins (scenario, model, solver, result) and none of
them imports it.
"""

from __future__ import annotations

import dataclasses
import functools
import os
import weakref
from collections import OrderedDict
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Literal

import numpy as np

from ._warnings import emit_user_level_warning as warn
from .exceptions import ParameterError
from .model import MAX_MODES, Damping, SolverOptions
from .model.beam import Beam, Contactor
from .model.loading import Excitation
from .model.starting import InitialCondition, Preload
from .result import SimulationResult
from .scenario.checks import check_response, check_run
from .solver import ModalState, PiecewiseSolution, basis_signature, integrate
from .solver.convergence import AUTO_COUNTS, ConvergenceStudy, can_decide, coarser_counts, estimate, length_scale

if TYPE_CHECKING:
    from .scenario import Scenario

__all__ = ["convergence_study", "simulate", "simulate_system"]

Method = Literal["exact", "ivp"]


def simulate_system(
    beam: Beam,
    contactors: Sequence[Contactor] = (),
    *,
    damping: Damping | None = None,
    excitation: Excitation | None = None,
    initial: InitialCondition | None = None,
    options: SolverOptions | None = None,
    points: Sequence[float] | None = None,
    method: Method = "exact",
    progress: Callable[[float], None] | None = None,
    name: str = "system",
    start: ModalState | None = None,
    preload: Preload | None = None,
) -> SimulationResult:
    """Simulate a beam given as objects rather than as a scenario; see :func:`simulate`.

    Parameters
    ----------
    beam : Beam
    contactors : sequence of Contactor
    damping : Damping, optional
        Default: undamped.
    excitation : Excitation, optional
        Default: none.
    initial : InitialCondition, optional
        Default: at rest.
    options : SolverOptions, optional
        Default settings when None.
    points : sequence of float, optional, [m]
        Output points; default: the contactors, then the right end.
    method : {"exact", "ivp"}
        As for :func:`simulate`.
    progress : callable, optional
        As for :func:`simulate`.
    name : str
        Name of the run (in result files).
    start : ModalState, optional
        As for :func:`simulate`.
    preload : Preload, optional
        The constant load of ``[preload]`` (gravity, a base acceleration or a
        point force), acting throughout.
    """
    damping = damping or Damping()
    excitation = excitation or Excitation()
    initial = initial or InitialCondition()
    options = options or SolverOptions()
    contactors = tuple(contactors)
    pts_arr = _checked_points(beam, contactors, excitation, initial, options, points, method)
    _check_start(start, beam, contactors, options, method, excitation)

    def run(n_modes: int, *, announce: bool = True,
            report: Callable[[float], None] | None = progress) -> SimulationResult:
        opt = options if options.modes == n_modes else dataclasses.replace(options, modes=n_modes)
        if method == "ivp":
            from .solver.reference import integrate_ivp

            solution: PiecewiseSolution = integrate_ivp(beam, contactors, damping, excitation, initial, opt, preload)
        else:
            solution = integrate(beam, contactors, damping, excitation, initial, opt, report,
                                 None if start is None else (start.eta, start.deta), preload)
        if announce:
            for text in solution.warnings:
                warn(text)
        info = {"modes": n_modes, "time_step": opt.time_step, "end_time": opt.end_time, "method": method,
                "basis": opt.basis}
        return SimulationResult(solution, pts_arr, beam, contactors, n_modes, opt.time_step, opt.end_time, name,
                                info, rerun=functools.partial(run, announce=False, report=None),
                                tolerance=opt.tolerance)

    if options.modes != "auto":
        return run(int(options.modes))
    return _auto_modes(run)


_CHECKED: OrderedDict[tuple, tuple[weakref.ref, np.ndarray]] = OrderedDict()  # systems that passed _check_system
_CHECKED_SIZE = 64


def _checked_points(beam: Beam, contactors: tuple[Contactor, ...], excitation: Excitation,
                    initial: InitialCondition, options: SolverOptions, points: Sequence[float] | None,
                    method: str) -> np.ndarray:
    """:func:`_check_system`, remembered for systems that passed it.

    The checks read only immutable inputs and either raise or return the
    points, so a study repeating a system (the counts of a convergence
    estimate, a benchmark) checks it once; a refusal is never remembered.
    The excitation is held by a weak reference (a synthesised random load
    can be large), so the memory stays that of the small inputs.
    """
    pts = None if points is None else tuple(np.asarray(points, dtype=float).ravel().tolist())
    key = (beam, contactors, id(excitation), initial, options.end_time, options.modes, pts, method)
    try:
        hit = _CHECKED.get(key)
    except TypeError:  # an unhashable field: check every time
        return _check_system(beam, contactors, excitation, initial, options, points, method)
    if hit is None or hit[0]() is not excitation:
        hit = (weakref.ref(excitation), _check_system(beam, contactors, excitation, initial, options, points, method))
        _CHECKED[key] = hit
        if len(_CHECKED) > _CHECKED_SIZE:
            _CHECKED.popitem(last=False)
    return hit[1].copy()


def _check_system(beam: Beam, contactors: tuple[Contactor, ...], excitation: Excitation, initial: InitialCondition,
                  options: SolverOptions, points: Sequence[float] | None, method: str) -> np.ndarray:
    """ParameterError for what the solver cannot represent or would not finish; the output points as an array."""
    for i, c in enumerate(contactors):
        c.check_on(beam, f"contactors.{i}")
        if np.isinf(c.stiffness):
            k_ref = 3.0 * beam.bending_stiffness / beam.length**3
            raise ParameterError(
                f'contactors.{i}.stiffness: "inf" (a rigid stop) has contact-state modes (impactbeam modes) '
                "but cannot be simulated: an impact on a rigid stop needs a restitution law the modal model "
                f"does not have; give a finite stiffness (the stop's measured contact stiffness; for scale, "
                f"3 E I / L^3 of this beam is {k_ref:.4g} N/m)"
            )
    if points is None:
        pts = [c.position for c in contactors] + [beam.length]
        points = list(dict.fromkeys(pts))
    pts_arr = np.asarray(points, dtype=float)
    if pts_arr.size == 0:
        raise ParameterError("output.points: at least one output point is needed")
    if np.any(pts_arr < 0) or np.any(pts_arr > beam.length * (1 + 1e-12)):
        raise ParameterError(f"output.points: every point must lie on the beam [0, {beam.length:g}] m")
    if excitation.kind == "point_force" and excitation.position is not None:
        if excitation.position > beam.length * (1 + 1e-12):
            raise ParameterError(f"excitation.position: {excitation.position:g} m is off the beam (length "
                                 f"{beam.length:g} m)")
        if excitation.active:
            beam.require_free(excitation.position, "excitation.position", "the force does no work on the beam")
    _check_distinct(contactors)
    # what a scenario file is refused for, refused for objects too (a load whose response overflows, a run
    # whose exact extrema would take out of proportion)
    check_response(beam, excitation, initial, options.end_time)
    check_run(beam, options.modes, options.end_time)
    if method not in ("exact", "ivp"):
        raise ParameterError(f"method: must be 'exact' or 'ivp', got {method!r}")
    return pts_arr


def _check_start(start: ModalState | None, beam: Beam, contactors: tuple[Contactor, ...],
                 options: SolverOptions, method: str, excitation: Excitation) -> None:
    """ParameterError unless ``start`` is a state of this model's free-state basis."""
    if start is None:
        return
    if not isinstance(start, ModalState):
        raise ParameterError(f"start: expected a ModalState (result.final_state()), got {type(start).__name__}")
    if method != "exact" or options.modes == "auto":
        raise ParameterError('start: a run from a modal state needs method = "exact" and a fixed solver.modes')
    if start.basis != basis_signature(beam, contactors, int(options.modes), options.basis, excitation):
        raise ParameterError(
            "start: the state belongs to another modal basis (beam, contactor positions, solver.modes or "
            "solver.basis differ); start from rest or from a state of this model"
        )


def _auto_modes(run: Callable[..., SimulationResult]) -> SimulationResult:
    """``solver.modes = "auto"``: add modes until every Table-2 metric's estimated error is below the tolerance.

    The counts of :data:`~impactbeam.solver.convergence.AUTO_COUNTS` in turn;
    each is estimated against the two counts before it, as a run with that
    fixed count is (:mod:`impactbeam.solver.convergence`). The result is that
    of the first count below ``solver.tolerance`` whose modes reach every
    contactor (``result.converged``; or of the last count, with its
    estimate and the unconverged warning). A count that cannot be run (a
    :class:`~impactbeam.exceptions.SimulationError`, e.g. a damping whose
    block coordinates are ill-conditioned at that size) ends the ladder: the
    previous count's result is returned with a warning saying why.
    """
    from .exceptions import SimulationError

    done: dict[int, dict] = {}
    res = None
    for n in AUTO_COUNTS:
        try:
            nxt = run(n, announce=False)
        except SimulationError as exc:
            if res is None:
                raise
            # a larger basis that cannot be run (an ill-conditioned damping): the last run stands, said so
            warn(f'solver.modes = "auto": {n} modes could not be run ({exc}); the result is the {res.n_modes}-mode '
                 "run, with its error estimate")
            break
        res = nxt
        done[n] = res.metrics()
        counts = coarser_counts(n)
        if can_decide(n):
            metrics, peaks = estimate(done[n], [done[c] for c in counts], length_scale(res.contactors))
            res.set_convergence(metrics, peaks, counts)
            if res.converged:  # below the tolerance, every contactor in the estimate's sight
                break
    assert res is not None  # the first count ran, or its error was raised
    for text in res.warnings:
        warn(text)
    return res


def convergence_study(
    scenario: Scenario,
    counts: Sequence[int] | None = None,
    *,
    max_modes: int = 64,
    progress: Callable[[float], None] | None = None,
) -> ConvergenceStudy:
    """The Table-2 metrics against the number of modes, each with its error estimate.

    Every count is run, and the counts its estimate compares with
    (:func:`~impactbeam.solver.convergence.coarser_counts`), so each row
    carries the estimate a run with that fixed count reports
    (``result.convergence``).

    Parameters
    ----------
    scenario : Scenario
    counts : sequence of int, optional
        Modes per state to show; default those of ``solver.modes = "auto"``,
        4, 6, 8, 12, 16, ... up to ``max_modes``.
    max_modes : int
        Largest count of the default ladder.
    progress : callable, optional
        Called with the fraction of the runs done (0..1).

    Returns
    -------
    ConvergenceStudy
    """
    _require_scenario(scenario)
    if counts is None:
        shown = [n for n in AUTO_COUNTS if n <= max_modes]
    else:
        shown = sorted({int(n) for n in counts})
    if not shown or shown[0] < 1 or shown[-1] > MAX_MODES:
        raise ParameterError(f"counts: expected mode counts from 1 to {MAX_MODES}, got {list(counts or shown)}")
    needed = sorted({c for n in shown for c in (n, *coarser_counts(n))})
    cost = [float(n) for n in needed]
    done: dict[int, SimulationResult] = {}
    for i, n in enumerate(needed):
        done[n] = simulate(scenario.with_values({"solver.modes": n}))
        if progress is not None:
            progress(sum(cost[: i + 1]) / sum(cost))
    table = {n: r.metrics() for n, r in done.items()}
    estimates: dict[int, dict[str, float] | None] = {}
    peak_estimates: dict[int, list[float] | None] = {}
    for n in shown:
        coarse = coarser_counts(n)
        if coarse:
            est, peaks = estimate(table[n], [table[c] for c in coarse], length_scale(scenario.contactors))
            estimates[n], peak_estimates[n] = est, [float(p) for p in peaks]
        else:
            estimates[n] = peak_estimates[n] = None
    return ConvergenceStudy(
        name=scenario.name, counts=tuple(shown), functions={n: int(done[n].solution.n_modes) for n in shown},
        metrics={n: table[n] for n in shown}, estimates=estimates,
        peak_forces={n: [float(r["peak_force"]) for r in table[n].get("impacts", [])] for n in shown},
        peak_force_estimates=peak_estimates, tolerance=float(scenario.solver.tolerance),
        unseen={n: done[n].unseen_flexibility for n in shown},
    )


def _check_distinct(contactors: tuple[Contactor, ...]) -> None:
    """Refuse two contactors at one point on one side with one gap: they would switch endlessly."""
    seen: dict[tuple[float, str, float], int] = {}
    for i, c in enumerate(contactors):
        key = (c.position, c.side, c.gap)
        if key in seen:
            j = seen[key]
            raise ParameterError(
                f"contactors.{i}: same position, side and gap as contactors.{j}; use one contactor of stiffness "
                f"{contactors[j].stiffness:g} + {c.stiffness:g} N/m instead"
            )
        seen[key] = i


def _require_scenario(scenario: object) -> None:
    """TypeError for anything but a Scenario (a path, a dict), saying what to do."""
    from .scenario import Scenario

    if isinstance(scenario, Scenario):
        return
    if isinstance(scenario, (str, os.PathLike)):
        raise TypeError(
            f"simulate: got the path {str(scenario)!r}; read it first: "
            "impactbeam.simulate(impactbeam.load_scenario(path))"
        )
    raise TypeError(
        f"simulate: expected a Scenario (from impactbeam.load_scenario or parse_scenario), got "
        f"{type(scenario).__name__}; for a beam given as objects use impactbeam.simulate_system"
    )


def simulate(
    scenario: Scenario,
    *,
    method: Method = "exact",
    progress: Callable[[float], None] | None = None,
    start: ModalState | None = None,
) -> SimulationResult:
    """Transient response of the scenario's beam (paper section 2, eqs. 9-12).

    Parameters
    ----------
    scenario : Scenario
        From :func:`impactbeam.load_scenario`.
    method : {"exact", "ivp"}
        ``"exact"``: closed-form integration between exactly located events.
        ``"ivp"``: the same modal equations by :func:`scipy.integrate.solve_ivp`
        with events (a slower independent reference used by the tests).
    progress : callable, optional
        Called with the current simulated time as the run advances.
    start : ModalState, optional
        Begin at t = 0 from this state (``previous_result.final_state()``)
        instead of ``[initial]``: a run continued from the end of another of
        the same model (same beam, contactor positions, modes and basis).

    Returns
    -------
    SimulationResult

    Raises
    ------
    TypeError
        When ``scenario`` is not a Scenario (e.g. a file path).
    ParameterError
        For a rigid contactor (``stiffness = inf``): give a finite stiffness.

    Notes
    -----
    The solution is exact for the truncated N-mode model: between events
    every mode is integrated in closed form for the half-sine pulse, the step,
    and tables held constant or linear between samples, for any damping ratio
    (including 0, critical and over-damped) and for rigid-body modes.
    The remaining errors are modal truncation (``solver.modes``) and the event
    time tolerance (``solver.event_tolerance``, 1e-13 s by default). With
    ``solver.basis = "enriched"`` (default) all states share one Ritz basis
    (the free modes plus a static attachment shape per contactor,
    :mod:`~impactbeam.solver.ritz`) and a switch is exact; with ``"paper"``
    each state has its own exact modes and a switch is the projection of
    paper eq. (12), an L2 projection of the displacement and velocity onto N
    modes, lossy for contactors much stiffer than the retained modes.

    Events are located on the closed form, independently of the output
    step: the scan advances by steps that a bound on the second derivative of
    each contactor's opening (from the modal amplitudes and frequencies)
    proves free of any crossing, subdivides a step that it cannot prove, and
    refines a proven single crossing by Newton's method to
    ``solver.event_tolerance``. A dip into a stop deeper than 1e-12 of the
    beam length cannot be missed; a tangency at the start of a segment (zero
    gap at rest, a contactor just switched) is decided by the first
    derivative of the opening that is not zero up to round-off. The output
    samples (``result.time``) are evaluated from the exact solution only when
    asked for, and the metrics come from the exact solution (extrema by
    branch and bound on the closed form, impulses in closed form).

    Warnings the solver raises (:class:`~impactbeam.exceptions.ImpactBeamWarning`)
    are also listed in ``result.warnings``.
    """
    _require_scenario(scenario)
    res = simulate_system(
        scenario.beam,
        scenario.contactors,
        damping=scenario.damping,
        excitation=scenario.excitation,
        initial=scenario.initial,
        options=scenario.solver,
        points=scenario.output_points,
        method=method,
        progress=progress,
        name=scenario.name,
        start=start,
        preload=scenario.preload,
    )
    object.__setattr__(res, "scenario", scenario)
    return res
