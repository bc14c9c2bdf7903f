"""Steady states without contact against the closed-form modal FRF; strobe and period detection.

Without contact the beam is linear, and its steady state under
``A sin(Omega t + phase)`` is ``Im[H A e^{i(Omega t + phase)}]``: the FRF of
the same modes, written in frequency domain (:func:`linear_frf`), while the
simulation integrates in time. Started on that state, the time-domain run
must stay on it to round-off; started from rest, it must converge to it at
the rate of the slowest free decay.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import impactbeam as ib
from impactbeam.exceptions import ParameterError, ScenarioError
from impactbeam.periodic.frf import frequency_response, linear_frf, linear_steady_state
from impactbeam.periodic.strobe import analyse_steady_state, detect_period, run_periods, steady_state, still_settling
from impactbeam.scenario import parse_scenario

G = 9.80665


def _scenario(frequency: float, *, gap: str = "10 mm", damping: float = 0.011, phase: float = 0.7):
    return parse_scenario({
        "beam": {"length": 0.10920, "width": 9.93e-3, "height": 3.03e-3, "youngs_modulus": "1834 MPa",
                 "density": "951.98 kg/m^3"},
        "supports": {"left": "clamped", "right": "free"},
        "contactors": [{"position_ratio": 0.484, "stiffness": 4030, "gap": gap, "side": "above"}],
        "damping": {"free": damping, "contact": 0.02},
        "excitation": {"kind": "base_acceleration", "shape": "harmonic", "amplitude": "1 g",
                       "frequency": frequency, "phase": phase},
        "solver": {"modes": 8},
    })


def _f1() -> float:
    return float(ib.modes(_scenario(50.0)).free.frequencies_hz[0])


@pytest.mark.parametrize("ratio", [0.5, 1.0, 1.6])
def test_linear_steady_state_equals_frf_to_roundoff(ratio):
    """Below, at and above the first resonance: max and min over the record are |H| A."""
    f = ratio * _f1()
    sc = _scenario(f)
    amp = abs(linear_frf(sc, [f])[0, 0]) * G
    ss = steady_state(sc, settle_periods=2, record_periods=10, start_state=linear_steady_state(sc))
    assert ss.period == 1
    assert ss.impacts_per_period == 0
    # tolerance: the same modes in time and frequency domain, so round-off: 1e-12 relative (2e-16 measured)
    assert ss.max == pytest.approx(amp, rel=1e-12)
    assert ss.min == pytest.approx(-amp, rel=1e-12)
    # the strobe samples are Im[H A e^{i phase}] at every period
    want = (linear_frf(sc, [f])[0, 0] * G * np.exp(0.7j)).imag
    np.testing.assert_allclose(ss.strobe, want, rtol=0, atol=1e-12 * amp)


def test_frf_by_hand_single_mode_sum():
    """linear_frf against the textbook sum over modes with a physical beam formula for the load weights."""
    sc = _scenario(40.0)
    ms = ib.mode_set(sc.beam, (), 8)
    x = sc.contactors[0].position
    f = np.array([20.0, 57.0, 300.0])
    Om = 2 * np.pi * f[:, None]
    xi = 0.011
    # base acceleration load -rho A int W_n, each mode a damped oscillator
    H = (-ms.inertia_integral() * ms.shapes([x])[:, 0]) / (ms.omega**2 - Om**2 + 2j * xi * ms.omega * Om)
    want = H.sum(axis=1)
    got = linear_frf(sc, f)[:, 0]
    # tolerance: the solver's basis adds one attachment shape (the static remainder of the truncated modes at
    # the contactor), which changes H by 4e-7 at 20 Hz and 6e-6 at 300 Hz (measured); 5e-5 allows for it
    np.testing.assert_allclose(got, want, rtol=5e-5)


def test_from_rest_converges_to_frf():
    """From rest the free transient decays like exp(-xi omega_1 t); after 100 + 50 periods it is below 1e-4.

    The run itself, analysed (``steady_state`` would record the linear limit at once: the 10 mm gap is never
    reached, see test_periodic_linear.py).
    """
    f = 0.8 * _f1()
    sc = _scenario(f, damping=0.03)
    amp = abs(linear_frf(sc, [f])[0, 0]) * G
    res, t_load = run_periods(sc, 150)
    ss = analyse_steady_state(res, sc, settle_periods=100, record_periods=50, start=t_load)
    assert ss.period == 1
    # tolerance: exp(-0.03 * omega_1 * 100 / f) = exp(-0.03 * 2 pi * 125) ~ 6e-11 times the transient amplitude
    # (of order the forced one), so 1e-8 is the bound and would catch any wrong steady-state amplitude
    assert ss.max == pytest.approx(amp, rel=1e-8)


def test_frequency_response_without_contact_is_the_frf():
    fs = [30.0, 50.0, 70.0]
    sc = _scenario(50.0)
    fr = frequency_response(sc, fs, sweep="both", settle_periods=400, record_periods=20)
    assert list(fr.direction) == ["up"] * 3 + ["down"] * 3
    assert np.all(fr.impacts_per_period == 0)
    # the 10 mm gap is out of reach of the linear response and of every transient: each value records the
    # linear limit exactly (settled after 0 periods); tolerance round-off, 1e-12 (2e-16 measured)
    assert all(p.state.settled_after == 0 for p in fr.diagram.points)
    np.testing.assert_allclose(fr.max, fr.linear, rtol=1e-12)
    np.testing.assert_allclose(fr.min, -fr.linear, rtol=1e-12)


def test_detect_period_synthetic():
    k = np.arange(60)
    s = np.c_[np.cos(2 * np.pi * k / 3), np.sin(2 * np.pi * k / 3)]
    assert detect_period(s, 1e-9)[0] == 3
    assert detect_period(np.c_[np.ones(60)], 1e-9)[0] == 1
    rng = np.random.default_rng(1)
    assert detect_period(rng.uniform(-1, 1, (60, 2)), 1e-3)[0] == 0
    # a decaying oscillation strobed near twice its period: neighbouring repetitions agree to 0.2 (the old
    # lag-by-lag test took it for period 2), the record's first and last ones do not; and a shorter lag's
    # mismatch shrinking over the record marks it as a transient besides
    d = np.exp(-0.05 * k) * np.cos(np.pi * 0.98 * k)
    s = np.c_[d + 1.0, np.zeros(60)]
    assert float(np.max(np.abs(s[2:] - s[:-2]))) <= 0.2
    assert detect_period(s, 0.2)[0] == 0
    assert still_settling(s, 2, 0.2)
    # a strobe drifting by 4e-5 per period repeats within 1e-4 from one period to the next, not over the record
    drift = np.c_[1.0 + 4e-5 * k, np.ones(60)]
    assert float(np.max(np.abs(drift[1:] - drift[:-1]))) <= 1e-4 and detect_period(drift, 1e-4)[0] == 0


def _period_by_definition(s, tolerance, max_period=None):
    """The period test written pair by pair: the smallest n with |s_{k+jn} - s_k| <= tolerance for all k, j."""
    s = s[:, None] if s.ndim == 1 else s
    top = (s.shape[0] - 1) // 2 if max_period is None else min(int(max_period), s.shape[0] - 1)
    best = math.inf
    for n in range(1, max(top, 0) + 1):
        mism = float(np.max([np.max(np.abs(s[lag:] - s[:-lag])) for lag in range(n, s.shape[0], n)]))
        if mism <= tolerance:
            return n, mism
        best = min(best, mism)  # a NaN lag (a run stopped early) never counts
    return 0, best


def test_detect_period_gives_the_definitions_numbers():
    # every lag in one gather must give the period and mismatch of the lag-by-lag definition to the bit:
    # records with periods 1-7 and noise from 1e-7 to 1e-2, some ending in NaN, 1-D or up to 5 components
    rng = np.random.default_rng(1)
    for _ in range(1500):
        n, p, per = int(rng.integers(1, 60)), int(rng.integers(1, 6)), int(rng.integers(1, 8))
        base = rng.normal(size=(per, p))
        s = base[np.arange(n) % per] + rng.normal(size=(n, p)) * 10 ** rng.uniform(-7, -2)
        if rng.random() < 0.1:
            s[rng.integers(0, n):] = np.nan
        if rng.random() < 0.3:
            s = s[:, 0]
        top = None if rng.random() < 0.7 else int(rng.integers(0, 30))
        tol = 10 ** rng.uniform(-6, -2)
        assert detect_period(s, tol, top) == _period_by_definition(np.asarray(s), tol, top)


def test_not_periodic_warns():
    sc = _scenario(0.8 * _f1(), damping=0.0)
    with pytest.warns(ib.ImpactBeamWarning, match="no period"):
        ss = steady_state(sc, settle_periods=5, record_periods=20, max_settle_periods=5)
    assert ss.period == 0
    assert ss.warnings


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [({"settle_periods": -1}, "settle_periods"), ({"record_periods": 1}, "record_periods"),
     ({"record_periods": 2.5}, "record_periods")],
)
def test_bad_counts(kwargs, field):
    with pytest.raises(ParameterError, match=field):
        steady_state(_scenario(50.0), **kwargs)


def test_needs_harmonic_load():
    raw = {"beam": {"length": 0.1, "width": 0.01, "height": 0.003, "youngs_modulus": 2e9, "density": 1000},
           "excitation": {"kind": "base_acceleration", "shape": "half_sine", "amplitude": 1, "duration": 0.01}}
    with pytest.raises(ScenarioError, match="excitation.shape"):
        steady_state(parse_scenario(raw))
    assert math.isfinite(_f1())


def test_point_force_frf_and_steady_state():
    """A harmonic point force: the FRF is sum W_n(x) W_n(x_p) / (omega_n^2 - Omega^2 + 2 i xi omega_n Omega)."""
    raw = {
        "beam": {"length": 0.10920, "width": 9.93e-3, "height": 3.03e-3, "youngs_modulus": "1834 MPa",
                 "density": "951.98 kg/m^3"},
        "supports": {"left": "clamped", "right": "free"},
        "damping": {"free": 0.02, "contact": 0.02},
        "excitation": {"kind": "point_force", "shape": "harmonic", "amplitude": "0.01 N", "frequency": 300.0,
                       "position_ratio": 1.0},
        "solver": {"modes": 8},
        "output": {"points": [0.05, 0.1092]},
    }
    sc = parse_scenario(raw)
    ms = ib.mode_set(sc.beam, (), 8)
    Om = 2 * np.pi * 300.0
    Wx, Wp = ms.shapes([0.05])[:, 0], ms.shapes([0.1092])[:, 0]
    want = np.sum(Wx * Wp / (ms.omega**2 - Om**2 + 2j * 0.02 * ms.omega * Om))
    got = linear_frf(sc, [300.0])[0, 0]
    # tolerance: without contactors the solver's basis is the free modes themselves: round-off, 1e-12
    assert got == pytest.approx(want, rel=1e-12)
    ss = steady_state(sc, settle_periods=1, record_periods=6, start_state=linear_steady_state(sc))
    # 0.01 N at the tip; extremes of the linear steady state, round-off (1e-12)
    assert ss.max == pytest.approx(abs(got) * 0.01, rel=1e-12)


def test_the_linear_peak_of_the_figure_is_the_frfs_between_the_swept_values():
    """14 frequencies from 25 to 90 Hz (5 Hz apart) miss the first resonance: the figure drew |H| A at the
    swept values only and wrote "linear peak 1.08 mm at 55 Hz". The curve is now evaluated on a fine grid with
    its peak refined: at the first free mode, 56.97 Hz (beta_1 L = 1.8751, closed form), times sqrt(1 - 2 xi^2)
    (1.1 % modal damping: a 1.2e-4 shift; tolerance 1e-3 for the neighbouring modes' share), and 3.5 mm."""
    pytest.importorskip("matplotlib")
    from pathlib import Path

    sc = ib.load_scenario(Path(__file__).resolve().parents[1] / "examples" / "periodic" / "specimen_harmonic.toml")
    fr = frequency_response(sc, np.linspace(25.0, 90.0, 14), sweep="up", settle_periods=20, record_periods=4)
    b = sc.beam
    f1 = 1.8751040687**2 / (2 * math.pi * b.length**2) * math.sqrt(b.bending_stiffness / b.mass_per_length)
    grid, amp = fr.linear_curve
    k = int(np.argmax(amp))
    assert grid[k] == pytest.approx(f1 * math.sqrt(1 - 2 * 0.011**2), rel=1e-3)
    assert amp[k] == pytest.approx(3.50e-3, rel=0.01) and amp[k] > 3 * fr.linear.max()
    handles = fr.plot()
    note = handles.artists["linear_peak"].get_text()
    assert f"{amp[k] * 1e3:.3g} mm" in note and f"{grid[k]:.4g} Hz" in note and "56.9" in note
