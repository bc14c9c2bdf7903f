"""The validation manual's machinery: checks, case results, the report and the runner.

A case (:mod:`.codeaster`, :mod:`.paper_table2`) runs impactbeam on a
published validation test and returns a :class:`CaseResult`: one
:class:`Check` per compared quantity (reference, result, difference,
tolerance and why), and the series its figure draws. :func:`validate` runs
the cases; a case that cannot be run (the solver refuses it) is reported as
``"not run"`` with the solver's message, never as passed
(:func:`impactbeam.validation.run.validate`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np


__all__ = ["Check", "CaseResult", "ValidationReport", "register", "CASES", "sample"]

CheckKind = Literal["relative", "absolute", "info"]
Status = Literal["passed", "failed", "not run"]


@dataclass(frozen=True)
class Check:
    """One compared quantity.

    Attributes
    ----------
    quantity : str
        What is compared (``"k = 18000 N/m, w(L) at 3 ms"``).
    unit : str
        SI unit of ``reference`` and ``result``.
    reference : float
        The published value.
    result : float or None
        impactbeam's value (None when the case did not run).
    tolerance : float or None
        A fraction of ``|reference|`` (``kind = "relative"``) or a value in
        ``unit`` (``"absolute"``); None for ``"info"`` (shown, not judged).
    kind : {"relative", "absolute", "info"}
    basis : str
        Where the tolerance comes from (code_aster's PRECISION, a stated
        measurement uncertainty, ...).
    other : float or None
        The value the reference's own code obtained (code_aster's VALE_CALC), for context.
    """

    quantity: str
    unit: str
    reference: float
    result: float | None
    tolerance: float | None
    kind: CheckKind
    basis: str = ""
    other: float | None = None

    @property
    def difference(self) -> float | None:
        """``result - reference`` (None without a result)."""
        return None if self.result is None else self.result - self.reference

    @property
    def relative_difference(self) -> float | None:
        """``(result - reference) / |reference|`` (None without a result or for a zero reference)."""
        d = self.difference
        return None if d is None or self.reference == 0.0 else d / abs(self.reference)

    @property
    def passed(self) -> bool | None:
        """Within the tolerance (None for an informative check or without a result)."""
        if self.kind == "info" or self.result is None or self.tolerance is None:
            return None
        d = self.relative_difference if self.kind == "relative" else self.difference
        return d is not None and math.isfinite(d) and abs(d) <= self.tolerance

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready fields, with the difference and the verdict."""
        return {"quantity": self.quantity, "unit": self.unit, "reference": self.reference, "result": self.result,
                "difference": self.difference, "relative_difference": self.relative_difference,
                "tolerance": self.tolerance, "kind": self.kind, "basis": self.basis, "other": self.other,
                "passed": self.passed}


@dataclass(frozen=True, eq=False)
class CaseResult:
    """The outcome of one validation case.

    Attributes
    ----------
    name : str
        ``"SDLX400"``, ``"SDNL32"``, ``"SDNL104"``, ``"Table2"``.
    title : str
    source : str
        Key of :data:`impactbeam.validation.references.SOURCES`.
    checks : tuple of Check
    status : {"passed", "failed", "not run"}
    message : str
        Why a case did not run, or a one-line summary.
    series : dict
        Named arrays for the case's figure.
    elapsed : float, [s]
    """

    name: str
    title: str
    source: str
    checks: tuple[Check, ...]
    status: Status
    message: str = ""
    series: dict[str, Any] = field(default_factory=dict, repr=False)
    elapsed: float = 0.0

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready fields (without the figure series)."""
        from .references import SOURCES

        return {"name": self.name, "title": self.title, "source": SOURCES[self.source].citation,
                "status": self.status, "message": self.message, "elapsed": self.elapsed,
                "checks": [c.as_dict() for c in self.checks]}


def case_result(name: str, title: str, source: str, checks: Sequence[Check], series: dict[str, Any] | None = None,
                elapsed: float = 0.0) -> CaseResult:
    """A run case: passed when every judged check is within its tolerance."""
    judged = [c.passed for c in checks if c.passed is not None]
    status: Status = "passed" if all(judged) else "failed"
    n_fail = sum(1 for p in judged if not p)
    message = f"{len(judged) - n_fail} of {len(judged)} checks within tolerance"
    n_info = sum(1 for c in checks if c.kind == "info")
    if n_info:
        message += f", {n_info} informative"
    return CaseResult(name, title, source, tuple(checks), status, message, series or {}, elapsed)


@dataclass(frozen=True)
class _Case:
    name: str
    title: str
    source: str
    run: Callable[[], CaseResult]
    references: Callable[[], list[Check]]


#: The registered cases, in the manual's order.
CASES: dict[str, _Case] = {}


def register(name: str, title: str, source: str, references: Callable[[], list[Check]]) -> Callable:
    """Decorator registering a case runner (``run() -> CaseResult``) under ``name``.

    Parameters
    ----------
    name : str
    title : str
    source : str
        Key of :data:`~impactbeam.validation.references.SOURCES`.
    references : callable
        The case's checks without results (reported when the case cannot run).
    """

    def deco(fn: Callable[[], CaseResult]) -> Callable[[], CaseResult]:
        CASES[name] = _Case(name, title, source, fn, references)
        return fn

    return deco


@dataclass(frozen=True, eq=False)
class ValidationReport:
    """Every case's result.

    Attributes
    ----------
    cases : tuple of CaseResult
    """

    cases: tuple[CaseResult, ...]

    @property
    def passed(self) -> bool:
        """True when every case ran and every judged check is within its tolerance."""
        return all(c.status == "passed" for c in self.cases)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready report."""
        return {"passed": self.passed, "cases": [c.as_dict() for c in self.cases]}


def sample(result: Any, point: float, t: np.ndarray) -> np.ndarray:
    """``w(point, t)`` [m] from the exact solution of a result."""
    return np.asarray(result.displacement([point], np.asarray(t, dtype=float)))[0]
