"""Events that cannot be missed: adversarial timing, tangency at t = 0, output-step independence.

Issue 10, item 4. The scan advances by steps that a bound on the opening's
second derivative proves free of crossings (solver/_events.py), so these
must hold exactly, whatever the output step:

* a grazing dip 1e-12 m deep into the stop is an impact;
* two crossings closer together than any output step are both found;
* two contactors hit at the same instant (a symmetric beam) both switch;
* a zero-gap contactor with the load toward it is in contact from t = 0 for
  any number of modes (the tangency is judged from the first derivative
  that is not round-off, not from the sign of round-off).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import impactbeam as ib
from impactbeam.model.beam import Beam, Contactor
from impactbeam.model.loading import Excitation
from impactbeam.model.starting import InitialCondition
from impactbeam.model import Damping, SolverOptions

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _pinned(L: float = 1.0) -> Beam:
    return Beam.rectangular(L, 0.02, 0.01, 2.1e11, 7850.0, "pinned", "pinned")


def test_grazing_dip_of_1e_12_m_is_an_impact():
    # one undamped mode released from eta0: w(a, t) = eta0 W(a) cos(w t); the stop
    # below sits 1e-12 m above the lowest point, reached at t = pi / w
    # (beam length 0.5 m: the touch tolerance 1e-12 L is 5e-13 m, below the dip)
    beam = _pinned(0.5)
    ms = ib.mode_set(beam, (), 1)
    a = 0.37 * beam.length
    Wa = float(ms.shapes([a])[0, 0])
    eta0 = 2e-3 / Wa
    gap = 2e-3 - 1e-12
    c = Contactor(a, 1e3, gap, "below")
    res = ib.simulate_system(
        beam, [c], initial=InitialCondition(modal_displacement=(eta0,)),
        options=SolverOptions(modes=1, time_step=1e-3, end_time=0.9 * 2 * math.pi / ms.omega[0]),
    )
    t_low = math.pi / ms.omega[0]
    kinds = [e.kind for e in res.events]
    assert kinds[:2] == ["impact", "rebound"]
    # the dip is 1e-12 deep: the chord lasts 2 sqrt(2 depth / (w^2 A)) around t_low
    half = math.sqrt(2e-12 / (ms.omega[0] ** 2 * 2e-3))
    assert abs(res.events[0].time - t_low) <= 2 * half
    assert res.events[1].time - res.events[0].time <= 4 * half


def test_two_crossings_inside_one_output_step():
    # a fast second mode on a slow first one: the opening dips below zero and back
    # within 1e-5 s, while the output step is 1e-2 s; both crossings must be found
    beam = _pinned()
    ms = ib.mode_set(beam, (), 3)
    a = 0.5
    W = ms.shapes([a])[:, 0]
    # mode 1 at its lowest at t=0 going up slowly; mode 3 (symmetric) adds a ripple
    eta = np.array([-1e-3 / W[0], 0.0, -2e-6 / W[2]])
    gap = 1e-3 + 1.5e-6
    res = ib.simulate_system(
        beam, [Contactor(a, 1.0, gap, "below")], initial=InitialCondition(modal_displacement=tuple(eta)),
        damping=Damping(0.0, 0.0), options=SolverOptions(modes=3, time_step=1e-2, end_time=2e-2),
    )
    impacts = [e for e in res.events if e.kind == "impact"]
    assert len(impacts) >= 1
    first_gap = res.events[1].time - res.events[0].time
    assert 0 < first_gap < 1e-2


def test_simultaneous_impacts_at_two_contactors():
    # a pinned-pinned beam under a uniform load, stops at L/4 and 3L/4: by symmetry
    # both are reached at the same instant, and both must engage
    beam = _pinned()
    cs = [Contactor(0.25, 1e4, 1e-6, "below"), Contactor(0.75, 1e4, 1e-6, "below")]
    exc = Excitation(kind="distributed_force", shape="step", amplitude=-200.0)
    res = ib.simulate_system(beam, cs, excitation=exc, options=SolverOptions(modes=8, time_step=1e-4,
                                                                             end_time=0.02))
    first = {e.contactor: e.time for e in res.events if e.kind == "impact"}
    assert set(first) == {0, 1}
    assert abs(first[0] - first[1]) <= 1e-9  # the same instant, up to the symmetry's round-off


@pytest.mark.parametrize("modes", [8, 12, 16, 24, 32])
def test_zero_gap_load_toward_the_stop_contacts_from_t0(modes):
    sc = ib.load_scenario(EXAMPLES / "case09.toml")
    sc = sc.with_values({"excitation.amplitude": "-15 g", "solver.modes": modes})
    res = ib.simulate(sc)
    assert res.events[0].time == 0.0 and res.events[0].kind == "impact"
    m = res.metrics()
    assert m["first_impact_time"] == 0.0
    # the penetration converges with the modes (8 -> 32: 0.14040 mm within 1e-5 relative)
    assert m["max_penetration"] == pytest.approx(1.40401e-4, rel=1e-4)


@pytest.mark.parametrize("dt", [1e-6, 1e-5, 1e-3])
def test_metrics_equal_at_every_output_step(dt):
    # 1e-9 relative asked; they are identical since neither scan nor metrics read the grid
    sc = ib.load_scenario(EXAMPLES / "case03.toml")
    ref = ib.simulate(sc).metrics()
    got = ib.simulate(sc.with_values({"solver.time_step": dt})).metrics()
    for key in ("max_response", "t_max", "first_impact_time", "free_duration", "contact_duration",
                "min_response", "max_penetration", "n_impacts"):
        assert got[key] == pytest.approx(ref[key], rel=1e-9, abs=0.0), key


def test_auto_modes_converge_and_report_the_change():
    sc = ib.load_scenario(EXAMPLES / "case03.toml").with_values({"solver.modes": "auto", "solver.tolerance": 1e-3})
    res = ib.simulate(sc)
    assert res.n_modes in (8, 12, 16) and res.converged
    assert max(res.convergence.values()) < 1e-3
    # a fixed count is compared with a smaller one on request
    fixed = ib.simulate(sc.with_values({"solver.modes": 8}))
    assert set(fixed.convergence) == set(res.convergence) and fixed.converged


def test_unconverged_fixed_count_warns():
    # two modes cannot resolve the contact state of Case 3 to 1e-6
    sc = ib.load_scenario(EXAMPLES / "case03.toml").with_values({"solver.modes": 2, "solver.tolerance": 1e-6})
    res = ib.simulate(sc)
    with pytest.warns(ib.ImpactBeamWarning, match="not converged in the number of modes"):
        assert not res.converged
    assert any("not converged" in w for w in res.warnings)


@pytest.mark.parametrize("value, match", [("many", "solver.modes"), (0, "solver.modes"), (1.5, "solver.tolerance")])
def test_bad_auto_settings(value, match):
    key = "solver.tolerance" if match == "solver.tolerance" else "solver.modes"
    with pytest.raises(ib.ParameterError, match=match):
        ib.load_scenario(EXAMPLES / "case03.toml").with_values({key: value})


def _ringing(gap: float, damping: Damping, load: Excitation | None = None):
    """Six modes of a pinned beam released from a mixed state, a stop below at 0.37 L."""
    beam = _pinned()
    ms = ib.mode_set(beam, (), 6)
    a = 0.37
    W = ms.shapes([a])[:, 0]
    eta = np.array([1.0, -0.4, 0.3, 0.2, -0.1, 0.05]) * 1e-3
    deta = np.array([0.5, 0.3, -0.2, 0.4, 0.1, -0.3]) * 1e-3 * ms.omega
    res = ib.simulate_system(
        beam, [Contactor(a, 1e5, gap, "below")], damping=damping, excitation=load,
        initial=InitialCondition(modal_displacement=tuple(eta), modal_velocity=tuple(deta)),
        options=SolverOptions(modes=6, time_step=1e-3, end_time=0.5),
    )
    return res, W, eta, deta, ms.omega, a


@pytest.mark.parametrize("damped", [False, True])
def test_a_stop_out_of_reach_is_skipped_and_one_just_within_reach_is_hit(damped):
    # The scan skips a segment whose rows are proven clear to its end (each mode's
    # contribution below sqrt(v^2 + w^2 x^2) / w, its energy never growing): the
    # free run below takes no scan step at all. Just within reach, the stop must
    # still be hit: the gap is set 1e-9 m inside the lowest deflection the same
    # run reaches without contact (its exact extremes, found independently of the
    # scan by the dense output's branch-and-bound search).
    damping = Damping(free=0.02, contact=0.02) if damped else Damping(0.0, 0.0)
    load = Excitation(kind="point_force", shape="harmonic", amplitude=50.0, position=0.6, frequency=37.0)
    res, W, eta, deta, om, a = _ringing(1.0, damping)
    reach = float(np.sum(np.abs(W) * np.sqrt(deta**2 + om**2 * eta**2) / om))
    far, *_ = _ringing(1.01 * reach, damping)
    assert far.events == [] and far.solution.evaluations == 0
    for with_load in (None, load):
        free, *_ = _ringing(1.0, damping, with_load)  # a stop 1 m away: never reached
        lowest = -float(free.solution.extrema([(a, 0.0, 0.5, -1.0, 0.0, None)])[0, 0])
        assert free.events == []
        near, *_ = _ringing(-lowest - 1e-9, damping, with_load)
        assert near.events and near.events[0].kind == "impact"
        clear, *_ = _ringing(-lowest + 1e-9, damping, with_load)
        assert clear.events == []
