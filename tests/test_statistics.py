"""Statistics of a run: rainflow, S-N and Miner, Dirlik, impacts from the exact events, sweeps and ensembles.

Independent values: ASTM E1049's published rainflow counts; a harmonic
steady state whose stress is an exact sinusoid (Miner's damage of k cycles
of amplitude S is k / N(S), S found by scipy's optimiser on the stress);
Dirlik's closed form against FLife's implementation; impact statistics
against the contact force sampled on a fine grid; Rice's crossing rate from
the exact modes; ensembles against their members run alone.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from click.testing import CliRunner

import impactbeam as ib
from impactbeam.cli import main
from impactbeam.model.fatigue import FatigueSpec
from impactbeam.statistics import (
    cycles_to_failure,
    dirlik_damage_rate,
    fatigue_statistics,
    impact_statistics,
    miner_damage,
    rainflow_cycles,
    spectral_moments,
)
from impactbeam.statistics.record import case_record
from random_cases import LinearReference, linear_data

SPEC = FatigueSpec(points=(0.0,), sn_stress=20e6, sn_cycles=1e6, sn_exponent=8.0)


def test_rainflow_counts_of_astm_e1049_example():
    # ASTM E1049-85 (reapproved 2017), section 5.4.4, Fig. 6: the load sequence -2, 1, -3, 5, -1, 3,
    # -4, 4, -2 counts ranges 3: 0.5, 4: 1.5, 6: 0.5, 8: 1.0, 9: 0.5 (its table of rainflow counts)
    rng, _, count = rainflow_cycles([-2, 1, -3, 5, -1, 3, -4, 4, -2])
    got: dict[float, float] = {}
    for r, c in zip(rng, count):
        got[float(r)] = got.get(float(r), 0.0) + float(c)
    assert got == {3.0: 0.5, 4.0: 1.5, 6.0: 0.5, 8.0: 1.0, 9.0: 0.5}


def test_rainflow_of_a_monotone_record_is_one_half_cycle():
    # ASTM E1049-85 5.4.4: the ranges left at the end count one half each; a point inside the ramp changes nothing
    for series in ([0.0, 5.0], [0.0, 2.0, 5.0], [5.0, 0.0]):
        rng, mean, count = rainflow_cycles(series)
        assert (rng.tolist(), mean.tolist(), count.tolist()) == ([5.0], [2.5], [0.5])
    assert all(a.size == 0 for a in rainflow_cycles([1.0, 1.0]))


def test_basquin_endurance_and_goodman_by_hand():
    spec = FatigueSpec(points=(0.0,), sn_stress=100e6, sn_cycles=1e6, sn_exponent=5.0, endurance_limit=40e6,
                       mean_stress="goodman", ultimate_strength=400e6)
    n = cycles_to_failure(np.array([100e6, 50e6, 50e6, 30e6, 30e6, 10e6]),
                          np.array([0.0, 0.0, 200e6, 200e6, -100e6, 500e6]), spec)
    assert n[0] == pytest.approx(1e6, rel=1e-15)
    assert n[1] == pytest.approx(1e6 * 2.0**5, rel=1e-14)
    assert n[2] == pytest.approx(1e6, rel=1e-14)  # Goodman: 50 / (1 - 200/400) = 100 MPa
    assert n[3] == pytest.approx(1e6 * (100 / 60) ** 5, rel=1e-14)  # 30 -> 60 MPa, above the limit
    assert math.isinf(n[4])  # compressive mean: no credit, no penalty; 30 MPa below the 40 MPa limit
    assert n[5] == 0.0  # mean above the ultimate strength
    damage, cyc = miner_damage([0.0, 100e6, -100e6, 100e6, -100e6, 0.0], spec)
    assert damage == pytest.approx(cyc["count"][0] / 1e6 * 0 + np.sum(cyc["count"] / cyc["cycles_to_failure"]))


def _harmonic_scenario() -> ib.Scenario:
    return ib.parse_scenario({
        "beam": linear_data()["beam"],
        "damping": {"free": 0.02, "contact": 0.02},
        "excitation": {"kind": "base_acceleration", "shape": "harmonic", "frequency": "40 Hz", "amplitude": "3 g"},
        "solver": {"modes": 4, "end_time": 0.3},
        "fatigue": {"points": [0.0, 0.03], "sn_stress": "2 MPa", "sn_cycles": 1e5, "sn_exponent": 8},
    })


def test_a_mean_stress_beyond_the_ultimate_strength_is_warned():
    # Goodman with ultimate_strength = 1 Pa: every tensile-mean cycle breaks the part at once, the damage is
    # infinite, which JSON shows as null (it read as "not applicable") next to a life of 0, without a word
    sc = _harmonic_scenario().with_values({"fatigue.mean_stress": "goodman", "fatigue.ultimate_strength": 1.0})
    with pytest.warns(ib.ImpactBeamWarning, match=r"fatigue: at x = 0 m, \d+ cycle\(s\) have a mean stress at or "
                      "above fatigue.ultimate_strength"):
        fat = fatigue_statistics(ib.simulate(sc))
    assert math.isinf(fat[0]["damage"]) and fat[0]["life"] == 0.0


def test_harmonic_miner_damage_is_f_over_n():
    """No contact, the exact harmonic steady state: k cycles of amplitude S give D = k / N(S)."""
    from scipy.optimize import minimize_scalar

    from impactbeam.periodic.frf import linear_steady_state

    sc = _harmonic_scenario()
    res = ib.simulate(sc, start=linear_steady_state(sc))
    f, k = 40.0, 8
    for x in sc.fatigue.points:
        t = np.linspace(0.0, 1.0 / f, 401)
        s = res.bending_stress([x], t)[0]
        i = int(np.argmax(np.abs(s)))
        opt = minimize_scalar(lambda tt: -abs(res.bending_stress([x], [tt])[0, 0]),
                              bounds=(t[max(i - 1, 0)], t[i + 1]), method="bounded", options={"xatol": 1e-13})
        tp, amp = float(opt.x), -float(opt.fun)
        out = fatigue_statistics(res, sc.fatigue, window=(tp, tp + k / f))
        row = out[[p["point"] for p in out].index(x)]
        n_s = 1e5 * (amp / 2e6) ** -8
        # tolerance 1e-9: the turning points are exact to ~1e-12 relative, raised to the power m = 8
        assert row["cycles"] == pytest.approx(k, abs=1e-12)
        assert row["damage"] == pytest.approx(k / n_s, rel=1e-9)
        assert row["damage_rate"] == pytest.approx(f / n_s, rel=1e-9)
        assert row["life"] == pytest.approx(n_s / f, rel=1e-9)
        # from the peak over 0.4 period the stress falls monotonically to amp cos(0.8 pi): the window's two
        # ends are its only turning points, one half cycle (ASTM E1049-85 5.4.4; none before the fix)
        row = fatigue_statistics(res, sc.fatigue, window=(tp, tp + 0.4 / f))[sc.fatigue.points.index(x)]
        half = 0.5 * amp * (1.0 - math.cos(0.8 * math.pi))
        assert row["cycles"] == 0.5
        assert row["damage"] == pytest.approx(0.5 / (1e5 * (half / 2e6) ** -8), rel=1e-9)



def test_fatigue_reports_its_progress_and_the_chunks_change_nothing(monkeypatch):
    """The stress scan and the refinement report their progress (a 100 s record takes seconds per point);
    the chunks the stress is sampled in (here 97 samples instead of 65,536) change no number."""
    import impactbeam.statistics.fatigue as fatigue_module
    from impactbeam.statistics import run_statistics, statistics_stages

    sc = _harmonic_scenario()
    whole = fatigue_statistics(ib.simulate(sc), sc.fatigue)
    monkeypatch.setattr(fatigue_module, "_CHUNK", 97)
    res = ib.simulate(sc)
    seen: list[float] = []
    out = run_statistics(res, seen.append)
    assert out["fatigue"] == whole
    assert statistics_stages(res) == 3  # the impacts and two fatigue points
    assert len(seen) > 40 and seen[-1] == 3.0
    assert all(b >= a for a, b in zip(seen, seen[1:]))  # it only moves forward

def test_dirlik_against_flife():
    """Our closed form of Dirlik's damage against FLife's implementation on the same density."""
    flife = pytest.importorskip("FLife")
    f = np.linspace(0.0, 500.0, 5001)
    g = 1e12 * (np.exp(-((f - 60.0) / 8.0) ** 2) + 0.3 * np.exp(-((f - 350.0) / 20.0) ** 2))  # Pa^2/Hz
    m = spectral_moments(f, g)
    ours = dirlik_damage_rate(m, sn_stress=20e6, sn_cycles=1e6, sn_exponent=6.0)
    sd = flife.SpectralData(input={"PSD": g, "f": f})
    life = flife.Dirlik(sd).get_life(C=1e6 * (20e6) ** 6, k=6.0)
    # tolerance 1e-6: both use the same closed form; the moments are trapezoid sums on one grid
    assert ours == pytest.approx(1.0 / life, rel=1e-6)


def test_impact_statistics_of_a_transient_against_the_sampled_force(scenario_file):
    import specimen

    text = specimen.BEAM + specimen.CONTACTOR + """
