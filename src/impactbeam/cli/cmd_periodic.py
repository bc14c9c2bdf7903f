"""``impactbeam periodic``: a periodic orbit under harmonic forcing and its Floquet multipliers.

Runs :func:`impactbeam.periodic.shooting.periodic_orbit` and prints a summary
or, with ``--json``, ``{"converged", "multiple", "period", "strobe",
"multipliers", "stable", "impacts_per_period", ...}`` with the warnings.
"""

from __future__ import annotations

import click

from ._group import handle_errors

__all__ = ["periodic"]


@click.command("periodic")
@click.argument("scenario", metavar="SCENARIO")
@click.option("--multiple", "multiple", type=int, default=1, show_default=True, metavar="M",
              help="Look for an orbit of period M forcing periods (M >= 1).")
@click.option("--settle-periods", "settle_periods", type=float, default=None, metavar="P",
              help="Forcing periods simulated before the search [default: up to solver.end_time].")
@click.option("--max-iterations", "max_iterations", type=int, default=20, show_default=True, metavar="N",
              help="Newton steps at most.")
@click.option("--json", "as_json", is_flag=True, help="Print JSON instead of a summary.")
@handle_errors
def periodic(scenario: str, multiple: int, settle_periods: float | None, max_iterations: int, as_json: bool) -> None:
    """Find the periodic response of SCENARIO (shape = "harmonic") of period M/f by shooting.

    Newton's method on the stroboscopic map, from the state the simulation
    has settled on, with the exact Jacobian of the event-driven map; the
    eigenvalues of that Jacobian at the orbit are its Floquet multipliers
    (stable when all lie inside the unit circle). The strobe values are w
    at the first contactor (the first output point without one) at
    t = start + k/f. A search that does not converge is reported with
    "converged": false and a warning.
    """
    from .._io import json_text
    from ._group import load_with_overrides, take_warnings
    from ..periodic.shooting import periodic_orbit

    sc = load_with_overrides(scenario)
    orbit = periodic_orbit(sc, multiple=multiple, settle_periods=settle_periods, max_iterations=max_iterations)
    if as_json:
        click.echo(json_text({**orbit.to_dict(), "warnings": take_warnings()}))
        return
    lines = [f"Periodic orbit of {sc.name!r}: period {orbit.multiple} x 1/f = {orbit.period * 1e3:.6g} ms",
             f"  {orbit.message}",
             f"  impacts per period: {orbit.impacts_per_period}",
             "  strobe w [mm] at t = start + k/f: " + ", ".join(f"{w * 1e3:.6g}" for w in orbit.strobe)]
    shown = orbit.multipliers[:6]
    if shown.size:
        lines.append("  largest multipliers |mu|: " + ", ".join(f"{abs(m):.6g}" for m in shown)
                     + (" ..." if orbit.multipliers.size > shown.size else ""))
        lines.append(f"  {'stable' if orbit.stable else 'NOT stable' if orbit.converged else 'not converged'}")
    else:  # the Jacobian is not finite: the warning says so
        lines.append("  multipliers not defined (the map's Jacobian is not finite)")
        lines.append("  stability unknown" if orbit.converged else "  not converged")
    click.echo("\n".join(lines))  # the warnings go to stderr, printed by handle_errors when the command ends
