"""Records, identification and comparison (impactbeam.experiment; paper section 4).

Ground truth: synthetic measurements made by the simulator with known
parameters, sampled as a high-speed camera would (2 kHz) with seeded noise
(5 um rms, 0.25 % of the 2 mm release), or closed-form damped sinusoids.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import impactbeam as ib
from impactbeam import experiment as ex
from impactbeam.exceptions import ParameterError, ScenarioError

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
CLI = Path(sys.executable).with_name("impactbeam")
G = 9.80665

E_TRUE = 1900e6  # Pa; the scenario files say 1834 MPa
XI_TRUE = 0.011
FS = 2000.0  # camera frame rate [Hz]
NOISE = 5e-6  # m rms


@pytest.fixture(scope="module")
def case0() -> ib.Scenario:
    return ib.load_scenario(EXAMPLES / "case00.toml")


@pytest.fixture(scope="module")
def free_decay(case0) -> tuple[ex.Record, ib.Scenario]:
    """Release from 2 mm (Case 0) with E = 1900 MPa, 0.5 s at 2 kHz, noise 5 um."""
    truth = case0.with_values({"beam.youngs_modulus": E_TRUE, "damping.free": XI_TRUE, "solver.end_time": 0.5})
    res = ib.simulate(truth)
    t = np.arange(1000) / FS
    w = res.displacement([truth.beam.length], t)[0]
    w = w + np.random.default_rng(11).normal(0.0, NOISE, t.size)
    return ex.Record(t, w, name="deflection"), truth


def shaker_pulse(t: np.ndarray, amplitude: float = 15 * G, duration: float = 0.015, delay: float = 0.002) -> np.ndarray:
    """A distorted half-sine like the paper's Fig. 3."""
    tau = (t - delay) / duration
    a = np.zeros_like(t)
    m = (tau >= 0) & (tau <= 1)
    a[m] = amplitude * np.sin(np.pi * tau[m]) ** 1.3 * (1 + 0.18 * (0.5 - tau[m]))
    m = (tau > 1) & (tau <= 1.8)
    a[m] = -0.12 * amplitude * np.sin(np.pi * (tau[m] - 1) / 0.8)
    return a


@pytest.fixture(scope="module")
def case3_truth() -> tuple[ib.Scenario, ib.SimulationResult]:
    """Case 3 with E = 1900 MPa and k = 5200 N/m driven by a distorted pulse (x 1.1)."""
    sc = ib.load_scenario(EXAMPLES / "case03.toml").with_values(
        {"beam.youngs_modulus": E_TRUE, "contactors.0.stiffness": 5200.0, "excitation.scale": 1.1,
         "solver.end_time": 0.2}
    )
    ta = np.arange(600) / 1e4
    sc = ex.drive_with_trace(sc, ex.Record(ta, shaker_pulse(ta), name="acc", quantity="acceleration"))
    return sc, ib.simulate(sc)


# --------------------------------------------------------------------------- identification


def test_identify_f1_within_0p2_percent(free_decay):
    """f1 from the spectrum within 0.2 % (the issue's requirement; the record's
    resolution fs/N = 2 Hz is 3.4 % of f1, so this needs the peak interpolation).
    The truth is the undamped modal frequency of the simulated beam; the
    damped one differs by 6e-5 relative at 1.1 % damping."""
    rec, truth = free_decay
    f_true = ib.modes(truth).free.frequencies_hz
    est = ex.identify_frequencies(rec, 2)
    assert est.resolution_hz == pytest.approx(2.0)
    assert abs(est.frequencies_hz[0] / f_true[0] - 1) < 0.002
    # the second mode (2.5 % of the tip deflection, near the noise after ~0.1 s) is
    # found in the first quarter of the record (resolution 8 Hz = 2.2 % of f2): 1 %
    assert abs(est.frequencies_hz[1] / f_true[1] - 1) < 0.01


