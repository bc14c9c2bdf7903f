"""Batched runs, interpreted kernels and resumable scans give the bits of a single compiled run (issue 24).

Every check here is bit-for-bit, with no tolerance: the paths compared run
the same arithmetic in the same order (one BLAS thread), so any difference
is a bug, not round-off.

* a case run in a batch (:func:`impactbeam.sweeps.cases.run_cases`, the path of
  sweeps) against ``simulate_system(...).metrics(impacts=False)`` alone;
* the interpreted twins of the kernels (the first-use path) against the
  compiled ones: segment records, events, samples, extrema and the metrics
  with the per-impact table, on every code path (the paper's basis, the
  shared basis, dashpots and free-mode damping in general states, rigid-body
  modes, a harmonic load, a chattering stop);
* a run returning to Python every few scan steps against one that never does;
* the compiled pairwise sum against NumPy's ``sum``;
* the sweep's case builder against re-parsing the scenario.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import impactbeam as ib
from impactbeam.model import Damping, SolverOptions
from impactbeam.model.beam import Contactor, Support
from impactbeam.model.loading import Excitation
from impactbeam.model.starting import InitialCondition, Preload
from impactbeam.result.metrics import METRIC_UNITS
from impactbeam.sweeps.cases import Case, run_cases
from impactbeam.solver import engine, kernels

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _case3() -> ib.Scenario:
    return ib.load_scenario(EXAMPLES / "case03.toml")


def _same(a: float | None, b: float) -> bool:
    return bool(np.isnan(b)) if a is None else a == b


def _variants() -> dict[str, Case]:
    """Cases covering the engine's paths, each short."""
    sc = _case3()
    rep = dataclasses.replace
    c0 = sc.contactors[0]
    L = sc.beam.length
    short = rep(sc.solver, end_time=0.06)

    def case(**kw) -> Case:
        base = dict(beam=sc.beam, contactors=sc.contactors, damping=sc.damping, excitation=sc.excitation,
                    initial=sc.initial, options=short, points=sc.output_points)
        base.update(kw)
        return Case(**base)

    free_free = rep(sc.beam, left=Support.preset("free"), right=Support.preset("free"))
    return {
        "case3": case(),
        "zero_gap_below": case(contactors=(rep(c0, gap=0.0, side="below"),)),
        "paper_basis": case(options=rep(short, basis="paper")),
        "two_stops_dashpot": case(contactors=(rep(c0, damping=0.3), rep(c0, position=L, side="below", gap=3e-4))),
        "free_modes_damping": case(damping=Damping(0.011, 0.0, "free_modes")),
        "chattering": case(options=rep(short, max_events=5)),
        "no_contactor": case(contactors=(), points=(L,)),
        "rigid_modes": case(beam=free_free, contactors=(rep(c0, position=0.1 * L, side="below"),),
                            excitation=Excitation(kind="point_force", shape="half_sine", amplitude=-0.05,
                                                  duration=0.004, position=0.3 * L), points=(0.1 * L,)),
        "harmonic": case(excitation=Excitation(kind="base_acceleration", shape="harmonic", amplitude=30.0,
                                               frequency=70.0), options=rep(short, end_time=0.1)),
        "rayleigh": case(damping=Damping(model="rayleigh", alpha=2.0, beta=2e-5)),
        "initial_velocity": case(initial=InitialCondition(velocity=-0.05)),
        # the equilibrium under gravity depends on the gap: engaged at zero gap, free at 0.1 mm (per case)
        "preload_engaged": case(contactors=(rep(c0, gap=0.0, side="below"),), preload=Preload("gravity", -9.81),
                                initial=InitialCondition(equilibrium=True)),
        "preload_free": case(contactors=(rep(c0, gap=1e-4, side="below"),), preload=Preload("gravity", -9.81),
                             initial=InitialCondition(equilibrium=True)),
    }


def _alone(c: Case) -> ib.SimulationResult:
    return ib.simulate_system(c.beam, c.contactors, damping=c.damping, excitation=c.excitation, initial=c.initial,
                              options=c.options, points=c.points, preload=c.preload)


