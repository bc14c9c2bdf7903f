"""The validation manual's figures, one per case, in the journal style of :mod:`impactbeam.plot`."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .core import CaseResult, ValidationReport

__all__ = ["case_figure", "write_figures"]


def _sdlx400(case: CaseResult, ax) -> None:
    rel = [100 * (c.relative_difference or np.nan) for c in case.checks]
    tol = [100 * (c.tolerance or np.nan) for c in case.checks]
    x = np.arange(len(rel))
    ax.bar(x, rel, color="0.35", width=0.6, label="impactbeam - reference")
    ax.plot(x, tol, "k_", ms=14, label="code_aster PRECISION")
    ax.plot(x, [-t for t in tol], "k_", ms=14)
    ax.set_xticks(x, [c.quantity.replace(" [Hz]", "").replace(", ", "\n") for c in case.checks], fontsize=7)
    ax.set_ylabel("relative difference [%]")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.legend(fontsize=7)


def _sdnl32(case: CaseResult, ax) -> None:
    t = case.series["t"]
    for i, k in enumerate((18000, 45000)):
        ls = ("-", "--")[i]
        ax.plot(1e3 * t, 1e3 * case.series[f"k{k}"], color="k", ls=ls, lw=1.0, label=f"impactbeam, k = {k} N/m")
        refs = [c for c in case.checks if c.quantity.startswith(f"k = {k} ")]
        ax.plot(np.arange(1, 13), [1e3 * c.reference for c in refs], "os"[i], mfc="none", color="k", ms=5,
                label=f"VPCS reference, k = {k} N/m")
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("tip deflection w(L) [mm]")
    ax.legend(fontsize=7)


def _sdnl104(case: CaseResult, ax) -> None:
    t = case.series["t"]
    for i, label in enumerate(k for k in case.series if k != "t"):
        ax.plot(t, 1e6 * case.series[label], lw=1.0, ls=("-", "--", ":", "-.", (0, (5, 1)))[i % 5], label=label)
    ref = case.checks[0]
    ax.plot([0.1315], [1e6 * ref.reference], "ko", mfc="none", ms=6, label="reference (DYNA_NON_LINE)")
    ax.axhline(-100.0, color="0.5", lw=0.5)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("tip deflection w(L) [um]")
    ax.set_ylim(-130.0, 20.0)
    ax.legend(fontsize=6, loc="lower left")


def _table2(case: CaseResult, ax) -> None:
    s = case.series
    x = np.arange(len(s["labels"]))
    ax.bar(x - 0.2, 1e3 * np.asarray(s["measured_max"]), width=0.4, color="0.7", label="measured (Table 2)")
    ax.bar(x + 0.2, 1e3 * np.asarray(s["simulated_max"]), width=0.4, color="0.25", label="impactbeam, ideal pulse")
    ax.set_xticks(x, [f"Case {c}" for c in s["cases"]], fontsize=7)
    ax.set_ylabel("maximum response [mm]")
    ax.legend(fontsize=7)


_DRAW = {"SDLX400": _sdlx400, "SDNL32": _sdnl32, "SDNL104": _sdnl104, "Table2": _table2}


def case_figure(case: CaseResult):
    """The figure of one case (a matplotlib Figure), or None when the case did not run.

    Parameters
    ----------
    case : CaseResult
    """
    if case.status == "not run" or case.name not in _DRAW:
        return None
    from ..plot import STYLE, figure_size
    from ..plot.figure import _new_figure
    from .._optional import require

    mpl = require("matplotlib", "plot")
    with mpl.rc_context(STYLE):
        fig, axes = _new_figure(figure_size("double", 0.42))
        ax = axes[0, 0]
        _DRAW[case.name](case, ax)
        ax.set_title(f"{case.name}: {case.title}", fontsize=8)
    return fig


def write_figures(report: ValidationReport, directory: str | Path) -> list[Path]:
    """Write ``validation_<case>.png`` for every case that ran into ``directory``; their paths.

    Parameters
    ----------
    report : ValidationReport
    directory : str or path-like
    """
    from ..plot import save_figure

    out = []
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    for case in report.cases:
        fig = case_figure(case)
        if fig is not None:
            out.append(save_figure(fig, d / f"validation_{case.name.lower()}.png", dpi=150))
    return out