def test_frequencies_of_closed_form_decay_beat_resolution():
    """Two damped sinusoids (closed form, not the simulator): both frequencies to
    better than 2 % of the resolution 1/T = 4 Hz (noise-free: interpolation bias only)."""
    t = np.arange(500) / 2000.0
    f1, f2 = 61.37, 402.9
    x = np.exp(-0.01 * 2 * np.pi * f1 * t) * np.cos(2 * np.pi * f1 * t) + 0.05 * np.exp(
        -0.01 * 2 * np.pi * f2 * t
    ) * np.sin(2 * np.pi * f2 * t)
    est = ex.identify_frequencies(ex.Record(t, x), 2)
    assert np.all(np.abs(est.frequencies_hz - [f1, f2]) < 0.02 * est.resolution_hz)


def test_damping_within_0p1_points(free_decay):
    """Damping ratio by logarithmic decrement within 0.1 percentage point of the
    simulated 1.1 % (issue requirement), with a spread over cycles of the order
    of the paper's +/- 0.1 %."""
    rec, _ = free_decay
    f1 = ex.identify_frequencies(rec, 1).frequencies_hz[0]
    d = ex.damping_log_decrement(rec, f1)
    assert abs(d.damping_ratio - XI_TRUE) < 0.001
    assert abs(d.mean - XI_TRUE) < 0.001
    assert d.n_cycles >= 10
    assert 0 < d.spread < 0.005


def test_damping_of_closed_form_decay():
    """A noise-free exp(-xi w t) cos(w_d t) at 2 kHz: xi to 1e-5 absolute (the band-pass
    does not change the decay rate; peak refinement error only)."""
    xi, fn = 0.02, 73.0
    wn = 2 * np.pi * fn
    t = np.arange(1600) / 2000.0
    x = np.exp(-xi * wn * t) * np.cos(wn * math.sqrt(1 - xi**2) * t)
    d = ex.damping_log_decrement(ex.Record(t, x))
    assert d.damping_ratio == pytest.approx(xi, abs=1e-5)
    assert d.frequency_hz == pytest.approx(fn * math.sqrt(1 - xi**2), rel=1e-4)


def test_log_decrement_refuses_a_decay_over_before_its_filter_settles():
    """zeta = 0.2 at 57 Hz with 5 um of noise on 2 mm: the decay is gone (e^-14) before the band-pass filter's
    start-up is trimmed (0.17 s), and the peaks left were noise, whose "decrement" read 1.85 %. Refused now;
    the same decay at zeta = 0.02 is still measured (1e-5, the test above)."""
    wn = 2 * np.pi * 57.0
    t = np.arange(1000) / 2000.0
    clean = 2e-3 * np.exp(-0.2 * wn * t) * np.cos(wn * math.sqrt(1 - 0.04) * t)
    noisy = clean + np.random.default_rng(3).normal(0.0, 5e-6, t.size)
    with pytest.raises(ParameterError, match="fewer than two usable cycles"):
        ex.damping_log_decrement(ex.Record(t, noisy), 57.0 * math.sqrt(1 - 0.04))


def test_modulus_within_0p5_percent(free_decay, case0):
    """E from the identified f1 within 0.5 % of the true 1900 MPa (issue
    requirement; E ~ f^2, so 0.2 % in f is 0.4 % in E), and the recomputed
    modes of the tuned beam reproduce the target frequency."""
    rec, _ = free_decay
    f1 = ex.identify_frequencies(rec, 1).frequencies_hz[0]
    e = ex.modulus_from_frequency(case0, f1)
    assert abs(e / E_TRUE - 1) < 0.005
    tuned = case0.with_values({"beam.youngs_modulus": e})
    assert ib.modes(tuned).free.frequencies_hz[0] == pytest.approx(f1, rel=1e-10)