@pytest.mark.filterwarnings("ignore:initial.velocity")  # a uniform velocity of a cantilever: the clamp holds part
def test_a_case_gives_the_same_bits_alone_or_in_a_batch():
    cases = _variants()
    names = list(cases)
    # every case twice, and Case 3 with other gaps and loads in the same batch as Case 3
    sc = _case3()
    extra = [dataclasses.replace(cases["case3"], contactors=(dataclasses.replace(sc.contactors[0], gap=g),),
                                 excitation=dataclasses.replace(sc.excitation, amplitude=a))
             for g, a in ((1e-4, 100.0), (4e-4, 180.0), (0.0, 60.0))]
    batch = [cases[n] for n in names] + extra + [cases[n] for n in names]
    with pytest.warns(ib.ImpactBeamWarning, match="chattering contact.* results cover 0 to"):  # as alone
        res = run_cases(batch)
    assert all(e is None for e in res.errors), res.messages
    for k, c in enumerate(batch):
        alone = _alone(c)
        m = alone.metrics(impacts=False)
        for j, key in enumerate(METRIC_UNITS):
            assert _same(m[key], res.scalars[k, j]), (k, key, m[key], res.scalars[k, j])
        assert res.status[k] == alone.status
        assert res.messages[k] == alone.message
    assert res.status[names.index("chattering")] == 1


def test_a_failing_case_fails_alone_in_its_batch():
    sc = _case3()
    good = Case(sc.beam, sc.contactors, sc.damping, sc.excitation, sc.initial,
                dataclasses.replace(sc.solver, end_time=0.02), sc.output_points)
    off_beam = dataclasses.replace(good, contactors=(dataclasses.replace(sc.contactors[0], position=0.2),))
    res = run_cases([good, off_beam, good])
    assert res.status.tolist() == [0, -1, 0]
    assert "contactors.0" in res.messages[1] and isinstance(res.errors[1], ib.ParameterError)
    np.testing.assert_array_equal(res.scalars[0], res.scalars[2])


def test_a_case_warns_in_its_batch_as_it_warns_alone():
    # Found by a hunt: a study's case lacked two warnings its run gives alone, impacts resolved only at the touch
    # tolerance's scale (a restitution stop settling by ever smaller bounces: 2915 of its 2917 impacts at most
    # 1.1e-11 m deep) and a response too small for the extrema (Case 3 at 1e-12 g: 6.8e-17 m). A batched case now
    # warns as metrics(impacts=False) does alone, and that no longer needs the impact table to count them.
    from impactbeam._warnings import WarningLog
    from test_dissipation import _SETTLING

    sc = _case3()
    cases = [Case(s.beam, s.contactors, s.damping, s.excitation, s.initial, s.solver, s.output_points, s.preload)
             for s in (ib.parse_scenario(_SETTLING), sc.with_values({"excitation.amplitude": "1e-12 g"}), sc)]
    with pytest.warns(ib.ImpactBeamWarning, match="touch tolerances"):
        res = run_cases(cases)
    for k, c in enumerate(cases):
        with WarningLog() as log:
            _alone(c).metrics(impacts=False)
        assert sorted(res.warnings[k]) == sorted(log.messages), k
    assert any("2915 of 2917 impacts" in w for w in res.warnings[0])
    assert any("the response is only ~6.8e-17 m" in w for w in res.warnings[1])
    assert res.warnings[2] == []


def _records(sol) -> list[np.ndarray]:
    return [sol.t0, sol.t1, sol.slot, sol.piece, sol.eta0, sol.deta0, *sol.event_arrays, sol.energy_jumps,
            sol.event_penetrations]


@pytest.mark.parametrize("name", ["case3", "paper_basis", "two_stops_dashpot", "free_modes_damping", "rigid_modes",
                                  "harmonic", "chattering", "no_contactor"])
def test_interpreted_kernels_give_the_compiled_bits(name):
    c = _variants()[name]
    out = {}
    for kind in ("compiled", "interpreted"):
        with kernels.forced(kind):
            res = _alone(c)
            x = np.array(sorted({*c.points, c.beam.length}))
            t = np.linspace(0.0, c.options.end_time, 23)
            smp = res.solution.sample(x, t, modal=True, energy=True)
            ext = res.solution.extrema([(x[0], 0.0, c.options.end_time, 1.0, 0.0, None),
                                        (x[-1], 0.01, 0.03, -1.0, 0.0, None)])
            ints = res.solution.integrals([(x[0], 0.0, c.options.end_time)])
            out[kind] = (_records(res.solution), res.metrics(), [smp.w, smp.w_t, smp.eta, smp.energies], ext, ints)
    a, b = out["compiled"], out["interpreted"]
    for u, v in zip(a[0] + a[2] + [a[3], a[4]], b[0] + b[2] + [b[3], b[4]]):
        np.testing.assert_array_equal(u, v)
    assert a[1] == b[1]  # every metric and the per-impact table, to the bit


