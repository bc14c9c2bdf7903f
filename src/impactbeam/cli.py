"""The ``impactbeam`` command line: thin wrappers around the Python API.

Every command reports bad input (:class:`~impactbeam.exceptions.ParameterError`,
which includes :class:`~impactbeam.exceptions.ScenarioError`) as exactly one
line ``error: <message>`` on stderr and exits with status 2; a failed
computation (:class:`~impactbeam.exceptions.SimulationError` and other
:class:`~impactbeam.exceptions.ImpactBeamError`) exits with status 1. Never a
traceback for those.

Heavy modules (numpy, the solver, matplotlib) are imported inside the
commands, so ``impactbeam --help`` stays fast.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import json
import math
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any, TypeVar

import click

from ._warnings import WarningLog
from .exceptions import ImpactBeamError, ParameterError

__all__ = ["main", "to_jsonable", "handle_errors", "take_warnings", "warning_lines"]

F = TypeVar("F", bound=Callable[..., Any])

#: File types accepted by ``simulate --out`` (written by impactbeam.result.write_result).
RESULT_SUFFIXES = (".nc", ".csv", ".parquet")
#: File types accepted by ``simulate --plot`` (matplotlib formats).
PLOT_SUFFIXES = (".png", ".pdf", ".svg", ".jpg", ".jpeg", ".eps", ".ps", ".tif", ".tiff", ".webp")


def _fail(message: str, status: int) -> None:
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
                _fail(str(exc), 2)
            except ImpactBeamError as exc:  # SimulationError, ModeSolveError, ...
                _fail(str(exc), 1)
            finally:
                _WARNING_LOG.reset(token)
        if not log.consumed:
            for line in warning_lines(log.messages):
                click.echo(line, err=True)
        return out

    return wrapper  # type: ignore[return-value]


def to_jsonable(value: Any) -> Any:
    """Convert ``value`` for :func:`json.dumps`: numpy scalars and arrays to Python
    numbers and lists, tuples to lists, NaN, infinity and None to ``null``."""
    import numpy as np

    if isinstance(value, Mapping):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return [to_jsonable(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, Path):
        return str(value)
    return str(value)


def _dumps(obj: Any) -> str:
    return json.dumps(to_jsonable(obj), allow_nan=False)


def _number_or_text(value: Any) -> Any:
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            return value
    return value


def _load(path: str, overrides: Mapping[str, Any] | None = None) -> Any:
    from .scenario import load_scenario

    scenario = load_scenario(path)
    # a command-line number is documented as SI: pass it as a number (a string would be a unit-less string)
    overrides = {k: _number_or_text(v) for k, v in (overrides or {}).items() if v is not None}
    if overrides:
        scenario = scenario.with_values(overrides)
    return scenario


def _check_output(option: str, path: str | None, suffixes: tuple[str, ...]) -> None:
    """Reject an unsupported suffix or a missing directory before any computing."""
    if path is None:
        return
    p = Path(path)
    if not path.strip():
        raise ParameterError(f"{option}: the file name is empty (use {', '.join(suffixes)})")
    if p.is_dir() or path.endswith(("/", "\\")):
        raise ParameterError(
            f'{option}: "{path}" is a directory; give a file name in it, e.g. "{p / ("result" + suffixes[0])}"'
        )
    if p.suffix.lower() not in suffixes:
        raise ParameterError(
            f'{option}: unsupported file type "{p.suffix or p.name}" (use {", ".join(suffixes)})'
        )
    if not p.parent.is_dir():
        raise ParameterError(f'{option}: directory "{p.parent}" does not exist')


class Interrupted(KeyboardInterrupt):
    """SIGTERM (or SIGINT) received: the command stops, keeping finished work, exit 128 + signum."""

    def __init__(self, signum: int) -> None:
        super().__init__(f"interrupted by signal {signum}")
        self.signum = signum


def _raise_interrupted(signum: int, frame: Any) -> None:
    raise Interrupted(signum)


class _Commands(click.Group):
    """The command group: Ctrl-C exits 130 and SIGTERM 143, with one line, never a traceback."""

    def main(self, *args: Any, **kwargs: Any) -> Any:
        previous = None
        if threading.current_thread() is threading.main_thread():
            previous = signal.signal(signal.SIGTERM, _raise_interrupted)
        try:
            return super().main(*args, **kwargs)
        finally:
            if previous is not None:
                signal.signal(signal.SIGTERM, previous)

    def invoke(self, ctx: click.Context) -> Any:
        try:
            return super().invoke(ctx)
        except KeyboardInterrupt as exc:
            signum = int(getattr(exc, "signum", signal.SIGINT))
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


# --------------------------------------------------------------------------- modes


@main.command()
@click.argument("scenario", metavar="SCENARIO")
@click.option("--count", "count", type=int, default=None,
              help="Number of modes per state [default: the scenario's solver.modes].")
@click.option("--json", "as_json", is_flag=True, help="Print JSON instead of a table.")
@click.option("--plot", "plot_path", default=None, metavar="FILE.png",
              help="Draw the free-state mode shapes with steps, springs, masses and contactors marked.")
@handle_errors
def modes(scenario: str, count: int | None, as_json: bool, plot_path: str | None = None) -> None:
    """Natural frequencies of the free and the contact state.

    The contact state has every contactor engaged; it is omitted without
    contactors. Section steps, point masses and permanent springs
    (``[[beam.sections]]``, ``[[masses]]``, ``[[springs]]``) belong to both
    states; the JSON then has a ``structure`` entry listing them.
    """
    from .solver.options import MAX_MODES

    if count is not None and not 1 <= count <= MAX_MODES:
        raise ParameterError(f"--count: expected 1 to {MAX_MODES} modes (the limit of solver.modes), got {count}")
    if count is not None and count < 1:
        raise ParameterError(f"--count: must be a positive integer, got {count}")
    sc = _load(scenario)
    from .modes import scenario_modes

    n = sc.solver.modes if count is None else count
    ms = scenario_modes(sc, n)
    free = [float(f) for f in ms.free.frequencies_hz]
    contact = None if ms.contact is None else [float(f) for f in ms.contact.frequencies_hz]
    if plot_path is not None:
        from .modeplot import plot_modes

        plot_modes(ms.free, count=min(n, 6), contactors=sc.contactors, path=plot_path,
                   title=f"{sc.name}: free-state mode shapes")
    if as_json:
        out: dict[str, Any] = {"free": {"frequencies_hz": free}}
        if contact is not None:
            out["contact"] = {"frequencies_hz": contact}
        if not sc.beam.is_uniform:
            out["structure"] = _structure(sc.beam)
        click.echo(_dumps(out))
        return
    click.echo(_modes_table(sc, ms, free, contact))


def _structure(beam: Any) -> dict[str, Any]:
    """Steps, point masses and permanent springs of a beam, for the JSON of ``modes`` (SI; "inf" = rigid)."""
    lengths = [p.length for p in beam.pieces()]
    rigid = lambda k: "inf" if math.isinf(k) else k  # noqa: E731 - the scenario's spelling of a rigid spring
    return {
        "section_steps": [math.fsum(lengths[: i + 1]) for i in range(len(lengths) - 1)],
        "masses": [{"position": m.position, "mass": m.mass, "rotary_inertia": m.rotary_inertia} for m in beam.masses],
        "springs": [{"position": s.position, "translational": rigid(s.translational), "rotational": rigid(s.rotational)}
                    for s in beam.springs],
    }


def _modes_table(sc: Any, ms: Any, free: list[float], contact: list[float] | None) -> str:
    n_contactors = len(sc.contactors)
    title = f"Natural frequencies of {sc.name!r}: {sc.beam.left.describe()}-{sc.beam.right.describe()} beam"
    b = sc.beam
    extras = [f"{len(b.sections)} sections" if b.sections else "",
              f"{len(b.masses)} point mass{'es' if len(b.masses) > 1 else ''}" if b.masses else "",
              f"{len(b.springs)} interior spring{'s' if len(b.springs) > 1 else ''}" if b.springs else ""]
    if any(extras):
        title += " with " + ", ".join(e for e in extras if e)
    if n_contactors:
        title += f", {n_contactors} contactor{'s' if n_contactors > 1 else ''} (contact state: all engaged)"
    rows = max(len(free), len(contact or []))
    headers = ["mode", "free f [Hz]"] + (["contact f [Hz]"] if contact is not None else [])

    def cell(values: list[float], i: int, n_rigid: int) -> str:
        if i >= len(values):
            return ""
        return "0 (rigid)" if i < n_rigid else f"{values[i]:.4f}"

    table = []
    for i in range(rows):
        row = [str(i + 1), cell(free, i, int(ms.free.n_rigid))]
        if contact is not None:
            row.append(cell(contact, i, int(ms.contact.n_rigid)))
        table.append(row)
    widths = [max(len(h), *(len(r[j]) for r in table)) if table else len(h) for j, h in enumerate(headers)]
    lines = [title, "  ".join(h.rjust(w) for h, w in zip(headers, widths))]
    lines += ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in table]
    return "\n".join(lines)


# --------------------------------------------------------------------------- simulate


@main.command()
@click.argument("scenario", metavar="SCENARIO")
@click.option("--json", "as_json", is_flag=True, help="Print the metrics as JSON.")
@click.option("--out", "out", default=None, metavar="FILE",
              help="Write the full result (.nc, .csv or .parquet).")
@click.option("--plot", "plot", default=None, metavar="FILE", help="Save a figure (e.g. .png, .pdf).")
@click.option("--modes", "n_modes", default=None, metavar="N|auto",
              help='Override solver.modes (modes per state, or "auto").')
@click.option("--time-step", "time_step", default=None, metavar="DT",
              help='Override solver.time_step [s]; a unit is allowed ("10 us").')
@click.option("--end-time", "end_time", default=None, metavar="T",
              help='Override solver.end_time [s]; a unit is allowed ("500 ms").')
@handle_errors
def simulate(
    scenario: str,
    as_json: bool,
    out: str | None,
    plot: str | None,
    n_modes: str | None,
    time_step: str | None,
    end_time: str | None,
) -> None:
    """Simulate SCENARIO and print the response metrics.

    The metrics are those of w at the first contactor (or the first output
    point without contactors), as u positive away from the contactor
    (u = -w for a contactor above the beam, u = w below).
    """
    _check_output("--out", out, RESULT_SUFFIXES)
    _check_output("--plot", plot, PLOT_SUFFIXES)
    modes: int | str | None = n_modes
    if n_modes is not None and n_modes.strip().lstrip("+").isdigit():
        modes = int(n_modes)
    sc = _load(
        scenario,
        {"solver.modes": modes, "solver.time_step": time_step, "solver.end_time": end_time},
    )
    from .solver import simulate as run

    # import the writers before the (possibly long) run, so a broken install fails fast
    from ._optional import require

    if out is not None:
        from .result import check_output_size, write_result

        backend = {".nc": "h5netcdf", ".parquet": "pyarrow"}.get(Path(out).suffix.lower())
        if backend:
            require(backend, "io", feature=f"--out {Path(out).suffix.lower()}")
        n_t = int(math.floor(sc.solver.end_time / sc.solver.time_step * (1.0 + 1e-12))) + 1
        n_m = 200 if sc.solver.modes == "auto" else int(sc.solver.modes)
        check_output_size(n_t, len(sc.output_points), len(sc.contactors), n_m)  # before any work
    if plot is not None:
        require("matplotlib", "plot", feature="--plot")
        from .plot import plot_result

    with _progress(sc.solver.end_time) as report:
        result = run(sc, progress=report)
    metrics = result.metrics()
    metrics["modes"] = result.n_modes
    metrics["convergence"] = result.convergence  # computed now, so its warning is caught below
    if out is not None:
        try:
            write_result(result, out)
        except OSError as exc:
            _fail(f'--out: cannot write "{out}": {exc.strerror or exc}', 1)
        except ImportError as exc:  # an optional writer backend is missing
            _fail(f'--out: cannot write "{out}": {exc}', 1)
    if plot is not None:
        try:
            plot_result(result, plot, excitation=sc.excitation)
        except OSError as exc:
            _fail(f'--plot: cannot write "{plot}": {exc.strerror or exc}', 1)
        except ImportError as exc:
            _fail(f'--plot: cannot write "{plot}": {exc}', 1)
    caught = take_warnings()
    if as_json:
        click.echo(_dumps({**metrics, "warnings": caught}))
    else:
        click.echo("\n".join([_summary(sc, metrics), *warning_lines(caught)]))
    for label, path in (("result", out), ("figure", plot)):
        if path is not None:
            click.echo(f"wrote {label} to {path}", err=True)


@contextlib.contextmanager
def _progress(end_time: float, after: float = 2.0) -> Iterator[Callable[[float], None]]:
    """A progress callback that shows a bar on stderr once a run has taken ``after`` seconds."""
    start = time.monotonic()
    bar: Any = None

    def report(t: float) -> None:
        nonlocal bar
        if bar is None and time.monotonic() - start > after:
            from tqdm import tqdm

            bar = tqdm(total=end_time, unit="s", unit_scale=True, desc="simulate", file=sys.stderr,
                       bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.4g}/{total:.4g} s simulated [{elapsed}<{remaining}]")
        if bar is not None:
            bar.update(max(0.0, min(t, end_time) - bar.n))

    try:
        yield report
    finally:
        if bar is not None:
            bar.close()


def _number(value: Any) -> float | None:
    try:
        x = float(value)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None




def _summary(sc: Any, metrics: Mapping[str, Any]) -> str:
    from .metrics import METRIC_DISPLAY

    if sc.contactors:
        c = sc.contactors[0]
        where = (
            f"u at the first contactor, x = {c.position * 1e3:.4g} mm "
            f"(side {c.side}: u = {'-w' if c.side == 'above' else 'w'}, positive away from it)"
        )
    else:
        where = f"u = w at x = {sc.output_points[0] * 1e3:.4g} mm"
    lines = [f"Simulation of {sc.name!r}: {where}"]
    rows = []
    shown = {"events"}
    for key, label, scale, unit in METRIC_DISPLAY:
        if key not in metrics:
            continue
        shown.add(key)
        x = _number(metrics[key])
        if key == "n_impacts" and x is not None:
            text = str(int(x))
        else:
            text = "n/a" if x is None else f"{x * scale:.4f} {unit}".rstrip()
        rows.append((label, text))
    for key, value in metrics.items():  # anything the lead adds later
        if key in shown or isinstance(value, (list, tuple, dict)):
            continue
        x = _number(value)
        rows.append((key.replace("_", " "), "n/a" if x is None else f"{x:.6g}"))
    width = max((len(r[0]) for r in rows), default=0)
    lines += [f"  {label.ljust(width)}  {text}" for label, text in rows]
    events = list(metrics.get("events") or [])
    if events:
        lines.append(f"  events ({len(events)}):")
        for ev in events[:20]:
            t = _number(ev.get("time"))
            lines.append(
                f"    {'n/a' if t is None else f'{t * 1e3:10.4f} ms'}  {ev.get('kind', '?'):<8}"
                f"contactor {ev.get('contactor', '?')}"
            )
        if len(events) > 20:
            lines.append(f"    ... {len(events) - 20} more (use --json for all)")
    conv = metrics.get("convergence")
    if conv:
        key = max(conv, key=lambda k: conv[k])
        lines.append(f"  modes: {metrics.get('modes')}; largest relative change against fewer modes: "
                     f"{conv[key]:.2g} ({key})")
    return "\n".join(lines)


# --------------------------------------------------------------------------- info


_INFO_PACKAGES = ("numpy", "scipy", "xarray", "dask", "matplotlib", "pint")


@main.command()
@handle_errors
def info() -> None:
    """Versions of impactbeam, Python and the main dependencies."""
    import platform
    from importlib.metadata import PackageNotFoundError, version

    def ver(name: str) -> str:
        try:
            return version(name)
        except PackageNotFoundError:
            return "not installed"

    rows = [("impactbeam", ver("impactbeam")), ("python", platform.python_version())]
    rows += [(name, ver(name)) for name in _INFO_PACKAGES]
    width = max(len(n) for n, _ in rows)
    for name, v in rows:
        click.echo(f"{name.ljust(width)}  {v}")


# --------------------------------------------------------------------------- more subcommands
# ============================================================================
# Other modules register their subcommands HERE (the lead adds them):
#   from .paper import reproduce_command; main.add_command(reproduce_command, "reproduce")
#   sweep, plot, identify, compare, fit ...
# Wrap each command body with @handle_errors so bad input exits 2 with one line.
# ============================================================================

from .commands import register as _register_commands  # noqa: E402

_register_commands(main)


if __name__ == "__main__":
    main()
