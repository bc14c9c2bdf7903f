"""The compiled fast path (:mod:`impactbeam.solver.fast`) against the Python event loop.

The oracle is ``engine._Integrator._run_from``: the event-driven exact
integrator written in Python (paper section 2, eqs. 9-12), which the rest of
the test suite checks against closed forms, solve_ivp and the paper. The fast
path ports the same algorithm to one numba function, so both must agree to
round-off: event times within 1e-12 s (the event tolerance is 1e-13 s and
both locate events with the same Brent iteration on the same closed form),
every sampled array within 1e-12 of its largest magnitude (both evaluate the
same closed form at the same times; they differ only in how ``exp(mu tau)``
is advanced along the grid, ~1e-14 relative), identical event kinds and
contactors, state codes, status and message.
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest

import impactbeam as ib
from impactbeam.loading import Excitation
from impactbeam.result import SimulationResult
from impactbeam.solver import engine, fast
from impactbeam.solver.options import Damping

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CASES = sorted(EXAMPLES.glob("case[0-9][0-9].toml"))
G = 9.80665

T_EVENT = 1e-12  # s, see the module docstring
R_SAMPLE = 1e-12  # relative to the largest magnitude of each array

FIELDS = (
    "w", "w_t", "w_contact", "w_t_contact", "kinetic", "modal_strain", "load_power", "damping_power", "eta", "eta_t",
)


def python_engine(beam, contactors, damping, excitation, initial, options, points) -> engine.RawSolution:
    """The Python event loop, whatever ``engine.integrate`` dispatches to."""
    integ = engine._Integrator(beam, tuple(contactors), damping, excitation, initial, options, points, None)
    eta, deta = engine.space_initial_coordinates(integ.space, beam, initial, options.modes)
    return integ._run_from(eta, deta)


def problem(path: Path = EXAMPLES / "case03.toml", **changes):
    """The inputs of a scenario as a dict, with fields replaced."""
    sc = ib.load_scenario(path)
    args = {
        "beam": sc.beam,
        "contactors": tuple(sc.contactors),
        "damping": sc.damping,
        "excitation": sc.excitation,
        "initial": sc.initial,
        "options": sc.solver,
        "points": np.asarray(sc.output_points, dtype=float),
    }
    args.update(changes)
    return args


def with_options(args: dict, **opts) -> dict:
    return {**args, "options": dataclasses.replace(args["options"], **opts)}


def with_contactor(args: dict, i: int = 0, **fields) -> dict:
    cs = list(args["contactors"])
    cs[i] = dataclasses.replace(cs[i], **fields)
    return {**args, "contactors": tuple(cs)}


def with_excitation(args: dict, **fields) -> dict:
    return {**args, "excitation": dataclasses.replace(args["excitation"], **fields)}


def normalized_message(message: str, args: dict) -> str:
    """The message, with the figures of a projection warning about a zero-gap contactor masked.

    For a contactor with zero gap the warning's scale is the deflection at the
    event, which is zero up to round-off (~1e-22 m), so its figures (moved
    distance, percentage) are round-off in both paths; everything else must
    match exactly.
    """
    m = re.search(r"contactor (\d+) by \S+ m \(\d+ %", message)
    if m and args["contactors"][int(m.group(1))].gap == 0.0:
        message = message[: m.start()] + f"contactor {m.group(1)} by <x> m (<y> %" + message[m.end():]
    return message


def deviations(ref: engine.RawSolution, got: engine.RawSolution) -> dict[str, float]:
    """Largest differences of two runs with the same event sequence.

    Event times in seconds; event velocities, every sampled array and the
    switch energy jumps relative to their largest magnitude in ``ref``.
    """
    out: dict[str, float] = {"event_time": 0.0, "velocity": 0.0, "jumps": 0.0}
    if ref.events:
        out["event_time"] = max(abs(a.time - b.time) for a, b in zip(ref.events, got.events))
        vscale = max(abs(e.velocity) for e in ref.events) + 1e-300
        out["velocity"] = max(abs(a.velocity - b.velocity) for a, b in zip(ref.events, got.events)) / vscale
    for name in FIELDS:
        a, b = getattr(ref, name), getattr(got, name)
        scale = np.nanmax(np.abs(a)) if np.isfinite(a).any() else 0.0
        out[name] = float(np.nanmax(np.abs(a - b)) / scale) if scale > 0 else 0.0
    if ref.switch_energy_jumps:
        e_scale = np.nanmax(ref.kinetic + ref.modal_strain) + 1e-300
        out["jumps"] = float(np.max(np.abs(np.subtract(ref.switch_energy_jumps, got.switch_energy_jumps)))) / e_scale
    return out


def conditioning(args: dict, ref: engine.RawSolution) -> dict[str, float]:
    """How far the Python engine itself moves when contactor 0's gap changes by 4 ulp.

    A run with many impacts amplifies round-off (each impact is a sensitive
    map), so two correct implementations that differ only in round-off can
    drift apart by more than 1e-12 at the end. This measures that drift on the
    Python engine alone, from an input perturbation of the same size as
    round-off; the fast path must stay within 10 times it.
    """
    worst: dict[str, float] = {}
    c0 = args["contactors"][0]
    for sign in (1.0, -1.0):
        pert = with_contactor(args, gap=c0.gap * (1.0 + sign * 4 * np.finfo(float).eps))
        run = python_engine(**pert)
        assert [(e.kind, e.contactor) for e in run.events] == [(e.kind, e.contactor) for e in ref.events]
        for key, val in deviations(ref, run).items():
            worst[key] = max(worst.get(key, 0.0), val)
    return worst


def compare(args: dict, chaotic: bool = False) -> tuple[engine.RawSolution, engine.RawSolution]:
    """Run both paths and assert they agree; return (python, fast).

    ``chaotic``: allow 10 times the engine's own round-off sensitivity
    (:func:`conditioning`) where it exceeds the fixed tolerances.
    """
    assert fast.supported(**{k: v for k, v in args.items() if k != "initial"})
    ref = python_engine(**args)
    got = fast.integrate_fast(**args)
    assert got.status == ref.status
    assert normalized_message(got.message, args) == normalized_message(ref.message, args)
    assert [(e.kind, e.contactor) for e in got.events] == [(e.kind, e.contactor) for e in ref.events]
    np.testing.assert_array_equal(got.time, ref.time)
    np.testing.assert_array_equal(got.state_code, ref.state_code)
    assert got.state_keys == ref.state_keys
    for name in FIELDS:
        a, b = getattr(ref, name), getattr(got, name)
        assert a.shape == b.shape, name
        np.testing.assert_array_equal(np.isnan(a), np.isnan(b), err_msg=name)
    assert len(got.switch_energy_jumps) == len(ref.switch_energy_jumps)
    dev = deviations(ref, got)
    allowed = {key: (T_EVENT if key == "event_time" else R_SAMPLE) for key in dev}
    if chaotic:
        cond = conditioning(args, ref)
        allowed = {key: max(allowed[key], 10.0 * cond[key]) for key in dev}
    bad = {key: (dev[key], allowed[key]) for key in dev if not dev[key] <= allowed[key]}
    assert not bad, bad
    # segments: same boundaries and states (dense output: see dense_check)
    assert len(got.segments) == len(ref.segments)
    for sa, sb in zip(ref.segments, got.segments):
        assert abs(sa.t0 - sb.t0) <= allowed["event_time"] and abs(sa.t1 - sb.t1) <= allowed["event_time"]
        assert sa.engaged == sb.engaged
    return ref, got


def dense_check(args: dict, ref, got) -> None:
    """SimulationResult.displacement/velocity (exact dense output) agree between the paths."""
    beam, cs = args["beam"], args["contactors"]
    ra = SimulationResult.from_raw(ref, beam, cs, args["points"], args["options"].modes, "a", {})
    rb = SimulationResult.from_raw(got, beam, cs, args["points"], args["options"].modes, "b", {})
    t_end = ref.segments[-1].t1
    t = np.linspace(0.0, t_end, 377)
    x = np.array([0.3, 0.7, 1.0]) * beam.length
    for fa, fb in ((ra.displacement, rb.displacement), (ra.velocity, rb.velocity)):
        a, b = fa(x, t), fb(x, t)
        scale = np.nanmax(np.abs(a))
        assert np.nanmax(np.abs(a - b)) <= R_SAMPLE * scale
    for key in ("kinetic", "strain", "contactor", "total", "residual"):
        a, b = ra.energy[key], rb.energy[key]
        scale = np.nanmax(np.abs(ra.energy["total"]))
        assert np.nanmax(np.abs(a - b)) <= R_SAMPLE * scale


@pytest.mark.parametrize("path", CASES, ids=[p.stem for p in CASES])
def test_examples_agree(path):
    args = problem(path)
    ref, got = compare(args)
    if path.stem == "case03":
        assert len(ref.events) == 24  # the benchmark case
        dense_check(args, ref, got)


@pytest.mark.parametrize("k", [64000.0, 1e5])
def test_stiff_contactor_agrees(k):
    # stiff contactors refine the scan grid (sub > 1) and release in tension after the projection
    args = with_contactor(problem(), stiffness=k)
    ref, _got = compare(args, chaotic=True)
    assert ref.events


def test_zero_gap_load_toward_contactor():
    # at rest on the contactor and pushed into it: the consistency check engages it at t = 0
    args = with_excitation(with_contactor(problem(), gap=0.0), amplitude=-15 * G)
    ref, _got = compare(args)
    assert ref.events[0].time == 0.0 and ref.events[0].kind == "impact"


def test_zero_gap_load_away_from_contactor():
    args = with_contactor(problem(), gap=0.0)
    compare(args)


def test_two_contactors_at_one_point():
    args = problem()
    c0 = args["contactors"][0]
    below = dataclasses.replace(c0, side="below", gap=2.0 * c0.gap)
    args = {**args, "contactors": (c0, below)}
    ref, got = compare(args)
    assert {e.contactor for e in ref.events} == {0, 1}
    dense_check(args, ref, got)


def test_three_contactors():
    args = problem()
    c0 = args["contactors"][0]
    L = args["beam"].length
    cs = (c0, dataclasses.replace(c0, side="below", gap=0.5 * c0.gap), dataclasses.replace(c0, position=0.9 * L, gap=2e-4))
    ref, _got = compare({**args, "contactors": cs})
    assert len({e.contactor for e in ref.events}) >= 2


@pytest.mark.parametrize("hold", ["linear", "constant"])
def test_table_excitation(hold):
    times = np.array([0.0, 0.002, 0.005, 0.009, 0.012, 0.015])
    values = np.array([0.0, 60.0, 150.0, 120.0, 40.0, 0.0]) * G
    exc = Excitation(kind="base_acceleration", shape="table", times=times, values=values, hold=hold, start=0.001)
    args = problem(excitation=exc)
    ref, got = compare(args)
    assert ref.events
    dense_check(args, ref, got)


def test_point_force():
    L = problem()["beam"].length
    exc = Excitation(kind="point_force", shape="half_sine", amplitude=-3.0, duration=0.004, position=0.8 * L)
    ref, _got = compare(problem(excitation=exc))
    assert ref.events


def test_distributed_force_step():
    exc = Excitation(kind="distributed_force", shape="step", amplitude=5.0, start=0.002)
    ref, _got = compare(problem(excitation=exc))
    assert ref.events


def test_chattering_guard():
    args = with_options(problem(), max_events=5)
    ref, got = compare(args)
    assert ref.status == 1 and "max_events" in ref.message
    assert np.isnan(got.w[-1]).all()


def test_projection_warning_text():
    # a contactor far stiffer than 3 modes can resolve: the projection moves w(a) (warning in the message)
    args = with_options(with_contactor(problem(), stiffness=1e7), modes=3, end_time=0.05, basis="paper")
    ref, _got = compare(args)
    assert "Warning" in ref.message


def test_contact_projection():
    compare(with_options(with_contactor(problem(), stiffness=64000.0), projection="contact"), chaotic=True)


def test_initial_tip_displacement_without_load():
    compare(problem(EXAMPLES / "case00.toml"))


@pytest.mark.parametrize("dt", [1e-3, 2e-6])
def test_time_steps(dt):
    end = 0.2 if dt >= 1e-5 else 0.04
    compare(with_options(problem(), time_step=dt, end_time=end))


def test_undamped_and_resonant_sine():
    # zero damping with the half-sine frequency equal to a free mode: the resonant particular solution
    args = problem(damping=Damping(0.0, 0.0))
    beam = args["beam"]
    om1 = ib.mode_set(beam, (), 8).omega[0]
    exc = dataclasses.replace(args["excitation"], duration=math.pi / om1, amplitude=2 * G)
    compare({**args, "excitation": exc})


def test_no_contactors():
    args = problem(contactors=())
    args["points"] = np.array([args["beam"].length])
    compare(args)


def test_unsupported_problems():
    args = problem()
    base = {k: v for k, v in args.items() if k != "initial"}
    assert fast.supported(**base)
    assert not fast.supported(**base, progress=lambda t: None)
    assert not fast.supported(**{**base, "damping": Damping(0.011, 1.5)})  # over-damped contact state
    c0 = args["contactors"][0]
    four = tuple(dataclasses.replace(c0, gap=c0.gap * (1 + i)) for i in range(4))
    assert not fast.supported(**{**base, "contactors": four})
    with pytest.raises(ValueError, match="not supported"):
        fast.integrate_fast(**{**args, "damping": Damping(0.011, 1.5)})


def test_lazy_segments_behave_like_a_list():
    args = problem()
    ref, got = compare(args)
    segs = got.segments
    assert len(list(segs)) == len(segs)
    assert segs[-1] is segs[len(segs) - 1]
    assert [s.t0 for s in segs[1:3]] == [segs[1].t0, segs[2].t0]
    with pytest.raises(IndexError):
        segs[len(segs)]
    # the lazily built closed form reproduces the sampled output inside a segment
    s = segs[3]
    i = math.ceil(s.t0 / args["options"].time_step) + 1
    tau = ref.time[i] - s.t0
    eta, _deta = s.solution.evaluate(np.array([tau]))
    np.testing.assert_allclose(eta[:, 0], got.eta[i], rtol=0, atol=1e-12 * np.abs(got.eta).max())


def test_simulation_result_from_fast_path():
    # the whole public result (metrics, energy account, xarray) built on the fast RawSolution
    args = problem()
    ref, got = compare(args)
    ra = SimulationResult.from_raw(ref, args["beam"], args["contactors"], args["points"], 8, "a", {})
    rb = SimulationResult.from_raw(got, args["beam"], args["contactors"], args["points"], 8, "b", {})
    ma, mb = ra.metrics(), rb.metrics()
    assert ma["n_impacts"] == mb["n_impacts"] == 12
    for key in ("max_response", "t_max", "first_impact_time", "free_duration", "contact_duration"):
        assert mb[key] == pytest.approx(ma[key], rel=1e-12, abs=1e-15), key
    ds = rb.to_xarray()
    np.testing.assert_array_equal(ds["w"].values, got.w)


if __name__ == "__main__":  # benchmark: python tests/test_fast_engine.py
    import time

    args = problem()
    fast.integrate_fast(**args)  # compile or load the cache
    for label, fn in (("fast", lambda: fast.integrate_fast(**args)), ("python", lambda: python_engine(**args))):
        n = 200 if label == "fast" else 20
        times = []
        for _ in range(n):
            t0 = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t0)
        print(f"Case 3 integrate ({label}): best {1e3 * min(times):.2f} ms, median {1e3 * np.median(times):.2f} ms")
