"""Running the validation manual's cases: :func:`validate`."""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence

from ..exceptions import ImpactBeamError, ParameterError
from . import codeaster, paper_table2  # noqa: F401 - registers the cases
from .core import CASES, CaseResult, ValidationReport, _Case

__all__ = ["validate"]


def _run_one(case: _Case) -> CaseResult:
    t0 = time.perf_counter()
    try:
        return case.run()
    except ImpactBeamError as exc:  # the solver refuses the case: reported, never passed
        checks = tuple(case.references())
        return CaseResult(case.name, case.title, case.source, checks, "not run", str(exc), {},
                          time.perf_counter() - t0)


def validate(cases: Sequence[str] | None = None, *, progress: Callable[[str], None] | None = None) -> ValidationReport:
    """Run the validation manual's cases and compare them with their published references.

    Parameters
    ----------
    cases : sequence of str, optional
        Names of the cases to run (default all: ``SDLX400``, ``SDNL32``,
        ``SDNL104``, ``Table2``).
    progress : callable, optional
        Called with each case's name before it runs.

    Returns
    -------
    ValidationReport

    Raises
    ------
    ParameterError
        For an unknown case name.
    """
    names = list(CASES) if cases is None else list(cases)
    for n in names:
        if n not in CASES:
            raise ParameterError(f"--case: unknown validation case {n!r} (known: {', '.join(CASES)})")
    out = []
    for n in names:
        if progress is not None:
            progress(n)
        out.append(_run_one(CASES[n]))
    return ValidationReport(tuple(out))
