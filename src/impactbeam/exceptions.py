"""Exceptions raised by impactbeam.

Every exception derives from :class:`ImpactBeamError` and from the built-in
exception that fits its meaning, so ``except ValueError`` keeps working.
"""

from __future__ import annotations

import os
import sys
import warnings

__all__ = [
    "ImpactBeamError",
    "ParameterError",
    "ScenarioError",
    "ModeSolveError",
    "SimulationError",
    "ResourceError",
    "ImpactBeamWarning",
    "warn",
]


class ImpactBeamError(Exception):
    """Base class of every error raised by impactbeam."""


class ParameterError(ImpactBeamError, ValueError):
    """A parameter has a value outside its valid range.

    The message names the parameter, the value received and what was expected.
    """


class ScenarioError(ParameterError):
    """A scenario, sweep or record file is invalid.

    ``key`` holds the dotted path of the offending field (``contactors.0.gap``)
    when there is one.
    """

    def __init__(self, message: str, key: str | None = None) -> None:
        super().__init__(message)
        self.key = key


class ModeSolveError(ImpactBeamError, RuntimeError):
    """The modal analysis could not isolate or refine a natural frequency."""


class SimulationError(ImpactBeamError, RuntimeError):
    """The time integration could not be completed."""


class ResourceError(ParameterError):
    """A request would exceed a documented resource limit (memory, modes, samples).

    The message gives the estimate, the limit, and how to reduce the request.
    """


class ImpactBeamWarning(UserWarning):
    """A result the solver is not sure of (e.g. a lossy projection, unconverged modes)."""


def _stacklevel() -> int:
    """Stack level of the first frame outside the impactbeam package (xarray's approach)."""
    pkg = os.path.dirname(os.path.abspath(__file__))
    level = 1
    frame = sys._getframe(1)
    while frame is not None and os.path.abspath(frame.f_code.co_filename).startswith(pkg):
        level += 1
        frame = frame.f_back
    return level


def warn(message: str, category: type[Warning] = ImpactBeamWarning) -> None:
    """Issue ``message`` as a warning attributed to the user's code, not to impactbeam."""
    warnings.warn(message, category, stacklevel=_stacklevel())