def test_modulus_with_elastic_support_is_refined(case0):
    """With a rotational spring at the root the frequency is not proportional to
    sqrt(E): the scaling guess is refined until the modes match to 1e-9."""
    sc = case0.with_values({"supports.left": {"translational": "inf", "rotational": 2.0}})
    f0 = ib.modes(sc).free.frequencies_hz[0]
    target = 1.05 * f0
    e = ex.modulus_from_frequency(sc, target)
    f_new = ib.modes(sc.with_values({"beam.youngs_modulus": e})).free.frequencies_hz[0]
    assert f_new == pytest.approx(target, rel=1e-9)
    assert e != pytest.approx(sc.beam.youngs_modulus * 1.05**2, rel=1e-4)


def test_contact_stiffness_round_trip():
    """k -> contact-state fundamental -> k (brentq on exact modes): 1e-8 relative;
    the paper's 4030 N/m on the specimen sits between the free and pinned limits."""
    sc = ib.load_scenario(EXAMPLES / "case03.toml")
    for k in (4030.0, 5200.0, 2e5):
        f = ex.contact_state_frequency(sc, k)
        assert ex.contact_stiffness_from_frequency(sc, f) == pytest.approx(k, rel=1e-8)
    f_free = ib.modes(sc).free.frequencies_hz[0]
    assert f_free < ex.contact_state_frequency(sc, 4030.0)
    with pytest.raises(ParameterError, match="outside the range"):
        ex.contact_stiffness_from_frequency(sc, 0.9 * f_free)
    with pytest.raises(ParameterError, match="no contactor"):
        ex.contact_stiffness_from_frequency(ib.load_scenario(EXAMPLES / "case12.toml"), 100.0)


def test_contact_frequency_from_record(case3_truth):
    """The contact portions of a noise-free 2 kHz record give the contact-state
    fundamental within 12 % (an approximate estimate, see the docstring: the
    second contact mode is excited too), much closer than timing the contacts
    as half cycles, which is biased high by more than 20 % (the gap preload puts
    the contact equilibrium on the free side of the surface)."""
    sc, res = case3_truth
    t = np.arange(400) / FS
    rec = ex.Record(t, res.displacement([sc.contactors[0].position], t)[0])
    cf = ex.contact_frequency_from_record(rec, sc)
    f_true = ex.contact_state_frequency(sc, 5200.0)
    assert abs(cf.frequency_hz / f_true - 1) < 0.12
    assert cf.half_period_hz > 1.2 * f_true
    assert abs(cf.frequency_hz - f_true) < 0.5 * abs(cf.half_period_hz - f_true)
    assert len(cf.intervals) >= 8


# --------------------------------------------------------------------------- driving and comparing


def test_trace_reproduces_half_sine():
    """A finely sampled (20 kHz) half-sine trace with linear hold reproduces the
    analytic half-sine response: error O(dt^2) of the interpolation, < 0.2 % of
    the peak; held constant (the paper's steps) it is O(dt), still < 2 %."""
    sc = ib.load_scenario(EXAMPLES / "case03.toml").with_values({"solver.end_time": 0.04})
    x = sc.contactors[0].position
    ref = ib.simulate(sc)
    ta = np.arange(0, 0.0150001, 5e-5)
    trace = ex.Record(ta, 15 * G * np.sin(np.pi * ta / 0.015), quantity="acceleration")
    t = np.linspace(0, 0.04, 400)
    w_ref = ref.displacement([x], t)[0]
    peak = np.max(np.abs(w_ref))
    for hold, tol in (("linear", 0.002), ("constant", 0.02)):
        res = ib.simulate(ex.drive_with_trace(sc, trace, hold=hold))
        assert np.max(np.abs(res.displacement([x], t)[0] - w_ref)) < tol * peak


