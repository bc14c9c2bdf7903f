"""``impactbeam random``: an ensemble of independent random records, its estimates and their confidence.

``impactbeam random SCENARIO --seeds N [--workers W | --scheduler ADDRESS] [--json] [--out DIR]``
runs :func:`impactbeam.random_response`. With ``--out DIR`` the per-seed
statistics go to ``DIR/seeds.zarr`` as members finish (the same command
resumes an interrupted ensemble) and the estimates to ``DIR/summary.json``.

Exit status: 0 done; 2 bad input (one line on stderr naming the key or
option); 1 a failed computation; 128 + signal number when interrupted by
SIGINT/SIGTERM (the store keeps every finished member).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import click

from .._io import json_text, write_text
from ..exceptions import ParameterError
from ._group import handle_errors, load_with_overrides, take_warnings, warning_lines

__all__ = ["random_command"]


@click.command("random")
@click.argument("scenario", metavar="SCENARIO")
@click.option("--seeds", "seeds", type=int, required=True, metavar="N", help="Number of independent records.")
@click.option("--workers", "workers", type=int, default=None, metavar="W",
              help="Worker processes of a local Dask cluster [default: all cores]; 0 runs in this process.")
@click.option("--scheduler", "scheduler", default=None, metavar="ADDRESS",
              help="Use a running Dask scheduler (e.g. tcp://127.0.0.1:8786) and its workers.")
@click.option("--json", "as_json", is_flag=True, help="Print the estimates as JSON.")
@click.option("--out", "out", default=None, metavar="DIR",
              help="Directory for the per-seed store (seeds.zarr, resumed) and summary.json.")
@click.option("--end-time", "end_time", default=None, metavar="T",
              help='Override solver.end_time, the length of each record [s]; a unit is allowed ("100 s").')
@click.option("--no-progress", "no_progress", is_flag=True, help="No progress bar.")
@handle_errors
def random_command(scenario: str, seeds: int, workers: int | None, scheduler: str | None, as_json: bool,
                   out: str | None, end_time: str | None, no_progress: bool) -> None:
    """Run SEEDS independent records of the random SCENARIO and print the estimates.

    RMS deflection and velocity per output point, impact statistics per
    contactor and, with [fatigue], damage rate and life per point, each with
    a 95 % confidence interval from the spread between seeds (Student t).
    """
    if seeds < 1:
        raise ParameterError(f"--seeds: must be a positive integer, got {seeds}")
    if workers is not None and scheduler is not None:
        raise ParameterError("--workers and --scheduler exclude each other (a local cluster or a running one)")
    if workers is not None and workers < 0:
        raise ParameterError(f"--workers: must be >= 0, got {workers}")
    sc = load_with_overrides(scenario, {"solver.end_time": end_time})
    from ..random import random_response
    from ..random.ensemble import SUMMARY_NAME
    from ..sweeps import SweepInterrupted

    try:
        res = random_response(sc, seeds, workers, scheduler=scheduler, out=out, progress=not no_progress)
    except SweepInterrupted as exc:
        click.echo(exc.summary("seeds", out or "memory (lost: no --out)"), err=True)
        sys.exit(128 + exc.signum)
    caught = take_warnings()
    data = {**res.to_dict(), "warnings": caught}
    if out is not None:
        write_text(Path(out) / SUMMARY_NAME, json_text(data, indent=1))
    if as_json:
        click.echo(json_text(data))
    else:
        click.echo("\n".join([*_summary(sc, res), *warning_lines(caught)]))
    if out is not None:
        click.echo(f"wrote {Path(out) / SUMMARY_NAME} and the per-seed store {Path(out) / 'seeds.zarr'}", err=True)


def _summary(sc: Any, res: Any) -> list[str]:
    from ._statistics import statistics_lines

    lines = [
        f"Random response of {sc.name!r}: {res.seeds} seeds from seed {res.seed}, {res.duration:.4g} s each after "
        f"{res.warmup:.3g} s of settling ({100 * res.confidence:.0f} % intervals from the spread between seeds)",
        f"  {'x [mm]':>10}  {'RMS w [mm]':>24}  {'RMS w_t [m/s]':>24}",
    ]
    for x, r, rc, v, vc in zip(res.points, res.rms, res.rms_ci, res.rms_velocity, res.rms_velocity_ci):
        lines.append(f"  {x * 1e3:10.4g}  {r * 1e3:9.4g} [{rc[0] * 1e3:.4g}, {rc[1] * 1e3:.4g}]".ljust(38)
                     + f"  {v:9.4g} [{vc[0]:.4g}, {vc[1]:.4g}]")
    return lines + statistics_lines(res.impacts, res.fatigue)
