"""Solver settings: damping per state and integration options."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import nonnegative_finite, positive_finite
from ..exceptions import ParameterError

__all__ = ["BASES", "Damping", "SolverOptions"]

#: Values of ``solver.basis``: the shared enriched Ritz basis, the paper's per-state modes.
BASES = ("enriched", "paper")


def _ratios(name: str, value: float | tuple[float, ...]) -> float | tuple[float, ...]:
    if isinstance(value, (list, tuple, np.ndarray)):
        if len(value) == 0:
            raise ParameterError(f"{name}: the list of damping ratios is empty")
        return tuple(nonnegative_finite(f"{name}[{i}]", v) for i, v in enumerate(value))
    return nonnegative_finite(name, value)


@dataclass(frozen=True)
class Damping:
    """Modal damping ratios ``xi_n`` of the free and of the contact states (paper eq. 9).

    Each is one ratio for every mode or a sequence per mode (the last value is
    repeated for modes beyond the sequence). 0 is undamped; >= 1 is allowed
    (critically and over-damped modes are integrated exactly too).
    """

    free: float | tuple[float, ...] = 0.0
    contact: float | tuple[float, ...] = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "free", _ratios("damping.free", self.free))
        object.__setattr__(self, "contact", _ratios("damping.contact", self.contact))

    def ratios(self, engaged: bool, n_modes: int) -> np.ndarray:
        """Damping ratios of ``n_modes`` modes of a free (False) or contact (True) state."""
        spec = self.contact if engaged else self.free
        if isinstance(spec, tuple):
            out = np.full(n_modes, spec[-1], dtype=float)
            k = min(n_modes, len(spec))
            out[:k] = spec[:k]
            return out
        return np.full(n_modes, float(spec))


@dataclass(frozen=True)
class SolverOptions:
    """Options of :func:`impactbeam.simulate`.

    Parameters
    ----------
    modes : int
        Number of modes kept in every state (rigid-body modes included).
    time_step : float, [s]
        Output sampling interval; also the scan interval for events (see the
        solver's Notes). The solution itself does not depend on it.
    end_time : float, [s]
    max_events : int
        Chattering guard: the run stops (status 1) after this many events.
    event_tolerance : float, [s]
        Absolute accuracy of located event times.
    projection : {"paper", "contact"}
        How modal coordinates pass from one state to the next at an event.
        ``"paper"`` (default): the L2 projection of displacement and velocity
        onto the new modes (paper eq. 12). ``"contact"``: the same projection
        constrained to keep ``w`` and ``w_t`` at every contactor exactly
        continuous. Both converge to the same limit as modes are added; for a
        contactor much stiffer than the beam at its position (k L^3/EI >> the
        retained modes' stiffness) neither converges with few modes, the
        constrained one injecting more energy. The result's message warns
        when a projection moves a contactor's deflection by more than 5 % of
        its gap.
    basis : {"enriched", "paper"}
        ``"paper"``: each state has its own exact modes and a switch is the
        projection of eq. (12) (``projection`` applies). ``"enriched"``: all
        states share one Ritz basis, the ``modes`` retained free modes plus one
        static attachment shape per contactor
        (:mod:`~impactbeam.solver.ritz`), so every state has
        ``modes + n_contactors`` modes, its stiffness is exact in the basis and
        a switch is an exact change of coordinates (no projection loss); it
        converges with few modes for stiff contactors.
    """

    modes: int = 8
    time_step: float = 1e-5
    end_time: float = 0.2
    max_events: int = 10000
    event_tolerance: float = 1e-13
    projection: str = "paper"
    basis: str = "enriched"

    def __post_init__(self) -> None:
        if self.basis not in BASES:
            raise ParameterError(f"solver.basis: must be 'enriched' or 'paper', got {self.basis!r}")
        if self.projection not in ("contact", "paper"):
            raise ParameterError(f"solver.projection: must be 'contact' or 'paper', got {self.projection!r}")
        if isinstance(self.modes, bool) or not isinstance(self.modes, (int, np.integer)) or self.modes < 1:
            raise ParameterError(f"solver.modes: must be a positive integer, got {self.modes!r}")
        if self.modes > 200:
            raise ParameterError(f"solver.modes: at most 200 modes are supported, got {self.modes}")
        object.__setattr__(self, "modes", int(self.modes))
        object.__setattr__(self, "time_step", positive_finite("solver.time_step", self.time_step))
        object.__setattr__(self, "end_time", positive_finite("solver.end_time", self.end_time))
        if self.time_step > self.end_time:
            raise ParameterError(
                f"solver.time_step: {self.time_step:g} s is longer than solver.end_time {self.end_time:g} s"
            )
        if self.end_time / self.time_step > 5e7:
            raise ParameterError(
                f"solver.time_step: {self.end_time / self.time_step:.3g} output samples is too many (max 5e7)"
            )
        if isinstance(self.max_events, bool) or not isinstance(self.max_events, (int, np.integer)) or self.max_events < 1:
            raise ParameterError(f"solver.max_events: must be a positive integer, got {self.max_events!r}")
        object.__setattr__(self, "max_events", int(self.max_events))
        object.__setattr__(
            self, "event_tolerance", positive_finite("solver.event_tolerance", self.event_tolerance)
        )
