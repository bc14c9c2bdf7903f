"""Random loads: the density, its synthesis, and the linear response against the exact modes.

Independent values: log-log interpolation and its closed-form integral
against scipy's quadrature; the synthesised history's density against the
target within Welch's chi-squared band; the deflection and velocity RMS of a
linear run against ``int |H|^2 G df`` from the exact modes (random_cases.py).
"""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from click.testing import CliRunner

import impactbeam as ib
from impactbeam.cli import main
from impactbeam.model.psd import PowerSpectralDensity, synthesize
from impactbeam.statistics import response_statistics, welch_psd
from impactbeam.units import STANDARD_GRAVITY, to_si
from random_cases import BAND, LinearReference, linear_data


def test_log_log_interpolation_and_exact_integral():
    from scipy.integrate import quad

    psd = PowerSpectralDensity([10.0, 100.0, 1000.0], [0.01, 0.01, 0.001])
    # a straight line on log-log axes: the geometric mean of the ends at the geometric mean frequency
    assert psd(np.sqrt(100.0 * 1000.0))[0] == pytest.approx(np.sqrt(0.01 * 0.001), rel=1e-14)
    assert psd([5.0, 10.0, 1000.0, 1000.1]).tolist() == [0.0, 0.01, 0.001, 0.0]  # zero outside the table
    # tolerance 1e-9: the adaptive quadrature's own accuracy (the closed form is exact)
    ref = quad(lambda f: psd(f)[0], 10.0, 1000.0, points=[100.0], epsabs=0, epsrel=1e-12, limit=200)[0]
    assert psd.variance() == pytest.approx(ref, rel=1e-9)
    # b = -1 (G ~ 1/f): the logarithmic case of the closed form
    inv = PowerSpectralDensity([10.0, 1000.0], [1.0, 0.01])
    assert inv.variance() == pytest.approx(10.0 * np.log(100.0), rel=1e-13)
    # a zero level makes its segments zero (the limit of the log-log line)
    edge = PowerSpectralDensity([10.0, 20.0, 40.0], [0.0, 1.0, 1.0])
    assert edge(15.0)[0] == 0.0 and edge(20.0)[0] == 1.0 and edge.variance() == pytest.approx(20.0, rel=1e-14)
    assert edge.band == (20.0, 40.0)


def test_spectral_density_units():
    assert to_si("0.01 g^2/Hz", "acceleration_psd", "k") == pytest.approx(0.01 * STANDARD_GRAVITY**2, rel=1e-15)
    assert to_si("2 N^2/Hz", "force_psd", "k") == 2.0
    assert to_si("1 (N/m)^2/Hz", "force_per_length_psd", "k") == 1.0
    with pytest.raises(ib.ScenarioError, match=r"excitation\.psd\.0\.1: .*velocity.*spectral density"):
        to_si("0.01 g/Hz", "acceleration_psd", "excitation.psd.0.1")
    # g squared with a superscript is standard gravity squared too; "mg" is a milligram, and the message says
    # how g is read (it said "[mass] ** 2 * [time]" alone)
    assert to_si("0.01 g²/Hz", "acceleration_psd", "k") == pytest.approx(0.01 * STANDARD_GRAVITY**2, rel=1e-15)
    with pytest.raises(ib.ScenarioError, match=r'g written alone is standard gravity here, "0\.01 g\^2/Hz"; "mg" is a '
                                               r"milligram"):
        to_si("1 mg^2/Hz", "acceleration_psd", "excitation.psd.0.1")
    with pytest.raises(ib.ScenarioError, match=r'standard gravity here, "15 g"'):
        to_si("15 mg", "acceleration", "excitation.amplitude")


