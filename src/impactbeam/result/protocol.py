"""What the metrics, stresses and figures read of a simulation result: the protocol ``ResultLike``.

:mod:`impactbeam.result.metrics`, :mod:`impactbeam.plot` and :mod:`impactbeam.result.stress` read a simulation result;
:class:`~impactbeam.result.SimulationResult` calls them for its ``metrics()``
and ``plot()`` methods. So that the import arrows run one way (result ->
metrics, result -> plot, plot -> metrics), metrics and plot name the result by
the protocol below instead of importing its class.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:  # pragma: no cover - for type checkers
    import numpy as np

    from ..model.beam import Beam, Contactor
    from ..solver.solution import Event, PiecewiseSolution

__all__ = ["ResultLike"]


class ResultLike(Protocol):
    """What metrics and plots read of a :class:`~impactbeam.result.SimulationResult`."""

    solution: PiecewiseSolution
    points: np.ndarray
    beam: Beam
    contactors: tuple[Contactor, ...]
    scenario_name: str
    end_time: float

    @property
    def events(self) -> list[Event]: ...

    @property
    def energy_jumps(self) -> np.ndarray: ...

    @property
    def time(self) -> np.ndarray: ...

    @property
    def w(self) -> np.ndarray: ...

    @property
    def w_contact(self) -> np.ndarray: ...

    @property
    def contact_force(self) -> np.ndarray: ...

    def displacement(self, x: Any, t: Any) -> np.ndarray: ...

    def check_points(self, x: Any) -> np.ndarray: ...
