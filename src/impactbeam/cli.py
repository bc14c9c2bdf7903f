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

import functools
import json
import math
import sys
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, TypeVar

import click

from .exceptions import ImpactBeamError, ParameterError

__all__ = ["main", "to_jsonable"]

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


def handle_errors(fn: F) -> F:
    """Decorator for commands: bad input -> exit 2, failed computation -> exit 1.

    Other modules that register subcommands should use it too.
    """

    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        try:
            return fn(*args, **kwargs)
        except ParameterError as exc:
            _fail(str(exc), 2)
        except ImpactBeamError as exc:  # SimulationError, ModeSolveError, ...
            _fail(str(exc), 1)

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


def _load(path: str, overrides: Mapping[str, Any] | None = None) -> Any:
    from .scenario import load_scenario

    scenario = load_scenario(path)
    overrides = {k: v for k, v in (overrides or {}).items() if v is not None}
    if overrides:
        scenario = scenario.with_values(overrides)
    return scenario


def _check_output(option: str, path: str | None, suffixes: tuple[str, ...]) -> None:
    """Reject an unsupported suffix or a missing directory before any computing."""
    if path is None:
        return
    p = Path(path)
    if p.suffix.lower() not in suffixes:
        raise ParameterError(
            f'{option}: unsupported file type "{p.suffix or p.name}" (use {", ".join(suffixes)})'
        )
    if not p.parent.is_dir():
        raise ParameterError(f'{option}: directory "{p.parent}" does not exist')


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
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
@handle_errors
def modes(scenario: str, count: int | None, as_json: bool) -> None:
    """Natural frequencies of the free and the contact state.

    The contact state has every contactor engaged; it is omitted without
    contactors.
    """
    if count is not None and count < 1:
        raise ParameterError(f"--count: must be a positive integer, got {count}")
    sc = _load(scenario)
    from .modes import scenario_modes

    n = sc.solver.modes if count is None else count
    ms = scenario_modes(sc, n)
    free = [float(f) for f in ms.free.frequencies_hz]
    contact = None if ms.contact is None else [float(f) for f in ms.contact.frequencies_hz]
    if as_json:
        out: dict[str, Any] = {"free": {"frequencies_hz": free}}
        if contact is not None:
            out["contact"] = {"frequencies_hz": contact}
        click.echo(_dumps(out))
        return
    click.echo(_modes_table(sc, ms, free, contact))


def _modes_table(sc: Any, ms: Any, free: list[float], contact: list[float] | None) -> str:
    n_contactors = len(sc.contactors)
    title = f"Natural frequencies of {sc.name!r}: {sc.beam.left.describe()}-{sc.beam.right.describe()} beam"
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
@click.option("--modes", "n_modes", type=int, default=None, metavar="N",
              help="Override solver.modes (modes per state).")
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
    n_modes: int | None,
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
    sc = _load(
        scenario,
        {"solver.modes": n_modes, "solver.time_step": time_step, "solver.end_time": end_time},
    )
    from .solver import simulate as run

    # import the writers before the (possibly long) run, so a broken install fails fast
    from ._optional import require

    if out is not None:
        from .result import write_result

        backend = {".nc": "h5netcdf", ".parquet": "pyarrow"}.get(Path(out).suffix.lower())
        if backend:
            require(backend, "io", feature=f"--out {Path(out).suffix.lower()}")
    if plot is not None:
        require("matplotlib", "plot", feature="--plot")
        from .plot import plot_result

    result = run(sc)
    metrics = result.metrics()
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
    if as_json:
        click.echo(_dumps(metrics))
    else:
        click.echo(_summary(sc, metrics))
    for label, path in (("result", out), ("figure", plot)):
        if path is not None:
            click.echo(f"wrote {label} to {path}", err=True)


def _number(value: Any) -> float | None:
    try:
        x = float(value)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


# (key, label, scale, unit) of the metrics, in print order
_METRIC_ROWS = (
    ("max_response", "max response", 1e3, "mm"),
    ("t_max", "  at time", 1e3, "ms"),
    ("free_duration", "free duration", 1e3, "ms"),
    ("contact_duration", "contact duration", 1e3, "ms"),
    ("min_response", "min response", 1e3, "mm"),
    ("first_impact_time", "first impact", 1e3, "ms"),
    ("n_impacts", "impacts", 1.0, ""),
    ("max_penetration", "max penetration", 1e3, "mm"),
)


def _summary(sc: Any, metrics: Mapping[str, Any]) -> str:
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
    for key, label, scale, unit in _METRIC_ROWS:
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
