"""The validation report as text: the command line's table and the manual's Markdown tables."""

from __future__ import annotations

from .core import CaseResult, Check, ValidationReport

__all__ = ["format_value", "check_row", "text_table", "markdown_table"]

_SCALE = {"m": (1e3, "mm"), "m/s": (1e3, "mm/s"), "s": (1e3, "ms"), "Hz": (1.0, "Hz")}
_HEAD = ("quantity", "reference", "impactbeam", "difference", "tolerance", "status")


def format_value(value: float | None, unit: str) -> str:
    """A value in the table's unit (mm or um, mm/s, ms, Hz), 5 significant digits; ``-`` for None."""
    if value is None:
        return "-"
    k, u = _SCALE.get(unit, (1.0, unit))
    if unit in ("m", "m/s") and 0.0 < abs(value) < 1e-5:
        k, u = 1e6, "um" if unit == "m" else "um/s"
    return f"{value * k:.5g} {u}".strip()


def _status(c: Check) -> str:
    if c.kind == "info":
        return "info"
    if c.result is None:
        return "not run"
    return "pass" if c.passed else "FAIL"


def check_row(c: Check) -> tuple[str, ...]:
    """The row of one check: quantity, reference, result, difference, tolerance, status."""
    diff = "-"
    if c.difference is not None:
        rel = c.relative_difference
        diff = format_value(c.difference, c.unit) + (f" ({100 * rel:+.3g} %)" if rel is not None else "")
    if c.kind == "relative" and c.tolerance is not None:
        tol = f"{100 * c.tolerance:.3g} %"
    elif c.kind == "absolute" and c.tolerance is not None:
        tol = format_value(c.tolerance, c.unit)
    else:
        tol = "-"
    return (c.quantity, format_value(c.reference, c.unit), format_value(c.result, c.unit), diff, tol, _status(c))


def text_table(report: ValidationReport) -> str:
    """The command line's table: every case, its checks and its verdict."""
    lines: list[str] = []
    for case in report.cases:
        rows = [check_row(c) for c in case.checks]
        widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(_HEAD)]
        lines.append(f"{case.name}: {case.title} -- {case.status.upper()} ({case.message})")
        lines.append("  " + "  ".join(h.ljust(w) for h, w in zip(_HEAD, widths)).rstrip())
        lines.append("  " + "  ".join("-" * w for w in widths))
        lines += ["  " + "  ".join(v.ljust(w) for v, w in zip(r, widths)).rstrip() for r in rows]
        lines.append("")
    n_pass = sum(c.status == "passed" for c in report.cases)
    lines.append(f"{n_pass} of {len(report.cases)} cases passed" + ("" if report.passed else "; see above"))
    return "\n".join(lines)


def markdown_table(case: CaseResult) -> str:
    """The manual's table of one case (Markdown), with code_aster's own result where it has one."""
    other = any(c.other is not None for c in case.checks)
    head = [*_HEAD[:3], *(("code_aster",) if other else ()), *_HEAD[3:]]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for c in case.checks:
        r = list(check_row(c))
        if other:
            r.insert(3, format_value(c.other, c.unit))
        lines.append("| " + " | ".join(r) + " |")
    return "\n".join(lines) + "\n"
