"""Exceptions raised by impactbeam.

Every exception derives from :class:`ImpactBeamError` and from the built-in
exception that fits its meaning, so ``except ValueError`` keeps working.
"""

from __future__ import annotations


__all__ = [
    "ImpactBeamError",
    "ParameterError",
    "ScenarioError",
    "ModeSolveError",
    "SimulationError",
    "ResourceError",
    "ImpactBeamWarning",
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
    """A result or an input that needs the user's attention, though not an error.

    Emitted through :func:`impactbeam._warnings.emit_user_level_warning`, so
    the warning points at the user's line, not at impactbeam's internals. The
    command line collects them and prints each as ``warning: ...`` in its
    summary and under ``"warnings"`` in ``--json`` output. Silence them with
    ``warnings.filterwarnings("ignore", category=impactbeam.ImpactBeamWarning)``
    or turn them into errors with ``"error"``.
    """
