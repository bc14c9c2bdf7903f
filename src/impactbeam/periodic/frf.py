"""Frequency-response curves of the impacting beam, and the linear modal FRF.

:func:`frequency_response` sweeps the forcing frequency up and down
(:func:`~impactbeam.periodic.bifurcation.bifurcation` over
``excitation.frequency``) and keeps the extremes of ``w`` over each steady
state; where the beam does not touch a contactor they equal the linear
modal FRF of the free state, :func:`linear_frf`:

``w(x, t) = Im[ H(x, f) A e^{i (2 pi f (t - start) + phase)} ]``,
``H(x, f) = sum_n W_n(x) p_n / (omega_n^2 - Omega^2 + 2 i xi_n omega_n Omega)``,

with the modes ``W_n``, frequencies ``omega_n``, damping ratios ``xi_n`` and
load weights ``p_n`` (paper eq. 8) of the solver's free state, so the same
truncated model as the simulation.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .bifurcation import BifurcationDiagram, bifurcation
from .forcing import strobe_point
from .linear import linear_frf, linear_steady_state
from .strobe import PERIOD_TOLERANCE, with_modes_of

if TYPE_CHECKING:
    from ..scenario import Scenario

__all__ = ["FrequencyResponse", "frequency_response", "from_diagram", "linear_frf", "linear_steady_state"]


@dataclass(frozen=True, eq=False)
class FrequencyResponse:
    """Steady-state extremes against the forcing frequency, swept up and down.

    Attributes
    ----------
    diagram : BifurcationDiagram
        The underlying sweep over ``excitation.frequency`` (strobe samples, periods).
    frequency : ndarray, [Hz]
    direction : ndarray of str
    max, min : ndarray, [m]
        Extremes of ``w`` at ``point`` over each recorded steady state.
    period, impacts_per_period : ndarray
    linear : ndarray, [m]
        ``|H| A``: the amplitude without contact at the same frequencies.
    point : float, [m]
    warnings : list of str
    linear_curve : (ndarray, ndarray), ([Hz], [m])
        ``|H| A`` on a fine grid over the swept range, its peak located to
        1e-9 of its frequency (the swept values alone may miss a resonance
        between them).
    """

    diagram: BifurcationDiagram = field(repr=False)
    frequency: np.ndarray
    direction: np.ndarray
    max: np.ndarray
    min: np.ndarray
    period: np.ndarray
    impacts_per_period: np.ndarray
    linear: np.ndarray
    point: float
    warnings: list[str] = field(default_factory=list)
    linear_curve: tuple[np.ndarray, np.ndarray] = field(default=(np.empty(0), np.empty(0)), repr=False)

    def to_dict(self) -> dict[str, Any]:
        return {"point": self.point, "points": [
            {"frequency": float(f), "direction": str(d), "max": float(a), "min": float(b), "period": int(p),
             "impacts_per_period": float(i), "linear": float(lin)}
            for f, d, a, b, p, i, lin in zip(self.frequency, self.direction, self.max, self.min, self.period,
                                             self.impacts_per_period, self.linear)
        ], "warnings": list(self.warnings)}

    def plot(self, path: str | os.PathLike[str] | None = None, **kwargs: Any) -> Any:
        """The frequency-response curve: max and min of the steady state against the forcing frequency.

        Parameters
        ----------
        path : str or path-like, optional
            Also write the figure there (format from the suffix).
        **kwargs
            Passed to the plotting function.
        """
        from ..plot.periodic import plot_frequency_response

        return plot_frequency_response(self, path, **kwargs)


def frequency_response(
    scenario: Scenario,
    frequencies: Sequence[Any],
    *,
    sweep: str = "both",
    from_rest: bool = False,
    settle_periods: int = 100,
    record_periods: int = 50,
    tolerance: float = PERIOD_TOLERANCE,
    progress: Callable[[int, int], None] | None = None,
) -> FrequencyResponse:
    """Frequency-response curve: max and min of the steady state of ``w`` against the forcing frequency.

    Parameters
    ----------
    scenario : Scenario
        With a harmonic load; its frequency is replaced by each of ``frequencies``.
    frequencies : sequence of float or str, [Hz]
    sweep : {"up", "down", "both"}
        ``"both"`` (default) shows the hysteresis of coexisting orbits.
    from_rest, settle_periods, record_periods, tolerance, progress
        As for :func:`~impactbeam.periodic.bifurcation.bifurcation`.

    Returns
    -------
    FrequencyResponse
        With the linear FRF amplitude ``|H| A`` beside: without contact the
        curves equal it.
    """
    d = bifurcation(scenario, "excitation.frequency", frequencies, sweep=sweep,  # type: ignore[arg-type]
                    from_rest=from_rest, settle_periods=settle_periods, record_periods=record_periods,
                    tolerance=tolerance, progress=progress)
    return from_diagram(scenario, d)


def from_diagram(scenario: Scenario, d: BifurcationDiagram) -> FrequencyResponse:
    """The frequency-response curve of a bifurcation diagram over ``excitation.frequency``."""
    from ..exceptions import ParameterError

    if d.parameter != "excitation.frequency":
        raise ParameterError(f"a frequency-response curve needs --parameter excitation.frequency, got {d.parameter}")
    f = np.array([p.value for p in d.points])
    if d.points:  # the diagram's own mode count (solver.modes = "auto" chose it on the first value)
        scenario = with_modes_of(scenario, d.points[0].state.result)
    ex = scenario.excitation
    gain = abs(ex.scale * ex.amplitude)
    lin = np.abs(linear_frf(scenario, f)[:, 0]) * gain
    return FrequencyResponse(
        diagram=d, frequency=f, direction=np.array([p.direction for p in d.points]),
        max=np.array([p.state.max for p in d.points]), min=np.array([p.state.min for p in d.points]),
        period=np.array([p.state.period for p in d.points]),
        impacts_per_period=np.array([p.state.impacts_per_period for p in d.points]),
        linear=lin, point=strobe_point(scenario), warnings=list(d.warnings),
        linear_curve=_linear_curve(scenario, f, gain),
    )


def _linear_curve(scenario: Scenario, f: np.ndarray, gain: float) -> tuple[np.ndarray, np.ndarray]:
    """``|H| A`` on 2001 frequencies over the range of ``f``, with its largest value refined to 1e-9 of its frequency."""
    if not f.size:
        return np.empty(0), np.empty(0)
    if f.min() == f.max():  # one frequency: nothing between swept values to miss
        return f.copy(), np.abs(linear_frf(scenario, f)[:, 0]) * gain
    from scipy.optimize import minimize_scalar

    grid = np.linspace(f.min(), f.max(), 2001)
    amp = np.abs(linear_frf(scenario, grid)[:, 0]) * gain
    k = int(np.argmax(amp))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    best = minimize_scalar(lambda x: -float(np.abs(linear_frf(scenario, [x])[0, 0])), bounds=(lo, hi),
                           method="bounded", options={"xatol": 1e-9 * hi})
    peak = float(best.x)
    grid = np.insert(grid, int(np.searchsorted(grid, peak)), peak)
    amp = np.abs(linear_frf(scenario, grid)[:, 0]) * gain
    return grid, amp