def test_compare_identity(case3_truth):
    """Comparing the truth with its own noise-free samples: rms difference at
    round-off (the simulation is evaluated exactly at the samples), and the
    section-4 quantities agree to the accuracy of 2 kHz sampling: peaks by a
    parabola within 1 % (the contact peak is sharp: 8 samples per contact),
    times and durations within 0.1 ms (a fifth of the 0.5 ms frame)."""
    sc, res = case3_truth
    t = np.arange(200) / FS
    rec = ex.Record(t, res.displacement([sc.contactors[0].position], t)[0])
    cmp = ex.compare(sc, rec)
    assert cmp.rms_difference < 1e-12
    f = cmp.features
    for key in ("first_peak", "first_negative_peak"):
        assert f[key]["measured"] == pytest.approx(f[key]["simulated"], rel=0.01)
    for key in ("first_peak_time", "first_negative_peak_time", "first_contact_duration", "negative_period"):
        assert abs(f[key]["measured"] - f[key]["simulated"]) < 1e-4
    # definitions: the simulated first contact duration is the solver's (metrics) first contact after t_max
    assert f["first_contact_duration"]["simulated"] == pytest.approx(res.metrics()["contact_duration"], abs=1e-6)
    assert f["first_peak"]["simulated"] == pytest.approx(res.metrics()["max_response"], rel=1e-6)
    text = cmp.table()
    assert "first major peak" in text and "period around first negative peak" in text
    fig, ax, lines = cmp.plot()
    assert ax.get_xlabel() == "time [s]" and "[mm]" in ax.get_ylabel()
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_compare_a_window_and_a_point_off_the_contactor(case3_truth):
    """The truth's own samples from 50 ms on: the simulated features were taken from t = 0 (the first major
    peak 45 % off, its time 80 %) while the measured ones came from the window; at the tip the contact
    duration was the time the tip's deflection spent beyond the contactor's gap (5.17 ms for 4.02 ms)."""
    sc, res = case3_truth
    t = np.arange(100, 400) / FS
    x = sc.contactors[0].position
    cmp = ex.compare(sc, ex.Record(t, res.displacement([x], t)[0]))
    for key in ("first_peak", "first_negative_peak"):  # sampling at 2 kHz: 1 % (test above)
        assert cmp.features[key]["measured"] == pytest.approx(cmp.features[key]["simulated"], rel=0.01)
    for key in ("first_peak_time", "first_negative_peak_time", "first_contact_duration"):
        assert abs(cmp.features[key]["measured"] - cmp.features[key]["simulated"]) < 1e-4
    tip = sc.beam.length
    cmp = ex.compare(sc, ex.Record(t, res.displacement([tip], t)[0]), point=tip)
    assert cmp.features["first_contact_duration"] == {"simulated": None, "measured": None, "difference_percent": None}
    assert cmp.features["first_peak"]["simulated"] is not None


def test_compare_finds_amplitude_error(case3_truth):
    """A model whose pulse is 10 % weaker under-predicts the first peak by about
    10 % (linear before the first impact): -12 % < difference < -7 %."""
    sc, res = case3_truth
    t = np.arange(120) / FS
    rec = ex.Record(t, res.displacement([sc.contactors[0].position], t)[0])
    weaker = ex.drive_with_trace(
        ib.load_scenario(EXAMPLES / "case03.toml").with_values(
            {"beam.youngs_modulus": E_TRUE, "contactors.0.stiffness": 5200.0}
        ),
        ex.Record(sc.excitation.times, sc.excitation.values, quantity="acceleration"),
    )
    cmp = ex.compare(weaker, rec)
    assert -12 < cmp.features["first_peak"]["difference_percent"] < -7


# --------------------------------------------------------------------------- reading records