def test_the_solution_does_not_depend_on_where_the_run_returns_to_python(monkeypatch):
    """A scan stopped every 3 steps resumes where it was: the same segments as an uninterrupted run."""
    sc = _case3()
    plain = ib.simulate(sc).solution
    seen = []
    monkeypatch.setattr(engine, "_BUDGET", 3)
    cut = ib.simulate_system(sc.beam, sc.contactors, damping=sc.damping, excitation=sc.excitation,
                             options=sc.solver, progress=seen.append).solution
    assert len(seen) > 50  # it did return often
    assert np.all(np.diff(seen) >= 0.0)  # progress moves forward, also inside a segment
    for u, v in zip(_records(plain), _records(cut)):
        np.testing.assert_array_equal(u, v)


def test_a_run_of_switches_with_few_scan_steps_returns_to_python(monkeypatch):
    """A contact settling by ever smaller bounces: 5834 switches, about one scan step each.

    The budget of a call counted scan steps alone, so such a run reached no checkpoint: a first run in a
    process stayed on the interpreted kernels throughout (46 s on the test machine; 0.9 s since), with no
    progress report and no Ctrl-C until it ended. Switches and segment set-ups count too now; the solution is
    the same to the bit wherever the run returns.
    """
    from test_dissipation import _SETTLING

    sc = ib.parse_scenario(_SETTLING)
    with kernels.forced("compiled"):  # the compiled budget from the start (an interpreted one is 200 times less)
        plain = ib.simulate(sc).solution
        monkeypatch.setattr(engine, "_BUDGET", 20_000)
        assert plain.evaluations < 20_000  # scan steps alone would not have returned once
        seen = []
        cut = ib.simulate(sc, progress=seen.append).solution
    assert len(seen) > 10  # measured 33 (32 returns and the end); the old budget: 1 (the end)
    for u, v in zip(_records(plain), _records(cut)):
        np.testing.assert_array_equal(u, v)


@pytest.mark.parametrize("kind", ["compiled", "interpreted"])
def test_pairwise_sum_is_numpy_sum(kind):
    K = kernels.compiled() if kind == "compiled" else kernels.interpreted()
    rng = np.random.default_rng(24)
    for n in [*range(0, 40), 127, 128, 129, 255, 256, 257, 300, 1000, 1031]:
        x = rng.standard_normal(n) * 10.0 ** rng.integers(-12, 3, n)
        assert K.pairwise_sum(x, n) == np.sum(x), n
    zero = np.array([-0.0])
    assert np.signbit(K.pairwise_sum(zero, 1)) == np.signbit(np.sum(zero))  # +0.0, as NumPy adds to 0.0


def test_case_builder_gives_the_model_objects_of_a_reparse():
    """Direct paths set on the model objects equal a full re-parse of the scenario, field by field."""
    from impactbeam.sweeps.batches import _CaseBuilder

    sc = _case3()
    paths = ("contactors.0.stiffness", "contactors.0.gap", "contactors.0.side", "excitation.amplitude",
             "excitation.duration", "excitation.start", "excitation.scale", "solver.end_time",
             "solver.event_tolerance", "solver.max_events", "solver.time_step")
    rng = np.random.default_rng(7)
    values = [[float(rng.choice([4030.0, 5000.0])), float(rng.choice([0.0, 1e-4, 2.29e-4])),
               str(rng.choice(["above", "below"])), float(rng.choice([50.0, 147.1])), float(rng.choice([5e-3, 0.015])),
               float(rng.choice([0.0, 1e-3])), float(rng.choice([0.5, 1.0])), float(rng.choice([0.05, 0.2])),
               float(rng.choice([1e-13, 1e-12])), int(rng.choice([100, 10_000])), float(rng.choice([1e-5, 1e-4]))]
              for _ in range(40)]
    values.append([4030.0, -1e-4, "above", 50.0, 0.015, 0.0, 1.0, 0.2, 1e-13, 100, 1e-5])  # a negative gap
    built = _CaseBuilder(sc, paths).cases(values)
    for vals, case in zip(values, built):
        try:
            ref = sc.with_values(dict(zip(paths, vals)))
        except ib.ScenarioError as exc:
            assert isinstance(case, ib.ScenarioError) and str(case) == str(exc)
            continue
        assert case.beam == ref.beam and case.contactors == ref.contactors and case.damping == ref.damping
        assert case.options == ref.solver and case.points == ref.output_points
        for f in dataclasses.fields(Excitation):
            u, v = getattr(case.excitation, f.name), getattr(ref.excitation, f.name)
            assert (u is None and v is None) or np.array_equal(u, v), f.name
        assert dataclasses.astuple(case.initial) == dataclasses.astuple(ref.initial)


