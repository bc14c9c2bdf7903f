"""Bifurcation diagrams of the harmonically forced beam over any scenario key.

For each value of the parameter the scenario is re-read with that value,
run ``settle + record`` forcing periods and sampled once per period
(:mod:`~impactbeam.periodic.strobe`). By default each value starts from the
final state of the previous one (natural-parameter continuation): the
previous run ended a whole number of periods after its load began, so the
next run starts at t = 0 with the load on and the same phase, and an up
sweep and a down sweep follow different branches where orbits coexist
(hysteresis). With ``from_rest`` every value starts from the scenario's
initial condition.

A parameter that changes the modal basis (beam, contactor positions,
``solver.modes``) cannot carry the modal state across; then every value
starts from rest and a warning says so.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from .._warnings import emit_user_level_warning
from ..exceptions import ParameterError, ScenarioError
from .forcing import harmonic_period
from .strobe import PERIOD_TOLERANCE, SteadyState, count, settle_and_analyse, with_modes_of

if TYPE_CHECKING:
    from ..scenario import Scenario

__all__ = ["BifurcationPoint", "BifurcationDiagram", "bifurcation", "parameter_values"]

Direction = Literal["up", "down", "both"]


@dataclass(frozen=True, eq=False)
class BifurcationPoint:
    """One value of the parameter on one sweep direction."""

    value: float
    direction: str
    state: SteadyState = field(repr=False)

    def to_dict(self) -> dict[str, Any]:
        s = self.state
        return {"value": self.value, "direction": self.direction, "period": s.period,
                "impacts_per_period": s.impacts_per_period, "strobe": [float(v) for v in s.strobe],
                "max": s.max, "min": s.min}


@dataclass(frozen=True, eq=False)
class BifurcationDiagram:
    """Strobe samples, periods and extremes over a parameter.

    Attributes
    ----------
    parameter : str
        The scenario key varied.
    points : list of BifurcationPoint
        In the order computed (up sweep, then down sweep).
    unit : str
        SI unit of the parameter ("" when dimensionless or unknown).
    settle_periods, record_periods : int
    warnings : list of str
    scenario : str
        The base scenario as TOML (the files' provenance).
    """

    parameter: str
    points: list[BifurcationPoint]
    unit: str = ""
    settle_periods: int = 100
    record_periods: int = 50
    warnings: list[str] = field(default_factory=list)
    scenario: str = field(default="", repr=False)  # the base scenario, as TOML (the files' provenance)

    def to_dict(self) -> dict[str, Any]:
        """``{"parameter", "points": [...], "warnings"}`` (the ``--json`` output)."""
        return {"parameter": self.parameter, "points": [p.to_dict() for p in self.points],
                "warnings": list(self.warnings)}

    def to_xarray(self) -> Any:
        """Dataset with dims (value, sample): strobe, strobe_velocity, strobe_time; period, extremes per value."""
        import xarray as xr

        from ..result.dataset import provenance

        n, r = len(self.points), self.record_periods
        strobe = np.full((n, r), np.nan)
        vel = np.full((n, r), np.nan)
        tim = np.full((n, r), np.nan)
        for i, p in enumerate(self.points):
            m = min(r, p.state.strobe.size)
            strobe[i, :m], vel[i, :m], tim[i, :m] = p.state.strobe[:m], p.state.strobe_velocity[:m], p.state.times[:m]

        def per(name: str) -> np.ndarray:
            return np.array([getattr(p.state, name) for p in self.points], dtype=float)

        dims = ("value", "sample")
        ds = xr.Dataset(
            {
                "strobe": (dims, strobe, {"units": "m", "long_name": "w at the strobe point, once per forcing period"}),
                "strobe_velocity": (dims, vel, {"units": "m/s", "long_name": "w_t at the strobe point"}),
                "strobe_time": (dims, tim, {"units": "s", "long_name": "strobe time start + k / f"}),
                "period": ("value", np.array([p.state.period for p in self.points], dtype=np.int64),
                           {"units": "1", "long_name": "response period in forcing periods (0: none found)"}),
                "impacts_per_period": ("value", per("impacts_per_period"), {"units": "1"}),
                "max": ("value", per("max"), {"units": "m", "long_name": "max of w over the record"}),
                "min": ("value", per("min"), {"units": "m", "long_name": "min of w over the record"}),
                "mismatch": ("value", per("mismatch"), {"units": "1", "long_name": "relative mismatch of the period"}),
                "frequency": ("value", per("frequency"), {"units": "Hz", "long_name": "forcing frequency"}),
            },
            coords={
                "value": ("value", np.array([p.value for p in self.points], dtype=float),
                          {"units": self.unit, "long_name": self.parameter}),
                "direction": ("value", np.array([p.direction for p in self.points], dtype=str)),
                "sample": ("sample", np.arange(r)),
            },
            attrs={**provenance(f"impactbeam bifurcation diagram over {self.parameter}", "bifurcation",
                                "strobe samples of exact piecewise modal runs, each value continued from the last"),
                   "parameter": self.parameter, "settle_periods": self.settle_periods,
                   "record_periods": self.record_periods, "warnings": "\n".join(self.warnings),
                   "scenario": self.scenario},
        )
        return ds

    def write(self, path: str | os.PathLike[str]) -> None:
        """Write the dataset to a netCDF file (atomically).

        Parameters
        ----------
        path : str or path-like
            The ``.nc`` file.

        Raises
        ------
        WriteError
            The file could not be written (a read-only or full file system): nothing is left behind.
        """
        from .._io import write_netcdf

        write_netcdf(self.to_xarray(), path)

    def plot(self, path: str | os.PathLike[str] | None = None, **kwargs: Any) -> Any:
        """The diagram (see :func:`~impactbeam.plot.periodic.plot_bifurcation`); written to ``path`` when given.

        Parameters
        ----------
        path : str or path-like, optional
            Also write the figure there (format from the suffix).
        **kwargs
            Passed to :func:`~impactbeam.plot.periodic.plot_bifurcation`.
        """
        from ..plot.periodic import plot_bifurcation

        return plot_bifurcation(self, path, **kwargs)


def _dimension(parameter: str, scenario: Scenario) -> str:
    """The dimension a value of ``parameter`` is read in (:func:`impactbeam.scenario.path_dimension`)."""
    dim = scenario.path_dimension(parameter)
    return "dimensionless" if dim in (None, "integer") else dim


def parameter_values(parameter: str, scenario: Scenario, values: Sequence[Any]) -> list[float]:
    """The values in SI (numbers as given, strings with units converted); ScenarioError naming the key."""
    from ..units import to_si

    dim = _dimension(parameter, scenario)
    out = []
    for i, v in enumerate(values):
        if isinstance(v, str):
            try:
                v = float(v)
            except ValueError:
                v = to_si(v, dim, f"{parameter} (value {i + 1})")
        if isinstance(v, bool) or not isinstance(v, (int, float, np.number)) or not math.isfinite(float(v)):
            raise ParameterError(f"{parameter}: value {i + 1} ({v!r}) is not a finite number")
        out.append(float(v))
    if not out:
        raise ParameterError(f"{parameter}: no values given")
    return out


def _with(scenario: Scenario, parameter: str, value: float) -> Scenario:
    try:
        return scenario.with_values({parameter: value})
    except ScenarioError:
        raise
    except (KeyError, TypeError, ValueError) as exc:
        raise ScenarioError(f"{parameter}: cannot set it to {value!r} ({exc})", key=parameter) from None


def _order(values: list[float], sweep: str) -> list[tuple[float, str]]:
    up = sorted(values)
    if sweep == "up":
        return [(v, "up") for v in up]
    if sweep == "down":
        return [(v, "down") for v in reversed(up)]
    if sweep == "both":
        return [(v, "up") for v in up] + [(v, "down") for v in reversed(up)]
    raise ParameterError(f"sweep: expected 'up', 'down' or 'both', got {sweep!r}")


def bifurcation(
    scenario: Scenario,
    parameter: str,
    values: Sequence[Any],
    *,
    sweep: Direction = "up",
    from_rest: bool = False,
    settle_periods: int = 100,
    record_periods: int = 50,
    tolerance: float = PERIOD_TOLERANCE,
    max_settle_periods: int | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> BifurcationDiagram:
    """Bifurcation diagram of the steady state over ``parameter``.

    Parameters
    ----------
    scenario : Scenario
        With a harmonic load (``[excitation] shape = "harmonic"``).
    parameter : str
        Any scenario key: ``"excitation.frequency"``, ``"excitation.amplitude"``,
        ``"contactors.0.gap"``, ...
    values : sequence of float or str
        The parameter values (SI numbers, or strings with units); swept in
        increasing order (``"up"``), decreasing (``"down"``) or both.
    sweep : {"up", "down", "both"}
    from_rest : bool
        Start every value from the scenario's initial condition instead of
        the previous value's final state.
    settle_periods, record_periods : int
        Forcing periods discarded, then recorded, per value.
    tolerance : float
        Relative tolerance of the period test (:mod:`~impactbeam.periodic.strobe`).
    max_settle_periods : int, optional
        A value whose period is not found is run on up to this many settling
        periods (default ``10 * settle_periods``;
        :func:`~impactbeam.periodic.strobe.steady_state`).
    progress : callable, optional
        ``progress(done, total)`` after each value.

    Returns
    -------
    BifurcationDiagram
        ``points`` in the order computed; ``warnings`` lists every value
        whose period was not found (also issued as ImpactBeamWarning).

    Notes
    -----
    With ``solver.modes = "auto"`` the first value's run chooses the mode
    count and every value is run with it (``point.state.result.n_modes``):
    continuation carries the modal state from one value to the next.

    Examples
    --------
    >>> d = bifurcation(sc, "excitation.frequency", np.linspace(40, 80, 81), sweep="both")  # doctest: +SKIP
    >>> d.plot("diagram.png")                                                                # doctest: +SKIP
    """
    if not isinstance(parameter, str) or not parameter:
        raise ParameterError(f"parameter: expected a scenario key such as excitation.frequency, got {parameter!r}")
    settle = count("settle_periods", settle_periods, 0)
    record = count("record_periods", record_periods, 2)
    limit = 10 * settle if max_settle_periods is None else count("max_settle_periods", max_settle_periods, 0)
    if not (isinstance(tolerance, (int, float)) and 0.0 < tolerance < 1.0):
        raise ParameterError(f"tolerance: expected a number in (0, 1), got {tolerance!r}")
    harmonic_period(scenario)
    si = parameter_values(parameter, scenario, values)
    plan = _order(si, sweep)
    scenarios = {v: _with(scenario, parameter, v) for v in dict.fromkeys(si)}  # all checked before any run
    for sc in scenarios.values():
        harmonic_period(sc)
    warns: list[str] = []
    searched: list[tuple[float, str, Future[SteadyState]]] = []
    state = None
    # the extremes of each record are searched on a second thread while the next value runs (compiled code
    # on both, without the interpreter lock): the same numbers, one core's worth sooner
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="impactbeam-extremes") as extremes:
        try:
            for i, (v, direction) in enumerate(plan):
                sc = scenarios[v]
                start = None if from_rest else state
                if start is not None and not _same_basis(start, sc):
                    warns.append(f"{parameter} changes the modal basis: each value starts from rest (no "
                                 "continuation)")
                    from_rest = True
                    start = None
                rec = settle_and_analyse(sc, settle, record, start, tolerance, None, limit)
                res = rec.result
                if sc.solver.modes == "auto":  # the first value's count, kept: continuation carries the state
                    scenarios = {u: with_modes_of(s, res) for u, s in scenarios.items()}
                for w in rec.warnings:
                    warns.append(f"{parameter} = {v:.6g} ({direction}): {w}")
                state = res.final_state() if res.status == 0 else None
                # submitted after the final state: the search's Python then runs while the next value's loop
                # (compiled, without the interpreter lock) does, not while this thread waits for the lock
                searched.append((v, direction, extremes.submit(rec.steady_state)))
                if state is None and not from_rest and i + 1 < len(plan):
                    warns.append(f"{parameter} = {v:.6g} ({direction}): the run stopped early, so the next value "
                                 "starts from rest")
                if progress is not None:
                    progress(i + 1, len(plan))
        except BaseException:  # Ctrl-C or an error: the searches not yet started are dropped
            for _, _, f in searched:
                f.cancel()
            raise
        points = [BifurcationPoint(v, direction, f.result()) for v, direction, f in searched]
    for w in warns:
        emit_user_level_warning(w)
    unit = _unit(_dimension(parameter, scenario))
    return BifurcationDiagram(parameter, points, unit, settle, record, warns, scenario.to_toml())


def _same_basis(state: Any, scenario: Scenario) -> bool:
    from ..solver.solution import basis_signature

    opt = scenario.solver
    if opt.modes == "auto":
        return False
    return state.basis == basis_signature(scenario.beam, scenario.contactors, int(opt.modes), opt.basis,
                                          scenario.excitation)


def _unit(dimension: str) -> str:
    from ..units import DIMENSIONS

    return DIMENSIONS[dimension].si_unit if dimension in DIMENSIONS else ""
