"""``impactbeam convergence``: the mode-count study of a scenario, each metric with its error estimate."""

from __future__ import annotations

from typing import Any

import click

from .._io import PLOT_SUFFIXES, check_output, json_text
from ..exceptions import ParameterError
from ._group import handle_errors, load_with_overrides, progress_bar, take_warnings, warning_lines

__all__ = ["convergence"]


def _counts(text: str | None) -> list[int] | None:
    """``--modes 4,8,16`` as integers (None when not given)."""
    if text is None:
        return None
    try:
        counts = [int(part) for part in text.split(",") if part.strip()]
    except ValueError:
        raise ParameterError(f"--modes: expected mode counts separated by commas (e.g. 4,8,16), got {text!r}") from None
    if not counts:
        raise ParameterError("--modes: give at least one mode count")
    return counts


@click.command()
@click.argument("scenario", metavar="SCENARIO")
@click.option("--modes", "counts", default=None, metavar="N1,N2,...",
              help="Mode counts to show [default: 4, 6, 8, 12, 16, 24, 32, 48, 64 up to --max-modes].")
@click.option("--max-modes", "max_modes", type=int, default=None,
              help="Largest count of the default ladder [default: 64; not with --modes].")
@click.option("--json", "as_json", is_flag=True, help="Print the study as JSON.")
@click.option("--plot", "plot", default=None, metavar="FILE", help="Save the figure (e.g. .png, .pdf).")
@handle_errors
def convergence(scenario: str, counts: str | None, max_modes: int | None, as_json: bool, plot: str | None) -> None:
    """The Table-2 metrics of SCENARIO against the number of modes, with their error estimates.

    Every count is run with the counts its estimate compares with (about
    half and three quarters of it), so each row shows what a run with that
    count reports as its convergence: the estimated relative error of each
    metric (the largest change against the two coarser runs). The JSON and
    the figure are described in the documentation (Convergence study).
    """
    from ..model.options import MAX_MODES

    check_output("--plot", plot, PLOT_SUFFIXES)
    mode_counts = _counts(counts)  # (the option's value is "counts", as the API's argument: one message rule)
    if max_modes is not None and counts is not None:
        raise ParameterError("--max-modes: only for the default ladder; with --modes the counts shown are those given")
    max_modes = 64 if max_modes is None else max_modes
    if not 4 <= max_modes <= MAX_MODES:
        raise ParameterError(f"--max-modes: expected 4 to {MAX_MODES}, got {max_modes}")
    sc = load_with_overrides(scenario)
    if plot is not None:
        from .._optional import require

        require("matplotlib", "plot", feature="--plot")
    from ..simulation import convergence_study

    with progress_bar(1.0, desc="convergence", unit="", bar_format="{desc}: {percentage:3.0f}%|{bar}| "
                      "[{elapsed}<{remaining}]") as report:
        study = convergence_study(sc, mode_counts, max_modes=max_modes, progress=report)
    if plot is not None:
        _figure(study, plot)
    caught = take_warnings()
    if as_json:
        click.echo(json_text({**study.as_dict(), "warnings": caught}))
    else:
        click.echo("\n".join([_table(study, "--modes" if counts else "--max-modes"), *warning_lines(caught)]))
    if plot is not None:
        click.echo(f"wrote figure to {plot}", err=True)


def _table(study: Any, more: str = "--max-modes") -> str:
    """Values and estimated relative errors, one row per mode count."""
    from ..result.metrics import METRIC_DISPLAY
    from ..solver.convergence import CONVERGENCE_METRICS

    shown = [(k, label, scale, unit) for k, label, scale, unit in METRIC_DISPLAY if k in CONVERGENCE_METRICS]
    head = ["modes", "functions"] + [f"{label} [{unit}]" if unit else label for _, label, _, unit in shown]
    rows = []
    for n in study.counts:
        m, est = study.metrics[n], study.estimates.get(n)
        cells = [str(n), str(study.functions[n])]
        for key, _, scale, _ in shown:
            v = m.get(key)
            text = "-" if v is None else (str(int(v)) if key == "n_impacts" else f"{v * scale:.7g}")
            if est is not None and v is not None:
                text += f" ±{est[key]:.1e}"
            cells.append(text)
        rows.append(cells)
    widths = [max(len(r[i]) for r in [head, *rows]) for i in range(len(head))]
    lines = [f"Convergence in the number of modes of {study.name!r}: each metric with its estimated relative "
             "error (against the two coarser counts)"]
    lines += ["  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in [head, *rows]]
    best = study.converged_count
    lines.append(f"estimate below solver.tolerance = {study.tolerance:g} from {best} modes" if best is not None
                 else f"no count reaches solver.tolerance = {study.tolerance:g}; use more modes ({more})")
    return "\n".join(lines)


def _figure(study: Any, path: str) -> None:
    """The study's figure (:func:`impactbeam.plot.study.plot_convergence_study`)."""
    from ..plot.study import plot_convergence_study
    from ..result.metrics import METRIC_DISPLAY
    from ..solver.convergence import CONVERGENCE_METRICS

    labels = {k: label for k, label, _, _ in METRIC_DISPLAY}
    keys = [k for k in CONVERGENCE_METRICS if any(study.metrics[n].get(k) is not None for n in study.counts)]
    values = {k: [study.metrics[n].get(k) for n in study.counts] for k in keys}
    estimates = {k: [None if study.estimates.get(n) is None else study.estimates[n][k] for n in study.counts]
                 for k in keys}
    plot_convergence_study(study.counts, values, estimates, metric_labels=labels, path=path, tolerance=study.tolerance,
                           title=f"{study.name}: convergence in the number of modes")