[damping]
free = 0.011
contact = 0.02
[excitation]
kind = "base_acceleration"
shape = "half_sine"
amplitude = "15 g"
duration = "15 ms"
[solver]
modes = 8
time_step = 1e-6
end_time = 0.2
"""
    sc = ib.load_scenario(scenario_file(text))
    res = ib.simulate(sc)
    st = impact_statistics(res)
    c0 = st.contactors[0]
    m = res.metrics()
    assert st.window == (0.0, 0.2)
    assert c0["n_impacts"] == m["n_impacts"] and c0["rate"] == pytest.approx(m["n_impacts"] / 0.2, rel=1e-15)
    assert c0["peak_force_max"] == max(r["peak_force"] for r in m["impacts"])
    # the contact force sampled every microsecond (independent of the quadrature): tolerance 1e-4,
    # the trapezoid rule's error on 1 us steps at the contact's kinks
    F = res.contact_force[:, 0]
    dt = res.time_step
    assert c0["force_rms"] == pytest.approx(math.sqrt(np.trapezoid(F**2, dx=dt) / 0.2), rel=1e-4)
    assert c0["force_mean"] == pytest.approx(np.trapezoid(F, dx=dt) / 0.2, rel=1e-4)
    assert c0["contact_fraction"] == pytest.approx(np.mean(res.engaged[:, 0]), abs=2e-5)
    # the JSON of simulate: the statistics and the table
    out = CliRunner().invoke(main, ["simulate", str(sc.source), "--json"], catch_exceptions=False)
    data = json.loads(out.stdout)
    assert data["impact_statistics"][0]["rate"] == c0["rate"] and "fatigue" not in data
    out = CliRunner().invoke(main, ["simulate", str(sc.source)], catch_exceptions=False)
    assert "impacts per second" in out.stdout


def test_simulate_json_has_fatigue_with_a_fatigue_table(scenario_file):
    sc = _harmonic_scenario()
    path = scenario_file(sc.to_toml())
    out = CliRunner().invoke(main, ["simulate", str(path), "--json"], catch_exceptions=False)
    data = json.loads(out.stdout)
    assert [p["point"] for p in data["fatigue"]] == [0.0, 0.03]
    assert all(p["damage_rate"] > 0 and p["life"] == pytest.approx(1 / p["damage_rate"]) for p in data["fatigue"])


def test_ensemble_members_repeat_alone_and_sweeps_store_statistics(tmp_path):
    """A member of an ensemble is the scenario with its stream: the same bits when run alone."""
    data = linear_data(end_time=3.0)
    data["contactors"] = [{"position": 0.1092, "stiffness": 4030, "gap": "0.4 mm", "side": "below"}]
    data["fatigue"] = {"points": [0.0], "sn_stress": "2 MPa", "sn_cycles": 1e5, "sn_exponent": 8}
    sc = ib.parse_scenario(data)
    ens = ib.random_response(sc, seeds=2, workers=0, out=tmp_path / "ens")
    alone = case_record(ib.simulate(sc.with_values({"excitation.stream": 1})))
    ds = ens.dataset.sel({"excitation.stream": 1})
    for name, value in alone.items():
        assert np.array_equal(np.asarray(ds[name].values), np.asarray(value), equal_nan=True), name
    d = ens.to_dict()
    for key in ("seeds", "duration", "points", "rms", "rms_ci", "rms_velocity", "impacts", "fatigue"):
        assert key in d
    assert set(d["impacts"][0]) >= {"rate", "rate_ci", "force_rms", "peak_force_mean", "peak_force_max",
                                     "contact_fraction", "duration_mean", "impulse_mean"}
    assert set(d["fatigue"][0]) >= {"damage_rate", "damage_rate_ci", "life"}
    # the rate is the mean of the members' rates, its interval brackets it
    rates = np.asarray(ens.dataset["impact_rate"].values)[:, 0]
    assert d["impacts"][0]["rate"] == pytest.approx(np.mean(rates), rel=1e-15)
    assert d["impacts"][0]["rate_ci"][0] <= d["impacts"][0]["rate"] <= d["impacts"][0]["rate_ci"][1]
    # resumed from its store: nothing recomputed, the same numbers
    again = ib.random_response(sc, seeds=2, workers=0, out=tmp_path / "ens")
    assert again.to_dict() == d


def test_members_warnings_survive_a_resumed_ensemble(tmp_path):
    # Each member of a 0.2 s ensemble warns that its statistics include the start from rest. The warnings
    # were those issued in the process: a resumed ensemble, whose members come from the store, had none
    # (and rewrote its summary without them). They are stored with each member now, and counted.
    sc = ib.parse_scenario(linear_data(end_time=0.2))
    first = ib.random_response(sc, seeds=2, workers=0, out=tmp_path / "ens")
    mine = [w for w in first.warnings if w.startswith("2 of 2 members: statistics: the run lasts")]
    assert len(mine) == 1 and "start from rest" in mine[0]
    assert list(first.dataset["warnings"].values) == [mine[0].split("members: ", 1)[1]] * 2
    again = ib.random_response(sc, seeds=2, workers=0, out=tmp_path / "ens")
    assert again.warnings == first.warnings


def test_bad_ensemble_input_exits_2(scenario_file):
    path = scenario_file(ib.parse_scenario(linear_data(end_time=1.0)).to_toml())
    for args, key in ((["--seeds", "0"], "--seeds"), (["--seeds", "2", "--workers", "-1"], "--workers")):
        out = CliRunner().invoke(main, ["random", str(path), *args], catch_exceptions=False)
        assert out.exit_code == 2 and out.stderr.startswith(f"error: {key}")
    harmonic = scenario_file(_harmonic_scenario().to_toml(), "h.toml")
    out = CliRunner().invoke(main, ["random", str(harmonic), "--seeds", "2"], catch_exceptions=False)
    assert out.exit_code == 2 and out.stderr.startswith("error: excitation.shape:")


@pytest.mark.slow
def test_impact_rate_of_a_very_soft_far_stop_is_rices_rate():
    """A stop of 1e-3 N/m (3e-5 of 3 EI/L^3) at 1.5 sigma below the tip changes nothing: each impact is a
    down-crossing of -b, so the impact rate is Rice's nu_0 exp(-b^2 / 2 sigma^2) of the linear tip motion
    (sigma, sigma_v from the exact modes). Checked against the ensemble's 99 % interval (4 seeds of 40 s,
    ~720 impacts each; measured spread of the seeds 1 %)."""
    from impactbeam.statistics import rice_rate

    base = ib.parse_scenario(linear_data(end_time=40.0, points=(0.1092,)))
    ref = LinearReference(base)
    sigma, sigma_v = np.sqrt(ref.variance()[0]), np.sqrt(ref.variance(True)[0])
    b = 1.5 * sigma
    data = linear_data(end_time=40.0, points=(0.1092,))
    data["contactors"] = [{"position": 0.1092, "stiffness": 1e-3, "gap": b, "side": "below"}]
    ens = ib.random_response(ib.parse_scenario(data), seeds=4, workers=0, confidence=0.99)
    imp = ens.impacts[0]
    nu = rice_rate(b, sigma, sigma_v)
    assert imp["rate_ci"][0] <= nu <= imp["rate_ci"][1]
    assert imp["rate"] == pytest.approx(nu, rel=0.03)


@pytest.mark.slow
@pytest.mark.dask
def test_same_seed_same_bits_on_one_or_four_workers():
    data = linear_data(end_time=3.0)
    data["contactors"] = [{"position": 0.1092, "stiffness": 4030, "gap": "0.4 mm", "side": "below"}]
    sc = ib.parse_scenario(data)
    one = ib.random_response(sc, seeds=4, workers=1)
    four = ib.random_response(sc, seeds=4, workers=4)
    for name in one.dataset.data_vars:
        assert np.array_equal(one.dataset[name].values, four.dataset[name].values,
                              equal_nan=name != "message"), name
    assert one.to_dict() == four.to_dict()


def test_sweep_over_gap_and_level_stores_the_statistics():
    """The impact-rate-vs-clearance curve: a sweep of gaps and load levels (excitation.scale: the density
    times its square) stores each case's statistics, equal to those of the case run alone."""
    data = linear_data(end_time=2.5)
    data["contactors"] = [{"position": 0.1092, "stiffness": 4030, "gap": "0.4 mm", "side": "below"}]
    base = ib.parse_scenario(data)
    spec = {"base": base.data, "parameters": {"contactors.0.gap": {"values": ["0.3 mm", "0.6 mm"]},
                                              "excitation.scale": {"values": [1.0, 2.0]}},
            "outputs": {"metrics": ["n_impacts"], "statistics": True}}
    ds = ib.sweep(spec, workers=0, progress=False)
    assert ds["impact_rate"].dims == ("contactors.0.gap", "excitation.scale", "contactor")
    assert ds["impact_rate"].attrs["units"] == "1/s" and ds["rms"].dims[-1] == "output_point"
    case = base.with_values({"contactors.0.gap": "0.6 mm", "excitation.scale": 2.0})
    alone = impact_statistics(ib.simulate(case)).contactors[0]
    got = ds["impact_rate"].sel({"contactors.0.gap": 0.6e-3, "excitation.scale": 2.0}).values[0]
    assert got == alone["rate"]
    rates = ds["impact_rate"].values[..., 0]
    assert rates[0, 1] > rates[1, 1] and rates[1, 1] > rates[1, 0]  # closer or harder: more impacts
    # the statistics' count of impacts begun in the window is its own variable: it had replaced the Table-2
    # n_impacts (every impact of the run) under the same name
    at = {"contactors.0.gap": 0.6e-3, "excitation.scale": 2.0}
    assert int(ds["n_impacts"].sel(at).values) == ib.simulate(case).metrics(impacts=False)["n_impacts"]
    assert int(ds["window_impacts"].sel(at).values[0]) == alone["n_impacts"]
    assert ds["n_impacts"].dims == ("contactors.0.gap", "excitation.scale")


