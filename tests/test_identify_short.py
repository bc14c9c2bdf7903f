"""Identification on short records (issue 10 item 7; issue 11 item 5).

The paper's camera records are ~0.2 s long: Case 0 (57 Hz) at 2 kHz gives
~11 cycles, too few for the band-passed logarithmic decrement. The damping
of the fundamental must come out of such a record by two independent
estimators (damped-sine least squares, matrix pencil) with their spread.

Ground truth: the simulator's Case 0 free decay with modal damping 1.1 % in
every mode (so the fundamental's damping ratio is exactly 0.011), sampled
at 2 kHz for 0.2 s, plus seeded white noise of 1 % of the 2 mm release.
"""

from __future__ import annotations

import json
import math
import warnings
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import impactbeam as ib
from impactbeam import experiment as ex
from impactbeam.experiment.damping import damping_matrix_pencil, damping_sine_fit
from impactbeam.exceptions import ParameterError

ROOT = Path(__file__).resolve().parents[1]
CLI = Path(sys.executable).with_name("impactbeam")
FS = 2000.0
XI = 0.011
NOISE = 0.01 * 2e-3  # 1 % of the 2 mm release [m rms]


@pytest.fixture(scope="module")
def short_decay() -> tuple[np.ndarray, np.ndarray, float]:
    """Noise-free Case 0 tip deflection, 0.2 s at 2 kHz, and the model's first natural frequency."""
    sc = ib.load_scenario(ROOT / "examples" / "case00.toml").with_values({"solver.end_time": 0.2})
    res = ib.simulate(sc)
    t = np.arange(400) / FS
    w = res.displacement([sc.beam.length], t)[0]
    return t, w, float(ib.modes(sc).free.frequencies_hz[0])


def cramer_rao_xi(t: np.ndarray, amplitude: float, f_n: float, xi: float, noise: float) -> float:
    """Cramer-Rao standard deviation of xi for A exp(-xi wn t) cos(wd t + phi) + c in white noise.

    Computed here from the model's Fisher information J^T J / noise^2 (central
    differences), independently of the estimators under test.
    """
    wn = 2 * math.pi * f_n

    def model(p: np.ndarray) -> np.ndarray:
        a, phi, x, w, c = p
        return a * np.exp(-x * w * t) * np.cos(w * math.sqrt(1 - x * x) * t + phi) + c

    p0 = np.array([amplitude, 0.0, xi, wn, 0.0])
    h = np.array([1e-6 * amplitude, 1e-6, 1e-7, 1e-6 * wn, 1e-6 * amplitude])
    J = np.column_stack([(model(p0 + h[i] * e) - model(p0 - h[i] * e)) / (2 * h[i]) for i, e in enumerate(np.eye(5))])
    cov = np.linalg.inv(J.T @ J) * noise**2
    return float(math.sqrt(cov[2, 2]))


def test_short_record_damping_by_two_estimators(short_decay) -> None:
    """Both estimators within 4 Cramer-Rao standard deviations of 1.1 %, over 5 noise seeds.

    Tolerance: the Cramer-Rao bound (single mode, amplitude taken as the
    record's largest deflection, so the bound is if anything tight) is
    ~5e-5 (0.005 percentage points); 4 sigma leaves a false-failure chance
    of ~6e-5 per estimate for an efficient Gaussian estimator. The
    least-squares fit is the maximum-likelihood estimator and attains the
    bound; the matrix pencil measured ~1x the bound on this record (40 seeds:
    std 4.4e-5 vs 4.7e-5 for the fit). The logarithmic decrement gives no
    value on this record (fewer than two cycles clear of its filter transients).
    """
    t, w, f1 = short_decay
    tol = 4 * cramer_rao_xi(t, float(np.max(np.abs(w))), f1, XI, NOISE)
    assert 2e-5 < tol < 4e-4  # sanity of the derived tolerance (0.002 .. 0.04 percentage points)
    for seed in range(5):
        rec = ex.Record(t, w + np.random.default_rng(seed).normal(0.0, NOISE, t.size))
        ident = ib.identify(rec, 2)
        m1 = ident.damping[0]
        assert abs(m1.fit - XI) < tol, (seed, m1.fit, tol)
        assert abs(m1.pencil - XI) < tol, (seed, m1.pencil, tol)
        assert m1.spread == pytest.approx(abs(m1.fit - m1.pencil)) and m1.spread < 2 * tol
        # the fit's own standard error is of the order of the bound (within a factor 2)
        assert tol / 8 < m1.fit_standard_error < tol / 2
        assert m1.log_decrement is None and "fewer than two usable cycles" in m1.log_decrement_note
        assert abs(ident.frequencies_hz[0] / f1 - 1) < 0.002