def test_first_use_runs_interpreted_and_compiles_in_the_background(monkeypatch):
    """With an empty cache a run does not wait for numba: interpreted kernels, one background compile.

    And before the compiled kernels are loaded, small work runs interpreted without asking for them.
    """
    started = []
    monkeypatch.setattr(kernels, "_READY", False)
    monkeypatch.setattr(kernels, "_LOADED", False)
    monkeypatch.setattr(kernels, "_CHECKED", -1e9)
    monkeypatch.setattr(kernels, "_SPENT", 0.0)
    monkeypatch.setattr(kernels, "ready", lambda: False)
    monkeypatch.setattr(kernels, "_compile_in_background", lambda: started.append(1))
    assert kernels.for_work(10).interpreted and started == []  # small: not even a look at the cache
    assert kernels.active().interpreted and started == [1]
    sc = _case3()
    res = ib.simulate(dataclasses.replace(sc, solver=dataclasses.replace(sc.solver, end_time=0.03)))
    assert res.metrics()["n_impacts"] == 1


def test_batches_hold_a_bounded_memory_of_load_pieces(monkeypatch):
    # A batch pads every case's load pieces to the longest: 90 random loads of 100 s (800,000 samples each)
    # would hold ~5 GB at once. run_cases cuts a group into batches of at most BATCH_BYTES of pieces, and
    # a case gives the same bits in any of them.
    import impactbeam.sweeps.cases as cases_module
    import impactbeam.solver.batch as batch_module

    sc = _case3().with_values({
        "excitation.shape": "random", "excitation.amplitude": None, "excitation.duration": None,
        "excitation.psd": [["10 Hz", "0.01 g^2/Hz"], ["500 Hz", "0.01 g^2/Hz"]], "solver.end_time": 0.07,
    })
    cases = [Case(s.beam, s.contactors, s.damping, s.excitation, s.initial, s.solver, s.output_points)
             for s in (sc.with_values({"excitation.seed": seed}) for seed in (1, 2, 3, 4, 5))]
    per_case = cases_module.case_bytes(cases[0])
    assert per_case > 72 * cases[0].excitation.times.size  # the samples, their pieces and a margin
    monkeypatch.setattr(cases_module, "BATCH_BYTES", 2 * per_case)
    sizes = []
    real = batch_module.integrate_batch
    monkeypatch.setattr(batch_module, "integrate_batch", lambda *a, **k: (sizes.append(len(a[1])), real(*a, **k))[1])
    res = run_cases(cases)
    assert sizes == [2, 2, 1]
    for k, c in enumerate(cases):
        m = _alone(c).metrics(impacts=False)
        assert all(_same(m[key], res.scalars[k, j]) for j, key in enumerate(METRIC_UNITS)), k


@pytest.mark.filterwarnings("ignore:excitation.psd")
def test_a_sweep_of_a_random_load_stores_what_each_run_gives(tmp_path):
    # The case builder sets some values on the model objects directly; a random load's record lasts
    # solver.end_time and is drawn when the scenario is read, so a sweep over end_time (or anything the
    # record depends on) must read each case whole: each stored metric is that case's own run.
    from impactbeam.sweeps import run_sweep

    sc = _case3().with_values({
        "excitation.shape": "random", "excitation.amplitude": None, "excitation.duration": None,
        "excitation.psd": [["10 Hz", "0.05 g^2/Hz"], ["500 Hz", "0.05 g^2/Hz"]], "excitation.seed": 7,
        "solver.end_time": 0.07,
    })
    (tmp_path / "r.toml").write_text(sc.to_toml())
    spec = {"base": str(tmp_path / "r.toml"),
            "parameters": {"solver.end_time": {"values": [0.07, 0.12]},
                           "excitation.scale": {"values": [1.0, 1.5, 2.0, 2.5, 3.0]}},
            "outputs": {"metrics": "all"}}
    # one batch: after its first case the builder sets values directly (values recur across the cases)
    ds = run_sweep(spec, None, workers=0, batch_size=16, progress=False).dataset
    for end in (0.07, 0.12):
        for scale in (1.0, 1.5, 2.0, 2.5, 3.0):
            m = ib.simulate(sc.with_values({"solver.end_time": end, "excitation.scale": scale})).metrics(impacts=False)
            stored = ds.sel({"solver.end_time": end, "excitation.scale": scale})
            for key in METRIC_UNITS:
                assert _same(m[key], float(stored[key].values)), (end, scale, key)