def test_synthesis_repeats_bit_for_bit_and_streams_are_spawned_children():
    psd = PowerSpectralDensity(list(BAND), [1.0, 1.0])
    a = synthesize(psd, 5.0, 42)[1]
    assert np.array_equal(a, synthesize(psd, 5.0, 42)[1])
    assert not np.array_equal(a, synthesize(psd, 5.0, 43)[1])
    s2 = synthesize(psd, 5.0, 42, stream=2)[1]
    assert not np.array_equal(a, s2)
    # the stream is the child of SeedSequence.spawn: the same state words
    child = np.random.SeedSequence(42).spawn(3)[2]
    assert np.array_equal(child.generate_state(4), np.random.SeedSequence(42, spawn_key=(2,)).generate_state(4))
    assert a[0] == a[-1]  # periodic record: the last sample repeats the first
    assert abs(np.mean(a[:-1])) < 1e-12 * np.std(a)  # no line at 0 Hz: zero mean


def test_synthesised_density_within_its_chi2_band():
    """The held history (what the solver integrates) has the target density in the band."""
    sc = ib.parse_scenario(linear_data(end_time=60.0))
    ex = sc.excitation
    fs_load = 1.0 / float(ex.times[1] - ex.times[0])
    rate = 4.0 * fs_load  # the hold's images (near fs_load) stay far above the tested band
    t = np.arange(int(60.0 * rate)) / rate
    u = ex.history(t)
    est = welch_psd(u, rate, segment=int(rate))  # 1 Hz bins, ~115 degrees of freedom
    lo, hi = welch_psd(u, rate, segment=int(rate), confidence=0.99)["band"]
    f = est["frequency"]
    inside = (f >= 1.5 * BAND[0]) & (f <= BAND[1] / 1.1)
    target = ex.psd(f[inside])
    ratio = est["psd"][inside] / target
    # tolerance: a Gaussian estimate leaves the 99 % band in 1 % of the bins; random phases with
    # exact line amplitudes scatter less (measured: none outside); allow 2 %
    assert np.mean((ratio < lo) | (ratio > hi)) <= 0.02
    # the level itself: the mean over ~250 bins within 1 % (the scatter of a mean of 250 estimates)
    assert np.mean(ratio) == pytest.approx(1.0, abs=0.01)
    # variance of the history against int G df: the lines are a Riemann sum of the integral (error
    # ~ 1/(60 s * 290 Hz)), the hold's images add (f/fs)^4-weighted power: both below 0.5 %
    assert np.var(u) == pytest.approx(ex.psd.variance(), rel=5e-3)


def test_linear_rms_against_the_exact_modes():
    """Deflection and velocity RMS of a linear run against int |H|^2 G df (exact modes).

    Statistical error stated: over random phases the window's mean square scatters around the
    line sum with the relative standard deviation of LinearReference.window_std (~0.9 % here);
    the tolerance is four of those (plus the line sum against the integral, ~1e-5, and the
    start-up residue, below 1e-3 by the settling time).
    """
    sc = ib.parse_scenario(linear_data(end_time=40.0))
    ref = LinearReference(sc)
    res = ib.simulate(sc)
    stats = response_statistics(res)
    lo, hi = stats["window"]
    assert lo > 0.5  # the start from rest is left out
    for velocity, key in ((False, "rms"), (True, "rms_velocity")):
        exact = ref.variance(velocity)
        tol = 4 * ref.window_std(40.0, hi - lo, velocity) + 1e-3
        for got, want, rtol in zip(np.array(stats[key]) ** 2, exact, tol):
            assert got == pytest.approx(want, rel=rtol)


