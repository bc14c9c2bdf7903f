"""The ``impactbeam`` command group and what every subcommand shares.

Every command reports bad input (:class:`~impactbeam.exceptions.ParameterError`,
which includes :class:`~impactbeam.exceptions.ScenarioError`) as exactly one
line ``error: <message>`` on stderr and exits with status 2; a failed
computation (:class:`~impactbeam.exceptions.SimulationError` and other
:class:`~impactbeam.exceptions.ImpactBeamError`) exits with status 1, and so
does a file that cannot be written (:class:`~impactbeam._io.WriteError`, its
line prefixed by the option the path came from, ``--out: cannot write ...``),
any other operating-system error and running out of memory. Never a
traceback for those.

Ctrl-C ends a command with status 130 and SIGTERM with 143, with one line
and never a traceback (:class:`_Commands`). Warnings raised while a command
runs are collected (:func:`take_warnings`) so the command can show them in its
summary and its ``--json``.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import os
import signal
import sys
import threading
from collections.abc import Callable, Iterator, Mapping
from typing import Any, NoReturn, TypeVar

import click

from .._warnings import Progress, WarningLog
from ..exceptions import ImpactBeamError, ParameterError

__all__ = ["main", "console_main", "handle_errors", "take_warnings", "warning_lines", "load_with_overrides", "Interrupted", "fail", "progress_bar", "number_or_text"]

F = TypeVar("F", bound=Callable[..., Any])

def fail(message: str, status: int) -> NoReturn:
    """Print one ``error:`` line on stderr and exit with ``status``."""
    one_line = " ".join(str(message).split())
    click.echo(f"error: {one_line}", err=True)
    sys.exit(status)


_WARNING_LOG: contextvars.ContextVar[WarningLog | None] = contextvars.ContextVar("warning_log", default=None)


def take_warnings() -> list[str]:
    """The ImpactBeamWarnings raised so far in the running command (each once).

    A command that reports them itself (in its summary as ``warning: ...``
    lines and in ``--json`` as ``"warnings"``) calls this; otherwise
    :func:`handle_errors` prints them on stderr when the command ends.
    """
    log = _WARNING_LOG.get()
    return [] if log is None else log.take()


def pending_warnings() -> list[str]:
    """The ImpactBeamWarnings raised so far in the running command, left to be reported (:func:`take_warnings`)."""
    log = _WARNING_LOG.get()
    return [] if log is None else log.messages


def warning_lines(messages: list[str]) -> list[str]:
    """``warning: <message>`` lines for a terminal summary."""
    return [f"warning: {m}" for m in messages]


def handle_errors(fn: F) -> F:
    """Decorator for commands: bad input -> exit 2, failed computation -> exit 1.

    It also records the :class:`~impactbeam.exceptions.ImpactBeamWarning` s
    raised during the command (see :func:`take_warnings`); those the command
    did not report are printed on stderr as ``warning: ...`` when it succeeds
    (an error exit prints only its one ``error:`` line). Other modules that
    register subcommands should use it too.
    """

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        with WarningLog() as log:
            token = _WARNING_LOG.set(log)
            try:
                out = fn(*args, **kwargs)
            except ParameterError as exc:
                fail(_as_option(str(exc)), 2)
            except ImpactBeamError as exc:  # SimulationError, ModeSolveError, WriteError ...
                fail(_named(exc), 1)
            except OSError as exc:  # a file or a port the command did not report itself
                fail(_os_error(exc), 1)
            except MemoryError:
                fail("out of memory: the request is larger than this machine can hold; ask for less "
                     "(a larger solver.time_step, fewer points, modes or cases)", 1)
            finally:
                _WARNING_LOG.reset(token)
        if not log.consumed:
            for line in warning_lines(log.messages):
                click.echo(line, err=True)
        return out

    return wrapper  # type: ignore[return-value]


def _as_option(message: str) -> str:
    """A message about an API argument (``multiple: ...``) named by the command's option (``--multiple: ...``)."""
    ctx = click.get_current_context(silent=True)
    name, sep, rest = message.partition(": ")
    if ctx is None or not sep:
        return message
    for param in ctx.command.params:
        if isinstance(param, click.Option) and param.name == name:
            return f"{max(param.opts, key=len)}: {rest}"
    return message