def test_random_figures(tmp_path):
    pytest.importorskip("matplotlib")
    from impactbeam.plot.random import plot_input_psd, plot_random

    data = linear_data(end_time=3.0, points=(0.1092,))
    data["contactors"] = [{"position": 0.1092, "stiffness": 4030, "gap": "0.4 mm", "side": "below"}]
    res = ib.simulate(ib.parse_scenario(data))
    h = plot_random(res, path=tmp_path / "random.png", dpi=80)
    assert len(h.axes) == 4 and (tmp_path / "random.png").stat().st_size > 10_000
    assert [ax.get_xlabel() for ax in h.axes] == ["frequency [Hz]", "frequency [Hz]", "peak impact force [N]",
                                                  "stress range at x = 0 mm [MPa]"]
    with pytest.raises(ib.ParameterError, match="random"):
        plot_input_psd(_harmonic_scenario().excitation)


_PULLED = {  # the paper's basis, 10 modes: a stiff dashpot stop whose contacts the projection leaves pulling
    "beam": {"length": 0.1092, "width": 0.00993, "height": 0.00303, "youngs_modulus": 1834e6, "density": 951.98,
             "theory": "timoshenko", "poisson_ratio": 0.35},
    "supports": {"left": {"translational": "inf", "rotational": 50.0}, "right": "free"},
    "contactors": [{"position_ratio": 0.517, "stiffness": 419.389, "gap": 1e-05, "side": "below"},
                   {"position_ratio": 0.835, "stiffness": 422151.12, "gap": 5e-05, "side": "below",
                    "damping": 1.03784}],
    "damping": {"free": 0.3, "contact": 0.05},
    "excitation": {"kind": "distributed_force", "shape": "half_sine", "amplitude": 1.0, "duration": 0.005},
    "initial": {"velocity": -0.2},
    "solver": {"modes": 10, "end_time": 0.02, "basis": "paper"}}


