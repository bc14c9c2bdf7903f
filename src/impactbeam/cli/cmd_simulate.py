"""``impactbeam simulate``: one run of a scenario, its summary, JSON, result file and figure."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import click

from .._io import PLOT_SUFFIXES, RESULT_SUFFIXES, check_output, json_text
from ._group import fail, handle_errors, load_with_overrides, pending_warnings, progress_bar, take_warnings

__all__ = ["simulate"]



@click.command()
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

    The metrics are read on u, the deflection w at the first contactor (the
    first output point without contactors) positive away from it: u = -w
    for a contactor above the beam, u = w below; contact is u < -gap. In
    the summary lengths are in mm and times in ms; --json gives SI values,
    null where a metric does not apply.

    \b
    max_response       the largest u; t_max its time
    first_impact_time  the start of the first contact
    n_impacts          the contacts that begin during the run
    free_duration      the free interval containing t_max: from the last
                       rebound before it (or t = 0) to the next impact
    contact_duration   the first contact that begins after t_max
    min_response       the least u in that contact
    max_penetration    the deepest compression of the run, max(-gap - u)

    --json adds "impacts", one row per contact of every contactor:
    contactor, start, end, duration, peak_force (the largest contact force)
    and impulse (the integral of the force over the contact).
    """
    check_output("--out", out, RESULT_SUFFIXES)
    check_output("--plot", plot, PLOT_SUFFIXES)
    modes: int | str | None = n_modes
    if n_modes is not None and n_modes.strip().lstrip("+").isdigit():
        modes = int(n_modes)
    sc = load_with_overrides(
        scenario,
        {"solver.modes": modes, "solver.time_step": time_step, "solver.end_time": end_time},
    )
    from ..simulation import simulate as run

    # import the writers before the (possibly long) run, so a broken install fails fast
    from .._optional import require

    if out is not None:
        from .._memory import check_output_size, sample_count
        from ..result import write_result

        backend = {".nc": "h5netcdf", ".parquet": "pyarrow"}.get(Path(out).suffix.lower())
        if backend:
            require(backend, "io", feature=f"--out {Path(out).suffix.lower()}")
        n_t = sample_count(sc.solver.end_time, sc.solver.time_step)
        n_m = 200 if sc.solver.modes == "auto" else int(sc.solver.modes)
        check_output_size(n_t, len(sc.output_points), len(sc.contactors), n_m)  # before any work
    if plot is not None:
        require("matplotlib", "plot", feature="--plot")
        from ..plot.response import plot_result

    from ..solver.kernels import active

    # the run, the convergence estimate's two re-runs and the statistics' sampling: more than a short run's
    # work, so the compiled kernels when numba's cache holds them (Case 3: 0.1 s compiled after 0.6 s to
    # import numba and load them, against 0.8 s interpreted); else the interpreted ones (kernels.active)
    active()
    with progress_bar(sc.solver.end_time, desc="simulate", unit="s", unit_scale=True,
                      bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.4g}/{total:.4g} s simulated "
                                 "[{elapsed}<{remaining}]") as report:
        result = run(sc, progress=report)
    metrics = result.metrics()
    metrics["modes"] = result.n_modes
    from ..solver.convergence import coarser_counts

    with progress_bar(max(len(coarser_counts(result.n_modes)), 1), desc="convergence estimate", unit="run") as report:
        metrics["convergence"] = result.estimate_convergence(report)  # now, so that its warning is caught below
    from ..statistics import run_statistics, statistics_stages

    with progress_bar(statistics_stages(result), desc="statistics", unit="stage") as report:
        metrics.update(run_statistics(result, report))  # impact statistics per contactor; with [fatigue], fatigue
    if sc.excitation.shape == "random":
        metrics["seed"] = sc.excitation.seed  # drawn when the scenario gives none: reported to repeat the run
    if out is not None:
        try:
            write_result(result, out, report={**metrics, "warnings": pending_warnings()})
        except ImportError as exc:  # an optional writer backend is missing
            fail(f'--out: cannot write "{out}": {exc}', 1)
    if plot is not None:
        try:
            plot_result(result, plot, excitation=sc.excitation)
        except ImportError as exc:
            fail(f'--plot: cannot write "{plot}": {exc}', 1)
    if as_json:
        click.echo(json_text({**metrics, "warnings": take_warnings()}))
    else:  # the warnings go to stderr, printed by handle_errors when the command ends
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




def _summary(sc: Any, metrics: Mapping[str, Any]) -> str:
    from ..result.metrics import METRIC_DISPLAY

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
        whole = isinstance(value, int) and not isinstance(value, bool)  # a seed, a count: every digit
        rows.append((key.replace("_", " "), "n/a" if x is None else str(int(value)) if whole else f"{x:.6g}"))
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
    from ._statistics import statistics_lines

    lines += statistics_lines(metrics.get("impact_statistics") or [], metrics.get("fatigue") or [],
                              metrics.get("statistics_window"))
    return "\n".join(lines)
