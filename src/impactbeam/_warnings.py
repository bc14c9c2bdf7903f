"""What a run tells its user on stderr besides its results: warnings and progress.

Every warning of the package goes through :func:`emit_user_level_warning`
(the pattern of xarray's ``emit_user_level_warning``): the category is
:class:`~impactbeam.exceptions.ImpactBeamWarning` and the reported location
is the first stack frame outside the package, i.e. the user's call of
``load_scenario`` or ``simulate``, not an internal line.

:class:`WarningLog` records the warnings raised while a command runs, for the
command line's summary and ``--json`` output.

:class:`Progress` reports the progress of long work (a simulation, a sweep,
the paper's reproduction): a :class:`tqdm.tqdm` bar redrawn in place on a
terminal, and whole lines into a file or a pipe (a CI log, ``2> log``), where
a bar's carriage returns would run into the warning lines that follow.
"""

from __future__ import annotations

import math
import os
import sys
import time
import warnings
from types import TracebackType
from typing import Any

from .exceptions import ImpactBeamWarning

__all__ = ["Progress", "WarningLog", "emit_user_level_warning"]

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


#: Seconds between two progress lines written into a file or a pipe.
LINE_EVERY = 10.0


class Progress:
    """Progress of long work on stderr, shown once it has run ``after`` seconds.

    Call it with the work done so far (``progress(done)``) or advance it
    (``progress.advance(n)``); :meth:`close` it at the end (or use it as a
    context manager). On a terminal it is a :class:`tqdm.tqdm` bar; into a
    file or a pipe it is whole lines, ``desc: 40% (4/10 cases) after 12 s``,
    at most one every :data:`LINE_EVERY` seconds and one at the end (where
    an interrupted or failed run stopped).

    Parameters
    ----------
    total : float
        What ``done`` reaches at the end (simulated seconds, cases, steps ...).
    desc, unit : str
        The label and unit.
    after : float, [s]
        Quiet for short work: nothing before this much wall time.
    enabled : bool
        False: report nothing.
    done : float
        Work already done at the start (a resumed sweep).
    **tqdm_options
        Passed to :class:`tqdm.tqdm` (e.g. ``unit_scale``, ``bar_format``).
    """

    def __init__(self, total: float, *, desc: str, unit: str, after: float = 2.0, enabled: bool = True,
                 done: float = 0.0, **tqdm_options: Any) -> None:
        self.total = float(total)
        self.desc, self.unit, self.after, self.enabled = desc, unit, after, enabled
        self._options = tqdm_options
        self._start = time.monotonic()
        self._done = float(done)
        self._bar: Any = None
        self._last = -math.inf
        self._shown = False
        self._closed = False  # later reports (work that outlived its bar) are not shown
        self._interactive = _is_terminal(sys.stderr)

    def __call__(self, done: float) -> None:
        self._done = max(0.0, min(float(done), self.total))
        if not self.enabled or self._closed or time.monotonic() - self._start <= self.after:
            return
        if not self._interactive:
            if time.monotonic() - self._last >= LINE_EVERY:
                self._line()
            return
        if self._bar is None:
            from tqdm import tqdm

            self._bar = tqdm(total=self.total, unit=self.unit, desc=self.desc, file=sys.stderr, **self._options)
        self._bar.update(self._done - self._bar.n)

    def advance(self, n: float = 1.0) -> None:
        """Count ``n`` more done."""
        self(self._done + n)

    def close(self) -> None:
        """The bar's last state, or the last line, is out before anything else is written."""
        self._closed = True
        if self._bar is not None:
            self._bar.close()
            self._bar = None
        elif self._shown:
            self._line()  # the end, or where an interrupted or failed run stopped
            self._shown = False
        sys.stderr.flush()

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def _line(self) -> None:
        pct = 100.0 * self._done / self.total if self.total > 0 else 100.0
        unit = f" {self.unit}" if self.unit else ""
        print(f"{self.desc}: {pct:3.0f}% ({self._done:.4g}/{self.total:.4g}{unit}) after "
              f"{time.monotonic() - self._start:.0f} s", file=sys.stderr, flush=True)
        self._last = time.monotonic()
        self._shown = True


def _is_terminal(stream: Any) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False