def test_impulses_never_pull_and_follow_the_state_jumps_of_per_state_modes():
    # Found by a random hunt (statistics against a dense quadrature of the force): with per-state modes the
    # projection of eq. (12) can leave a struck stop on the wrong side, and every switch moves the state. The
    # impulse k int d dt + c [d] then counted pulls (the table's impulses of this stop down to -3.8e-4 N s,
    # force_mean -0.040 N where the force never pulls) and a dashpot's share across other switches. Against
    # Simpson's rule on 400,001 points of max(k d + c d', 0) per contact: measured 1.3e-16 N s; the tolerance
    # is a bound of that rule's error at a kink of the force (slope ~1 N / 10 us, step ~5e-10 s: 1e-13 N s),
    # with room.
    from scipy.integrate import simpson

    with pytest.warns(ib.ImpactBeamWarning):  # the projection's warning, which is the point here
        res = ib.simulate(ib.parse_scenario(_PULLED))
    c, ci = res.contactors[1], 1
    dash = float(res.solution.dashpots[ci])
    rows = [r for r in res.metrics()["impacts"] if r["contactor"] == ci]
    assert rows and all(r["impulse"] >= 0.0 for r in rows)
    dense = []
    for r in rows:
        t = np.linspace(r["start"], np.nextafter(r["end"], -np.inf), 400_001)  # the end from the left
        F = np.asarray(c.force(res.displacement([c.position], t)[0], res.velocity([c.position], t)[0], dash))
        dense.append(simpson(F, x=t))
    assert np.max(np.abs(np.array([r["impulse"] for r in rows]) - dense)) < 1e-10
    stats = impact_statistics(res).contactors[ci]
    T = float(res.solution.t_end)
    assert stats["force_mean"] == pytest.approx(sum(dense) / T, rel=1e-6)  # measured 1.7e-9; the old code -0.040 N


