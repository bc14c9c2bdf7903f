"""Benchmark: a frequency-response sweep of the specimen against solve_ivp, in one run.

The specimen (examples/specimen.toml) with a 0.1 mm gap, driven by a 2 g
harmonic base acceleration, swept over 400 forcing frequencies from 30 Hz
to 130 Hz, up and then down (800 steady states, each continued from the
previous one), with 100 settle and 50 recorded forcing periods per point
(``ib.frequency_response``, the exact engine). The baseline runs a few of
those points from rest with the project's ``solve_ivp`` path
(``simulate(..., method="ivp")``: the same modal equations, DOP853 with
rtol 1e-10 and events), 150 periods each; the exact engine runs the same
points from rest too, and the strobe samples of both are compared. Both
are timed in this process, one after the other; the script prints times,
the ratio per point, the sweep time extrapolated for the baseline, and the
largest strobe difference. It prints ratios, not pass/fail.

Run with ``python benchmarks/bench_periodic.py [--points N] [--baseline-points M] [--breakdown]``;
``--breakdown`` also says where the sweep's time goes: the compiled kernels
(event loop, extremes of the records, strobe sampling) timed at each call, the
rest being Python, and the forcing periods run against those asked. The
extremes are searched on a second thread while the next values run, so the
main thread's share is the event loop, the sampling and Python.
"""

from __future__ import annotations

import argparse
import os
import time
import warnings
from pathlib import Path

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

import impactbeam as ib  # noqa: E402
from impactbeam.periodic.strobe import analyse_steady_state, run_periods  # noqa: E402

from _kernel_clock import KernelClock  # noqa: E402

SPECIMEN = Path(__file__).resolve().parents[1] / "examples" / "specimen.toml"
SETTLE, RECORD = 100, 50


def scenario() -> ib.Scenario:
    sc = ib.load_scenario(SPECIMEN)
    return sc.with_values({
        "contactors.0.gap": "0.1 mm", "excitation.shape": "harmonic", "excitation.amplitude": "2 g",
        "excitation.frequency": "60 Hz", "excitation.duration": None,
    })


class SweepClock(KernelClock):
    """The kernels a bifurcation sweep spends its compiled time in."""

    NAMES = {"run": "event loop", "extremum": "extremes of the records", "sample": "strobe sampling"}

    def __init__(self) -> None:
        super().__init__(self.NAMES)

    def report(self, total: float, periods: int, asked: int) -> None:
        main_thread = self.spent["run"] + self.spent["sample"]
        for name, label in self.names.items():
            where = " on the second thread, while the next values run" if name == "extremum" else ""
            print(f"  {label:26s} {self.spent[name]:6.2f} s ({self.calls[name]} calls){where}")
        print(f"  {'compiled, main thread':26s} {main_thread:6.2f} s ({main_thread / total:.0%}); Python and the rest "
              f"{total - main_thread:.2f} s (waits for the interpreter lock included)")
        print(f"  forcing periods run {periods:,} ({asked:,} asked: the rest extend records whose period "
              "was not found)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--points", type=int, default=400, help="forcing frequencies (each swept up and down)")
    ap.add_argument("--baseline-points", type=int, default=3,
                    help="points run by the solve_ivp baseline (0: the sweep alone)")
    ap.add_argument("--breakdown", action="store_true", help="time the compiled kernels inside the sweep too")
    args = ap.parse_args()
    warnings.simplefilter("ignore", ib.ImpactBeamWarning)  # counted below instead
    sc = scenario()
    from impactbeam.solver import kernels

    kernels.active()  # the compiled kernels from the start
    freqs = np.linspace(30.0, 130.0, args.points)
    ib.frequency_response(sc, freqs[:2], settle_periods=2, record_periods=2)  # compile / warm caches

    t0, c0 = time.perf_counter(), time.process_time()
    fr = ib.frequency_response(sc, freqs, sweep="both", settle_periods=SETTLE, record_periods=RECORD)
    t_sweep, c_sweep = time.perf_counter() - t0, time.process_time() - c0
    n_runs = len(fr.frequency)
    no_period = int(np.sum(fr.period == 0))
    extended = sum(p.state.settled_after > SETTLE for p in fr.diagram.points)
    no_impact = sum(p.state.impacts_per_period == 0 for p in fr.diagram.points)
    print(f"specimen, gap 0.1 mm, 2 g harmonic base acceleration, {SETTLE} settle + {RECORD} recorded periods")
    print(f"exact engine: {args.points} frequencies up and down = {n_runs} steady states in {t_sweep:.2f} s "
          f"(target 1 s), {c_sweep:.2f} s CPU ({t_sweep / n_runs * 1e3:.2f} ms per point; {extended} extended while "
          f"settling, {no_period} without a period, {no_impact} without an impact in their record); "
          f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")
    if args.breakdown:  # a second sweep, its kernels timed (the timing wrappers cost microseconds per call)
        with SweepClock() as clock:
            t0 = time.perf_counter()
            again = ib.frequency_response(sc, freqs, sweep="both", settle_periods=SETTLE, record_periods=RECORD)
            t_again = time.perf_counter() - t0
        same = all(np.array_equal(a.state.strobe, b.state.strobe) and a.state.max == b.state.max
                   for a, b in zip(fr.diagram.points, again.diagram.points))
        print(f"where the time goes (a second sweep, {t_again:.2f} s; the same diagram to the bit: {same}):")
        clock.report(t_again, sum(p.state.settled_after + RECORD for p in again.diagram.points),
                     len(again.diagram.points) * (SETTLE + RECORD))

    if args.baseline_points < 1:  # the sweep alone (its time, its breakdown)
        return
    picks = freqs[np.linspace(0, freqs.size - 1, args.baseline_points + 2).astype(int)[1:-1]]
    t_ivp = t_exact = 0.0
    worst = 0.0
    for f in picks:
        one = sc.with_values({"excitation.frequency": float(f)})
        t0 = time.perf_counter()
        res, t_load = run_periods(one, SETTLE + RECORD)
        a = analyse_steady_state(res, one, settle_periods=SETTLE, record_periods=RECORD, start=t_load)
        t_exact += time.perf_counter() - t0
        end = t_load + (SETTLE + RECORD) / f
        ivp_sc = one.with_values({"solver.end_time": end})
        t0 = time.perf_counter()
        ref = ib.simulate(ivp_sc, method="ivp")
        t_ivp += time.perf_counter() - t0
        w_ref = ref.displacement([a.point], a.times)[0]
        worst = max(worst, float(np.max(np.abs(w_ref - a.strobe)) / max(abs(a.max), abs(a.min))))
        print(f"  {f:7.2f} Hz from rest: period {a.period}, impacts/period {a.impacts_per_period:g}")
    m = len(picks)
    print(f"solve_ivp baseline (rtol 1e-10): {m} points from rest in {t_ivp:.2f} s ({t_ivp / m:.2f} s per point)")
    print(f"exact engine, same points from rest: {t_exact * 1e3:.1f} ms ({t_exact / m * 1e3:.2f} ms per point)")
    print(f"ratio solve_ivp / exact per point: {t_ivp / t_exact:8.0f}")
    print(f"the {n_runs}-point sweep by solve_ivp would take about {t_ivp / m * n_runs / 60:.0f} min "
          f"({t_ivp / m * n_runs / t_sweep:.0f} x the exact sweep)")
    print(f"largest strobe difference exact - solve_ivp: {worst:.2g} of the steady-state amplitude")


if __name__ == "__main__":
    main()