def test_random_scenario_keys_and_drawn_seed(scenario_file):
    data = linear_data(end_time=2.0)
    del data["excitation"]["seed"]
    sc = ib.parse_scenario(data)
    seed = sc.excitation.seed
    assert sc.excitation.seed_drawn and sc.data["excitation"]["seed"] == seed  # kept: runs repeat
    again = ib.parse_scenario(sc.data)
    assert np.array_equal(again.excitation.values, sc.excitation.values)
    text = sc.to_toml()
    assert f"seed = {seed}" in text
    path = scenario_file(ib.parse_scenario(data).to_toml().replace("seed = ", "# seed = "), "noseed.toml")
    out = CliRunner().invoke(main, ["simulate", str(path), "--json"], catch_exceptions=False)
    assert out.exit_code == 0
    assert isinstance(json.loads(out.stdout)["seed"], int)  # the drawn seed is reported
    out = CliRunner().invoke(main, ["simulate", str(path)], catch_exceptions=False)
    drawn = re.search(r"(?m)^  seed +(\S+)$", out.stdout).group(1)
    assert re.fullmatch(r"\d+", drawn), drawn  # every digit, so the run can be repeated (was "1.48518e+09")


BAD = [
    ('psd = [["20 Hz", "0.01 g^2/Hz"], ["10 Hz", "0.01 g^2/Hz"]]', "excitation.psd.1.0", "increase"),
    ('psd = [["10 Hz", "-0.01 g^2/Hz"], ["100 Hz", "0.01 g^2/Hz"]]', "excitation.psd.0.1", "zero or positive"),
    ('psd = [["10 Hz", "0.01 g"], ["100 Hz", "0.01 g^2/Hz"]]', "excitation.psd.0.1", "spectral density"),
    ('psd = [["10 s", "0.01 g^2/Hz"], ["100 Hz", "0.01 g^2/Hz"]]', "excitation.psd.0.0", "frequency"),
    ('psd = [["10 Hz", "0.01 g^2/Hz"]]', "excitation.psd", "two"),
    ('psd = [[10, 0.1, 3], [100, 0.1]]', "excitation.psd.0", "row of 2"),
    ('psd = [[10, 0.1], [100, 0.1]]\nseed = -1', "excitation.seed", ">= 0"),
    ('psd = [[10, 0.1], [100, 0.1]]\namplitude = "1 g"', "excitation.amplitude", "no effect"),
    ('psd = [[10, 0.1], [100, 0.1]]\nsample_rate = "150 Hz"', "excitation.sample_rate", "twice"),
    # absurd magnitudes: a traceback from NumPy, and a response of 1e146 m
    ('psd = [[10, 0.1], [100, 0.1]]\nsample_rate = 1e300', "excitation.sample_rate", "load samples) would need"),
    ('psd = [[10, 1e300], [100, 1e300]]', "excitation.psd", "would drive the beam to a deflection"),
]
BAD_FATIGUE = [
    ('points = [0.2]\nsn_stress = "20 MPa"\nsn_cycles = 1e6\nsn_exponent = 8', "fatigue.points.0", "off the beam"),
    ('points = [0.0]\nsn_stress = "20 MPa"\nsn_cycles = 1e6\nsn_exponent = 0', "fatigue.sn_exponent", "positive"),
    ('points = [0.0]\nsn_stress = "20 MPa"\nsn_cycles = 1e6\nsn_exponent = -3', "fatigue.sn_exponent", "positive"),
    ('points = [0.0]\nsn_stress = "20 mm"\nsn_cycles = 1e6\nsn_exponent = 8', "fatigue.sn_stress", "stress"),
    ('points = [0.0]\nsn_stress = "20 MPa"\nsn_cycles = 1e6\nsn_exponent = 8\nmean_stress = "goodman"',
     "fatigue.ultimate_strength", "required"),
    ('points = [0.0]\nsn_stress = "20 MPa"\nsn_exponent = 8', "fatigue.sn_cycles", "required"),
    # pint's cycle is a turn, 2 pi rad: "1e6 cycles" was a count of 6.28e6
    ('points = [0.0]\nsn_stress = "20 MPa"\nsn_cycles = "1e6 cycles"\nsn_exponent = 8', "fatigue.sn_cycles",
     "has an angle in its unit, expected a dimensionless number (a count of cycles is a plain number: 1e6)"),
]

_HEAD = """
[beam]
length = 0.1092
width = 9.93e-3
height = 3.03e-3
youngs_modulus = 1834e6
density = 951.98
[solver]
modes = 2
end_time = 0.5
"""