def test_estimators_exact_on_noise_free_damped_sines() -> None:
    """Two closed-form damped sinusoids, no noise, 0.15 s at 2 kHz: both estimators to 1e-7.

    Noise-free data fit the model exactly, so only the solvers' tolerances remain.
    """
    t = np.arange(300) / FS
    modes = [(61.37, 0.015, 1.0), (402.9, 0.008, 0.05)]
    x = 0.3 + sum(a * np.exp(-z * 2 * np.pi * f * t) * np.cos(2 * np.pi * f * math.sqrt(1 - z * z) * t + 0.4)
                  for f, z, a in modes)
    fd = [f * math.sqrt(1 - z * z) for f, z, _ in modes]
    fit = damping_sine_fit(t, x, [fd[0] * 1.003, fd[1] * 0.997])
    pencil, fp = damping_matrix_pencil(x, 1 / FS, fd)
    for k, (f, z, _) in enumerate(modes):
        assert fit.damping_ratios[k] == pytest.approx(z, abs=1e-7)
        assert pencil[k] == pytest.approx(z, abs=1e-7)
        assert fit.frequencies_hz[k] == pytest.approx(fd[k], rel=1e-9)
        assert fp[k] == pytest.approx(fd[k], rel=1e-9)


def test_cli_identify_short_record_reports_both_estimators(tmp_path: Path, short_decay) -> None:
    t, w, _ = short_decay
    x = w + np.random.default_rng(3).normal(0.0, NOISE, t.size)
    p = tmp_path / "short.csv"
    p.write_text("time (ms),deflection (mm)\n" + "\n".join(f"{float(a) * 1e3!r},{float(b) * 1e3!r}" for a, b in zip(t, x)))
    proc = subprocess.run([str(CLI), "identify", str(p), "--json"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    d = json.loads(proc.stdout)
    assert abs(d["damping_ratios"][0] - XI) < 3e-4 and abs(d["damping_matrix_pencil"][0] - XI) < 3e-4
    assert d["damping_spread"][0] == pytest.approx(abs(d["damping_ratios"][0] - d["damping_matrix_pencil"][0]))
    assert d["damping_log_decrement"][0] is None and d["warnings"] == []
    text = subprocess.run([str(CLI), "identify", str(p)], capture_output=True, text=True, timeout=120)
    assert text.returncode == 0 and "pencil" in text.stdout and "spread" in text.stdout


@pytest.mark.parametrize(
    ("values", "needle"),
    [("0.001", "no significant oscillation"), ("0", "all zero"), ("{t} * 0.01", "no significant oscillation")],
    ids=["constant", "zero", "pure-trend"],
)
def test_identify_refuses_a_record_without_oscillation(tmp_path: Path, values: str, needle: str) -> None:
    """Issue 11 item 5: exit 2 with the reason, not peaks of a window function."""
    t = np.arange(400) / FS
    p = tmp_path / "flat.csv"
    p.write_text("time,deflection\n" + "\n".join(f"{float(a)!r},{eval(values.format(t=float(a)))!r}" for a in t))
    proc = subprocess.run([str(CLI), "identify", str(p)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and needle in lines[0] and "flat.csv" in lines[0]
    with pytest.raises(ParameterError, match=needle):
        ib.identify(ex.load_record(p), 2)


def test_fit_failure_falls_back_to_the_pencil_with_a_warning(short_decay, monkeypatch) -> None:
    """A fit that does not converge is reported as n/a (None in JSON) with a warning, not as an error."""
    import impactbeam.experiment.damping as dmp

    def fail(*args, **kwargs):
        raise ParameterError("damping fit: did not converge (test)")

    monkeypatch.setattr(dmp, "damping_sine_fit", fail)
    t, w, _ = short_decay
    rec = ex.Record(t, w + np.random.default_rng(0).normal(0.0, NOISE, t.size))
    with pytest.warns(ib.ImpactBeamWarning, match="damping from the matrix pencil only"):
        ident = ib.identify(rec, 2)
    d = ident.to_dict()
    assert d["damping_ratios"] == [None, None] and d["damping_spread"] == [None, None]
    assert abs(d["damping_matrix_pencil"][0] - XI) < 3e-4


def test_a_strongest_second_mode_is_not_taken_for_the_first(short_decay) -> None:
    """Asked for one frequency, a 0.05 s decay (3 cycles of the 57 Hz fundamental) shows its second mode most:
    the modulus was computed as if 363 Hz were the first mode's frequency (x88, and through a damping of
    74 +- 83 % taken as resolved, worse). The frequency is matched to the model's nearest mode, which gives the
    modulus within the record's error (the truth is the scenario's own 1834 MPa: 0.5 %, the second mode's
    frequency error on 25 cycles), with a warning; a record sampled at 100 Hz, below twice 57 Hz, is warned."""
    t, w, _ = short_decay
    sc = ib.load_scenario(ROOT / "examples" / "case00.toml")
    rec = ex.Record(t[:100], w[:100], name="short", quantity="deflection")
    with pytest.warns(ib.ImpactBeamWarning, match="nearest the model's mode 2"):
        ident = ex.identify(rec, count=1, scenario=sc)
    assert ident.model["mode"] == 2
    assert ident.model["youngs_modulus"] == pytest.approx(sc.beam.youngs_modulus, rel=5e-3)
    ts = np.arange(100) / 100.0  # 1 s at 100 Hz
    slow = ex.Record(ts, ib.simulate(sc.with_values({"solver.end_time": 1.0})).displacement([sc.beam.length], ts)[0],
                     name="slow", quantity="deflection")
    with pytest.warns(ib.ImpactBeamWarning, match="below twice the model's first frequency"):
        ex.identify(slow, count=1, scenario=sc)


def _decay(fs: float, seconds: float, seed: int, modes=((1.97e-3, 60.964), (0.03e-3, 382.055)), xi: float = 0.01):
    """A cantilever-like free decay (the specimen with E = 2100 MPa: 60.964 and 382.055 Hz), 5 um noise."""
    t = np.arange(0.0, seconds, 1.0 / fs)
    wd = np.sqrt(1.0 - xi**2)
    w = sum(a * np.exp(-xi * 2 * np.pi * f * t) * (np.cos(2 * np.pi * f * wd * t) + xi / wd * np.sin(2 * np.pi * f * wd * t))
            for a, f in modes)
    return t, w + np.random.default_rng(seed).normal(0.0, 5e-6, t.size)


def test_a_record_that_breaks_the_model_is_warned_about() -> None:
    """Found by a hunt with records synthesised outside the package, each given without a warning before:

    * sampled at 600 Hz, mode 2 (382 Hz) shows at its alias 219 Hz with its damping 1.74 times too high;
    * a sensor clipped at +/-1 mm (a 2 mm decay): mode 1's damping 0.709 +/- 0.010 % (truth 1 %) and the
      pencil's 1.26 % differ by 54 standard errors, and a clipping harmonic at 5 f1 passes for mode 2;
    * 20 ms at 5 kHz (about one cycle): the fit's 71 +/- 30 % damping "corrected" the frequency 1.4 times and
      gave E = 4153 MPa (truth 2100 MPa); taken as it is (the pencil says 0.97 %) E is within 3 %."""
    sc = ib.load_scenario(ROOT / "examples" / "case03.toml")
    t, w = _decay(600.0, 0.5, 21)
    with pytest.warns(ib.ImpactBeamWarning, match=r"mode 2 at 21\d.\d+ Hz is where the model's mode 2 \(382"):
        ib.identify(ex.Record(t, w, name="aliased"), 2, scenario=sc)
    t, w = _decay(2000.0, 0.5, 31)
    with pytest.warns(ib.ImpactBeamWarning) as record:
        ib.identify(ex.Record(t, np.clip(w, -1e-3, 1e-3), name="clipped"), 2)
    said = " ".join(str(x.message) for x in record)
    assert "sit exactly at the record's largest value" in said and "differ by" in said
    t, w = _decay(5000.0, 0.02, 5, modes=((1.94138e-3, 60.964), (4.943e-5, 382.055), (6.31e-6, 1069.773)))
    with pytest.warns(ib.ImpactBeamWarning, match="nearest the model's mode 2"):
        one = ib.identify(ex.Record(t, w, name="short"), 1, scenario=sc)
    assert one.model["youngs_modulus"] == pytest.approx(2100e6, rel=0.03)  # 2044 MPa measured: mode 2, undamped
    # and a clean record of the same decay at 2 kHz gives none of these warnings
    t, w = _decay(2000.0, 0.5, 21)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ib.identify(ex.Record(t, w, name="clean"), 2, scenario=sc)


def test_a_record_in_milli_g_is_told_how_g_is_read(tmp_path: Path) -> None:
    # an accelerometer's "acceleration (mg)" was refused with the length's reason only ("mg" is a mass, expected
    # a length); the acceleration's reason, with the note on how g is read, is now given too
    from impactbeam.exceptions import ScenarioError

    path = tmp_path / "mg.csv"
    path.write_text("time [s],acceleration (mg)\n" + "\n".join(f"{i * 1e-3},{(-1) ** i}" for i in range(12)))
    with pytest.raises(ScenarioError, match=r'as an acceleration: .*"mg" is a milligram'):
        ex.load_record(path)


def test_a_record_in_the_wrong_units_is_warned_about_before_a_comparison_or_fit() -> None:
    # Found by a hunt: under unit-less headers a deflection in mm was read in m (a 1.08 m peak on a 0.109 m beam)
    # and a time in ms in s (compare then simulated 120 s of a record "sampled at 2 Hz"), without a word
    from impactbeam.experiment.compare import prepare_run

    sc = ib.load_scenario(ROOT / "examples" / "case03.toml")
    t = np.arange(0.0, 0.06, 5e-4)
    w = 1e-3 * np.sin(2 * np.pi * 57.0 * t)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        prepare_run(sc, ex.Record(t, w, name="right"), None, "linear", None)
    with pytest.warns(ib.ImpactBeamWarning, match=r"more than half the beam's length \(0.1092 m\)"):
        prepare_run(sc, ex.Record(t, 1e3 * w, name="mm as m"), None, "linear", None)
    with pytest.warns(ib.ImpactBeamWarning, match=r"sampled at 2 Hz, below twice the beam's first frequency"):
        prepare_run(sc, ex.Record(1e3 * t, w, name="ms as s"), None, "linear", None)
