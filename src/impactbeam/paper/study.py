"""The reproduction study: the plan (Table 1 cases, convergence, the one-at-a-time parameter study, the refit),
its runner with progress, and :func:`reproduce`, which writes the report and its figures.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any
import numpy as np

from ..exceptions import ParameterError
if TYPE_CHECKING:
    from ..result import SimulationResult
    from ..scenario import Scenario
from .conventions import PaperMetrics, paper_metrics
from .data import PAPER_FREQUENCIES, SECTION4, TABLE1, TABLE2_MEASURED
from .._io import write_text
from .._warnings import Progress
from ..experiment.damping import ratio_from_decrement
from .document import _document
from .figures import _figures
from .findings import (
    ReproductionReport,
    _convergence_findings,
    _diff,
    _parameter_findings,
    _section3_findings,
)
from .plan import (
    CONVERGENCE_MODES,
    FLEX_HEIGHTS,
    FLEX_STIFFNESS,
    N_FIGURES,
    PARAMETER_STUDY,
    _all_scenarios,
    _closed_form_cantilever,
    _flex_values,
    _param_values,
    _refit_variants,
    _table1_scenarios,
)

__all__ = ["planned_simulations", "reproduce"]


def planned_simulations() -> int:
    """Number of distinct runs :func:`reproduce` makes (identical scenarios run once)."""
    return len({_Runner.key(sc) for sc in _all_scenarios()})


class _Runner:
    """Runs scenarios once each (keyed by their data), counting and reporting progress."""

    def __init__(self, progress: Callable[[str], None] | None) -> None:
        self._cache: dict[str, Any] = {}
        self._progress = progress
        self.count = 0
        self.warnings: list[str] = []  # each run's, labelled with the run (the report lists them)

    @staticmethod
    def key(sc: Scenario) -> str:
        # the validated objects, so that "15 ms" and 0.015 are the same run
        return repr((sc.beam, sc.contactors, sc.damping, sc.excitation, sc.initial, sc.solver, sc.output_points))

    def run(self, sc: Scenario, label: str = "") -> SimulationResult:
        from ..exceptions import SimulationError
        from ..simulation import simulate

        k = self.key(sc)
        if k not in self._cache:
            from .._warnings import WarningLog, emit_user_level_warning

            with WarningLog() as log:  # said again with the run they belong to
                res = simulate(sc)
            for text in log.messages:
                self.warnings.append(f"{label or sc.name}: {text}")
                emit_user_level_warning(self.warnings[-1])
            if not res.success:
                raise SimulationError(f"{label or sc.name}: {res.message}")
            self._cache[k] = res
            self.count += 1
            if self._progress is not None:
                self._progress(label or sc.name)
        return self._cache[k]


def _free_decay(result: SimulationResult) -> dict[str, float]:
    """First-mode frequency (zero crossings) and damping (log decrement) from a release record at the tip.

    On the exact solution, not the output grid: the up-crossings of ``w`` are located on its scan grid
    (:func:`~impactbeam.result.timegrid.scan_times`) and refined by Brent's method, the peaks between them
    are the solver's extrema.
    """
    from scipy.optimize import brentq

    from ..result.timegrid import scan_times

    x, t_end = float(result.points[-1]), float(result.solution.t_end)
    if not t_end > 0.05:
        return {"frequency_hz": float("nan"), "damping_ratio": float("nan"), "cycles": 0.0}
    t = scan_times(result, 0.05, t_end, breaks=False)  # from 50 ms: modes >= 2 have died out (1/(xi w) < 45 ms)
    w = result.displacement([x], t)[0]
    up = np.nonzero((w[:-1] < 0) & (w[1:] >= 0))[0]
    tc = np.array([brentq(lambda s: float(result.displacement([x], [s])[0, 0]), float(t[i]), float(t[i + 1]),
                          xtol=1e-15) if w[i + 1] > 0 else float(t[i + 1]) for i in up])
    f = (tc.size - 1) / (tc[-1] - tc[0]) if tc.size > 2 else float("nan")
    peaks = [float(v) for v in result.solution.extrema([(x, a, b, 1.0, 0.0, None)
                                                         for a, b in zip(tc[:-1], tc[1:])])[:, 0]]
    if len(peaks) > 2 and peaks[-1] > 0:
        delta = math.log(peaks[0] / peaks[-1]) / (len(peaks) - 1)
        xi = ratio_from_decrement(delta)
    else:
        xi = float("nan")
    return {"frequency_hz": float(f), "damping_ratio": float(xi), "cycles": float(max(tc.size - 1, 0))}


def reproduce(out_dir: str | os.PathLike[str], *, progress: bool = True) -> ReproductionReport:
    """Rebuild the paper's results section and set it beside the paper's numbers.

    Runs, with ideal half-sine pulses and the paper's raw parameters (nothing
    is tuned): every Table 1 case; the natural frequencies; the Table 2
    analogue and the section 4 values; the section 3 findings; a mode
    convergence study (2, 4, 8, 16 modes, Cases 12 and 3); the one-at-a-time
    study of the seven parameters of section 2 around Case 3; the refit of
    section 4.2 (k = 7000 N/m, pulse +20 %). Writes ``report.md``,
    ``report.html`` and ``figures/*.png`` into ``out_dir``.

    Parameters
    ----------
    out_dir : path-like
        Created if missing.
    progress : bool
        Show progress on stderr (a bar on a terminal, lines into a file or a pipe).

    Returns
    -------
    ReproductionReport

    Raises
    ------
    ParameterError
        ``out_dir`` exists and is not a directory.
    SimulationError
        A run did not reach its end time.
    """
    t_start = time.perf_counter()
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise ParameterError(f'--out: "{out}" exists and is not a directory')
    fig_dir = out / "figures"
    fig_dir.mkdir(parents=True, exist_ok=True)

    n_figs = N_FIGURES
    bar = Progress(planned_simulations() + n_figs, desc="reproduce", unit="step", enabled=progress, after=0.0,
                   dynamic_ncols=True, leave=True)

    def tick(label: str) -> None:
        bar.advance(1)

    runner = _Runner(tick)
    try:
        data = _compute(runner)
        figures = _figures(data, fig_dir, tick)
    finally:
        bar.close()
    report = _assemble(data, out, figures, runner.count, time.perf_counter() - t_start)
    report.warnings = list(runner.warnings)
    doc = _document(report, data)
    write_text(report.report_md, doc.markdown())
    write_text(report.report_html, doc.html("impactbeam: reproduction of Xu & Ervin (2013)"))
    return report


def _compute(runner: _Runner) -> dict[str, Any]:
    """Run every simulation of the reproduction; return the raw material of the report."""
    from ..modal import scenario_modes

    data: dict[str, Any] = {}
    # --- Table 1 cases; no-contactor cases recorded at a and the tip
    scs = _table1_scenarios()
    results = {n: runner.run(sc, f"case {n}") for n, sc in scs.items()}
    data["scenarios"], data["results"] = scs, results
    free_period = 1.0 / float(scenario_modes(scs[3], 1).free.frequencies_hz[0])
    data["metrics"] = {n: paper_metrics(r, free_period=free_period) for n, r in results.items()}

    # --- frequencies
    sm = scenario_modes(scs[3], 8)
    data["modes"] = sm
    data["closed_form"] = _closed_form_cantilever(scs[3].beam, 2)
    data["free_decay"] = {n: _free_decay(results[n]) for n in (0, 13)}

    # --- convergence
    conv: dict[int, dict[int, PaperMetrics]] = {}
    for n in (12, 3):
        conv[n] = {}
        for m in CONVERGENCE_MODES:
            sc = scs[n].with_values({"solver.modes": m})
            conv[n][m] = paper_metrics(runner.run(sc, f"case {n}, {m} modes"), free_period=free_period)
    data["convergence"] = conv

    # --- parameter study around Case 3
    base = scs[3]
    study: dict[str, list[tuple[float, PaperMetrics]]] = {}
    long_pulse: Any = None
    for name, spec in PARAMETER_STUDY.items():
        rows = []
        for v in spec["values"]:
            sc = base.with_values(_param_values(name, v))
            fp = free_period if name not in ("height", "modulus") else None
            res = runner.run(sc, f"{name} = {v:.4g}")
            rows.append((v, paper_metrics(res, free_period=fp)))
            if name == "duration" and v == max(spec["values"]):
                long_pulse = (sc, res)
        study[name] = rows
    data["study"] = study
    data["long_pulse"] = long_pulse
    flex: dict[float, dict[float, PaperMetrics]] = {}
    for hf in FLEX_HEIGHTS:
        flex[hf] = {}
        for kf in (*FLEX_STIFFNESS, 1.0):
            sc = base.with_values(_flex_values(hf, kf))
            flex[hf][kf] = paper_metrics(runner.run(sc, f"h x{hf}, k x{kf}"))
    data["flex"] = flex

    # --- refit (section 4.2)
    variants = _refit_variants(base)
    refit = {}
    for label, vals in variants.items():
        sc = base.with_values(vals) if vals else base
        refit[label] = (sc, runner.run(sc, f"refit: {label}"))
    data["refit"] = refit
    return data


def _assemble(data: dict[str, Any], out: Path, figures: dict[str, Path], n_sims: int, elapsed: float) -> ReproductionReport:
    met: dict[int, PaperMetrics] = data["metrics"]
    sm = data["modes"]
    # frequencies
    freqs = []
    for i in range(2):
        f_free = float(sm.free.frequencies_hz[i])
        pc, pm = PAPER_FREQUENCIES["computed_hz"][i], PAPER_FREQUENCIES["measured_hz"][i]
        freqs.append({
            "mode": i + 1, "free_hz": f_free, "contact_hz": float(sm.contact.frequencies_hz[i]),
            "closed_form_hz": data["closed_form"][i], "paper_computed_hz": pc, "paper_measured_hz": pm,
            "paper_measured_uncertainty_hz": PAPER_FREQUENCIES["measured_uncertainty_hz"],
            "diff_computed_percent": _diff(f_free, pc), "diff_measured_percent": _diff(f_free, pm),
            "within_measured_band": abs(f_free - pm) <= PAPER_FREQUENCIES["measured_uncertainty_hz"],
        })
    cases_out = {}
    for c in TABLE1:
        d = met[c.number].as_dict()
        d["label"] = c.label
        d["has_contactor"] = c.gap is not None
        cases_out[c.number] = d
    table2 = []
    for row in TABLE2_MEASURED:
        m = met[row.case]
        entry: dict[str, Any] = {"group": row.group, "value": row.value, "case": row.case}
        for key in ("max_response", "free_duration", "min_response", "contact_duration"):
            sim = getattr(m, key)
            meas = getattr(row, key)
            entry[key] = {"simulated": sim, "measured": meas, "diff_percent": _diff(sim, meas)}
        table2.append(entry)
    sec4 = []
    spec4 = [
        (12, "first_peak", "max_response", "Case 12 first peak", "mm"),
        (12, "first_negative_peak", "min_response", "Case 12 first negative peak", "mm"),
        (12, "negative_lobe_duration", "negative_lobe_duration", "Case 12 duration of the first negative peak", "ms"),
        (3, "first_peak", "max_response", "Case 3 first peak", "mm"),
        (3, "min_response", "min_response", "Case 3 first-contact minimum", "mm"),
        (3, "contact_duration", "contact_duration", "Case 3 first contact duration", "ms"),
    ]
    for n, pkey, mkey, label, unit in spec4:
        sim = getattr(met[n], mkey)
        ps, pm = SECTION4[n]["simulated"][pkey], SECTION4[n]["measured"][pkey]
        sec4.append({"case": n, "quantity": label, "key": pkey, "unit": unit, "simulated": sim,
                     "paper_simulated": ps, "paper_measured": pm,
                     "diff_simulated_percent": _diff(sim, ps), "diff_measured_percent": _diff(sim, pm)})
    direction = []
    for c in TABLE1:
        if c.gap is None or c.amplitude is None:
            continue
        r = data["results"][c.number]
        m = met[c.number]
        w_peak = float(r.displacement([r.contactors[0].position], [m.t_max])[0, 0])
        direction.append({"case": c.number, "t_max": m.t_max, "w_at_peak": w_peak, "first_impact_time": m.first_impact_time,
                          "away_first": w_peak < 0 and (not math.isfinite(m.first_impact_time) or m.first_impact_time > m.t_max)})
    conv_rows = []
    for n, runs in data["convergence"].items():
        ref = runs[max(CONVERGENCE_MODES)]
        for mm, pm_ in runs.items():
            conv_rows.append({
                "case": n, "modes": mm, "max_response": pm_.max_response,
                "max_response_change_percent": _diff(pm_.max_response, ref.max_response),
                "min_response": pm_.min_response, "min_response_change_percent": _diff(pm_.min_response, ref.min_response),
                "contact_duration": pm_.contact_duration,
                "contact_duration_change_percent": _diff(pm_.contact_duration, ref.contact_duration),
            })
    study_rows = {name: [{"value": v, **m.as_dict()} for v, m in rows] for name, rows in data["study"].items()}
    base_refit = data["refit"]["raw parameters (Case 3)"][1]
    s3m = SECTION4[3]["measured"]
    refit_rows = []
    for label, (sc, r) in data["refit"].items():
        m = paper_metrics(r)
        refit_rows.append({
            "variant": label, "contact_stiffness": sc.contactors[0].stiffness, "amplitude": sc.excitation.amplitude,
            "max_response": m.max_response, "min_response": m.min_response, "contact_duration": m.contact_duration,
            "diff_max_percent": _diff(m.max_response, s3m["first_peak"]),
            "diff_min_percent": _diff(m.min_response, s3m["min_response"]),
            "diff_contact_percent": _diff(m.contact_duration, s3m["contact_duration"]),
        })
    del base_refit
    report = ReproductionReport(
        out_dir=out, report_md=out / "report.md", report_html=out / "report.html", figures=figures,
        frequencies=freqs, cases=cases_out, table2=table2, section4=sec4, findings=[],
        free_decay=data["free_decay"][0], direction_check=direction, convergence=conv_rows,
        convergence_findings=[], parameter_study=study_rows, parameter_findings=[], refit=refit_rows,
        n_simulations=n_sims, elapsed=elapsed,
        settings={"modes": 8, "time_step": 1e-5, "end_time": 0.2, "pulse": "ideal half-sine"},
    )
    report.findings = _section3_findings(met)
    report.convergence_findings = _convergence_findings(data["convergence"])
    report.parameter_findings = _parameter_findings(data)
    return report