@pytest.mark.parametrize("lines,key,words", BAD + BAD_FATIGUE)
def test_bad_random_and_fatigue_input_exits_2_naming_the_key(scenario_file, lines, key, words):
    if key.startswith("fatigue"):
        text = _HEAD + '[excitation]\nkind = "base_acceleration"\nshape = "half_sine"\namplitude = "1 g"\n' \
            'duration = "5 ms"\n[fatigue]\n' + lines + "\n"
    else:
        text = _HEAD + '[excitation]\nkind = "base_acceleration"\nshape = "random"\n' + lines + "\n"
    path = scenario_file(text)
    out = CliRunner().invoke(main, ["simulate", str(path)], catch_exceptions=False)
    assert out.exit_code == 2, out.output
    line = out.stderr.strip()
    assert line.count("\n") == 0 and line.startswith(f"error: {key}:"), line
    assert words in line


def test_psd_keys_only_with_a_random_shape(scenario_file):
    text = _HEAD + '[excitation]\nkind = "base_acceleration"\nshape = "step"\namplitude = 1\nseed = 3\n'
    out = CliRunner().invoke(main, ["simulate", str(scenario_file(text))], catch_exceptions=False)
    assert out.exit_code == 2 and out.stderr.startswith("error: excitation.seed:")


def test_numbers_of_the_random_vibration_page():
    """docs/random-vibration.md: the numbers it shows, from the shipped code."""
    from pathlib import Path

    from impactbeam.model.psd import MIN_LINES, RATE_FACTOR
    from impactbeam.statistics import settling_time

    text = (Path(__file__).resolve().parents[1] / "docs" / "random-vibration.md").read_text()
    sigma = PowerSpectralDensity([10.0, 1000.0], [0.01, 0.01]).rms()  # in g
    assert f"= {sigma:.2f}\\,g" in text
    assert RATE_FACTOR == 8 and "$f_s = 8 f_{max}$" in text and f"(1/{RATE_FACTOR - 1:g})^4" in text
    assert f"fewer than {MIN_LINES} lines" in text
    case3 = ib.load_scenario(Path(__file__).resolve().parents[1] / "examples" / "case03.toml")
    sc = case3.with_values({"excitation.shape": "random", "excitation.amplitude": None, "excitation.duration": None,
                            "excitation.psd": [[10, 0.1], [1000, 0.1]], "excitation.seed": 1,
                            "solver.end_time": 0.05})
    res = ib.simulate(sc)
    assert f"{settling_time(res):.2f} s for Case 3's beam" in text
    f1 = ib.modes(case3).free.omega[0] / (2 * np.pi)
    assert f"{100 * case3.damping.free:.1f} % damping of its {f1:.0f} Hz first mode" in text


