"""Least-squares fits of scenario parameters to a measured deflection history (the fit itself).

The paper (section 4.2) closes its comparison by hand: "with k being 7000 N/m
and increasing the pulse by 20 %, the amplitude difference is about 6 %".
:func:`fit` does this systematically: chosen scenario parameters, named by
their dotted paths (``contactors.0.stiffness``, ``excitation.scale``,
``damping.free``, ``beam.youngs_modulus``), are adjusted by lmfit so that the
simulated deflection at the measured times matches the record in the least
squares sense, within bounds, with standard errors and confidence intervals.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from .._optional import require
from ..exceptions import ParameterError, ScenarioError, SimulationError
from ..experiment import Record, record_point
from ..experiment.compare import prepare_run
from .parameters import bounds_for, current_value, parse_bounds
from .result import FitResult

if TYPE_CHECKING:
    from ..model.loading import Excitation
    from ..scenario import Scenario

__all__ = ["fit"]


def _name(path: str) -> str:
    return "p_" + re.sub(r"\W", "_", path)


def fit(
    scenario: Scenario,
    measured: Record,
    params: Sequence[str] | str,
    *,
    bounds: Mapping[str, tuple[float | None, float | None]] | Sequence[str] | None = None,
    point: float | None = None,
    excitation: Record | Excitation | None = None,
    hold: Literal["constant", "linear"] = "linear",
    window: tuple[float | None, float | None] | None = None,
    max_nfev: int = 100,
    conf_interval: bool = False,
) -> FitResult:
    """Fit scenario parameters to a measured deflection history by least squares.

    Parameters
    ----------
    scenario : Scenario
        Starting point; it is not modified.
    measured : Record
        Deflection ``w`` [m] at ``point`` against time [s] (t = 0 is the
        start of the simulation; samples before 0 are not used).
    params : sequence of str, or a comma-separated str
        Dotted paths of the scenario to adjust (:func:`impactbeam.scenario.set_path`):
        ``contactors.0.stiffness``, ``excitation.scale`` (a pulse or trace
        scale), ``excitation.amplitude``, ``damping.free``, ``damping.contact``,
        ``beam.youngs_modulus``, ``contactors.0.gap``, ...
    bounds : mapping path -> (lower, upper), or ["PATH=LO:HI", ...], optional
        Either end may be None (open). Default for positive quantities
        (stiffness, modulus, lengths, duration): ``[x0/1000, 1000 x0]``;
        damping ratios ``[0, 1]``; gap ``[0, inf)``; others unbounded.
        A lower bound above the upper one, equal bounds, or a starting value
        outside the bounds is an error: bounds are never swapped or clipped.
    point : float, optional, [m]
        Where the record was taken; default the first contactor, else the
        first output point.
    excitation : Record or Excitation, optional
        A measured base-acceleration trace (held per ``hold``) or any
        excitation replacing the scenario's; ``excitation.scale`` then scales it.
    hold : {"constant", "linear"}
        How a measured trace is held between its samples.
    window : (start, stop), optional, [s]
        Fit only this part of the record.
    max_nfev : int
        Most simulations to run (each costs one :func:`impactbeam.simulate`
        to the last fitted time).
    conf_interval : bool
        Also compute lmfit's profile-likelihood confidence intervals (1 and 2
        sigma; costly: several fits per parameter).

    Returns
    -------
    FitResult

    Notes
    -----
    The residual is ``w_sim(x, t_i) - w_meas(t_i)``, with ``w_sim`` evaluated
    exactly at the measured times (:meth:`SimulationResult.displacement`).
    Each parameter is fitted as its ratio to the starting value (all of
    order 1, so the finite-difference Jacobian uses a relative step of 1e-6)
    by lmfit's ``least_squares`` (trust-region reflective, bounds enforced
    natively). The response is a smooth function of the parameters while the
    sequence of impacts does not change; start reasonably close (e.g. the
    contact stiffness from :func:`impactbeam.experiment.contact_stiffness_from_frequency`).

    Raises
    ------
    ParameterError / ScenarioError
        Unknown or non-numeric paths, bad bounds, a record that is not a deflection.
    SimulationError
        When a simulation fails during the fit.
    """
    lmfit = require("lmfit", "fit")

    from ..simulation import simulate

    paths, user_bounds = _checked_params(params, bounds, max_nfev, scenario)
    base, meas = prepare_run(scenario, measured, None, hold, window)
    override = _excitation_override(base, excitation, hold)
    # base.data drives with_values: keep the end time there too
    base = base.with_values({"solver.end_time": float(meas.time[-1])})
    x = record_point(base, point)

    probe = base if override is None else dataclasses.replace(base, excitation=override)
    initial = {p: current_value(probe, p) for p in paths}
    used_bounds = bounds_for(initial, user_bounds)
    scales = {p: abs(initial[p]) if initial[p] != 0 else 1.0 for p in paths}
    counter = {"n": 0}

    def simulate_at(values: Mapping[str, float]) -> np.ndarray:
        counter["n"] += 1
        res = simulate(_with_fitted(base, override, values))
        if not res.success:
            raise SimulationError(f"fit: simulation stopped early at {values}: {res.message}")
        return res.displacement([x], meas.time)[0]

    pars = lmfit.Parameters()
    for p in paths:
        lo, hi = used_bounds[p]
        s = scales[p]
        pars.add(_name(p), value=initial[p] / s, min=lo / s, max=hi / s)

    def residual(pv: Any) -> np.ndarray:
        values = {p: float(pv[_name(p)].value) * scales[p] for p in paths}
        return simulate_at(values) - meas.values

    r0 = simulate_at(initial) - meas.values
    minimizer = lmfit.Minimizer(residual, pars)
    out = minimizer.minimize(method="least_squares", max_nfev=int(max_nfev), diff_step=1e-6, x_scale=1.0)
    values = {p: float(out.params[_name(p)].value) * scales[p] for p in paths}
    stderr, ci95, corr = _uncertainties(out.params, paths, scales, values, meas.time.size)
    conf = None
    if conf_interval and all(stderr[p] is not None for p in paths):
        conf = _profile_intervals(lmfit, minimizer, out, paths, scales, values)
    final = residual(out.params) if out.residual is None else out.residual
    fitted = _with_fitted(base, override, values)
    data = fitted.data
    from ..scenario import set_path

    for p in paths:
        if not (override is not None and p.startswith("excitation.")):
            data = set_path(data, p, values[p])
    data = set_path(data, "solver.end_time", float(scenario.solver.end_time))
    rms = float(np.sqrt(np.mean(np.asarray(final) ** 2)))
    rms_m = float(np.sqrt(np.mean(meas.values**2)))
    return FitResult(
        paths=paths,
        initial=initial,
        values=values,
        stderr=stderr,
        ci95=ci95,
        conf_intervals=conf,
        correlation=corr,
        bounds=used_bounds,
        rms_residual=rms,
        initial_rms_residual=float(np.sqrt(np.mean(r0**2))),
        nrmse=rms / rms_m if rms_m > 0 else math.nan,
        nfev=counter["n"],
        success=bool(out.success),
        message=str(out.message),
        scenario=fitted,
        measured=meas,
        point=x,
        residual=np.asarray(final),
        _data=data,
        _override=override is not None,
    )


def _checked_params(
    params: Sequence[str] | str, bounds: Any, max_nfev: int, scenario: Scenario
) -> tuple[tuple[str, ...], dict[str, tuple[float, float]]]:
    """The fitted paths and the user's bounds, checked (see :func:`fit`)."""
    if isinstance(params, str):
        params = [p.strip() for p in params.split(",") if p.strip()]
    paths = tuple(params)
    if not paths:
        raise ParameterError("params: give at least one dotted path to fit (e.g. contactors.0.stiffness)")
    if len(set(paths)) != len(paths):
        raise ParameterError(f"params: a path is listed twice ({', '.join(paths)})")
    if isinstance(max_nfev, bool) or int(max_nfev) != max_nfev or max_nfev < 1:
        raise ParameterError(f"max_nfev: must be a positive integer, got {max_nfev!r}")
    user_bounds = parse_bounds(bounds, *scenario.load_kinds) if bounds is not None else {}
    for p in user_bounds:
        if p not in paths:
            raise ParameterError(f"bounds {p}: not among the fitted params ({', '.join(paths)})")
    return paths, user_bounds


