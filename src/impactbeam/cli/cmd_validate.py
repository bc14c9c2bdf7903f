"""``impactbeam validate``: rerun the validation manual's cases and compare them with their references.

Runs :func:`impactbeam.validation.validate` and prints the table (or JSON).
Exit status 0 when every case ran and lies within its tolerances, 1 when a
case is outside them or could not be run, 2 for bad options.
"""

from __future__ import annotations

import sys

import click

from .._io import json_text
from ._group import handle_errors, take_warnings, warning_lines

__all__ = ["validate"]


@click.command("validate")
@click.option("--json", "as_json", is_flag=True, help="Print JSON instead of the table.")
@click.option("--case", "cases", multiple=True, metavar="NAME",
              help="Run only this case (SDLX400, SDNL32, SDNL104, Table2); repeatable.")
@click.option("--figures", "figures", default=None, metavar="DIR",
              help="Also write one figure per case, DIR/validation_<case>.png.")
@handle_errors
def validate(as_json: bool, cases: tuple[str, ...], figures: str | None) -> None:
    """Rerun the validation manual: published tests side by side with impactbeam.

    code_aster's SDLX400 (pinned-free beam frequencies, with and without a tip
    spring), SDNL32 (a pinned beam swung onto a one-sided tip spring, the
    VPCS reference), SDNL104 (a cantilever pushed onto a stiff stop: 5-mode
    runs and the converged value), and the paper's experiment (measured
    frequencies; Table 2 shown for information). Exit status 1 if a case is
    outside its tolerance or cannot be run.
    """
    from ..validation import validate as run
    from ..validation.report import text_table

    report = run(list(cases) or None, progress=None if as_json else lambda n: click.echo(f"running {n} ...", err=True))
    warnings = take_warnings()
    if figures is not None:
        from ..validation.figures import write_figures

        for path in write_figures(report, figures):
            click.echo(f"figure: {path}", err=True)
    if as_json:
        out = report.as_dict()
        out["warnings"] = warnings
        click.echo(json_text(out))
    else:
        click.echo(text_table(report))
        for line in warning_lines(warnings):
            click.echo(line)
    if not report.passed:
        sys.exit(1)