@pytest.mark.slow
def test_sample_rate_evidence_of_the_random_vibration_page():
    """The table of docs/random-vibration.md, recomputed (benchmarks/bench_random.py --rates).

    The entries are shown as bounds: a record with impacts is sensitive to the last bit of its
    load (a changed bit moves an impact), so the impact rate and force RMS at 4 f_max are bounded
    by 1 % (measured 0.4-0.6 %: 2-3 of ~450 impacts) rather than given to more digits."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
    try:
        from bench_random import rate_changes
    finally:
        sys.path.pop(0)
    ch = {f: 100 * np.abs(v) for f, v in rate_changes(1000.0, 10.0).items()}
    assert np.all(ch[8] <= 0.01) and np.all(ch[16] <= 0.01)
    assert np.all(ch[4][:4] <= 0.04) and ch[4][4] <= 0.02
    assert ch[4][5] < 1.0 and ch[4][6] < 1.0


def test_random_load_exact_against_the_ivp_reference():
    """The random shape is a held-linear history: the independent solve_ivp path (which evaluates the
    samples itself, restarting at each) agrees on Case 3 with impacts. Events 1e-9 s, w 1e-8 relative,
    as for measured traces (test_solver.py)."""
    from pathlib import Path

    case3 = ib.load_scenario(Path(__file__).resolve().parents[1] / "examples" / "case03.toml")
    sc = case3.with_values({"excitation.shape": "random", "excitation.amplitude": None, "excitation.duration": None,
                            "excitation.psd": [["10 Hz", "0.5 g^2/Hz"], ["300 Hz", "0.5 g^2/Hz"]],
                            "excitation.seed": 3, "solver.end_time": 0.12, "solver.time_step": 1e-4})
    a = ib.simulate(sc)
    b = ib.simulate(sc, method="ivp")
    ka = [(e.kind, e.contactor) for e in a.events]
    assert ka == [(e.kind, e.contactor) for e in b.events] and len(ka) >= 2
    assert np.abs(np.array([e.time for e in a.events]) - np.array([e.time for e in b.events])).max() <= 1e-9
    assert np.abs(a.w - b.w).max() <= 1e-8 * np.abs(a.w).max()


def test_fatigue_needs_an_outer_fibre_and_sweeps_need_a_seed(tmp_path):
    from impactbeam.sweeps import parse_sweep

    data = linear_data(end_time=1.0)
    data["beam"] = {"length": 0.1092, "area": 3e-5, "second_moment": 2.3e-11, "youngs_modulus": 1.8e9, "density": 950}
    data["fatigue"] = {"points": [0.0], "sn_stress": 1e7, "sn_cycles": 1e6, "sn_exponent": 5}
    with pytest.raises(ib.ScenarioError, match=r"^fatigue\.points\.0: .*outer-fibre"):
        ib.parse_scenario(data)
    data = linear_data(end_time=1.0)
    del data["excitation"]["seed"]
    with pytest.raises(ib.ScenarioError, match=r"base: excitation\.seed: .*add excitation\.seed = \d+"):
        parse_sweep({"base": data, "parameters": {"excitation.scale": {"values": [1.0, 2.0]}}})


def test_a_density_above_the_retained_modes_is_warned_about():
    """A tip force on the specimen's cantilever, 1e-4 N^2/Hz from 10 Hz to 5 kHz: with 4 modes (the 4th at
    1959 Hz) the modes between 1959 Hz and 5 kHz respond at resonance and are missing. Measured on a 4 s record:
    the root's fatigue damage 1.57e-2 against 2.45e-2 converged (8, 12 and 16 modes agree to 0.02 %), with 2 modes
    4.7 times low; no warning was given. The run, the batch of a sweep and the solve_ivp path now say it alike;
    with 12 modes (the 8th at 8996 Hz) none do."""
    from impactbeam.sweeps.cases import Case, run_cases

    L = 0.1092
    sc = ib.parse_scenario({
        "beam": {"length": L, "width": 0.00993, "height": 0.00303, "youngs_modulus": 1834e6, "density": 951.98},
        "damping": {"free": 0.011, "contact": 0.02},
        "excitation": {"kind": "point_force", "position": L, "shape": "random", "seed": 1,
                       "psd": [["10 Hz", "1e-4 N^2/Hz"], ["5000 Hz", "1e-4 N^2/Hz"]]},
        "solver": {"modes": 4, "end_time": 0.02}})
    words = r"excitation\.psd reaches 5000 Hz, above the highest of the 4 retained modes \(1959 Hz\)"
    for method in ("exact", "ivp"):
        with pytest.warns(ib.ImpactBeamWarning, match=words):
            res = ib.simulate(sc, method=method)
        assert any(re.search(words, w) for w in res.warnings)
    batch = run_cases([Case(sc.beam, sc.contactors, sc.damping, sc.excitation, sc.initial, sc.solver)] * 2)
    assert all(any(re.search(words, w) for w in case) for case in batch.warnings)
    more = ib.simulate(sc.with_values({"solver.modes": 12}))
    assert not any("excitation.psd reaches" in w for w in more.warnings)