def _excitation_override(base: Scenario, excitation: Record | Excitation | None, hold: str) -> Excitation | None:
    """The excitation replacing the scenario's (a measured trace made into a table), if any."""
    from ..model.loading import Excitation

    if isinstance(excitation, Record):
        from ..experiment import drive_with_trace

        return drive_with_trace(base, excitation, hold=hold).excitation
    if isinstance(excitation, Excitation):
        return excitation
    if excitation is not None:
        raise ParameterError(f"excitation: expected a Record or an Excitation, got {type(excitation).__name__}")
    return None


def _with_fitted(base: Scenario, override: Excitation | None, values: Mapping[str, float]) -> Scenario:
    """``base`` with the fitted ``values`` applied (to the override excitation where it replaces the scenario's)."""
    sc = base.with_values({p: v for p, v in values.items() if not (override is not None and p.startswith("excitation."))})
    if override is None:
        return sc
    kw = {}
    for p, v in values.items():
        if p.startswith("excitation."):
            leaf = p.split(".", 1)[1]
            if not hasattr(override, leaf) or leaf in ("times", "values", "kind", "shape", "hold"):
                raise ScenarioError(f"{p}: cannot be fitted with a measured excitation trace", key=p)
            kw[leaf] = float(v)
    return dataclasses.replace(sc, excitation=dataclasses.replace(override, **kw))


