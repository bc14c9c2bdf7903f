"""Emitting impactbeam's warnings at the user's stack level, and recording them.

Every warning of the package goes through :func:`emit_user_level_warning`
(the pattern of xarray's ``emit_user_level_warning``): the category is
:class:`~impactbeam.exceptions.ImpactBeamWarning` and the reported location
is the first stack frame outside the package, i.e. the user's call of
``load_scenario`` or ``simulate``, not an internal line.

:class:`WarningLog` records the warnings raised while a command runs, for the
command line's summary and ``--json`` output.
"""

from __future__ import annotations

import os
import sys
import warnings
from types import TracebackType
from typing import Any

from .exceptions import ImpactBeamWarning

__all__ = ["WarningLog", "emit_user_level_warning"]

_PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))


def _stack_level() -> int:
    """``stacklevel`` for a ``warnings.warn`` call in :func:`emit_user_level_warning`.

    Level 2 is the caller of ``emit_user_level_warning``; each further frame
    inside the package adds one, until the first frame outside it.
    """
    level = 2
    frame: Any = sys._getframe(2)  # the caller of emit_user_level_warning
    while frame is not None and _internal(frame):
        frame = frame.f_back
        level += 1
    return level


def _in_package(frame: Any) -> bool:
    return os.path.abspath(frame.f_code.co_filename).startswith(_PACKAGE_DIR + os.sep)


def _internal(frame: Any) -> bool:
    """A frame of the package, or generated code (a dataclass ``__init__``) called by it."""
    if _in_package(frame):
        return True
    generated = frame.f_code.co_filename.startswith("<")
    return generated and frame.f_back is not None and _in_package(frame.f_back)


def emit_user_level_warning(message: str, category: type[Warning] = ImpactBeamWarning) -> None:
    """Warn with ``message``, located at the user's code (first frame outside impactbeam).

    Parameters
    ----------
    message : str
        One sentence naming the scenario key (when there is one) and what the
        user may want to do, e.g. ``"excitation.start: 0.5 s is after
        solver.end_time (0.2 s); the excitation never acts"``.
    category : type of Warning
        :class:`~impactbeam.exceptions.ImpactBeamWarning` (default) or a subclass.
    """
    warnings.warn(message, category, stacklevel=_stack_level())


class WarningLog:
    """Context manager recording the :class:`ImpactBeamWarning` s raised inside it.

    Other warnings are shown as usual when the block ends. Within the block,
    every ImpactBeamWarning is recorded (filter ``"always"``), so a repeated
    one is not lost to Python's once-per-location rule; :attr:`messages`
    lists each distinct message once, in order.

    Examples
    --------
    >>> with WarningLog() as log:
    ...     emit_user_level_warning("solver.modes: few modes")
    >>> log.messages
    ['solver.modes: few modes']
    """

    def __init__(self) -> None:
        self._catcher = warnings.catch_warnings(record=True)
        self._caught: list[warnings.WarningMessage] = []
        self._consumed = False

    def __enter__(self) -> WarningLog:
        self._caught = self._catcher.__enter__()  # type: ignore[assignment]
        warnings.simplefilter("always", ImpactBeamWarning)
        return self

    def __exit__(
        self, exc_type: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self._catcher.__exit__(exc_type, exc, tb)
        for w in self._caught:  # pass the others on, as if not recorded
            if not issubclass(w.category, ImpactBeamWarning):
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno, source=w.source)

    @property
    def messages(self) -> list[str]:
        """The distinct ImpactBeamWarning messages so far, in order."""
        out: list[str] = []
        for w in self._caught:
            if issubclass(w.category, ImpactBeamWarning):
                text = " ".join(str(w.message).split())
                if text not in out:
                    out.append(text)
        return out

    def take(self) -> list[str]:
        """:attr:`messages`, marking them reported (the command printed them itself)."""
        self._consumed = True
        return self.messages

    @property
    def consumed(self) -> bool:
        """Whether :meth:`take` was called."""
        return self._consumed