def test_load_csv_units_and_quantity(tmp_path):
    """Header units are applied (ms, mm, g = 9.80665 m/s^2); no units is SI."""
    p = tmp_path / "r.csv"
    p.write_text("# SYNTHETIC\ntime [ms],deflection [mm]\n" + "\n".join(f"{i * 0.5},{i * 0.1}" for i in range(10)) + "\n")
    r = ex.load_record(p)
    assert r.quantity == "deflection" and r.unit == "m"
    np.testing.assert_allclose(r.time, np.arange(10) * 0.5e-3, rtol=1e-12)
    np.testing.assert_allclose(r.values, np.arange(10) * 1e-4, rtol=1e-12)
    q = tmp_path / "a.csv"
    q.write_text("time,acceleration [g]\n" + "\n".join(f"{i * 1e-4},{1.0}" for i in range(10)) + "\n")
    a = ex.load_record(q)
    assert a.quantity == "acceleration" and a.values[0] == pytest.approx(G)
    s = tmp_path / "si.csv"
    s.write_text("time,deflection\n" + "\n".join(f"{i * 1e-3},{i}" for i in range(10)) + "\n")
    assert ex.load_record(s, value_unit="mm").values[3] == pytest.approx(3e-3)
    with pytest.raises(ScenarioError, match="remove one"):
        ex.load_record(p, value_unit="m")


def test_load_netcdf(tmp_path):
    xr = pytest.importorskip("xarray")
    t = np.arange(20) * 0.5
    ds = xr.Dataset({"deflection": ("time", np.linspace(0, 1, 20), {"units": "mm"})},
                    coords={"time": ("time", t, {"units": "ms"})})
    p = tmp_path / "r.nc"
    ds.to_netcdf(p, engine="h5netcdf")
    r = ex.load_record(p)
    assert r.step == pytest.approx(5e-4) and r.values[-1] == pytest.approx(1e-3)


def test_uneven_sampling_resampled_with_note(tmp_path):
    t = np.cumsum(np.r_[0, np.full(30, 1e-3) + np.tile([2e-4, -2e-4], 15)])
    p = tmp_path / "u.csv"
    p.write_text("time,deflection\n" + "\n".join(f"{float(a)!r},{math.sin(a * 50)!r}" for a in t) + "\n")
    r = ex.load_record(p)
    assert r.uniform and r.notes and "resampled" in r.notes[0]
    np.testing.assert_allclose(r.values, np.interp(r.time, t, np.sin(t * 50)), atol=1e-15)
    kept = ex.load_record(p, resample=False)
    assert not kept.uniform and not kept.notes


def test_gap_is_an_error(tmp_path):
    t = np.r_[np.arange(10) * 1e-3, 0.1 + np.arange(10) * 1e-3]
    p = tmp_path / "g.csv"
    p.write_text("time,deflection\n" + "\n".join(f"{float(a)!r},0.0" for a in t) + "\n")
    with pytest.raises(ScenarioError, match=r"gap of .* between line 11 and line 12"):
        ex.load_record(p)


BAD_RECORDS = {
    "one_column": ("time\n" + "\n".join(str(i) for i in range(10)), "only one column"),
    "non_numeric": ("time,deflection\n" + "\n".join(f"{i},{i}" for i in range(5)) + "\n5,abc\n6,1\n7,1\n8,1",
                    "line 7, column 2 (deflection): cannot read 'abc'"),
    "non_increasing": ("time,deflection\n" + "\n".join(f"{i},{i}" for i in range(5)) + "\n3,1\n6,1\n7,1\n8,1",
                       "line 7, column 1 (time): time 3 s does not come after the previous 4 s"),
    "nan": ("time,deflection\n" + "\n".join(f"{i},{i}" for i in range(5)) + "\n5,nan\n6,1\n7,1\n8,1",
            "line 7, column 2 (deflection): NaN value"),
    "too_short": ("time,deflection\n0,0\n1,1\n2,2", "at least 8"),
}


