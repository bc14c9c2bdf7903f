"""Benchmark: the exact solver against a straightforward SciPy ``solve_ivp`` modal model.

Runs the reference Case 3 (examples/case03.toml: the
specimen, 15 g / 15 ms half-sine base pulse, gap 0.229 mm, k = 4030 N/m at
0.4840 L, xi 1.1 % / 2 %, 8 modes, output step 1e-5 s, 0.2 s) with
``ib.simulate`` and with a baseline written here from scratch: the same 8
free and 8 contact modes from ``ib.mode_set``, the modal equations
integrated by ``solve_ivp`` (DOP853, rtol 1e-8), terminal events on the
contactor's opening, the state switched and the modal displacement and
velocity projected there (paper eq. 12). Both run in this process, one
after the other; the script prints median times, their ratio and the
difference of the metrics. It prints ratios, not pass/fail.

Notes: the mode sets are cached (``ib.mode_set``, an LRU cache), and both
methods are timed after a warm-up run, so neither timing includes the
modal analysis. The machine is shared: medians of wall time and of this
process's CPU time are both printed, with the load average. The split of
``simulate(...).metrics()`` into the compiled event loop, the compiled
metrics and the Python around them comes from timing each compiled call.

``--first-use`` also measures fresh processes of ``impactbeam simulate
examples/case03.toml`` (0.2 s, 26 segments) and of the harmonic example
run for 10 s (examples/periodic/specimen_harmonic.toml, 1,200 segments), with
an empty numba cache and no stored mode set (a fresh ``NUMBA_CACHE_DIR`` and
``IMPACTBEAM_CACHE_DIR``: a short run stays on the interpreted kernels, a
long one starts the background compile and goes on interpreted), the
compile of every kernel (``python -m impactbeam.solver.warmup``, what
``make install`` runs), and the same processes with the compiled kernels
and the mode sets cached: wall and CPU time (user + sys) of each process.

Run with ``python benchmarks/bench_solver.py [--repeats N] [--first-use]``.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import statistics
import time
from pathlib import Path

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402
from scipy.optimize import brentq  # noqa: E402

import impactbeam as ib  # noqa: E402
from _kernel_clock import KernelClock  # noqa: E402

CASE = Path(__file__).resolve().parents[1] / "examples" / "case03.toml"


def baseline(sc: ib.Scenario, rtol: float = 1e-8) -> dict:
    """Case 3 by solve_ivp: modal equations, contact events, projection at switches.

    Returns the metrics that the comparison uses: max of u = -w(a) (contactor above)
    and its time, first impact time, duration of the first contact after the
    maximum, number of impacts, and the event times.
    """
    beam, c = sc.beam, sc.contactors[0]
    a, k, gap = c.position, c.stiffness, c.gap
    s = 1.0 if c.side == "above" else -1.0
    n = sc.solver.modes
    T, dt = sc.solver.end_time, sc.solver.time_step
    ex = sc.excitation
    A, Td = ex.amplitude * ex.scale, ex.duration
    rho_a = beam.mass_per_length
    free = ib.mode_set(beam, (), n)
    cont = ib.mode_set(beam, [(a, k)], n)
    st = {}
    for key, ms, xi in ((False, free, float(sc.damping.free)), (True, cont, float(sc.damping.contact))):
        Wa = ms.shapes([a])[:, 0]
        # base acceleration: modal load -rho A ug'' int W dx; engaged: constant force s k c W(a)
        st[key] = dict(om2=ms.omega**2, c2=2 * xi * ms.omega, p=-rho_a * ms.integral(), Wa=Wa,
                       f0=(s * k * gap * Wa) if key else np.zeros(n))
    P = {True: cont.overlap(free), False: free.overlap(cont)}  # to-state <- from-state

    def ug(t: float) -> float:
        return A * math.sin(math.pi * t / Td) if t <= Td else 0.0

    # absolute tolerance: rtol times 1e-3 of the quasi-static modal amplitude of the pulse
    scale = abs(A) * float(np.max(np.abs(st[False]["p"]))) / float(free.omega[0]) ** 2
    atol = np.concatenate([np.full(n, 1e-3 * rtol * scale), np.full(n, 1e-3 * rtol * scale * free.omega[0])])
    t_grid = np.arange(int(round(T / dt)) + 1) * dt
    segs = []
    u = np.full(t_grid.size, np.nan)
    y = np.zeros(2 * n)
    t0, engaged = 0.0, False
    events: list[tuple[float, str]] = []
    breaks = [Td, T]
    while t0 < T:
        m = st[engaged]
        t1 = next(b for b in breaks if b > t0)

        def rhs(t, y, m=m):
            e, d = y[:n], y[n:]
            return np.concatenate([d, m["p"] * ug(t) + m["f0"] - m["c2"] * d - m["om2"] * e])

        def opening(t, y, m=m):
            return gap - s * float(m["Wa"] @ y[:n])

        opening.terminal = True
        opening.direction = 1.0 if engaged else -1.0
        sol = solve_ivp(rhs, (t0, t1), y, method="DOP853", rtol=rtol, atol=atol,
                        events=opening, dense_output=True)
        te = float(sol.t_events[0][0]) if sol.status == 1 else float(sol.t[-1])
        sel = (t_grid >= t0) & ((t_grid < te) | (te >= T))
        if sel.any():
            u[sel] = -s * (m["Wa"] @ sol.sol(t_grid[sel])[:n])  # u = -w above, +w below
        segs.append((t0, te, sol.sol, m["Wa"]))
        y = sol.sol(te)
        t0 = te
        if sol.status == 1:
            events.append((te, "rebound" if engaged else "impact"))
            engaged = not engaged
            Pm = P[engaged]
            y = np.concatenate([Pm @ y[:n], Pm @ y[n:]])
    kmax = int(np.nanargmax(u))
    # refine the maximum on the dense output (du/dt = 0 next to the best sample)
    t_max, u_max = float(t_grid[kmax]), float(u[kmax])
    t_lo, t_hi = t_grid[max(kmax - 1, 0)], t_grid[min(kmax + 1, t_grid.size - 1)]
    for ta_, tb_, so, Wa in segs:
        if ta_ <= t_lo and t_hi <= tb_:
            du = lambda t: -s * float(Wa @ so(t)[n:])  # noqa: E731
            for lo, hi in ((t_lo, t_max), (t_max, t_hi)):
                if du(lo) > 0 > du(hi):
                    tc = brentq(du, lo, hi, xtol=1e-14)
                    uc = -s * float(Wa @ so(tc)[:n])
                    if uc > u_max:
                        t_max, u_max = tc, uc
    imp = [t for t, kind in events if kind == "impact"]
    reb = [t for t, kind in events if kind == "rebound"]
    after = [(x, z) for x, z in zip(imp, reb) if x >= t_max]
    return {
        "max_response": u_max,
        "t_max": t_max,
        "first_impact_time": imp[0] if imp else None,
        "contact_duration": (after[0][1] - after[0][0]) if after else None,
        "n_impacts": len(imp),
        "event_times": np.array([t for t, _ in events]),
    }


def _median_time(fn, repeats: int) -> tuple[float, object]:
    out = fn()  # warm-up (mode sets cached, code paths compiled)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def _median_cpu(fn, repeats: int) -> float:
    """Median CPU time of this process per call (insensitive to other processes' load, not to cache sharing)."""
    fn()
    times = []
    for _ in range(repeats):
        c0 = time.process_time()
        fn()
        times.append(time.process_time() - c0)
    return statistics.median(times)


def _split(sc: ib.Scenario, repeats: int) -> dict[str, float]:
    """CPU per ``simulate(sc).metrics()`` in the compiled loop, the compiled metrics and the rest (Python)."""
    ib.simulate(sc).metrics()
    with KernelClock({"run": "loop", "run_metrics": "metrics"}, clock=time.process_time) as clock:
        c0 = time.process_time()
        for _ in range(repeats):
            ib.simulate(sc).metrics()
        total = time.process_time() - c0
    spent = {"loop": clock.spent["run"], "metrics": clock.spent["run_metrics"]}
    out = {k: v / repeats for k, v in spent.items()}
    out["python"] = total / repeats - out["loop"] - out["metrics"]
    out["total"] = total / repeats
    return out


def first_use() -> None:
    """Fresh processes with an empty numba cache, the compile of every kernel, and the same processes after it."""
    import resource
    import subprocess
    import sys
    import tempfile

    short = [sys.executable, "-m", "impactbeam", "simulate", str(CASE), "--json"]
    harmonic = CASE.parent / "periodic" / "specimen_harmonic.toml"  # 10 s: 600 periods, 1,200 segments
    long = [sys.executable, "-m", "impactbeam", "simulate", str(harmonic), "--json", "--end-time", "10"]
    warm = [sys.executable, "-m", "impactbeam.solver.warmup", "--quiet"]
    print(f"\nfirst use ({os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}); wall and CPU (user + sys) "
          "of each process:")
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache, IMPACTBEAM_CACHE_DIR=cache)  # no kernel, no mode set stored

        def one(label: str, cmd: list[str]) -> None:
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            subprocess.run(cmd, env=env, check=True, capture_output=True)
            wall = time.perf_counter() - t0
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
            print(f"  {label:62s} {wall:6.2f} s wall, {cpu:6.2f} s CPU (load {os.getloadavg()[0]:.1f})")

        def wait_for_compile() -> None:
            t0 = time.perf_counter()
            while any(True for _ in Path(cache).rglob("impactbeam-warmup.pid")):
                time.sleep(0.2)
            if time.perf_counter() - t0 > 0.5:
                print(f"  {'  (waited for its background compile to end)':62s} {time.perf_counter() - t0:6.2f} s wall")

        one("simulate case03.toml, empty cache (interpreted)", short)
        one("simulate periodic/specimen_harmonic.toml --end-time 10, empty cache", long)
        wait_for_compile()
        with tempfile.TemporaryDirectory() as other:
            env["NUMBA_CACHE_DIR"] = other
            one("python -m impactbeam.solver.warmup (every kernel, as make install)", warm)
            one("simulate case03.toml, kernels and mode sets cached (a second process)", short)
            one("the same again", short)
            one("simulate periodic/specimen_harmonic.toml --end-time 10, kernels cached", long)
            env["NUMBA_CACHE_DIR"] = cache


