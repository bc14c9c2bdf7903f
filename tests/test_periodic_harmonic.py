"""Harmonic excitation: scenario keys, the time law, and the exact response.

The exact solver is checked against a modal solution written here by hand
(the classical forced response of an undamped oscillator from rest, also at
resonance) and against the ``solve_ivp`` reference path.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import impactbeam as ib
from impactbeam.exceptions import ParameterError, ScenarioError
from impactbeam.model.loading import Excitation, time_pieces
from impactbeam.modal import mode_set
from impactbeam.scenario import parse_scenario

BEAM = {
    "length": 0.10920, "width": 9.93e-3, "height": 3.03e-3,
    "youngs_modulus": "1834 MPa", "density": "951.98 kg/m^3",
}


def _raw(excitation: dict, *, contact: bool = False, damping: float = 0.0, end: float = 0.1) -> dict:
    raw = {
        "beam": dict(BEAM),
        "supports": {"left": "clamped", "right": "free"},
        "damping": {"free": damping, "contact": damping},
        "excitation": excitation,
        "solver": {"modes": 6, "end_time": end},
        "output": {"points": [0.0528528, 0.10920]},
    }
    if contact:
        raw["contactors"] = [{"position_ratio": 0.484, "stiffness": 4030, "gap": "0.1 mm", "side": "above"}]
    return raw


def test_scenario_keys_and_units():
    ex = {"kind": "base_acceleration", "shape": "harmonic", "amplitude": "1 g", "frequency": "0.06 kHz",
          "phase": "90 deg", "start": "5 ms"}
    e = parse_scenario(_raw(ex)).excitation
    assert e.shape == "harmonic"
    assert e.frequency == pytest.approx(60.0, rel=1e-15)
    assert e.phase == pytest.approx(math.pi / 2, rel=1e-15)
    assert e.start == pytest.approx(5e-3, rel=1e-15)
    assert e.end_time() == math.inf


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"frequency": None}, "excitation.frequency"),
        ({"frequency": "2 ms"}, "excitation.frequency"),
        ({"frequency": 0}, "excitation.frequency"),
        ({"phase": "1 m"}, "excitation.phase"),
        ({"shape": "half_sine", "duration": 0.01}, "excitation.frequency"),
    ],
)
def test_scenario_errors_name_the_field(change, field):
    ex = {"kind": "base_acceleration", "shape": "harmonic", "amplitude": "1 g", "frequency": 60.0}
    for k, v in change.items():
        if v is None:
            ex.pop(k)
        else:
            ex[k] = v
    with pytest.raises(ScenarioError, match=field.replace(".", r"\.")):
        parse_scenario(_raw(ex))


def test_object_needs_frequency():
    with pytest.raises(ParameterError, match="excitation.frequency"):
        Excitation(kind="point_force", shape="harmonic", amplitude=1.0, position=0.1)


def test_history_matches_time_law_and_pieces():
    e = Excitation(kind="point_force", shape="harmonic", amplitude=2.0, position=0.1, frequency=37.0,
                   phase=0.4, start=0.013, scale=1.5)
    t = np.linspace(0.0, 0.2, 1001)
    expect = np.where(t >= 0.013, 3.0 * np.sin(2 * np.pi * 37.0 * (t - 0.013) + 0.4), 0.0)
    # tolerance: the same formula evaluated twice, up to a few ulps of the argument
    np.testing.assert_allclose(e.history(t), expect, rtol=0, atol=1e-13)
    pieces = time_pieces(e, 0.2)
    got = np.array([next(p for p in pieces if p.t0 <= ti <= p.t1).value(ti) for ti in t])
    np.testing.assert_allclose(got, expect, rtol=0, atol=1e-12)


def _by_hand(beam, n_modes: int, x: float, t: np.ndarray, amp: float, Om: float) -> np.ndarray:
    """Undamped forced response from rest under ``-rhoA int W_n amp sin(Om t)``, summed over modes."""
    ms = mode_set(beam, (), n_modes)
    p = -ms.inertia_integral() * amp
    W = ms.shapes([x])[:, 0]
    w = np.zeros_like(t)
    for n in range(ms.count):
        wn = ms.omega[n]
        if abs(wn - Om) < 1e-12 * wn:  # resonance: secular growth
            eta = p[n] / (2 * wn**2) * (np.sin(wn * t) - wn * t * np.cos(wn * t))
        else:
            eta = p[n] / (wn**2 - Om**2) * (np.sin(Om * t) - Om / wn * np.sin(wn * t))
        w += W[n] * eta
    return w


@pytest.mark.parametrize("which", ["resonance", "between"])
def test_undamped_exact_against_hand_solution(which):
    """Exact for every regime, including forcing exactly at a natural frequency."""
    sc0 = parse_scenario(_raw({"kind": "none"}))
    f1 = float(ib.modes(sc0).free.frequencies_hz[0])
    f = f1 if which == "resonance" else 1.7 * f1
    sc = parse_scenario(_raw({"kind": "base_acceleration", "shape": "harmonic", "amplitude": 1.0, "frequency": f}))
    res = ib.simulate(sc)
    t = np.linspace(0.0, 0.1, 401)
    got = res.displacement([0.10920], t)[0]
    want = _by_hand(sc.beam, 6, 0.10920, t, 1.0, 2 * np.pi * f)
    scale = np.max(np.abs(want))
    # tolerance: both are closed forms of the same 6-mode model, so they agree to round-off (4e-16 of
    # the peak measured); 1e-12 leaves room for other BLAS while any error of the law would be O(1)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * scale)


def test_contact_against_ivp_reference():
    """With a contactor: the exact engine and the solve_ivp reference (rtol 1e-10) agree."""
    raw = _raw({"kind": "base_acceleration", "shape": "harmonic", "amplitude": "1 g", "frequency": 60.0,
                "phase": 0.3}, contact=True, damping=0.01, end=0.15)
    sc = parse_scenario(raw)
    a, b = ib.simulate(sc), ib.simulate(sc, method="ivp")
    ta = [e.time for e in a.events]
    tb = [e.time for e in b.events]
    assert len(ta) == len(tb) > 4
    # tolerance: the reference locates events to ~1e-9 s with rtol 1e-10 over 0.15 s
    np.testing.assert_allclose(ta, tb, rtol=0, atol=1e-7)


@pytest.mark.parametrize("where", ["free", "contact"])
def test_continuation_from_final_state_is_seamless(where):
    """A run started from another's final state continues it: same w and events as one long run.

    Split inside a contact interval too (the state is carried into the free basis and back).
    """
    ex = {"kind": "base_acceleration", "shape": "harmonic", "amplitude": "1 g", "frequency": 60.0}
    whole = ib.simulate(parse_scenario(_raw(ex, contact=True, damping=0.01, end=0.3)))
    ev = whole.events
    if where == "free":
        split = 10 / 60.0
    else:
        i = next(k for k, e in enumerate(ev) if e.kind == "impact" and e.time > 0.1)
        split = 0.5 * (ev[i].time + ev[i + 1].time)
    first = ib.simulate(parse_scenario(_raw(ex, contact=True, damping=0.01, end=split)))
    # the second run restarts the clock at 0, so shift the load by the split (phase continuity)
    ex2 = dict(ex, phase=2 * np.pi * 60.0 * split)
    second = ib.simulate(parse_scenario(_raw(ex2, contact=True, damping=0.01, end=0.3 - split)),
                         start=first.final_state())
    t = np.linspace(0.0, 0.3 - split, 500)
    got = second.displacement([0.0528528, 0.10920], t)
    want = whole.displacement([0.0528528, 0.10920], t + split)
    # tolerance: the change of basis is orthogonal (exact); 1e-12 of the peak is a few hundred ulps
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())
    later = [e.time - split for e in ev if e.time > split + 1e-12]
    mine = [e.time for e in second.events if e.time > 1e-12]
    assert len(mine) == len(later)
    # tolerance: event times located to solver.event_tolerance (1e-13 s) in each run
    np.testing.assert_allclose(mine, later, rtol=0, atol=1e-11)


def test_start_from_another_basis_is_refused():
    ex = {"kind": "base_acceleration", "shape": "harmonic", "amplitude": "1 g", "frequency": 60.0}
    a = ib.simulate(parse_scenario(_raw(ex, contact=True, end=0.02)))
    raw = _raw(ex, contact=True, end=0.02)
    raw["solver"]["modes"] = 5
    with pytest.raises(ParameterError, match="start"):
        ib.simulate(parse_scenario(raw), start=a.final_state())
