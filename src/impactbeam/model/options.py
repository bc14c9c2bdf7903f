"""The run settings of a simulation: modes, output step, end time, events, basis (``[solver]``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._memory import MAX_OUTPUT_SAMPLES
from .._validation import positive_finite
from ..exceptions import ParameterError

__all__ = ["BASES", "SolverOptions", "MAX_MODES"]

#: Largest number of modes per state (solver.modes, impactbeam modes --count).
MAX_MODES = 200
#: Values of ``solver.basis``: the shared enriched Ritz basis, the paper's per-state modes.
BASES = ("enriched", "paper")


@dataclass(frozen=True)
class SolverOptions:
    """Options of :func:`impactbeam.simulate`.

    Parameters
    ----------
    modes : int or "auto"
        Number of modes kept in every state (rigid-body modes included), or
        ``"auto"``: add modes (4, 8, 12, 16, 24, 32, ...) until the Table-2
        metrics change by less than ``tolerance`` between two counts
        (:mod:`impactbeam.solver.convergence`).
    tolerance : float
        Relative change of the metrics that counts as converged (default 2e-3);
        also the threshold of the unconverged warning for a fixed count.
    time_step : float, [s]
        Output sampling interval; also the scan interval for events (see the
        solver's Notes). The solution itself does not depend on it.
    end_time : float, [s]
    max_events : int
        Chattering guard: the run stops (status 1) after this many events.
    event_tolerance : float, [s]
        Absolute accuracy of located event times. Must be smaller than
        ``time_step``; above 1e-3 ``time_step`` an
        :class:`~impactbeam.exceptions.ImpactBeamWarning` is emitted.
    projection : {"paper", "contact"}
        How modal coordinates pass from one state to the next at an event.
        ``"paper"`` (default): the L2 projection of displacement and velocity
        onto the new modes (paper eq. 12). ``"contact"``: the same projection
        constrained to keep ``w`` and ``w_t`` at every contactor exactly
        continuous. Both converge to the same limit as modes are added; for a
        contactor much stiffer than the beam at its position (k L^3/EI >> the
        retained modes' stiffness) neither converges with few modes, the
        constrained one injecting more energy. An ImpactBeamWarning (also in
        ``result.warnings``) says when a projection moves a contactor's
        deflection by more than 5 % of its gap. With ``basis = "enriched"``
        every switch is exact and this option has no effect.
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

    modes: int | str = 8
    time_step: float = 1e-5
    end_time: float = 0.2
    max_events: int = 10000
    event_tolerance: float = 1e-13
    projection: str = "paper"
    tolerance: float = 2e-3
    basis: str = "enriched"

    def __post_init__(self) -> None:
        if self.basis not in BASES:
            raise ParameterError(f"solver.basis: must be 'enriched' or 'paper', got {self.basis!r}")
        if self.projection not in ("contact", "paper"):
            raise ParameterError(f"solver.projection: must be 'contact' or 'paper', got {self.projection!r}")
        if self.modes != "auto":
            if isinstance(self.modes, bool) or not isinstance(self.modes, (int, np.integer)) or self.modes < 1:
                raise ParameterError(f"solver.modes: must be a positive integer or 'auto', got {self.modes!r}")
            if self.modes > MAX_MODES:
                raise ParameterError(f"solver.modes: at most {MAX_MODES} modes are supported, got {self.modes}")
            object.__setattr__(self, "modes", int(self.modes))
        tol = positive_finite("solver.tolerance", self.tolerance)
        if tol >= 1.0:
            raise ParameterError(f"solver.tolerance: a relative change, expected below 1, got {tol:g}")
        object.__setattr__(self, "tolerance", tol)
        object.__setattr__(self, "time_step", positive_finite("solver.time_step", self.time_step))
        object.__setattr__(self, "end_time", positive_finite("solver.end_time", self.end_time))
        if self.time_step > self.end_time:
            raise ParameterError(
                f"solver.time_step: {self.time_step:g} s is longer than solver.end_time {self.end_time:g} s"
            )
        if self.end_time / self.time_step > MAX_OUTPUT_SAMPLES:
            raise ParameterError(
                f"solver.time_step: {self.end_time / self.time_step:.3g} output samples is too many "
                f"(max {MAX_OUTPUT_SAMPLES:.0e})"
            )
        if (isinstance(self.max_events, bool) or not isinstance(self.max_events, (int, np.integer))
                or not 1 <= self.max_events <= 2**62):
            big = isinstance(self.max_events, (int, np.integer)) and not isinstance(self.max_events, bool) \
                and self.max_events > 2**62
            shown = f"{float(self.max_events):.3g}" if big else repr(self.max_events)
            raise ParameterError(f"solver.max_events: must be a positive integer up to 2^62, got {shown}")
        object.__setattr__(self, "max_events", int(self.max_events))
        object.__setattr__(
            self, "event_tolerance", positive_finite("solver.event_tolerance", self.event_tolerance)
        )
        self._check_event_tolerance()

    def _check_event_tolerance(self) -> None:
        """Refuse an event tolerance of a scan step or more; warn above 1e-3 of it.

        An event located only to within the output (and scan) step says
        nothing the grid does not; above 1e-3 of the step the event times, and
        the contact durations and impact times derived from them, carry an
        error visible at the output resolution.
        """
        tol, dt = self.event_tolerance, self.time_step
        if tol >= dt:
            raise ParameterError(
                f"solver.event_tolerance: {tol:g} s is not smaller than solver.time_step ({dt:g} s); "
                f"event times would be no better than the output grid (default 1e-13 s)"
            )
        if tol > 1e-3 * dt:
            from .._warnings import emit_user_level_warning

            emit_user_level_warning(
                f"solver.event_tolerance: {tol:g} s is more than 1e-3 of solver.time_step ({dt:g} s); "
                f"impact times and contact durations are only that accurate (default 1e-13 s)"
            )