def _uncertainties(
    params: Any, paths: tuple[str, ...], scales: Mapping[str, float], values: Mapping[str, float], n_samples: int
) -> tuple[dict[str, float | None], dict[str, tuple[float, float] | None], np.ndarray]:
    """Standard errors, 95 % intervals (Student t) and the correlation matrix of the fitted values."""
    from scipy.stats import t as student_t

    stderr: dict[str, float | None] = {}
    ci95: dict[str, tuple[float, float] | None] = {}
    dof = max(n_samples - len(paths), 1)
    tq = float(student_t.ppf(0.975, dof))
    for p in paths:
        se = params[_name(p)].stderr
        if se is None or not np.isfinite(se):
            stderr[p] = None
            ci95[p] = None
        else:
            stderr[p] = float(se) * scales[p]
            ci95[p] = (values[p] - tq * stderr[p], values[p] + tq * stderr[p])
    n = len(paths)
    corr = np.full((n, n), np.nan)
    for i, p in enumerate(paths):
        corr[i, i] = 1.0
        cp = params[_name(p)].correl or {}
        for j, q in enumerate(paths):
            if _name(q) in cp:
                corr[i, j] = float(cp[_name(q)])
    return stderr, ci95, corr


def _profile_intervals(
    lmfit: Any, minimizer: Any, out: Any, paths: tuple[str, ...], scales: Mapping[str, float], values: Mapping[str, float]
) -> dict[str, dict[str, float]]:
    """lmfit's profile-likelihood intervals (1 and 2 sigma) in the parameters' units."""
    try:
        ci = lmfit.conf_interval(minimizer, out, sigmas=[1, 2])
    except Exception as exc:  # lmfit raises plain exceptions when a profile fails
        raise SimulationError(f"fit: lmfit.conf_interval failed: {exc}") from None
    conf = {}
    for p in paths:
        rows = ci[_name(p)]
        conf[p] = {f"{'lower' if i < len(rows) // 2 else 'upper'}{round(100 * pr, 1):g}": v * scales[p]
                   for i, (pr, v) in enumerate(rows) if pr > 0}
        conf[p]["best"] = values[p]
    return conf
