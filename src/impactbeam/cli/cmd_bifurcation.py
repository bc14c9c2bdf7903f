"""``impactbeam bifurcation``: a bifurcation diagram of the harmonically forced beam.

``impactbeam bifurcation SCENARIO --parameter KEY (--values V1,V2,... | --range START STOP N)
[--sweep up|down|both] [--from-rest] [--settle-periods P] [--record-periods R]
[--out FILE.nc] [--plot FILE.png] [--json]`` (:func:`impactbeam.periodic.bifurcation.bifurcation`).

Exit status: 0 done (values whose period was not found are reported as
warnings); 2 bad input, one line on stderr; 1 a failed computation;
128 + signal number when interrupted (no file is written then).
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Callable, Iterator
from typing import Any

import click

from .._io import PLOT_SUFFIXES, check_output, json_text
from ._group import handle_errors, load_with_overrides, progress_bar, take_warnings
from ..exceptions import ParameterError

__all__ = ["bifurcation_command", "bifurcation_map_command", "frf_figure"]


def _values(parameter: str, values: str | None, span: tuple[str, str, str] | None, sc: Any,
            prefix: str = "") -> list[float]:
    from ..periodic.bifurcation import parameter_values

    opt_v, opt_r = (f"{prefix}-values", f"{prefix}-range") if prefix else ("--values", "--range")
    if (values is None) == (span is None):
        raise ParameterError(f"{opt_v} / {opt_r}: give exactly one of them")
    if values is not None:
        items = [v.strip() for v in values.split(",")]
        if any(not v for v in items):
            raise ParameterError(f"{opt_v}: expected V1,V2,... with no empty item, got {values!r}")
        return parameter_values(parameter, sc, items)
    assert span is not None
    a, b = parameter_values(parameter, sc, list(span[:2]))
    try:
        n = int(span[2])
    except ValueError:
        raise ParameterError(f"{opt_r}: N must be a whole number, got {span[2]!r}") from None
    if n < 1:
        raise ParameterError(f"{opt_r}: N must be at least 1, got {n}")
    import numpy as np

    return [float(v) for v in np.linspace(a, b, n)]


@contextlib.contextmanager
def _progress(desc: str = "bifurcation", unit: str = "value") -> Iterator[Callable[[int, int], None]]:
    """A ``progress(done, total)`` callback: a bar on stderr once the run takes a while."""
    bars: list[Any] = []
    with contextlib.ExitStack() as stack:

        def report(done: int, total: int) -> None:
            if not bars:
                bars.append(stack.enter_context(progress_bar(total, desc=desc, unit=unit)))
            bars[0](done)

        yield report


def _summary(diagram: Any) -> str:
    lines = [f"bifurcation over {diagram.parameter} ({len(diagram.points)} values, "
             f"{diagram.settle_periods} settle + {diagram.record_periods} recorded periods each)",
             f"{'value':>12} {'sweep':>5} {'period':>6} {'impacts/period':>14} {'max [mm]':>10} {'min [mm]':>10}"]
    for p in diagram.points:
        s = p.state
        per = str(s.period) if s.period else "-"
        lines.append(f"{p.value:12.6g} {p.direction:>5} {per:>6} {s.impacts_per_period:14.4g} "
                     f"{s.max * 1e3:10.4g} {s.min * 1e3:10.4g}")
    return "\n".join(lines)


def frf_figure(scenario: Any, diagram: Any, path: str | None = None) -> Any:
    """The frequency-response figure of ``--frf``: the diagram's extremes with the first contactor's surface.

    The strobe point is the first contactor, so its surface is drawn on its
    side: ``w = -gap`` for a contactor below the beam, ``+gap`` above.
    """
    from ..periodic.frf import from_diagram

    return from_diagram(scenario, diagram).plot(path, contactor=scenario.contactors[0] if scenario.contactors else None)


@click.command("bifurcation")
@click.argument("scenario", metavar="SCENARIO")
@click.option("--parameter", "parameter", required=True, metavar="KEY",
              help="Scenario key to vary (excitation.frequency, excitation.amplitude, contactors.0.gap, ...).")
@click.option("--values", "values", default=None, metavar="V1,V2,...",
              help="Parameter values (SI numbers or with units: '50 Hz').")
@click.option("--range", "span", nargs=3, default=None, metavar="START STOP N", help="N values from START to STOP.")
@click.option("--sweep", "sweep", type=click.Choice(["up", "down", "both"]), default="up", show_default=True,
              help="Increasing, decreasing, or up then down (hysteresis).")
@click.option("--from-rest", "from_rest", is_flag=True,
              help="Start every value from the scenario's initial condition, not the previous final state.")
@click.option("--settle-periods", "settle", type=int, default=100, show_default=True, metavar="P",
              help="Forcing periods discarded per value.")
@click.option("--record-periods", "record", type=int, default=50, show_default=True, metavar="R",
              help="Forcing periods recorded per value.")
@click.option("--out", "out", default=None, metavar="FILE.nc", help="netCDF dataset, dims (value, sample).")
@click.option("--plot", "plot", default=None, metavar="FILE.png", help="The diagram.")
@click.option("--frf", "frf", default=None, metavar="FILE.png",
              help="With --parameter excitation.frequency: the frequency-response curve (max, min, linear FRF).")
@click.option("--json", "as_json", is_flag=True, help="Print the points as JSON.")
@handle_errors
def bifurcation_command(scenario: str, parameter: str, values: str | None, span: tuple[str, str, str] | None,
                        sweep: str, from_rest: bool, settle: int, record: int, out: str | None, plot: str | None,
                        frf: str | None, as_json: bool) -> None:
    """Bifurcation diagram of SCENARIO (harmonic load) over the scenario key KEY.

    Each value is run SETTLE + RECORD forcing periods, starting from the
    previous value's final state (unless --from-rest), and sampled once per
    period at the first contactor (the first output point without one).
    """
    check_output("--out", out, (".nc",))
    check_output("--plot", plot, PLOT_SUFFIXES)
    check_output("--frf", frf, PLOT_SUFFIXES)
    if frf is not None and parameter != "excitation.frequency":
        raise ParameterError(f"--frf: needs --parameter excitation.frequency, got {parameter}")
    if settle < 0:
        raise ParameterError(f"--settle-periods: must be >= 0, got {settle}")
    if record < 2:
        raise ParameterError(f"--record-periods: must be >= 2, got {record}")
    from .._optional import require

    if out is not None:
        require("h5netcdf", "io", feature="--out .nc")
    if plot is not None or frf is not None:
        require("matplotlib", "plot", feature="--plot")
    sc = load_with_overrides(scenario)
    from ..periodic.bifurcation import bifurcation

    vals = _values(parameter, values, span, sc)
    with _progress() as report:
        diagram = bifurcation(sc, parameter, vals, sweep=sweep, from_rest=from_rest,  # type: ignore[arg-type]
                              settle_periods=settle, record_periods=record, progress=report)
    for option, path, write in (("--out", out, diagram.write), ("--plot", plot, diagram.plot),
                                ("--frf", frf, lambda p: frf_figure(sc, diagram, p))):
        if path is None:
            continue
        try:
            write(path)
        except OSError as exc:
            click.echo(f'error: {option}: cannot write "{path}": {exc.strerror or exc}', err=True)
            sys.exit(1)
    if as_json:
        click.echo(json_text({**diagram.to_dict(), "warnings": take_warnings()}))
    else:  # the table alone on stdout; the warnings go to stderr (handle_errors, when the command ends)
        click.echo(_summary(diagram))
    for label, path in (("dataset", out), ("figure", plot), ("frequency-response figure", frf)):
        if path is not None:
            click.echo(f"wrote {label} to {path}", err=True)


@click.command("bifurcation-map")
@click.argument("scenario", metavar="SCENARIO")
@click.option("--x", "x_key", required=True, metavar="KEY", help="Parameter along each row (swept with continuation).")
@click.option("--x-values", "x_values", default=None, metavar="V1,V2,...")
@click.option("--x-range", "x_span", nargs=3, default=None, metavar="START STOP N")
@click.option("--y", "y_key", required=True, metavar="KEY", help="Parameter across rows (one task per value).")
@click.option("--y-values", "y_values", default=None, metavar="V1,V2,...")
@click.option("--y-range", "y_span", nargs=3, default=None, metavar="START STOP N")
@click.option("--out", "out", required=True, metavar="MAP.zarr",
              help="Zarr store; an existing store of the same map is resumed.")
@click.option("--sweep", "sweep", type=click.Choice(["up", "down"]), default="up", show_default=True)
@click.option("--settle-periods", "settle", type=int, default=100, show_default=True, metavar="P")
@click.option("--record-periods", "record", type=int, default=20, show_default=True, metavar="R")
@click.option("--workers", "workers", type=int, default=None, metavar="N",
              help="Worker processes of a local Dask cluster [default: all cores]; 0 runs in this process.")
@click.option("--scheduler", "scheduler", default=None, metavar="ADDRESS", help="A running Dask scheduler.")
@click.option("--plot", "plot", default=None, metavar="FILE.png", help="Period and impacts per period over (x, y).")
@handle_errors
def bifurcation_map_command(scenario: str, x_key: str, x_values: str | None, x_span: tuple[str, str, str] | None,
                            y_key: str, y_values: str | None, y_span: tuple[str, str, str] | None, out: str,
                            sweep: str, settle: int, record: int, workers: int | None, scheduler: str | None,
                            plot: str | None) -> None:
    """Map the period and impacts per period of SCENARIO's steady state over two scenario keys.

    Each --y value is one task (a continuation sweep along --x) on a Dask
    cluster; rows are stored in MAP.zarr as they finish, so an interrupted
    map resumes where it stopped when the same command is run again.
    """
    check_output("--plot", plot, PLOT_SUFFIXES)
    if not out.rstrip("/").endswith(".zarr"):
        raise ParameterError(f'--out: expected a directory name ending in .zarr, got "{out}"')
    if settle < 0:
        raise ParameterError(f"--settle-periods: must be >= 0, got {settle}")
    if record < 2:
        raise ParameterError(f"--record-periods: must be >= 2, got {record}")
    if workers is not None and workers < 0:
        raise ParameterError(f"--workers: must be >= 0, got {workers}")
    from ..periodic.maps import bifurcation_map
    from ..plot.periodic import plot_map

    sc = load_with_overrides(scenario)
    xs = _values(x_key, x_values, x_span, sc, "--x")
    ys = _values(y_key, y_values, y_span, sc, "--y")
    with _progress(desc="map", unit="row") as report:
        ds = bifurcation_map(sc, (x_key, xs), (y_key, ys), out, sweep=sweep, settle_periods=settle,
                             record_periods=record, workers=workers, scheduler=scheduler, progress=report)
    if plot is not None:
        try:
            plot_map(ds, plot)
        except OSError as exc:
            click.echo(f'error: --plot: cannot write "{plot}": {exc.strerror or exc}', err=True)
            sys.exit(1)
    none = int(((ds["period"].values == 0) & ds["done"].values[:, None]).sum())
    click.echo(f"map of {y_key} x {x_key}: {ds.sizes['y']} x {ds.sizes['x']} steady states in {out}")
    if none:
        click.echo(f"warning: {none} of them without a period within the record (period = 0 in the store)", err=True)
    if plot is not None:
        click.echo(f"wrote figure to {plot}", err=True)
