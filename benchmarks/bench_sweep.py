"""Benchmark: sweeps around Case 3 against a plain serial loop over ``ib.simulate``.

Cases are Case 3 variants (examples/case03.toml: 8 modes, 0.2 s) over the
contactor gap (0 to 0.686 mm) x the pulse amplitude (5 g to 20 g). In one
process the script times

* the baseline: a plain Python loop ``ib.simulate(sc.with_values(...)).metrics()``
  over ``--serial-cases`` cases spread over the grid (cases per second);
* the batches of a sweep run in this process (:func:`impactbeam.sweeps.batches.run_batch`,
  the compiled batched path) over ``--steady-cases`` cases of a
  gap x amplitude grid: cases per second per core once started (the
  solver loaded, the mode sets built), wall and CPU time of this process;
* ``impactbeam sweep`` of 4,000 cases (50 gaps x 80 amplitudes) as a fresh
  process with ``--workers 2`` and ``--workers 1``: wall time end to end
  (start-up, store, writes) and the CPU time of the process and its workers;

and checks that the sweep stored exactly (bit for bit) what
``ib.simulate(...).metrics()`` gives for cases spread over the grid. The
machine is shared: the load average is printed with each figure, and ratios
are taken within one run. Targets of issue 24: 4,000 cases in at most 2.5 s
end to end on 2 workers, at least 2,000 cases per second per core once
started. It prints figures, not pass/fail.

Run: ``python benchmarks/bench_sweep.py [--serial-cases M] [--steady-cases N] [--workers 2 1] [--no-cli]``
(``--cases`` is ``--steady-cases``).
"""

from __future__ import annotations

import argparse
import math
import os
import resource
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
from impactbeam.sweeps.batches import _chunk_shape, _make_batch, _regions, default_batch_size, run_batch  # noqa: E402

CASE = Path(__file__).resolve().parents[1] / "examples" / "case03.toml"
KEYS = ("max_response", "t_max", "first_impact_time", "n_impacts", "free_duration", "contact_duration",
        "min_response", "max_penetration", "n_events", "energy_residual")

CLI_GRID = """
base = "{base}"
design = "grid"
[parameters."contactors.0.gap"]
range = [0.0, 0.686e-3, {n_gap}]
[parameters."excitation.amplitude"]
range = ["5 g", "20 g", {n_amp}]
[outputs]
metrics = "all"
"""


def grid(n_gap: int, n_amp: int):
    """The gap x amplitude sweep around Case 3."""
    import tomllib

    return parse_sweep(tomllib.loads(CLI_GRID.format(base=CASE.as_posix(), n_gap=n_gap, n_amp=n_amp)),
                       base_dir=CASE.parent)


def _load() -> str:
    return f"load {os.getloadavg()[0]:.1f}"


def serial_loop(spec, indices: list[int]) -> tuple[float, float, list[dict]]:
    """The baseline: a plain Python loop over ib.simulate; (wall, CPU, metrics)."""
    base = ib.load_scenario(CASE)
    out = []
    t0, c0 = time.perf_counter(), time.process_time()
    for i in indices:
        out.append(ib.simulate(base.with_values(spec.case_values(i))).metrics())
    return time.perf_counter() - t0, time.process_time() - c0, out


def steady(n_cases: int) -> None:
    """Cases per second of the batched path in this process, once started."""
    n_gap = max(1, round(math.sqrt(n_cases / 1.6)))
    spec = grid(n_gap, max(1, round(n_cases / n_gap)))
    chunk = _chunk_shape(spec, default_batch_size(spec.n_cases))
    batches = (_make_batch(spec, r, "record") for r in _regions(spec.shape, chunk))
    first = next(batches)
    run_batch(first)  # start-up: the solver loaded, the mode sets and states built
    n = 0
    t0, c0 = time.perf_counter(), time.process_time()
    for b in batches:
        n += len(run_batch(b)["status"])
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(f"batched path in this process, {spec.n_cases} cases ({' x '.join(map(str, spec.shape))}, batches of "
          f"{int(np.prod(chunk))}): once started {n / wall:.0f} cases/s wall, {n / cpu:.0f} cases/s per core (CPU); "
          f"{_load()}")


def command_line(workers: int) -> float:
    """Wall time of ``impactbeam sweep`` on 4,000 cases as a fresh process; prints wall and CPU."""
    exe = Path(sys.executable).parent / "impactbeam"
    with tempfile.TemporaryDirectory() as tmp:
        spec = Path(tmp) / "grid4000.toml"
        spec.write_text(CLI_GRID.format(base=CASE.as_posix(), n_gap=50, n_amp=80))
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        subprocess.run([str(exe), "sweep", str(spec), "--out", str(Path(tmp) / "o.zarr"), "--workers",
                        str(workers), "--no-progress"], check=True, capture_output=True)
        wall = time.perf_counter() - t0
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    print(f"impactbeam sweep, 4000 cases, --workers {workers}: {wall:.2f} s wall end to end (target 2.5 s on 2), "
          f"{cpu:.2f} s CPU (process and workers); {_load()}")
    return wall


def check_bits(spec, indices: list[int], baseline: list[dict]) -> None:
    """The sweep stores exactly what ib.simulate(...).metrics() gives."""
    with tempfile.TemporaryDirectory() as tmp:
        ds = run_sweep(spec, Path(tmp) / "c.zarr", workers=0, progress=False).dataset.load()
    bad = 0
    for i, expected in zip(indices, baseline):
        idx = np.unravel_index(i, spec.shape)
        for key in KEYS:
            stored = float(ds[key].values[idx])
            exp = expected[key]
            bad += not (math.isnan(stored) if exp is None else stored == float(exp))
    print(f"stored metrics differing from ib.simulate(...).metrics() (bit for bit, {len(indices)} cases x "
          f"{len(KEYS)} metrics): {bad}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--serial-cases", type=int, default=200, help="cases in the serial baseline [200]")
    ap.add_argument("--steady-cases", "--cases", type=int, default=20_000,
                    help="cases of the steady-rate run [20000]")
    ap.add_argument("--workers", type=int, nargs="+", default=[2, 1], help="workers of the command-line runs [2 1]")
    ap.add_argument("--no-cli", action="store_true", help="skip the command-line runs")
    args = ap.parse_args()
    print(f"Case 3 variants over gap x amplitude; {os.cpu_count()} cores, {_load()}")
    spec = grid(20, 20)
    from impactbeam.solver import kernels

    kernels.active()  # the compiled kernels (a short run alone would stay on the interpreted ones for a while)
    ib.simulate(ib.load_scenario(CASE))  # warm-up: imports, mode cache
    indices = sorted(set(np.linspace(0, spec.n_cases - 1, min(args.serial_cases, spec.n_cases)).round()
                         .astype(int).tolist()))
    wall, cpu, baseline = serial_loop(spec, indices)
    m = len(indices)
    print(f"serial loop over ib.simulate: {m} cases, {m / wall:.0f} cases/s wall, {m / cpu:.0f} cases/s CPU "
          f"({cpu / m * 1e3:.3f} ms CPU per case); {_load()}")
    check_bits(spec, indices, baseline)
    steady(args.steady_cases)
    if not args.no_cli:
        for w in args.workers:
            command_line(w)
    wall2, cpu2, _ = serial_loop(spec, indices)
    print(f"serial loop again (load drift): {m / wall2:.0f} cases/s wall, {m / cpu2:.0f} cases/s CPU; {_load()}")


if __name__ == "__main__":
    main()
