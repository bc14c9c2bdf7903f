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

import dataclasses
import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..exceptions import ParameterError
from .bifurcation import BifurcationDiagram, bifurcation
from .strobe import PERIOD_TOLERANCE, harmonic_period, strobe_point

if TYPE_CHECKING:
    from ..scenario import Scenario
    from ..solver.solution import ModalState

__all__ = ["FrequencyResponse", "frequency_response", "from_diagram", "linear_frf", "linear_steady_state"]


def _free_state(scenario: Scenario) -> tuple[Any, Any]:
    """The packed problem of the solver and its free state (slot 0)."""
    from ..solver.engine import pack

    opt = scenario.solver
    if opt.modes == "auto":
        opt = dataclasses.replace(opt, modes=8)
    pk = pack(scenario.beam, tuple(scenario.contactors), scenario.damping, scenario.excitation, opt)
    return pk, opt


def linear_frf(scenario: Scenario, frequencies: Sequence[float] | np.ndarray,
               points: Sequence[float] | None = None) -> np.ndarray:
    """Complex amplitude of ``w`` per unit load amplitude, without contact (module docstring).

    Parameters
    ----------
    scenario : Scenario
        Its beam, damping, load distribution (``excitation.kind``) and modes;
        contactors are kept open.
    frequencies : array_like, [Hz]
    points : sequence of float, optional, [m]
        Default: the strobe point (first contactor, else first output point).

    Returns
    -------
    ndarray, complex, (n_frequencies, n_points)
        ``H`` in m per unit of ``excitation.amplitude`` (times ``excitation.scale``).

    Raises
    ------
    ParameterError
        A point off the beam, or a negative or non-finite frequency.
    """
    pk, _ = _free_state(scenario)
    x = np.asarray([strobe_point(scenario)] if points is None else points, dtype=float)
    L = scenario.beam.length
    bad = ~np.isfinite(x) | (x < 0.0) | (x > L * (1.0 + 1e-12))
    if x.ndim != 1 or bad.any():
        shown = x[bad][0] if x.ndim == 1 else x
        raise ParameterError(f"points: {shown} m is not a position on the beam [0, {L:g}] m (a 1-D list)")
    f = np.asarray(frequencies, dtype=float)
    if f.ndim > 1 or not np.all(np.isfinite(f)) or np.any(f < 0.0):
        raise ParameterError("frequencies: expected finite frequencies >= 0 [Hz] in a 1-D list")
    W = pk.rows(x)[0]  # (n_x, n_modes), free state
    om, dec, pw = pk.om[0], pk.dec[0], pk.pw[0]
    Om = 2.0 * np.pi * np.atleast_1d(f)[:, None]
    modal = pw[None, :] / (om[None, :] ** 2 - Om**2 + 2j * dec[None, :] * Om)
    return modal @ W.T


def linear_steady_state(scenario: Scenario) -> ModalState:
    """The periodic state of the free (no contact) beam when its harmonic load has phase ``phase``.

    A run from this state (``simulate(..., start=)``, load on from t = 0)
    stays on the linear steady state as long as no contactor is touched:
    a start with no transient for frequency-response curves and tests.
    """
    from ..solver.solution import ModalState, basis_signature

    harmonic_period(scenario)
    ex = scenario.excitation
    pk, opt = _free_state(scenario)
    om, dec, pw = pk.om[0], pk.dec[0], pk.pw[0]
    Om = 2.0 * np.pi * float(ex.frequency)  # type: ignore[arg-type]
    q = pw * (ex.scale * ex.amplitude) / (om**2 - Om**2 + 2j * dec * Om) * np.exp(1j * ex.phase)
    basis = basis_signature(scenario.beam, scenario.contactors, int(opt.modes), opt.basis, ex)
    return ModalState(0.0, np.ascontiguousarray(q.imag), np.ascontiguousarray((1j * Om * q).imag), basis)


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
    ex = scenario.excitation
    lin = np.abs(linear_frf(scenario, f)[:, 0]) * abs(ex.scale * ex.amplitude)
    return FrequencyResponse(
        diagram=d, frequency=f, direction=np.array([p.direction for p in d.points]),
        max=np.array([p.state.max for p in d.points]), min=np.array([p.state.min for p in d.points]),
        period=np.array([p.state.period for p in d.points]),
        impacts_per_period=np.array([p.state.impacts_per_period for p in d.points]),
        linear=lin, point=strobe_point(scenario), warnings=list(d.warnings),
    )