def _variants(sc: ib.Scenario) -> dict[str, ib.Scenario]:
    """The issue's scaling cases around Case 3 (each compared with Case 3 at the same mode count)."""
    rep = dataclasses.replace
    c0 = sc.contactors[0]
    L = sc.beam.length
    s16 = rep(sc, solver=rep(sc.solver, modes=16))
    stops = tuple(
        rep(c0, position=x, side=side, gap=c0.gap) for x in (c0.position, L) for side in ("above", "below")
    )
    free_free = rep(sc.beam, left=ib.Support.preset("free"), right=ib.Support.preset("free"))
    ff = rep(
        sc, beam=free_free,
        contactors=(rep(c0, position=0.1 * L, side="below"), rep(c0, position=0.9 * L, side="below"),
                    rep(c0, position=0.5 * L, side="above", gap=1e-3)),
        excitation=ib.Excitation(kind="point_force", shape="half_sine", amplitude=-0.05, duration=0.004,
                                 position=0.3 * L),
    )
    return {
        "case3_16_modes": s16,
        "four_contactors_16_modes": rep(s16, contactors=stops),
        "overdamped_contact_xi_1.5": rep(sc, damping=ib.Damping(sc.damping.free, 1.5)),
        "free_free_rigid_modes": ff,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=200, help="timed runs of ib.simulate (default 200)")
    ap.add_argument("--baseline-repeats", type=int, default=5, help="timed runs of the solve_ivp model (default 5)")
    ap.add_argument("--first-use", action="store_true", help="also time a first run with an empty numba cache")
    args = ap.parse_args()
    sc = ib.load_scenario(CASE)
    from impactbeam.solver import kernels

    kernels.active()  # the compiled kernels (short runs alone stay interpreted until 0.3 s were spent so)
    # the default (enriched) basis for the timings; the accuracy check against the
    # solve_ivp model below uses the paper's basis, the model that baseline integrates
    paper_sc = sc.with_values({"solver.basis": "paper"})
    t_paper, _ = _median_time(lambda: ib.simulate(paper_sc).metrics(), args.repeats)
    t_exact, res = _median_time(lambda: ib.simulate(sc), args.repeats)
    t_metrics, m = _median_time(lambda: res.metrics(), args.repeats)
    t_both, _ = _median_time(lambda: ib.simulate(sc).metrics(), args.repeats)
    t_lean, _ = _median_time(lambda: ib.simulate(sc).metrics(impacts=False), args.repeats)
    t_base, b = _median_time(lambda: baseline(sc), args.baseline_repeats)
    # a tighter baseline as the accuracy reference for both
    ref = baseline(sc, rtol=1e-11)
    res_paper = ib.simulate(paper_sc)
    m_paper = res_paper.metrics()
    cpu_both = _median_cpu(lambda: ib.simulate(sc).metrics(), args.repeats)
    split = _split(sc, args.repeats)
    print(f"Case 3 ({CASE.name}): {sc.solver.modes} modes, step {sc.solver.time_step:g} s, end {sc.solver.end_time:g} s")
    print(f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}; mode sets cached (ib.mode_set LRU); "
          "medians after one warm-up run")
    print(f"  ib.simulate                         median {t_exact * 1e3:8.3f} ms  ({args.repeats} runs)")
    print(f"  result.metrics()                    median {t_metrics * 1e3:8.3f} ms")
    print(f"  simulate(...).metrics() together    median {t_both * 1e3:8.3f} ms  (target <= 0.3 ms); "
          f"CPU {cpu_both * 1e3:.3f} ms")
    print(f"    of which (CPU, mean) compiled event loop {split['loop'] * 1e3:.3f} ms, compiled metrics "
          f"{split['metrics'] * 1e3:.3f} ms, Python {split['python'] * 1e3:.3f} ms")
    print(f"  ... without the per-impact table    median {t_lean * 1e3:8.3f} ms  (a case of a single-run loop)")
    print(f"  ... with solver.basis = 'paper'     median {t_paper * 1e3:8.3f} ms")
    print(f"  solve_ivp model (rtol 1e-8)         median {t_base * 1e3:8.1f} ms  ({args.baseline_repeats} runs)")
    print(f"  ratio solve_ivp / (simulate + metrics): {t_base / t_both:8.0f}  (target >= 4000)")
    print(f"  closed-form evaluations in the event scan: {res.solution.evaluations}, "
          f"segments: {res.solution.n_segments}")
    print("\nthe same model (solver.basis = 'paper', the projection of eq. 12) against solve_ivp:")
    print("metric                 ib.simulate          solve_ivp 1e-8       |exact - ref|  |ivp1e-8 - ref|  (ref: solve_ivp rtol 1e-11)")
    for key in ("max_response", "t_max", "first_impact_time", "contact_duration", "n_impacts"):
        va, vb, vr = m_paper[key], b[key], ref[key]
        print(f"{key:20s} {va!s:>20.14} {vb!s:>20.14} {abs(va - vr):14.3g} {abs(vb - vr):16.3g}")
    ta = np.array([e.time for e in res_paper.events])
    if ta.size == b["event_times"].size == ref["event_times"].size:
        print(f"event times: max |exact - ref| {np.abs(ta - ref['event_times']).max():.3g} s, "
              f"max |ivp1e-8 - ref| {np.abs(b['event_times'] - ref['event_times']).max():.3g} s "
              f"({ta.size} events)")
    else:
        print(f"event counts differ: exact {ta.size}, solve_ivp {b['event_times'].size}, ref {ref['event_times'].size}")
    print("\nScaling (simulate + metrics, medians; ratio to Case 3 with the same mode count; target <= 3)")
    variants = _variants(sc)
    base16, _ = _median_time(lambda: ib.simulate(variants["case3_16_modes"]).metrics(), args.repeats)
    for name, v in variants.items():
        tv, rv = _median_time(lambda v=v: ib.simulate(v).metrics(), args.repeats)
        ref_t = base16 if v.solver.modes == 16 else t_both
        print(f"  {name:28s} {v.solver.modes:3d} modes {len(v.contactors)} contactors  {tv * 1e3:8.3f} ms  "
              f"x{tv / ref_t:5.2f}  ({rv['n_events']} events)")
    if args.first_use:
        first_use()


if __name__ == "__main__":
    main()
