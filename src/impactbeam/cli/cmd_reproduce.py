"""``impactbeam reproduce``: rebuild the results of Xu & Ervin (2013) and compare.

Runs :func:`impactbeam.paper.reproduce` with a progress bar on stderr, then
prints a summary table and the path of the report.
"""

from __future__ import annotations

from pathlib import Path

import click

from ._group import handle_errors
from ..exceptions import ParameterError

__all__ = ["reproduce"]


@click.command("reproduce")
@click.option("--out", "out", default="out/paper", show_default=True, metavar="DIR",
              help="Directory for report.md, report.html and figures/.")
@click.option("--docs", "docs", default=None, metavar="DIR",
              help="Also write the README section DIR/paper-reproduction.md and copy its figures to DIR/figures/.")
@click.option("--quiet", "-q", is_flag=True, help="No progress bar.")
@handle_errors
def reproduce(out: str, docs: str | None, quiet: bool) -> None:
    """Reproduce the paper's results section (Table 2, Figs. 4-8, section 4) beside its numbers.

    Simulates every Table 1 case with ideal half-sine pulses and the paper's
    raw parameters, plus convergence, parameter and refit studies, and writes
    a report (Markdown and HTML with PNG figures) into DIR.
    """
    from ..paper import reproduce as run
    from ..paper import write_readme_section

    out_dir = Path(out)
    if out_dir.exists() and not out_dir.is_dir():
        raise ParameterError(f'--out: "{out}" exists and is not a directory')
    if docs is not None and Path(docs).exists() and not Path(docs).is_dir():
        raise ParameterError(f'--docs: "{docs}" exists and is not a directory')
    try:
        report = run(out_dir, progress=not quiet)
    except OSError as exc:
        raise click.ClickException(f'--out: cannot write into "{out}": {exc.strerror or exc}') from exc
    rows = report.summary_rows()
    headers = ("quantity", "simulated", "paper", "difference")
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(headers)]
    click.echo("  ".join(h.ljust(w) for h, w in zip(headers, widths)))
    click.echo("  ".join("-" * w for w in widths))
    for r in rows:
        click.echo("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
    click.echo(f"\n{report.n_simulations} simulations, {report.elapsed:.1f} s")
    click.echo(f"report: {report.report_html}")
    click.echo(f"        {report.report_md}")
    if docs is not None:
        path = write_readme_section(report, docs)
        click.echo(f"README section: {path}")
