"""The compiled engine against the independent ``solve_ivp`` path, across the problem space.

The exact engine (closed form per segment, proven event scan, Brent) and
``simulate(method="ivp")`` (DOP853 at rtol 1e-10 with terminal events,
:mod:`impactbeam.solver.reference`) share only the modal data (mode sets,
load weights, transfer matrices of eq. 12): propagation, load evaluation,
event detection and location, extrema and integrals are written
independently. They must produce the same event sequence (kinds and
contactors), event times within ``T_EVENT`` and metrics within ``R_METRIC``.

Tolerances: DOP853 at rtol 1e-10 locates events on its dense output to
~1e-12 s on these problems (measured 4e-14 .. 3e-11 s); after a dozen impacts
the sensitivity of each impact to its entry state amplifies that, so event
times are compared at 1e-9 s and metrics (extrema, durations) at 1e-7
relative: any error in a closed form, an event rule or a projection shows up
at 1e-4 or more.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import impactbeam as ib
from impactbeam.model.beam import Beam, Contactor, Support
from impactbeam.model.loading import Excitation
from impactbeam.model import Damping

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CASES = sorted(EXAMPLES.glob("case[0-9][0-9].toml"))
G = 9.80665
T_EVENT = 1e-9
R_METRIC = 1e-7
_NUMBER = r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?"
SCALARS = ("max_response", "t_max", "first_impact_time", "free_duration", "contact_duration", "min_response",
           "max_penetration")


def _last_digit(token: str) -> float:
    """The value of one unit in the last digit of a printed number (``"2.03e-05"`` -> 1e-7)."""
    mantissa, _, exponent = token.lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    return 10.0 ** (int(exponent or 0) - decimals)


def problem(path: Path = EXAMPLES / "case03.toml", **changes) -> dict:
    sc = ib.load_scenario(path)
    args = {"beam": sc.beam, "contactors": tuple(sc.contactors), "damping": sc.damping,
            "excitation": sc.excitation, "initial": sc.initial, "options": sc.solver,
            "points": list(sc.output_points)}
    args.update(changes)
    return args


def with_options(args: dict, **opts) -> dict:
    return {**args, "options": dataclasses.replace(args["options"], **opts)}


def with_contactor(args: dict, i: int = 0, **fields) -> dict:
    cs = list(args["contactors"])
    cs[i] = dataclasses.replace(cs[i], **fields)
    return {**args, "contactors": tuple(cs)}


def run(args: dict, method: str = "exact") -> ib.SimulationResult:
    a = dict(args)
    beam, cs = a.pop("beam"), a.pop("contactors")
    return ib.simulate_system(beam, cs, method=method, **a)


def compare(args: dict, t_event: float = T_EVENT, r_metric: float = R_METRIC):
    """Run both methods, assert agreement, return (exact, ivp) results."""
    ex = run(args)
    iv = run(args, "ivp")
    assert ex.status == iv.status
    assert [(e.kind, e.contactor) for e in ex.events] == [(e.kind, e.contactor) for e in iv.events]
    if ex.events:
        dt = max(abs(a.time - b.time) for a, b in zip(ex.events, iv.events))
        assert dt <= t_event, dt
    me, mi = ex.metrics(), iv.metrics()
    # displacement scale of the run (a metric near zero is compared against it)
    scale = max(abs(me[k]) for k in ("max_response", "min_response", "max_penetration") if me[k] is not None)
    for key in SCALARS:
        a, b = me[key], mi[key]
        assert (a is None) == (b is None), key
        if key == "t_max" and abs(me["max_response"]) < 1e-6 * scale:
            continue  # the maximum is a plateau at rest (e.g. before a step): its time is not defined
        if a is not None:
            ref = scale if key in ("max_response", "min_response", "max_penetration") else max(abs(b), 1e-3)
            assert abs(a - b) <= r_metric * ref, (key, a, b)
    for ra, rb in zip(me["impacts"], mi["impacts"]):
        assert ra["peak_force"] == pytest.approx(rb["peak_force"], rel=1e-6, abs=1e-12)
        assert ra["impulse"] == pytest.approx(rb["impulse"], rel=1e-6, abs=1e-15)
    return ex, iv


@pytest.mark.parametrize("path", CASES, ids=[p.stem for p in CASES])
def test_examples_agree(path):
    ex, _ = compare(problem(path))
    if path.stem == "case03":
        assert len(ex.events) == 24  # the reference case: 12 impacts in 0.2 s


@pytest.mark.parametrize("free, contact", [(0.0, 0.0), (1.0, 1.0), (0.011, 1.5), (2.5, 0.02), (0.9999, 1.0001)])
def test_every_damping_regime(free, contact):
    compare(problem(damping=Damping(free, contact)))


def test_free_free_beam_with_rigid_body_modes():
    # two rigid-body modes (translation, rotation) and a stop on each side near each end
    sc = ib.load_scenario(EXAMPLES / "case03.toml")
    b = sc.beam
    beam = dataclasses.replace(b, left=Support.preset("free"), right=Support.preset("free"))
    L = beam.length
    cs = (Contactor(0.1 * L, 4030.0, 2e-4, "below"), Contactor(0.9 * L, 4030.0, 2e-4, "below"),
          Contactor(0.5 * L, 4030.0, 1e-3, "above"))
    exc = Excitation(kind="point_force", shape="half_sine", amplitude=-0.05, duration=0.004, position=0.3 * L)
    ex, _ = compare(problem(beam=beam, contactors=cs, excitation=exc, points=[0.0, L]))
    assert ex.solution.packed.om[0, :2].tolist() == [0.0, 0.0]
    assert ex.events


def two_sided(args: dict, positions: list[float], gap: float | list[float] = 2e-4, k: float = 4030.0) -> dict:
    gaps = np.broadcast_to(np.asarray(gap, dtype=float), (len(positions),))
    cs = []
    for x, g in zip(positions, gaps):
        cs += [Contactor(x, k, float(g), "above"), Contactor(x, k, float(g), "below")]
    return {**args, "contactors": tuple(cs)}


def test_four_contactors_two_sided_stops():
    L = problem()["beam"].length
    ex, _ = compare(two_sided(problem(), [0.484 * L, L]))
    assert len({e.contactor for e in ex.events}) >= 3


def test_six_contactors():
    L = problem()["beam"].length
    ex, _ = compare(two_sided(problem(), [0.3 * L, 0.6 * L, L], gap=[2e-5, 1e-4, 1e-3]))
    assert len({e.contactor for e in ex.events}) >= 4


@pytest.mark.parametrize("hold", ["linear", "constant"])
def test_table_excitation(hold):
    times = np.array([0.0, 0.002, 0.005, 0.009, 0.012, 0.015])
    values = np.array([0.0, 60.0, 150.0, 120.0, 40.0, 0.0]) * G
    exc = Excitation(kind="base_acceleration", shape="table", times=times, values=values, hold=hold, start=0.001)
    ex, _ = compare(problem(excitation=exc))
    assert ex.events


def test_point_force_and_distributed_step():
    L = problem()["beam"].length
    exc = Excitation(kind="point_force", shape="half_sine", amplitude=-3.0, duration=0.004, position=0.8 * L)
    assert compare(problem(excitation=exc))[0].events
    exc = Excitation(kind="distributed_force", shape="step", amplitude=5.0, start=0.002)
    assert compare(problem(excitation=exc))[0].events


def test_undamped_resonant_sine():
    # zero damping with the half-sine frequency equal to a free mode: the resonant particular solution
    args = problem(damping=Damping(0.0, 0.0))
    om1 = ib.mode_set(args["beam"], (), 8).omega[0]
    exc = dataclasses.replace(args["excitation"], duration=math.pi / om1, amplitude=2 * G)
    compare({**args, "excitation": exc})


def test_contact_preserving_projection_is_honoured_by_both():
    # the paper's basis: with the shared enriched basis every switch is exact and the projection moot
    args = with_options(with_contactor(problem(), stiffness=64000.0), projection="contact", end_time=0.05,
                        basis="paper")
    ex, _ = compare(args, t_event=1e-8, r_metric=1e-6)
    paper = run(with_options(args, projection="paper"))
    assert [e.time for e in paper.events] != [e.time for e in ex.events]


def test_chattering_guard_stops_both_paths():
    args = with_options(problem(), max_events=5)
    ex, _ = compare(args)
    assert ex.status == 1 and "max_events" in ex.message
    assert np.isnan(ex.w[-1]).all() and ex.solution.t_end < 0.2


def test_coincident_contactors_are_refused():
    c0 = problem()["contactors"][0]
    with pytest.raises(ib.ParameterError, match="contactors.1: same position, side and gap as contactors.0"):
        run(problem(contactors=(c0, dataclasses.replace(c0, stiffness=1e4))))


def test_sixteen_contactors_build_only_visited_states():
    # a tube through eight support plates: 8 two-sided stops = 16 contactors, 65536 states
    L = problem()["beam"].length
    args = with_options(two_sided(problem(), list(np.linspace(0.2, 1.0, 8) * L), gap=1e-4), end_time=0.05)
    res = run(args)
    visited = {tuple(sorted(res.solution.engaged(j))) for j in range(res.solution.n_segments)}
    built = res.solution.packed.keys  # every state built so far for this problem (cached across runs)
    assert set(visited) <= set(built)
    assert len(built) <= len(visited) + 2 < 100  # not 2**16: only states a switch asked for
    assert res.events and res.status == 0


def test_progress_reports_and_results_do_not_depend_on_it():
    args = with_options(problem(), end_time=2.0)
    seen: list[float] = []
    a = run({**args, "progress": seen.append})
    b = run(args)
    assert seen and seen[-1] == pytest.approx(2.0) and seen == sorted(seen)
    assert [e.time for e in a.events] == [e.time for e in b.events]


@pytest.mark.parametrize("dt", [1e-6, 1e-5, 1e-3])
def test_results_do_not_depend_on_the_output_step(dt):
    # the scan and the metrics never look at the output grid: identical to the last bit
    ref = run(problem()).metrics()
    got = run(with_options(problem(), time_step=dt, end_time=0.2 if dt > 1e-6 else 0.2)).metrics()
    for key in SCALARS + ("n_impacts",):
        assert got[key] == ref[key], key


def test_dense_output_reproduces_segment_starts():
    # evaluating at a segment start returns the stored modal state (STYLE.md practice 3)
    res = run(problem())
    sol = res.solution
    s = sol.sample(np.array([0.05]), sol.t0, modal=True)
    np.testing.assert_allclose(s.eta, sol.eta0, rtol=0, atol=1e-14 * np.abs(sol.eta0).max())


def test_compiled_code_also_runs_as_python():
    # NUMBA_DISABLE_JIT=1 runs the same kernels as plain Python: same events to 1e-12 s
    code = (
        "import impactbeam as ib, json;"
        f"sc = ib.load_scenario(r'{EXAMPLES / 'case03.toml'}');"
        "import dataclasses; sc = dataclasses.replace(sc, solver=dataclasses.replace(sc.solver, end_time=0.05));"
        "r = ib.simulate(sc); m = r.metrics();"
        "print(json.dumps([[e.time for e in r.events], m['max_response'], m['max_penetration']]))"
    )
    env = {**os.environ, "NUMBA_DISABLE_JIT": "1"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    import json

    times, mx, pen = json.loads(out.stdout.strip().splitlines()[-1])
    sc = ib.load_scenario(EXAMPLES / "case03.toml")
    res = ib.simulate(dataclasses.replace(sc, solver=dataclasses.replace(sc.solver, end_time=0.05)))
    assert np.max(np.abs(np.subtract(times, [e.time for e in res.events]))) <= 1e-12
    m = res.metrics()
    assert mx == pytest.approx(m["max_response"], rel=1e-12)
    assert pen == pytest.approx(m["max_penetration"], rel=1e-10)


@pytest.mark.parametrize("left, modes, k, gap, v0", [
    ("clamped", 2, 1e5, 1e-4, 0.3),   # each projection moves the tip by over 5 % of the gap (warned)
    ("clamped", 3, 1e5, 1e-4, 0.3),
    ("pinned", 4, 4564.3, 3e-4, 0.1),  # a rigid-body rotation; switched back and forth at one rebound
    ({"translational": 1e3, "rotational": 0.0}, 4, 4564.3, 3e-4, 0.1),
], ids=["clamped-2", "clamped-3", "pinned-4", "spring-4"])
def test_a_projection_leaving_a_contactor_on_the_wrong_side(left, modes, k, gap, v0):
    # With few paper modes, eq. (12) leaves the tip stop penetrated after a rebound (or separated after an
    # impact). Both paths apply the same rule: the contactor just switched, moving back to its side, switches
    # where its row turns back; any other row on the wrong side switches at once (twice per instant at most).
    # The solve_ivp path used to let such a state run with only downward crossings as events: the beam went
    # through the stop (errors of 20 % to 14 times the response, 1 impact instead of 9).
    L = 0.1092
    sc = ib.parse_scenario({
        "beam": {"length": L, "width": 9.93e-3, "height": 3.03e-3, "youngs_modulus": 1834e6, "density": 951.98},
        "supports": {"left": left, "right": "free"},
        "contactors": [{"position_ratio": 0.997, "stiffness": k, "gap": gap, "side": "above"}],
        "damping": {"free": 0.0, "contact": 0.0}, "initial": {"velocity": v0},
        "solver": {"modes": modes, "time_step": 1e-5, "end_time": 0.02, "basis": "paper"},
    })
    args = problem(beam=sc.beam, contactors=sc.contactors, damping=sc.damping, excitation=sc.excitation,
                   initial=sc.initial, options=sc.solver, points=[sc.contactors[0].position, L])
    ex, iv = compare(args)
    assert len(ex.events) >= 4
    # the projection's warning by the same rule: the same words, and the same numbers to within one unit of the
    # last digit printed (the two paths' switch times and deflections differ by ~1e-12 relative, which can round
    # a last digit apart on another machine)
    assert [re.sub(_NUMBER, "#", w) for w in iv.warnings] == [re.sub(_NUMBER, "#", w) for w in ex.warnings]
    for wi, we in zip(iv.warnings, ex.warnings):
        assert wi.partition("(worst")[0] == we.partition("(worst")[0]  # the counts of switches and modes, exactly
        for a, b in zip(re.findall(_NUMBER, wi.partition("(worst")[2]), re.findall(_NUMBER, we.partition("(worst")[2])):
            assert abs(float(a) - float(b)) <= 1.0001 * _last_digit(b), (a, b)
    t = np.linspace(0.0, 0.02, 2001)
    w_ex, w_iv = ex.displacement([L], t), iv.displacement([L], t)
    assert np.max(np.abs(w_ex - w_iv)) <= 1e-8 * np.max(np.abs(w_iv))  # measured 2e-11 .. 2e-10


def test_two_zero_gap_stops_crossed_at_one_instant():
    # A two-sided clamp with no clearance: as w passes 0 one stop releases and the other engages at the same
    # instant; after the switch the other row touches 0 and its slope points to the wrong side, so it switches
    # at once (the engine judges it by the sign of its first derivative). The solve_ivp path used to start such
    # a row a round-off below 0 and never see it cross.
    L = 0.1092
    sc = ib.parse_scenario({
        "beam": {"length": L, "width": 9.93e-3, "height": 3.03e-3, "youngs_modulus": 1834e6, "density": 951.98},
        "supports": {"left": "clamped", "right": "free"},
        "contactors": [{"position_ratio": 0.809, "stiffness": 6.7e4, "gap": 0.0, "side": "above"},
                       {"position_ratio": 0.809, "stiffness": 6.7e4, "gap": 0.0, "side": "below"}],
        "damping": {"free": 0.0, "contact": 0.0},
        "excitation": {"kind": "base_acceleration", "shape": "harmonic", "amplitude": -147.15, "frequency": 90.0},
        "solver": {"modes": 10, "time_step": 1e-5, "end_time": 0.02},
    })
    args = problem(beam=sc.beam, contactors=sc.contactors, damping=sc.damping, excitation=sc.excitation,
                   initial=sc.initial, options=sc.solver, points=[sc.contactors[0].position, L])
    ex, _ = compare(args)
    pairs = [(a.time, a.contactor, b.contactor) for a, b in zip(ex.events, ex.events[1:]) if a.time == b.time]
    assert len(pairs) == 3 and all({c0, c1} == {0, 1} for _, c0, c1 in pairs)


def test_a_dashpot_release_that_chatters_stops_both_paths():
    # A zero-gap dashpot stop whose beam damping jumps at contact (modal ratios 0.02 free, 0.8 engaged): where
    # the force k d + c d' reaches 0 the free state's slope of it points back into contact and the engaged
    # state's out of it, so both paths switch at every instant until the chattering guard (400 events here)
    # stops them, with the warning. The solve_ivp path used to let the engaged row run on from a round-off
    # below 0 and stay engaged, the spring pulling, for the whole run.
    L = 0.1092
    sc = ib.parse_scenario({
        "beam": {"length": L, "width": 9.93e-3, "height": 3.03e-3, "youngs_modulus": 1834e6, "density": 951.98},
        "supports": {"left": "pinned", "right": "free"},
        "contactors": [{"position_ratio": 0.544, "stiffness": 632.33, "gap": 0.0, "side": "above",
                        "damping": 0.0996}],
        "damping": {"free": 0.02, "contact": 0.8},
        "excitation": {"kind": "point_force", "shape": "harmonic", "amplitude": -0.2, "position": 0.10305,
                       "frequency": 40.0},
        "solver": {"modes": 16, "time_step": 1e-5, "end_time": 0.02, "max_events": 400},
    })
    runs = []
    for method in ("exact", "ivp"):
        with pytest.warns(ib.ImpactBeamWarning, match="chattering contact"):
            runs.append(ib.simulate(sc, method=method))
    ex, iv = runs
    assert ex.status == iv.status == 1 and len(ex.events) == len(iv.events) == 400
    # the release that starts it: DOP853's event location, ~1e-10 s here (3.4e-10 measured)
    release = ex.events[1].time
    assert abs(release - iv.events[1].time) < 1e-8
    # the chatter is at the release: both paths spend their 400 events within a microsecond after it
    # (measured 0.32 us for the engine, 0.16 us for solve_ivp)
    assert release < ex.solution.t_end < release + 1e-6 and release < iv.solution.t_end < release + 1e-6


def test_a_projection_without_effect_is_said():
    # solver.projection = "contact" with the shared enriched basis changed nothing (w identical to the bit),
    # in silence, where every other key without effect is refused or warned about
    args = with_options(with_contactor(problem(), stiffness=64000.0), projection="contact", end_time=0.01)
    with pytest.warns(ib.ImpactBeamWarning, match=r'solver\.projection = "contact" has no effect'):
        shared = run(args)
    assert np.array_equal(shared.w, run(with_options(args, projection="paper")).w)


def test_a_zero_gap_contactor_at_rest_before_the_load_is_no_chatter_for_solve_ivp():
    """A zero-gap stop touching the beam at rest, a tip step that starts at 3 ms. The solve_ivp path stopped at
    t = 0 as chattering (solve_ivp takes an event function that stays at 0 for a crossing; 4000 of 4002 samples
    NaN) while the engine ran: both now give the start-0 run's events shifted by 3 ms (1e-9 s, the comparison
    tolerance of this file)."""
    def scenario(start):
        return ib.parse_scenario({
            "beam": {"length": 0.1092, "width": 9.93e-3, "height": 3.03e-3, "youngs_modulus": 1834e6,
                     "density": 951.98},
            "contactors": [{"position_ratio": 0.3, "stiffness": 2000, "gap": 0.0, "side": "above"}],
            "damping": {"free": 0.011, "contact": 0.02},
            "excitation": {"kind": "point_force", "shape": "step", "amplitude": 0.02, "position_ratio": 1.0,
                           "start": start},
            "solver": {"modes": 8, "time_step": 1e-5, "end_time": 0.02}})

    first = ib.simulate(scenario(0.0))
    for method in ("exact", "ivp"):
        late = ib.simulate(scenario(0.003), method=method)
        assert late.status == 0 and len(late.events) == len(first.events)
        shifted = np.array([e.time for e in first.events]) + 0.003
        assert np.abs(np.array([e.time for e in late.events]) - shifted).max() <= 1e-9
