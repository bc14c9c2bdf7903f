"""Transient solver: exact piecewise modal integration with exact event times (paper section 2).

:func:`integrate` runs the one compiled engine on model objects and returns
the exact piecewise solution (:class:`Solution`, its :class:`Event` list and
:class:`ModalState` at any time); :mod:`.reference` is the independent
``solve_ivp`` path. The user's entry point, which wraps this in a result, is
:func:`impactbeam.simulate`.
"""

from __future__ import annotations

from ..model import Damping, SolverOptions
from .engine import integrate
from .solution import Event, ModalState, PiecewiseSolution, Solution, basis_signature

__all__ = [
    "integrate", "Damping", "SolverOptions", "Event", "Solution", "PiecewiseSolution", "ModalState",
    "basis_signature",
]
