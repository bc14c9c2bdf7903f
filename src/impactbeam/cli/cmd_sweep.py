"""``impactbeam sweep`` and ``impactbeam plot``: parameter studies from the command line.

``impactbeam sweep SWEEP.toml --out RESULTS.zarr [--workers N | --scheduler ADDRESS] [--batch-size B]``
runs (or resumes) a sweep (:func:`impactbeam.sweep.sweep`); ``impactbeam plot
RESULTS.zarr --x PARAM [--y PARAM] --metric NAME [--sel PARAM=VALUE] [--out FILE.png]``
draws one metric as a line or a heat map (:func:`impactbeam.sweep.plot_sweep`).

Exit status: 0 done (failed cases are recorded in the store, not fatal);
2 bad input (sweep file, options, a store made by another sweep), one line on
stderr; 1 a failed computation; 128 + signal number when interrupted by
SIGINT/SIGTERM (the store keeps every finished batch: run the same command
again to finish).
"""

from __future__ import annotations

import sys
from pathlib import Path

import click

from .._io import PLOT_SUFFIXES, check_output
from ._group import handle_errors
from .._optional import require
from ..exceptions import ParameterError

__all__ = ["sweep_command", "plot_command"]


@click.command("sweep")
@click.argument("sweep_file", metavar="SWEEP.toml")
@click.option("--out", "out", required=True, metavar="RESULTS.zarr",
              help="Zarr store for the results; an existing store of the same sweep is resumed.")
@click.option("--workers", "workers", type=int, default=None, metavar="N",
              help="Worker processes of a local Dask cluster [default: all cores]; 0 runs in this process.")
@click.option("--scheduler", "scheduler", default=None, metavar="ADDRESS",
              help="Use a running Dask scheduler (e.g. tcp://127.0.0.1:8786) and its workers.")
@click.option("--batch-size", "batch_size", type=int, default=None, metavar="B",
              help="Cases per task and per Zarr chunk [default: about 16 batches, at most 1,000 cases each].")
@click.option("--on-error", "on_error", type=click.Choice(["record", "raise"]), default="record",
              show_default=True, help="record: a failed case is stored with its message; raise: stop.")
@click.option("--no-progress", "no_progress", is_flag=True, help="No progress bar.")
@handle_errors
def sweep_command(
    sweep_file: str,
    out: str,
    workers: int | None,
    scheduler: str | None,
    batch_size: int | None,
    on_error: str,
    no_progress: bool,
) -> None:
    """Run the parameter study SWEEP.toml and store its results in RESULTS.zarr.

    Starting the same command again after an interruption computes only the
    missing cases. A summary line goes to stderr.
    """
    if workers is not None and scheduler is not None:
        raise ParameterError("--workers and --scheduler exclude each other (a local cluster or a running one)")
    from ..sweeps.cluster import check_workers

    check_workers(workers)
    if batch_size is not None and batch_size < 1:
        raise ParameterError(f"--batch-size: must be a positive integer, got {batch_size}")
    from ..sweeps import SweepInterrupted, load_sweep, run_sweep

    spec = load_sweep(sweep_file)
    try:
        run = run_sweep(
            spec, out, workers=workers, scheduler=scheduler, batch_size=batch_size,
            progress=not no_progress, on_error=on_error,  # type: ignore[arg-type]
        )
    except SweepInterrupted as exc:
        click.echo(exc.summary("cases", str(out)), err=True)
        sys.exit(128 + exc.signum)
    failed = "" if not run.failed else f" ({run.failed} failed: see the status and message variables)"
    ds = run.dataset
    warned = int((ds["warnings"] != "").sum()) if "warnings" in ds else 0
    note = "" if not warned else f"; {warned} with warnings (see the warnings variable)"
    click.echo(
        f"sweep {spec.name}: {run.n_cases} cases, {run.computed} computed, {run.skipped} already done"
        f"{failed}{note}; results in {out}",
        err=True,
    )


def _parse_sel(items: tuple[str, ...]) -> dict[str, str]:
    sel: dict[str, str] = {}
    for item in items:
        name, eq, value = item.partition("=")
        if not eq or not name or not value:
            raise ParameterError(f"--sel: expected PARAM=VALUE, got {item!r}")
        sel[name.strip()] = value.strip()
    return sel


@click.command("plot")
@click.argument("results", metavar="SWEEP_RESULTS")
@click.option("--x", "x", required=True, metavar="PARAM", help="Parameter on the horizontal axis.")
@click.option("--y", "y", default=None, metavar="PARAM", help="Second parameter: a heat map.")
@click.option("--metric", "metric", required=True, metavar="NAME", help="Metric to plot (e.g. max_response).")
@click.option("--sel", "sel", multiple=True, metavar="PARAM=VALUE",
              help="Value of another grid parameter (repeatable) [default: its first value].")
@click.option("--out", "out", default=None, metavar="FILE",
              help="Figure file (.png, .pdf, .svg ...) [default: RESULTS-METRIC.png].")
@handle_errors
def plot_command(
    results: str, x: str, y: str | None, metric: str, sel: tuple[str, ...], out: str | None
) -> None:
    """Plot one metric of sweep results: a line over --x, or a heat map over --x and --y.

    Grid parameters not plotted take the value given with --sel, else their
    first value (a note on stderr says which).
    """
    path = Path(results)
    if out is None:
        out = f"{path.name.removesuffix('.zarr')}-{metric}.png"
    check_output("--out", out, PLOT_SUFFIXES)
    if not path.exists():
        raise ParameterError(f'SWEEP_RESULTS: "{results}" does not exist')
    selection = _parse_sel(sel)

    plt = require("matplotlib.pyplot", "plot", feature="impactbeam sweep-plot")
    import xarray as xr

    from ..sweeps import plot_sweep, select_cases

    try:
        ds = xr.open_zarr(str(path), consolidated=False, chunks=None)
    except Exception as exc:  # not a Zarr store
        raise ParameterError(f'SWEEP_RESULTS: "{results}" is not a sweep result ({type(exc).__name__})') from None
    if "sweep_hash" not in ds.attrs:
        raise ParameterError(f'SWEEP_RESULTS: "{results}" is not a sweep result (no sweep_hash attribute)')
    if "case" not in ds.dims:
        _, chosen = select_cases(ds, [d for d in (x, y) if d is not None and d in ds.dims], selection)
        for name, value in chosen.items():
            if name not in selection and ds.sizes[name] > 1:
                click.echo(f"note: {name} = {value} (its first value; choose with --sel {name}=VALUE)", err=True)
    fig, ax = plt.subplots(figsize=(6.4, 4.6), layout="constrained")
    try:
        plot_sweep(ds, x, metric, y=y, sel=selection, ax=ax)
        try:
            fig.savefig(out, dpi=120)
        except OSError as exc:
            click.echo(f'error: --out: cannot write "{out}": {exc.strerror or exc}', err=True)
            sys.exit(1)
    finally:
        plt.close(fig)
    click.echo(f"wrote figure to {out}", err=True)