@pytest.mark.parametrize("case", sorted(BAD_RECORDS))
def test_bad_records_exit_2_with_one_line(tmp_path, case):
    """Each bad record: exit status 2, exactly one line on stderr naming the file
    and the line/column, no traceback (subprocess of the installed command)."""
    text, expected = BAD_RECORDS[case]
    p = tmp_path / f"{case}.csv"
    p.write_text(text + "\n")
    proc = subprocess.run([str(CLI), "identify", str(p)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("error: record ") and f"{case}.csv" in lines[0]
    assert expected in lines[0]
    assert proc.stdout == ""


def test_cli_identify_json(tmp_path, free_decay, case0):
    """identify --json on a CSV in mm with --scenario and --contact-frequency:
    the keys of the issue, E within 0.5 %, k matching the given frequency."""
    rec, _ = free_decay
    p = tmp_path / "free.csv"
    p.write_text("time [s],deflection [mm]\n" + "\n".join(f"{float(a)!r},{float(b) * 1e3!r}" for a, b in zip(rec.time, rec.values)))
    sc3 = EXAMPLES / "case03.toml"
    f_c = ex.contact_state_frequency(ib.load_scenario(sc3).with_values({"beam.youngs_modulus": E_TRUE}), 5200.0)
    out = tmp_path / "tuned.toml"
    proc = subprocess.run(
        [str(CLI), "identify", str(p), "--json", "--scenario", str(sc3), "--contact-frequency", f"{f_c!r}",
         "--out", str(out)],
        capture_output=True, text=True, timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    d = json.loads(proc.stdout)
    assert len(d["frequencies_hz"]) == 2 and len(d["damping_ratios"]) == 2 and len(d["damping_spread"]) == 2
    assert abs(d["damping_ratios"][0] - XI_TRUE) < 0.001
    assert abs(d["youngs_modulus"] / E_TRUE - 1) < 0.005
    # k from the frequency of the truth with the identified (not exact) E: within 1 %
    assert abs(d["contact_stiffness"] / 5200.0 - 1) < 0.01
    tuned = ib.load_scenario(out)
    assert tuned.beam.youngs_modulus == pytest.approx(d["youngs_modulus"])
    assert tuned.contactors[0].stiffness == pytest.approx(d["contact_stiffness"])


def test_cli_compare_json_and_plot(tmp_path, case3_truth):
    sc, res = case3_truth
    t = np.arange(100) / FS
    w = res.displacement([sc.contactors[0].position], t)[0]
    meas = tmp_path / "defl.csv"
    meas.write_text("time,deflection [mm]\n" + "\n".join(f"{float(a)!r},{float(b) * 1e3!r}" for a, b in zip(t, w)))
    trace = tmp_path / "acc.csv"
    trace.write_text("time [s],acceleration [m/s^2]\n" + "\n".join(
        f"{float(a)!r},{1.1 * float(b)!r}" for a, b in zip(sc.excitation.times, sc.excitation.values)))
    scen = tmp_path / "s.toml"
    from impactbeam.scenario import dump_scenario, set_path

    dump_scenario(set_path(sc.data, "excitation.scale", None), scen)
    png = tmp_path / "o.png"
    proc = subprocess.run(
        [str(CLI), "compare", str(scen), str(meas), "--excitation", str(trace), "--json", "--plot", str(png)],
        capture_output=True, text=True, timeout=120,
    )
    assert proc.returncode == 0, proc.stderr
    d = json.loads(proc.stdout)
    assert d["rms_difference"] < 1e-6  # the file holds the truth to ~17 digits in mm
    assert abs(d["features"]["first_peak"]["difference_percent"]) < 0.5
    assert png.stat().st_size > 1000


def test_a_record_of_the_other_quantity_is_named_with_its_article(tmp_path):
    # "a acceleration record" (the message of compare's check)
    from impactbeam.experiment.records import _require

    q = tmp_path / "a.csv"
    q.write_text("time,acceleration [g]\n" + "\n".join(f"{i * 1e-4},{1.0}" for i in range(10)) + "\n")
    with pytest.raises(ParameterError, match="a comparison needs a deflection record, got an acceleration record"):
        _require(ex.load_record(q), "deflection", "a comparison")
