"""``impactbeam modes``: natural frequencies of the free and the contact state (paper eqs. 3-7)."""

from __future__ import annotations

import math
from typing import Any

import click

from .._io import PLOT_SUFFIXES, check_output, json_text
from ..exceptions import ParameterError
from ._group import handle_errors, load_with_overrides

__all__ = ["modes"]



@click.command()
@click.argument("scenario", metavar="SCENARIO")
@click.option("--count", "count", type=int, default=None,
              help="Number of modes per state [default: the scenario's solver.modes].")
@click.option("--json", "as_json", is_flag=True, help="Print JSON instead of a table.")
@click.option("--plot", "plot_path", default=None, metavar="FILE.png",
              help="Draw the first six (at most) free-state mode shapes with steps, springs, masses and "
                   "contactors marked.")
@handle_errors
def modes(scenario: str, count: int | None, as_json: bool, plot_path: str | None = None) -> None:
    """Natural frequencies of the free and the contact state.

    The contact state has every contactor engaged; it is omitted without
    contactors. Section steps, point masses and permanent springs
    ([[beam.sections]], [[masses]], [[springs]]) belong to both states; the
    JSON then has a "structure" entry listing them.
    """
    from ..model.options import MAX_MODES

    if count is not None and not 1 <= count <= MAX_MODES:
        raise ParameterError(f"--count: expected 1 to {MAX_MODES} modes (the limit of solver.modes), got {count}")
    if count is not None and count < 1:
        raise ParameterError(f"--count: must be a positive integer, got {count}")
    check_output("--plot", plot_path, PLOT_SUFFIXES)
    sc = load_with_overrides(scenario)
    from ..modal import scenario_modes

    n = sc.solver.modes if count is None else count
    ms = scenario_modes(sc, n)
    free = [float(f) for f in ms.free.frequencies_hz]
    contact = None if ms.contact is None else [float(f) for f in ms.contact.frequencies_hz]
    if plot_path is not None:
        from ..plot.modes import plot_modes

        plot_modes(ms.free, count=min(n, 6), contactors=sc.contactors, path=plot_path,
                   title=f"{sc.name}: free-state mode shapes")
    if as_json:
        out: dict[str, Any] = {"free": {"frequencies_hz": free}}
        if contact is not None:
            out["contact"] = {"frequencies_hz": contact}
        if not sc.beam.is_uniform:
            out["structure"] = _structure(sc.beam)
        click.echo(json_text(out))
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
        "theory": beam.theory,
        **({"poisson_ratio": beam.poisson_ratio, "shear_coefficient": beam.kappa} if beam.is_timoshenko else {}),
    }


def _modes_table(sc: Any, ms: Any, free: list[float], contact: list[float] | None) -> str:
    n_contactors = len(sc.contactors)
    b = sc.beam
    kind = f"Timoshenko beam (nu = {b.poisson_ratio:g}, kappa = {b.kappa:.4g})" if b.is_timoshenko else "beam"
    title = f"Natural frequencies of {sc.name!r}: {b.left.describe()}-{b.right.describe()} {kind}"
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
