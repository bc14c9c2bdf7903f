"""Benchmark: sweeps around Case 3 on Dask against a plain serial loop.

First, the command line end to end: ``impactbeam sweep FILE --workers 2`` on a
16 x 16 x 16 = 4,096-case grid (gap x duration x amplitude), wall time of the
whole process (start-up, cluster, writes) against the serial loop's rate
measured in the same run; target 10 s on the 2-core machine.

Then the grid is gap x pulse duration x amplitude around the
reference Case 3 (examples/case03.toml: 8 modes, output step 1e-5 s,
0.2 s): 25 gaps in [0, 0.686] mm x 20 durations in [5, 20] ms x 20
amplitudes in [5, 20] g = 10,000 cases. ``--cases N`` scales the three counts
by (N / 10,000)^(1/3) to run a smaller grid of the same shape.

In the same run the script times

* a plain serial Python loop ``ib.simulate(sc.with_values(...)).metrics()``
  over the first ``--serial-cases`` cases of the grid (the baseline, whose
  rate is extrapolated to the whole grid), and
* :func:`impactbeam.sweep` into a fresh Zarr store with a local Dask
  cluster of 1 and of 2 worker processes (wall time including the cluster's
  start and shutdown and the Zarr writes),

checks that the sweep stored exactly the baseline's metrics for the cases
both computed, and prints cases per second, the ratios to the baseline and
the projected time of the 10,000-case grid (the fixed cost of a one-case
sweep plus the cases at the rate measured once running). The serial loop
runs again at the end to show how much the machine's load drifted. Target of the issue: 10,000 cases
in at most 60 s on a 2-core machine. It prints figures, not pass/fail.

Run: ``python benchmarks/bench_sweep.py [--cases N] [--serial-cases M] [--workers 1 2] [--batch-size B]``.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

import impactbeam as ib  # noqa: E402
from impactbeam.sweeps import parse_sweep, run_sweep  # noqa: E402

CASE = Path(__file__).resolve().parents[1] / "examples" / "case03.toml"
FULL = (25, 20, 20)
TARGET_CASES, TARGET_SECONDS = 10_000, 60.0


def grid_counts(cases: int) -> tuple[int, int, int]:
    """Counts of the three parameters, scaled from 25 x 20 x 20 to about ``cases``."""
    f = (cases / TARGET_CASES) ** (1.0 / 3.0)
    return tuple(max(1, round(n * f)) for n in FULL)  # type: ignore[return-value]


def spec_for(counts: tuple[int, int, int]):
    n_gap, n_dur, n_amp = counts
    data = {
        "base": str(CASE),
        "design": "grid",
        "parameters": {
            "contactors.0.gap": {"range": [0.0, 0.686e-3, n_gap]},
            "excitation.duration": {"range": [5e-3, 20e-3, n_dur]},
            "excitation.amplitude": {"range": ["5 g", "20 g", n_amp]},
        },
        "outputs": {"metrics": "all"},
    }
    return parse_sweep(data, base_dir=CASE.parent)


def subset(spec, m: int) -> list[int]:
    """``m`` flat case indices spread evenly over the grid (representative of all of it)."""
    return sorted(set(np.linspace(0, spec.n_cases - 1, m).round().astype(int).tolist()))


def serial_loop(spec, indices: list[int]) -> tuple[float, list[dict]]:
    """The baseline: a plain Python loop over ib.simulate; returns (seconds, metrics)."""
    base = ib.load_scenario(CASE)
    out = []
    t0 = time.perf_counter()
    for i in indices:
        res = ib.simulate(base.with_values(spec.case_values(i)))
        out.append(res.metrics())
    return time.perf_counter() - t0, out


def overhead(workers: int) -> float:
    """Wall time of a one-case sweep: cluster start and shutdown, store creation, one case."""
    one = spec_for((1, 1, 1))
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        run_sweep(one, Path(tmp) / "one.zarr", workers=workers, progress=False)
        return time.perf_counter() - t0


CLI_GRID = """
base = "{base}"
design = "grid"
[parameters."contactors.0.gap"]
range = [0.0, 0.686e-3, 16]
[parameters."excitation.duration"]
range = [5e-3, 20e-3, 16]
[parameters."excitation.amplitude"]
range = ["5 g", "20 g", 16]
[outputs]
metrics = "all"
"""


def command_line(workers: int, rate_serial: float) -> None:
    """Wall time of ``impactbeam sweep`` on 4,096 cases as a fresh process."""
    exe = Path(sys.executable).parent / "impactbeam"
    with tempfile.TemporaryDirectory() as tmp:
        spec = Path(tmp) / "grid4096.toml"
        spec.write_text(CLI_GRID.format(base=CASE.as_posix()))
        t0 = time.perf_counter()
        subprocess.run([str(exe), "sweep", str(spec), "--out", str(Path(tmp) / "o.zarr"), "--workers",
                        str(workers)], check=True, capture_output=True)
        wall = time.perf_counter() - t0
    print(f"impactbeam sweep (4096 cases, --workers {workers}), whole process: {wall:.2f} s "
          f"(target 10 s); the serial loop would take {4096 / rate_serial:.1f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--cases", type=int, default=TARGET_CASES, help="approximate grid size [10000]")
    ap.add_argument("--serial-cases", type=int, default=100, help="cases in the serial baseline [100]")
    ap.add_argument("--workers", type=int, nargs="+", default=[1, 2], help="worker counts to time [1 2]")
    ap.add_argument("--batch-size", type=int, default=None, help="cases per task [sweep default]")
    args = ap.parse_args()

    spec = spec_for(grid_counts(args.cases))
    n = spec.n_cases
    print(f"grid {' x '.join(map(str, spec.shape))} = {n} cases around Case 3 "
          f"(modes {spec.base.solver.modes}, time_step {spec.base.solver.time_step:g} s, "
          f"end_time {spec.base.solver.end_time:g} s); {os.cpu_count()} cores")

    ib.simulate(ib.load_scenario(CASE))  # warm-up: imports, mode cache
    indices = subset(spec, min(args.serial_cases, n))
    m = len(indices)
    t_serial, baseline = serial_loop(spec, indices)
    rate_serial = m / t_serial
    print(f"serial loop over ib.simulate: {m} cases spread over the grid in {t_serial:.2f} s = "
          f"{rate_serial:.1f} cases/s ({1e3 / rate_serial:.1f} ms/case); projected {n} cases: "
          f"{n / rate_serial:.0f} s" + ("" if n == TARGET_CASES else f", {TARGET_CASES}: {TARGET_CASES / rate_serial:.0f} s"))

    command_line(2, rate_serial)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for w in args.workers:
            fixed = overhead(w)
            out = Path(tmp) / f"bench_w{w}.zarr"
            t0 = time.perf_counter()
            run = run_sweep(spec, out, workers=w, batch_size=args.batch_size, progress=False)
            wall = time.perf_counter() - t0
            ds = run.dataset
            # the sweep stored exactly what the serial loop computed
            mismatches = 0
            for i, expected in zip(indices, baseline):
                idx = np.unravel_index(i, spec.shape)
                for key in ("max_response", "t_max", "first_impact_time", "n_impacts", "contact_duration"):
                    stored = float(ds[key].values[idx])
                    exp = expected[key]
                    same = math.isnan(stored) if exp is None else stored == float(exp)
                    mismatches += not same
            failed = int((ds["status"].values == -1).sum())
            rate = n / wall
            steady = n / max(wall - fixed, 1e-9)
            # a run not much longer than the fixed cost cannot give a steady rate: project from the wall rate
            projected = fixed + TARGET_CASES / steady if wall > 5 * fixed else TARGET_CASES / rate
            rows.append((w, wall, rate, projected))
            print(f"sweep, {w} worker{'s' if w > 1 else ''}: {n} cases in {wall:.2f} s = {rate:.1f} cases/s "
                  f"(x{rate / rate_serial:.2f} the serial loop); fixed cost (cluster start/stop, store) "
                  f"{fixed:.1f} s, so {steady:.1f} cases/s once running (x{steady / rate_serial:.2f}); "
                  f"projected {TARGET_CASES}: {projected:.0f} s (target {TARGET_SECONDS:.0f} s); "
                  f"failed {failed}; metrics differing from the loop: {mismatches}")
    t_after, _ = serial_loop(spec, indices)
    print(f"serial loop again after the sweeps (machine load drift): {m / t_after:.1f} cases/s")
    if len(rows) > 1:
        (w1, _, r1, _), *rest = rows
        for w, _, r, _ in rest:
            print(f"speed-up {w} workers / {w1}: x{r / r1:.2f}")
    best = min(p for *_, p in rows)
    verdict = "meets" if best <= TARGET_SECONDS else "misses"
    print(f"best projection: {TARGET_CASES} cases in {best:.0f} s; {verdict} the {TARGET_SECONDS:.0f} s target "
          f"(which needs ~{TARGET_CASES / TARGET_SECONDS:.0f} cases/s)")

if __name__ == "__main__":
    main()