def _option_of(path: str) -> str | None:
    """The option (``--out``) or argument of the running command whose value is ``path``."""
    ctx = click.get_current_context(silent=True)
    if ctx is None:
        return None
    target = os.path.normpath(path)
    for param in ctx.command.params:
        value = ctx.params.get(param.name or "")
        if isinstance(value, str) and value and os.path.normpath(value) == target:
            if isinstance(param, click.Option):
                return max(param.opts, key=len)
            return param.human_readable_name
    return None


def _named(exc: ImpactBeamError) -> str:
    """The message, with the option a failed write came from (``--out: cannot write ...``)."""
    from .._io import WriteError

    if isinstance(exc, WriteError) and exc.option is None:
        option = _option_of(exc.path)
        if option is not None:
            return f"{option}: {exc}"
    return str(exc)


def _os_error(exc: OSError) -> str:
    """One line for an operating-system error: the option or file, and the system's reason."""
    reason = exc.strerror or " ".join(str(exc).split()) or type(exc).__name__
    name = exc.filename
    if name is None:
        return reason
    option = _option_of(os.fspath(name))
    return f'{option + ": " if option else ""}"{os.fspath(name)}": {reason}'


def number_or_text(value: Any) -> Any:
    """A command-line value as a number when it reads as one (SI), else the text (a value with its unit)."""
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return value
    return value


def load_with_overrides(path: str, overrides: Mapping[str, Any] | None = None) -> Any:
    """The scenario at ``path`` with command-line ``overrides`` (dotted key -> value; None = not given)."""
    from ..scenario import load_scenario

    scenario = load_scenario(path)
    # a command-line number is documented as SI: pass it as a number (a string would be a unit-less string)
    overrides = {k: number_or_text(v) for k, v in (overrides or {}).items() if v is not None}
    if overrides:
        scenario = scenario.with_values(overrides)
    return scenario


@contextlib.contextmanager
def progress_bar(
    total: float, *, desc: str, unit: str, after: float = 2.0, **tqdm_options: Any
) -> Iterator[Callable[[float], None]]:
    """A callback ``report(done)`` showing a command's progress on stderr (:class:`~impactbeam._warnings.Progress`).

    Parameters
    ----------
    total : float
        What ``done`` reaches at the end (simulated seconds, values, cases ...).
    desc, unit : str
        The label and unit.
    after : float, [s]
        Quiet for short commands: nothing before this much wall time.
    **tqdm_options
        Passed to :class:`tqdm.tqdm` on a terminal (e.g. ``unit_scale``, ``bar_format``).
    """
    with Progress(total, desc=desc, unit=unit, after=after, **tqdm_options) as report:
        yield report


class Interrupted(KeyboardInterrupt):
    """SIGTERM (or SIGINT) received: the command stops, keeping finished work, exit 128 + signum."""

    def __init__(self, signum: int) -> None:
        super().__init__(f"interrupted by signal {signum}")
        self.signum = signum


_received: list[int] = []  # the signal received, for the exit status and a re-delivery


def _raise_interrupted(signum: int, frame: Any) -> None:
    _received[:] = [int(signum)]
    raise Interrupted(int(signum))


def _redeliver(signum: int, frame: Any) -> None:
    if _received:
        raise Interrupted(_received[0])


def _unraisable(previous: Callable[[Any], Any]) -> Callable[[Any], None]:
    """An unraisable-exception hook that re-delivers a swallowed interruption.

    An exception raised by a signal handler is swallowed ("Exception ignored
    in ...") when the signal arrives while Python runs a finaliser or a weakref
    callback (matplotlib's transform tree runs them at every figure). The hook
    drops that report and raises the interruption again 10 ms later, in
    ordinary code, through a one-shot timer.
    """

    def hook(unraisable: Any) -> None:
        if isinstance(unraisable.exc_value, KeyboardInterrupt) and _received:
            signal.setitimer(signal.ITIMER_REAL, 0.01)
            return
        previous(unraisable)

    return hook


def _install_handlers() -> dict[int, Any]:
    """Our handlers for SIGTERM, SIGINT and the re-delivery timer; returns the previous ones."""
    if threading.current_thread() is not threading.main_thread():
        return {}
    handlers = {signal.SIGTERM: _raise_interrupted, signal.SIGINT: _raise_interrupted, signal.SIGALRM: _redeliver}
    return {sig: signal.signal(sig, handler) for sig, handler in handlers.items()}


def _handled() -> None:
    """The interruption reached the command group: no re-delivery."""
    if threading.current_thread() is threading.main_thread():
        signal.setitimer(signal.ITIMER_REAL, 0.0)
    _received.clear()


