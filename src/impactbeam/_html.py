"""Compact HTML summaries for Jupyter (``_repr_html_``).

One small helper, :func:`table`, renders a captioned two-column table of
(label, value) rows; :func:`sections` stacks several. The ``_repr_html_``
methods of :class:`~impactbeam.scenario.Scenario`,
:class:`~impactbeam.modal.ModeSet` (and of the simulation result) build
their rows here, so every object looks the same in a notebook. All text is
escaped.
"""

from __future__ import annotations

import html
from collections.abc import Iterable, Sequence
from typing import Any

__all__ = ["mm", "modeset_html", "scenario_html", "sections", "table"]

_STYLE = (
    "border-collapse:collapse;font-size:0.9em;margin:0 0 0.6em 0;"
)
_CELL = "padding:1px 10px 1px 0;text-align:left;vertical-align:top;"


def table(rows: Iterable[Sequence[Any]], caption: str | None = None) -> str:
    """A two-column HTML table.

    Parameters
    ----------
    rows : iterable of (label, value) or (label, value, id)
        ``value`` is shown as text; ``id``, when given, becomes the ``id``
        of the value cell (for pages that read it back).
    caption : str, optional
        Shown above the table, in bold.
    """
    out = [f'<table style="{_STYLE}">']
    if caption:
        out.append(f'<caption style="text-align:left;font-weight:bold;">{html.escape(caption)}</caption>')
    for row in rows:
        label, value = row[0], row[1]
        ident = f' id="{html.escape(str(row[2]), quote=True)}"' if len(row) > 2 and row[2] else ""
        out.append(
            f'<tr><th style="{_CELL}font-weight:normal;color:#555;">{html.escape(str(label))}</th>'
            f'<td style="{_CELL}"{ident}>{html.escape(str(value))}</td></tr>'
        )
    out.append("</table>")
    return "".join(out)


def sections(title: str, parts: Iterable[str]) -> str:
    """Stack rendered tables under a title, in a block that Jupyter shows as is."""
    body = "".join(parts)
    return f'<div class="impactbeam-repr"><strong>{html.escape(title)}</strong>{body}</div>'


def mm(x: float) -> str:
    """A length in mm with 4 significant digits."""
    return f"{x * 1e3:.4g} mm"


def _ratios(value: Any) -> str:
    if isinstance(value, (tuple, list)):
        shown = ", ".join(f"{v * 100:.3g}" for v in value[:4])
        return f"[{shown}{', ...' if len(value) > 4 else ''}] %"
    return f"{float(value) * 100:.3g} %"


def scenario_html(sc: Any) -> str:
    """Summary of a :class:`~impactbeam.scenario.Scenario`: beam, contactors, load, damping, solver."""
    b = sc.beam
    beam_rows = [
        ("length", mm(b.length)),
        ("section", f"{mm(b.width)} x {mm(b.height)}" if b.width and b.height else f"A = {b.area:.4g} m^2"),
        ("E, rho", f"{b.youngs_modulus / 1e6:.5g} MPa, {b.density:.5g} kg/m^3"),
        ("supports", f"left {b.left.describe()}, right {b.right.describe()}"),
    ]
    parts = [table(beam_rows, "Beam")]
    if sc.contactors:
        rows = [
            (f"contactor {i}", f"x = {mm(c.position)} ({c.position / b.length:.4g} L), k = {c.stiffness:.5g} N/m, "
             f"gap = {mm(c.gap)}, {c.side}")
            for i, c in enumerate(sc.contactors)
        ]
        parts.append(table(rows, "Contactors"))
    ex = sc.excitation
    if ex.kind == "none":
        load = "none"
    elif ex.shape == "half_sine":
        unit = {"base_acceleration": "m/s^2", "point_force": "N", "distributed_force": "N/m"}.get(ex.kind, "")
        load = f"{ex.kind}, half-sine {ex.amplitude:.5g} {unit} for {ex.duration * 1e3:.4g} ms from {ex.start * 1e3:.4g} ms"
    else:
        load = f"{ex.kind}, {ex.shape}"
    parts.append(
        table(
            [
                ("excitation", load),
                ("damping", f"free {_ratios(sc.damping.free)}, contact {_ratios(sc.damping.contact)}"),
                ("solver", f"{sc.solver.modes} modes per state, dt = {sc.solver.time_step * 1e6:.4g} us, "
                           f"end = {sc.solver.end_time * 1e3:.4g} ms"),
                ("output at", ", ".join(mm(x) for x in sc.output_points)),
            ],
            "Load and solution",
        )
    )
    title = f"Scenario {sc.name!r}" + (f": {sc.description}" if sc.description else "")
    return sections(title, parts)


def modeset_html(ms: Any, max_rows: int = 8) -> str:
    """Summary of a :class:`~impactbeam.modal.ModeSet`: the state and its first frequencies."""
    f = ms.frequencies_hz
    springs = ", ".join(f"{k:.4g} N/m at {mm(x)}" for x, k in ms.springs) or "none (free state)"
    rows = [("modes", f"{ms.count} ({ms.n_rigid} rigid-body)"), ("contact springs", springs)]
    rows += [(f"f{n + 1}", f"{f[n]:.6g} Hz") for n in range(min(max_rows, f.size))]
    if f.size > max_rows:
        rows.append(("...", f"f{f.size} = {f[-1]:.6g} Hz"))
    return sections("ModeSet", [table(rows)])