@pytest.mark.parametrize("kind", ["compiled", "interpreted"])
def test_kernels_given_at_a_segment_end_give_the_bits_of_kernels_computed_there(kind):
    # The event loop computes the kernels at a segment's end once per slot and segment length and hands
    # them to the scan's last step (row_from) and to the state update (state_from): every regime must give
    # exactly what row_at and state_at compute there, or a run would depend on which path it took.
    K = kernels.compiled() if kind == "compiled" else kernels.interpreted()
    rng = np.random.default_rng(3)
    reg = np.array([0, 0, 1, 1, 2, 2], dtype=np.int64)  # under-, critically and over-damped; a rigid mode (1, 0)
    a = np.array([0.0, 12.0, 40.0, 0.0, 90.0, 5.0])
    om = np.array([300.0, 2000.0, 40.0, 0.0, 60.0, 0.0])
    w = np.where(reg == 0, np.sqrt(np.abs(om**2 - a**2)), np.where(reg == 2, np.sqrt(np.abs(a**2 - om**2)), 0.0))
    h0, dh0 = rng.normal(size=6), rng.normal(size=6)
    P = rng.normal(size=(6, 8))
    VH, VD, PV = rng.normal(size=(2, 6)), rng.normal(size=(2, 6)), rng.normal(size=(2, 8))
    base = rng.normal(size=2)
    for tau, Om, phi in ((1.25e-4, 0.0, 0.0), (3.7e-3, 210.0, 0.4)):
        kc, ks, kw = np.empty(6), np.empty(6), K.kernel_work(6)
        K.kernels_into(tau, reg, a, w, kc, ks, kw)
        for n in range(6):  # all modes at once (SIMD) give each mode's own kernels
            assert (kc[n], ks[n]) == K.kernel(reg[n], a[n], w[n], tau)
        e1, d1, e2, d2 = (np.empty(6) for _ in range(4))
        K.state_at(tau, reg, a, w, om, h0, dh0, P, Om, phi, e1, d1, kw)
        K.state_from(tau, kc, ks, a, om, h0, dh0, P, Om, phi, e2, d2)
        np.testing.assert_array_equal(e1, e2)
        np.testing.assert_array_equal(d1, d2)
        for c in range(2):
            assert K.row_at(c, tau, reg, a, w, om, VH, VD, base, PV, Om, phi, kw) == \
                K.row_from(c, tau, kc, ks, a, om, VH, VD, base, PV, Om, phi)


@pytest.mark.filterwarnings("ignore:excitation.psd")
def test_a_long_run_keeps_its_records_while_the_next_one_runs(monkeypatch):
    # A long run's solution takes the engine's record arrays without a copy; the next run in the thread
    # must then get arrays of its own, or it would overwrite the first solution's segments.
    monkeypatch.setattr(engine, "_TAKE", 64)  # "long" from 64 segments: a 0.07 s random record has ~280
    sc = _case3().with_values({
        "excitation.shape": "random", "excitation.amplitude": None, "excitation.duration": None,
        "excitation.psd": [["10 Hz", "0.05 g^2/Hz"], ["500 Hz", "0.05 g^2/Hz"]], "excitation.seed": 11,
        "solver.end_time": 0.07,
    })
    first = ib.simulate(sc).solution
    assert first.t0.size > 64 and first.eta0.base is not None  # taken, not copied
    kept = [np.array(r, copy=True) for r in _records(first)]
    ib.simulate(sc.with_values({"excitation.seed": 12}))
    ib.simulate(_case3())
    for u, v in zip(kept, _records(first)):
        np.testing.assert_array_equal(u, v)