def test_time_averages_of_an_over_damped_beam_against_the_closed_form():
    """Mean squares of w and w_t when every mode is over-damped (xi = 3), against their closed form.

    A step of base acceleration A from rest: mode n is eta_n = (p_n A / omega_n^2) (1 - (r2 e^{-r1 t} - r1
    e^{-r2 t}) / (r2 - r1)), r1,2 = omega_n (xi -+ sqrt(xi^2 - 1)), p_n = -int rho A W_n dx (exact modes: the
    paper's basis without contactors is the exact modes), so w and w_t are sums of exponentials whose squares
    integrate in closed form. One mode: its fast rate r2 = 5.8 omega_1 dies within a sixth of its period; on
    the uniform grid of 4 samples per period the mean square of w_t was 17 % off (of w 0.9 %). Tolerance 2e-3:
    the graded grid's trapezoid error on the transients (result.timegrid, ~1.5e-3 of their own integral;
    measured 5.5e-4 and 1.2e-4).
    """
    from impactbeam.statistics import response_statistics

    xi, A, T = 3.0, 9.81, 0.02
    sc = ib.parse_scenario({
        "beam": linear_data()["beam"], "damping": {"free": xi, "contact": xi},
        "excitation": {"kind": "base_acceleration", "shape": "step", "amplitude": A},
        "solver": {"modes": 1, "end_time": T, "basis": "paper"}, "output": {"points": [0.05, 0.1092]},
    })
    stats = response_statistics(ib.simulate(sc))
    ms = ib.mode_set(sc.beam, (), 1)
    om, W, p = ms.omega, ms.shapes(sc.output_points), -np.asarray(ms.inertia_integral())
    r1, r2 = om * (xi - math.sqrt(xi**2 - 1)), om * (xi + math.sqrt(xi**2 - 1))
    s = p * A / om**2  # static amplitudes
    # w = sum_n W_n s_n (1 + a_n e^{-r1 t} + b_n e^{-r2 t}); w_t = sum_n W_n s_n (-r1 a_n e^{-r1 t} - r2 b_n e^{-r2 t})
    a, b = -r2 / (r2 - r1), r1 / (r2 - r1)
    rates = np.concatenate([[0.0], r1, r2])

    def mean_square(coef: np.ndarray) -> np.ndarray:  # (1/T) int (sum_k c_k e^{-rates_k t})^2 dt, per point
        lam = rates[:, None] + rates[None, :]
        with np.errstate(divide="ignore", invalid="ignore"):
            integral = np.where(lam > 0, -np.expm1(-lam * T) / np.where(lam > 0, lam, 1.0), T)
        return np.einsum("kp,kl,lp->p", coef, integral, coef) / T

    Ws = W * s[:, None]  # (n, points)
    w_coef = np.vstack([Ws.sum(axis=0, keepdims=True), a[:, None] * Ws, b[:, None] * Ws])
    v_coef = np.vstack([np.zeros((1, W.shape[1])), -(r1 * a)[:, None] * Ws, -(r2 * b)[:, None] * Ws])
    assert np.asarray(stats["mean_square"]) == pytest.approx(mean_square(w_coef), rel=2e-3)
    assert np.asarray(stats["velocity_mean_square"]) == pytest.approx(mean_square(v_coef), rel=2e-3)


def test_an_ensembles_progress_says_ensemble(capsys):
    # the progress of `impactbeam random` was labelled "sweep" (the ensemble runs as a sweep over the stream)
    sc = ib.parse_scenario(linear_data(end_time=0.2))
    with pytest.warns(ib.ImpactBeamWarning):  # a 0.2 s record: its statistics include the start from rest
        ib.random_response(sc, seeds=2, workers=0, progress=True)
    err = capsys.readouterr().err
    assert "ensemble" in err and "sweep" not in err, err
