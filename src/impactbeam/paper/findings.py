"""Findings and verdicts: each statement of the paper checked against the simulations, and the report's data."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
import numpy as np

from ..result.timegrid import scan_times
from .conventions import PaperMetrics
from .data import PAPER_CONVERGENCE
from .plan import FLEX_HEIGHTS, FLEX_STIFFNESS, PARAMETER_STUDY, _BASE_VALUE, _quasi_static_deflection

__all__ = ["Finding", "ReproductionReport"]


@dataclass(frozen=True)
class Finding:
    """A statement of the paper checked on the simulation.

    Attributes
    ----------
    topic : str
    statement : str
        The paper's claim (quoted or paraphrased).
    verdict : str
        ``"holds"``, ``"holds partly"`` or ``"does not hold"``.
    evidence : str
        The numbers behind the verdict.
    """

    topic: str
    statement: str
    verdict: str
    evidence: str

    @property
    def holds(self) -> bool:
        """True for ``"holds"``."""
        return self.verdict == "holds"


@dataclass
class ReproductionReport:
    """Everything :func:`reproduce` computed and wrote.

    All numbers SI (m, s, Hz) unless a key says otherwise; percentages as
    ``(simulated - paper) / |paper| * 100``.

    Attributes
    ----------
    out_dir, report_md, report_html : Path
    figures : dict of str -> Path
        Name -> PNG file.
    frequencies : list of dict
        Per mode: ``mode``, ``free_hz``, ``contact_hz``, ``closed_form_hz``,
        ``paper_computed_hz``, ``paper_measured_hz`` and differences.
    cases : dict of int -> dict
        Per Table 1 case: the :class:`PaperMetrics` fields plus ``label``.
    table2 : list of dict
        The Table 2 analogue (simulated, measured, difference per metric).
    section4 : list of dict
    findings : list of Finding
        Section 3 qualitative findings.
    free_decay : dict
        Frequency and damping identified from Case 0's simulated record.
    convergence : list of dict
    convergence_findings : list of Finding
    parameter_study : dict of str -> list of dict
        Per parameter: rows of the varied value and the metrics.
    parameter_findings : list of Finding
    refit : list of dict
    n_simulations : int
    elapsed : float, [s]
    direction_check : list of dict
        Per contact case, the direction of the first excursion (away from the contactor first?).
    settings : dict
        The settings of the study (modes, output step, durations).
    warnings : list of str
        The runs' warnings, each labelled with its run (a run the solver does not trust: its findings with it).
    """

    out_dir: Path
    report_md: Path
    report_html: Path
    figures: dict[str, Path]
    frequencies: list[dict[str, Any]]
    cases: dict[int, dict[str, Any]]
    table2: list[dict[str, Any]]
    section4: list[dict[str, Any]]
    findings: list[Finding]
    free_decay: dict[str, float]
    direction_check: list[dict[str, Any]]
    convergence: list[dict[str, Any]]
    convergence_findings: list[Finding]
    parameter_study: dict[str, list[dict[str, Any]]]
    parameter_findings: list[Finding]
    refit: list[dict[str, Any]]
    n_simulations: int = 0
    elapsed: float = 0.0
    settings: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)

    def all_findings(self) -> list[Finding]:
        """Section 3, convergence and parameter-study findings together."""
        return [*self.findings, *self.convergence_findings, *self.parameter_findings]

    def summary_rows(self) -> list[tuple[str, str, str, str]]:
        """(quantity, simulated, paper, difference) rows for a terminal summary."""
        rows: list[tuple[str, str, str, str]] = []
        for f in self.frequencies[:2]:
            rows.append((f"f{f['mode']} free state", f"{f['free_hz']:.2f} Hz",
                         f"{f['paper_measured_hz']:.2f} Hz (measured)", _pct(f["diff_measured_percent"])))
        for r in self.section4:
            rows.append((r["quantity"], _fmt(r["simulated"], r["unit"]), _fmt(r["paper_measured"], r["unit"]) + " (test)",
                         _pct(r["diff_measured_percent"])))
        n_hold = sum(f.holds for f in self.all_findings())
        rows.append(("paper statements that hold", f"{n_hold} of {len(self.all_findings())}", "", ""))
        return rows


def _pct(x: float | None) -> str:
    if x is None or not math.isfinite(x):
        return "n/a"
    return f"{x:+.1f} %"


def _fmt(x: float | None, unit: str) -> str:
    """Format an SI value in the display unit ``mm``, ``ms``, ``Hz``, ``-`` or ``%``."""
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    if unit == "mm":
        return f"{x * 1e3:.4f}"
    if unit == "ms":
        return f"{x * 1e3:.2f}"
    if unit == "Hz":
        return f"{x:.2f}"
    if unit == "%":
        return f"{x:.2f}"
    if unit == "-":
        return f"{int(x)}" if float(x).is_integer() else f"{x:.3g}"
    return f"{x:.4g}"


def _diff(sim: float | None, ref: float | None) -> float:
    if sim is None or ref is None or not math.isfinite(sim) or not math.isfinite(ref) or ref == 0:
        return float("nan")
    return (sim - ref) / abs(ref) * 100.0


def _trend(x: Sequence[float], y: Sequence[float], rel_tol: float = 0.005) -> tuple[str, float]:
    """Classify ``y(x)`` as increasing / decreasing / flat / non-monotonic; also Spearman's rho.

    Successive changes smaller than ``rel_tol`` times ``max |y|`` count as no
    change. NaN points are dropped.
    """
    xa, ya = np.asarray(x, float), np.asarray(y, float)
    ok = np.isfinite(xa) & np.isfinite(ya)
    xa, ya = xa[ok], ya[ok]
    if ya.size < 2:
        return "undefined", float("nan")
    order = np.argsort(xa)
    ya = ya[order]
    tol = rel_tol * float(np.max(np.abs(ya))) if np.any(ya) else 0.0
    dy = np.diff(ya)
    rho = _spearman(xa[order], ya)
    if np.all(np.abs(dy) <= tol):
        return "flat", rho
    if np.all(dy >= -tol):
        return "increasing", rho
    if np.all(dy <= tol):
        return "decreasing", rho
    return "non-monotonic", rho


def _spearman(x: np.ndarray, y: np.ndarray) -> float:
    from scipy.stats import rankdata

    rx, ry = rankdata(x), rankdata(y)
    if np.std(rx) == 0 or np.std(ry) == 0:
        return float("nan")
    return float(np.corrcoef(rx, ry)[0, 1])


def _verdict_trend(trend: str, rho: float, expected: str) -> str:
    if trend == expected:
        return "holds"
    sign = 1.0 if expected == "increasing" else -1.0
    if trend == "non-monotonic" and math.isfinite(rho) and sign * rho >= 0.7:
        return "holds partly"
    return "does not hold"


def _mm(x: float) -> str:
    return f"{x * 1e3:.4f} mm" if math.isfinite(x) else "n/a"


def _ms(x: float) -> str:
    return f"{x * 1e3:.2f} ms" if math.isfinite(x) else "n/a"


def _section3_findings(met: Mapping[int, PaperMetrics]) -> list[Finding]:
    out = []
    d = {n: met[n] for n in met}
    # shorter pulse -> smaller maximum (Cases 3, 4, 5)
    seq = [(15, d[3]), (10, d[4]), (5, d[5])]
    vals = [m.max_response for _, m in seq]
    ok = vals[0] > vals[1] > vals[2]
    out.append(Finding("pulse duration", "Shortening the pulse lowers the maximum response (section 3.1).",
                       "holds" if ok else "does not hold",
                       "max d for 15 / 10 / 5 ms (Cases 3, 4, 5): " + " / ".join(_mm(v) for v in vals)
                       + f"; changes {_pct(_diff(vals[1], vals[0]))} and {_pct(_diff(vals[2], vals[0]))}"
                       " (measured -9.08 % and -24.26 %)."))
    vals = [m.free_duration for _, m in seq]
    ok = vals[0] > vals[1] > vals[2]
    out.append(Finding("pulse duration", "Shortening the pulse shortens the time in the free state (section 3.1).",
                       "holds" if ok else "does not hold",
                       "free duration for 15 / 10 / 5 ms: " + " / ".join(_ms(v) for v in vals)
                       + f"; changes {_pct(_diff(vals[1], vals[0]))} and {_pct(_diff(vals[2], vals[0]))}"
                       " (measured -21.39 % and -34.76 %)."))
    vals = [m.contact_duration for _, m in seq]
    spread = (max(vals) - min(vals)) / vals[0] * 100
    out.append(Finding("pulse duration", "The time in contact is insensitive to the pulse duration (abstract, 3.1); "
                       "criterion here: spread below 10 % of Case 3's value (the measured spread is 5 %).",
                       "holds" if spread < 10 else "does not hold",
                       "first contact duration for 15 / 10 / 5 ms: " + " / ".join(_ms(v) for v in vals)
                       + f"; spread {spread:.1f} %."))
    # stronger pulse -> larger maximum (Cases 7, 6, 8, 3)
    seq = [(5, d[7]), (10, d[6]), (12.5, d[8]), (15, d[3])]
    vals = [m.max_response for _, m in seq]
    ok = all(b > a for a, b in zip(vals, vals[1:]))
    out.append(Finding("pulse amplitude", "A stronger pulse gives a larger maximum response (section 3.2).",
                       "holds" if ok else "does not hold",
                       "max d for 5 / 10 / 12.5 / 15 g (Cases 7, 6, 8, 3): " + " / ".join(_mm(v) for v in vals)
                       + f"; +25 % and +50 % pulse from 10 g: {_pct(_diff(vals[2], vals[1]))} and "
                       f"{_pct(_diff(vals[3], vals[1]))} (measured +19.41 % and +40.79 %)."))
    vals = [m.contact_duration for _, m in seq[1:]]
    ok = vals[1] < vals[0] and vals[2] < vals[0]
    out.append(Finding("pulse amplitude", "A stronger pulse shortens the time in contact (section 3.2: -14.89 % for "
                       "+25 % and +50 %).", "holds" if ok else "does not hold",
                       "first contact duration for 10 / 12.5 / 15 g: " + " / ".join(_ms(v) for v in vals)
                       + f"; changes {_pct(_diff(vals[1], vals[0]))} and {_pct(_diff(vals[2], vals[0]))}."))
    # gap
    seq = [(0, d[9]), (0.102, d[2]), (0.229, d[3]), (0.432, d[10]), (0.686, d[11])]
    vals = [m.max_response for _, m in seq]
    ok = vals[0] == min(vals) and all(v > vals[0] for v in vals[1:])
    out.append(Finding("gap size", "No gap gives the smallest response (section 3.3).",
                       "holds" if ok else "does not hold",
                       f"max d with no gap (Case 9) {_mm(vals[0])} against {_mm(min(vals[1:]))} or more with a gap. "
                       f"The measured value with no gap, 0.2323 mm, is not approached: the simulation gives "
                       f"{_pct(_diff(vals[0], 0.2323e-3))}, because the first peak occurs before any contact, "
                       "so it is the same from rest in every case and d = u + c only adds the gap."))
    ok = all(b > a for a, b in zip(vals, vals[1:]))
    out.append(Finding("gap size", "A larger gap gives a larger maximum response (section 3.3).",
                       "holds" if ok else "does not hold",
                       "max d for gap 0 / 0.102 / 0.229 / 0.432 / 0.686 mm: " + " / ".join(_mm(v) for v in vals)
                       + f"; 0.229 -> 0.432 mm: {_pct(_diff(vals[3], vals[2]))} (measured +12.72 %)."))
    vals = [m.free_duration for _, m in seq[2:4]]
    out.append(Finding("gap size", "A larger gap extends the time in the free state (section 3.3, Cases 3 and 10).",
                       "holds" if vals[1] > vals[0] else "does not hold",
                       f"free duration gap 0.229 / 0.432 mm: {_ms(vals[0])} / {_ms(vals[1])} "
                       "(measured 18.7 / 20.0 ms)."))
    return out


def _convergence_findings(conv: Mapping[int, Mapping[int, PaperMetrics]]) -> list[Finding]:
    c12, c3 = conv[12], conv[3]
    d28 = abs(_diff(c12[2].max_response, c12[8].max_response))
    lim = PAPER_CONVERGENCE["no_contact_first_peak_2_vs_8_modes_percent"]
    out = [Finding("convergence", "Without contact the first peak differs by 0.01 % between 2 and 8 modes "
                   "(section 4); criterion: at most 0.01 %.", "holds" if d28 <= lim else "does not hold",
                   f"Case 12 first peak: {_mm(c12[2].max_response)} with 2 modes, {_mm(c12[8].max_response)} with 8: "
                   f"{d28:.4f} % apart.")]
    ch = {k: abs(_diff(getattr(c3[8], k), getattr(c3[16], k))) for k in ("max_response", "min_response", "contact_duration")}
    ch4 = {k: abs(_diff(getattr(c3[4], k), getattr(c3[16], k))) for k in ("min_response", "contact_duration")}
    ok = all(v < 1.0 for v in ch.values())
    out.append(Finding("convergence", "With contact (gap 0.229 mm) the response has converged at eight modes "
                       "(section 4); criterion: first peak, first-contact minimum and contact duration change by less "
                       "than 1 % from 8 to 16 modes.", "holds" if ok else "does not hold",
                       f"Case 3, 8 -> 16 modes: first peak {ch['max_response']:.3f} %, minimum {ch['min_response']:.3f} %, "
                       f"contact duration {ch['contact_duration']:.3f} % (4 -> 16 modes: {ch4['min_response']:.2f} % and "
                       f"{ch4['contact_duration']:.2f} %)."))
    return out


def _elasticity(rows: Sequence[tuple[float, PaperMetrics]], base: float, key: str) -> float:
    """d ln(metric) / d ln(parameter) between the two study values around ``base`` (NaN if undefined)."""
    xs = [v for v, _ in rows]
    i = int(np.argmin(np.abs(np.asarray(xs) - base)))
    if i == 0 or i == len(rows) - 1:
        return float("nan")
    (x0, m0), (x1, m1) = rows[i - 1], rows[i + 1]
    y0, y1 = float(getattr(m0, key)), float(getattr(m1, key))
    if min(x0, x1, y0, y1) <= 0 or not all(map(math.isfinite, (y0, y1))):
        return float("nan")
    return math.log(y1 / y0) / math.log(x1 / x0)


def _parameter_findings(data: dict[str, Any]) -> list[Finding]:
    study: dict[str, list[tuple[float, PaperMetrics]]] = data["study"]
    out: list[Finding] = []

    def trend_finding(name: str, key: str, expected: str, what: str, unit: str) -> Finding:
        rows = study[name]
        spec = PARAMETER_STUDY[name]
        xs = [v for v, _ in rows]
        ys = [getattr(m, key) for _, m in rows]
        tr, rho = _trend(xs, ys)
        verdict = _verdict_trend(tr, rho, expected)
        fmt = {"mm": _mm, "ms": _ms}.get(unit, lambda v: f"{v:.3g}")
        pairs = ", ".join(f"{v * spec['scale']:.4g}: {fmt(y) if math.isfinite(y) else 'n/a'}" for v, y in zip(xs, ys))
        extra = ""
        if tr == "non-monotonic":
            ya = np.asarray(ys, float)
            ok = np.isfinite(ya)
            xa = np.asarray(xs, float)[ok]
            extra = (f" (largest at {xa[np.argmax(ya[ok])] * spec['scale']:.4g} {spec['unit']}, smallest at "
                     f"{xa[np.argmin(ya[ok])] * spec['scale']:.4g} {spec['unit']})")
        return Finding(name, f"{what} {'increases' if expected == 'increasing' else 'decreases'} with "
                       f"{spec['label']}.", verdict,
                       f"{tr}{extra}, Spearman rho {rho:+.2f}; {spec['label']} [{spec['unit']}] -> {key}: {pairs}.")

    for name in ("height", "modulus"):
        out.append(trend_finding(name, "cycle_time", "decreasing", "The cycle time", "ms"))
        out.append(trend_finding(name, "max_response", "decreasing", "The maximum deflection", "mm"))
    flex = data["flex"]
    sens = {}
    for hf, runs in flex.items():
        lo, hi, mid = runs[FLEX_STIFFNESS[0]], runs[FLEX_STIFFNESS[1]], runs[1.0]
        sens[hf] = (abs(hi.cycle_time - lo.cycle_time) / mid.cycle_time * 100,
                    abs(hi.total_contact_time - lo.total_contact_time) / mid.total_contact_time * 100)
    f_lo, f_hi = sens[FLEX_HEIGHTS[0]], sens[FLEX_HEIGHTS[1]]
    ok = f_lo[0] > f_hi[0] and f_lo[1] > f_hi[1]
    part = f_lo[0] > f_hi[0] or f_lo[1] > f_hi[1]
    out.append(Finding("height", "The more flexible the structure, the more sensitive to the contact stiffness k; "
                       "measured as the change of cycle time and total contact time when k goes from 0.5x to 2x, "
                       "for h = 0.8 h0 against 1.2 h0.", "holds" if ok else ("holds partly" if part else "does not hold"),
                       f"h = 0.8 h0: cycle time {f_lo[0]:.1f} %, total contact time {f_lo[1]:.1f} %; "
                       f"h = 1.2 h0: {f_hi[0]:.1f} %, {f_hi[1]:.1f} %."))
    out.append(trend_finding("stiffness", "cycle_time", "decreasing", "The cycle time", "ms"))
    out.append(trend_finding("stiffness", "contact_duration", "decreasing", "The first contact duration", "ms"))
    out.append(trend_finding("stiffness", "total_contact_time", "decreasing", "The total contact time", "ms"))
    rows = study["stiffness"]
    multi = [(v, m.impacts_per_cycle) for v, m in rows]
    high = [ipc for v, ipc in multi if v > 4030.0]
    out.append(Finding("stiffness", "For higher k two or three impacts may occur in each cycle.",
                       "holds" if high and max(high) >= 2 else "does not hold",
                       "largest number of impacts in one cycle, by k [N/m]: "
                       + ", ".join(f"{v:g}: {n}" for v, n in multi) + "."))
    # location: most influential, and greatest rebound at the tip
    keys = ("n_impacts", "total_contact_time", "rebound_response")
    el = {name: tuple(_elasticity(rows, _BASE_VALUE[name], k) for k in keys) for name, rows in study.items()}
    firsts = []
    for j in range(len(keys)):
        best = max(el, key=lambda n: abs(np.nan_to_num(el[n][j])))
        firsts.append(best == "location")
    ok = all(firsts)
    part = any(firsts)
    out.append(Finding("location", "The contact location is the parameter that most affects impact and rebound "
                       "behaviour; measured by the local elasticity |d ln(metric) / d ln(parameter)| at Case 3 "
                       "(central difference between the two neighbouring values of each study) of the number of "
                       "impacts, the total contact time and the rebound response.",
                       "holds" if ok else ("holds partly" if part else "does not hold"),
                       "elasticities (impacts / total contact time / rebound response): "
                       + ", ".join(f"{n} {el[n][0]:+.2f} / {el[n][1]:+.2f} / {el[n][2]:+.2f}" for n in study)
                       + "; location is the largest for " + str(sum(firsts)) + " of 3."))
    rows = study["location"]
    reb = [(v, m.rebound_response) for v, m in rows if math.isfinite(m.rebound_response)]
    best = max(reb, key=lambda p: p[1])
    out.append(Finding("location", "Placing the contactor at the point of maximum deflection (the tip of a "
                       "cantilever) gives the greatest rebound response (largest d after the first rebound).",
                       "holds" if best[0] == max(v for v, _ in rows) else "does not hold",
                       "rebound response by a/L: " + ", ".join(f"{v:g}: {_mm(r)}" for v, r in reb)
                       + f"; greatest at a/L = {best[0]:g}."))
    # damping
    out.append(trend_finding("damping", "max_response", "decreasing", "The maximum response", "mm"))
    out.append(trend_finding("damping", "rebound_response", "decreasing", "The rebound response", "mm"))
    out.append(trend_finding("damping", "n_impacts", "decreasing", "The number of impacts (response complexity)", "-"))
    rows = study["damping"]
    a0, a1 = rows[0][1].max_response, rows[-1][1].max_response
    out.append(Finding("damping", "Increasing damping *drastically* decreases all amplitudes; criterion: the first "
                       "peak falls by more than 10 % over a 16-fold increase of the damping ratio.",
                       "holds" if _diff(a1, a0) < -10 else "does not hold",
                       f"first peak {_mm(a0)} at {rows[0][0] * 100:.3g} % damping, {_mm(a1)} at "
                       f"{rows[-1][0] * 100:.3g} %: {_pct(_diff(a1, a0))}; the peak is reached during the pulse, "
                       "within one period, so damping has little time to act."))
    # pulse duration
    out.append(trend_finding("duration", "cycle_time", "increasing", "The cycle time", "ms"))
    out.append(trend_finding("duration", "max_response", "increasing", "The maximum deflection", "mm"))
    sc, res = data["long_pulse"]
    t1 = sc.excitation.duration
    a = sc.contactors[0].position
    q = sc.beam.mass_per_length * sc.excitation.amplitude
    u_static = _quasi_static_deflection(sc.beam, a, q)  # away from the contactor
    lo, hi = 0.25 * t1, 0.75 * t1  # the middle half of the pulse, on the exact solution (not the output grid)
    tq = scan_times(res, lo, hi, breaks=False)
    amp_osc = float(np.max(np.abs(-res.displacement([a], tq)[0] - u_static * np.sin(np.pi * tq / t1))))
    quasi_static = u_static * t1 / np.pi * (math.cos(np.pi * lo / t1) - math.cos(np.pi * hi / t1))
    mean_offset = (-res.solution.integral(a, lo, hi) - quasi_static) / (hi - lo)
    free_during = not any(ev.time < t1 for ev in res.events if ev.kind == "impact")
    ok = free_during and abs(mean_offset) < 0.2 * u_static
    out.append(Finding("duration", "With a long enough pulse the beam vibrates about a balanced (quasi-static) "
                       "position in free motion while the load acts; checked for the longest pulse against the static "
                       "cantilever deflection q x^2 (6L^2 - 4Lx + x^2) / (24 EI), q = rho A a(t).",
                       "holds" if ok else "does not hold",
                       f"{t1 * 1e3:g} ms pulse: static deflection at a at the pulse peak {_mm(u_static)}; over the middle "
                       f"half of the pulse the deflection oscillates about it with amplitude up to {_mm(amp_osc)} and mean "
                       f"offset {_mm(mean_offset)}; "
                       + ("no impact while the pulse acts." if free_during else "impacts occur while the pulse acts.")))
    # clearance
    out.append(trend_finding("clearance", "cycle_time", "decreasing", "The cycle time", "ms"))
    out.append(trend_finding("clearance", "contact_fraction", "decreasing", "The contact fraction of the first cycle", "-"))
    rows = study["clearance"]
    xs = [v for v, _ in rows]
    pen = [-m.min_response for _, m in rows]
    tr, rho = _trend(xs, pen)
    out.append(Finding("clearance", "The deformation amplitude in the contact state increases (dramatically) with "
                       "the gap; measured as the penetration -d at the first-contact minimum.",
                       _verdict_trend(tr, rho, "increasing"),
                       f"{tr} (rho {rho:+.2f}); penetration by gap [mm]: "
                       + ", ".join(f"{v * 1e3:.3g}: {_mm(p)}" for v, p in zip(xs, pen)) + "."))
    return out