_NO_ARGS = getattr(click.exceptions, "NoArgsIsHelpError", ())  # click >= 8.2: the help for a bare group


def _usage_error(exc: click.UsageError) -> NoReturn:
    """A command-line usage error (unknown option or command, a value of the wrong type, a missing argument).

    One ``error:`` line naming the command and the problem, exit status 2, as
    for every bad input (click's own display takes three lines). A bare group
    (no command at all) shows its help, as click does.
    """
    if isinstance(exc, _NO_ARGS):
        raise exc
    ctx = getattr(exc, "ctx", None)
    where = f"{ctx.command_path}: " if ctx is not None else ""
    hint = f" (see {ctx.command_path} --help)" if ctx is not None else ""
    fail(f"{where}{exc.format_message().rstrip('.')}{hint}", exc.exit_code)


class _Commands(click.Group):
    """The command group: Ctrl-C exits 130 and SIGTERM 143, with one line, never a traceback; a usage error one line."""

    def make_context(self, info_name: str | None, args: list[str], parent: click.Context | None = None,
                     **extra: Any) -> click.Context:
        try:
            return super().make_context(info_name, args, parent=parent, **extra)
        except click.UsageError as exc:  # the group's own options
            _usage_error(exc)

    def main(self, *args: Any, **kwargs: Any) -> Any:
        previous = _install_handlers()
        hook, sys.unraisablehook = sys.unraisablehook, _unraisable(sys.unraisablehook)
        try:
            return super().main(*args, **kwargs)
        finally:
            _handled()
            sys.unraisablehook = hook
            for sig, handler in previous.items():
                signal.signal(sig, handler)

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except click.UsageError as exc:  # a command's options and arguments, or an unknown command
            _usage_error(exc)
        except KeyboardInterrupt as exc:
            _stop(exc)
        except Exception as exc:
            interrupt = _interrupt_behind(exc)
            if interrupt is None:
                raise
            _stop(interrupt)


def _interrupt_behind(exc: BaseException) -> KeyboardInterrupt | None:
    """The interruption an error was raised while handling, if any (its ``__context__`` chain).

    A library's clean-up can fail under a Ctrl-C and replace it: matplotlib's
    PDF writer, interrupted inside ``savefig``, raised an AttributeError while
    closing a stream the interrupt had left half-made, and the command ended
    with status 1 and a traceback instead of 130.
    """
    seen: set[int] = set()
    link: BaseException | None = exc
    while link is not None and id(link) not in seen:
        if isinstance(link, KeyboardInterrupt):
            return link
        seen.add(id(link))
        link = link.__context__
    return None


def _stop(exc: KeyboardInterrupt) -> None:
    """End an interrupted command: one line, finished files kept, status 128 + the signal's number."""
    signum = int(getattr(exc, "signum", _received[0] if _received else signal.SIGINT))
    _handled()
    click.echo(f"interrupted ({signal.Signals(signum).name}): stopped; finished files are kept, "
               "nothing half-written", err=True)
    sys.exit(128 + signum)


@click.group(cls=_Commands, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="impactbeam", prog_name="impactbeam")
def main() -> None:
    """Transient response of beams that impact stops (Xu & Ervin 2013, extended).

    A scenario is a TOML file (see examples/README.md). Bad input exits with
    status 2 and one line on stderr; a failed computation with status 1.
    """


def console_main() -> None:
    """The ``impactbeam`` script and ``python -m impactbeam``: the command group, then a quick exit.

    Once the command has returned (its files closed, its processes joined),
    the exit handlers run (:mod:`atexit`: logging, multiprocessing, progress
    bars), the standard streams are flushed and the process ends with
    :func:`os._exit`, without the interpreter's teardown of every object: a
    process that loaded the compiled kernels spent 0.25 s there releasing
    LLVM's code, after its work was done. Calling :data:`main` (tests,
    another program) ends normally.
    """
    try:
        main(prog_name="impactbeam")
        status: object = 0
    except SystemExit as exc:
        status = exc.code
    if status is None:
        code = 0
    elif isinstance(status, int):
        code = status
    else:  # sys.exit("text"): the text on stderr, status 1
        print(status, file=sys.stderr)
        code = 1
    import atexit

    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError):  # a closed pipe (impactbeam ... | head): nothing more to say
            code = code or 1
    os._exit(code)