@pytest.mark.filterwarnings("ignore:excitation.psd")
def test_a_batch_solution_handed_to_case_done_survives_the_next_cases(monkeypatch):
    # The batch reuses one set of record arrays for all its cases: the solution it hands to case_done
    # must be a copy even when it is long (only a single run's own records may be taken).
    from impactbeam.solver.batch import integrate_batch

    monkeypatch.setattr(engine, "_TAKE", 64)
    base = _case3().with_values({
        "excitation.shape": "random", "excitation.amplitude": None, "excitation.duration": None,
        "excitation.psd": [["10 Hz", "0.05 g^2/Hz"], ["500 Hz", "0.05 g^2/Hz"]], "solver.end_time": 0.07,
    })
    scs = [base.with_values({"excitation.seed": seed}) for seed in (21, 22)]
    kept = []
    with kernels.forced("compiled"):
        integrate_batch(base.beam, [s.contactors for s in scs], base.damping, [s.excitation for s in scs],
                        base.initial, [s.solver for s in scs], point=base.beam.length, sign=1.0,
                        case_done=lambda j, sol: kept.append(sol))
        alone = ib.simulate(scs[0]).solution
    assert kept[0].t0.size > 64
    for u, v in zip(_records(alone), _records(kept[0])):
        np.testing.assert_array_equal(u, v)


def test_a_system_is_checked_once_and_a_refusal_every_time(monkeypatch):
    # simulate checks what the model cannot represent (_check_system) and remembers a system that passed:
    # the second run of one scenario does not check again, gives the same bits, and a new excitation object
    # (held by a weak reference only) is checked afresh; a refused system is refused on every call.
    from impactbeam import simulation

    calls = []
    real = simulation._check_system
    monkeypatch.setattr(simulation, "_check_system", lambda *a: calls.append(a) or real(*a))
    monkeypatch.setattr(simulation, "_CHECKED", type(simulation._CHECKED)())
    sc = _case3().with_values({"solver.end_time": 0.05})
    first = ib.simulate(sc).metrics()
    second = ib.simulate(sc).metrics()
    assert len(calls) == 1 and first == second
    ib.simulate(dataclasses.replace(sc, excitation=dataclasses.replace(sc.excitation)))
    assert len(calls) == 2
    for expected in (3, 4):  # an output point off the 0.1092 m beam
        with pytest.raises(ib.ParameterError, match="output.points"):
            ib.simulate_system(sc.beam, sc.contactors, excitation=sc.excitation, options=sc.solver, points=[1.0])
        assert len(calls) == expected


_LEAK_CHECK = """
import numpy as np
import impactbeam as ib
from numba.core.runtime import rtsys
from impactbeam.solver import kernels

def every_entry_point():
    res = ib.simulate(ib.load_scenario({case3!r}))     # the event loop
    sol = res.solution
    res.metrics()                                       # the compiled metrics
    sol.sample(np.array([0.05, 0.1]), np.linspace(0.0, 0.2, 50))
    sol.extrema([(0.05, 0.0, 0.2, 1.0, 0.0, None), (0.1, 0.01, 0.1, -1.0, 0.0, None)])
    sol.integrals([(0.05, 0.0, 0.2)])

with kernels.forced("compiled"):
    every_entry_point()
    live = []
    for _ in range(3):
        for _ in range(20):
            every_entry_point()
        s = rtsys.get_allocation_stats()
        live.append(s.alloc - s.free)
print(live)
"""


def test_the_compiled_kernels_free_every_array_they_make():
    # a kernel compiled without reference counting never frees an array it makes (or that a callee returns):
    # the record extremes leaked 8.6 kB a call that way (a bifurcation map: hundreds of MB). numba's own count
    # of its live allocations must not grow over repeated calls of every entry point.
    import ast
    import os
    import subprocess
    import sys

    case3 = str(Path(__file__).resolve().parents[1] / "examples" / "case03.toml")
    env = {**os.environ, "NUMBA_NRT_STATS": "1"}
    proc = subprocess.run([sys.executable, "-c", _LEAK_CHECK.format(case3=case3)], capture_output=True, text=True,
                          env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr[-2000:]
    live = ast.literal_eval(proc.stdout.strip().splitlines()[-1])
    assert live[0] == live[1] == live[2], live
