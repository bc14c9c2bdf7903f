"""The finite-element references of the dissipation models checked against closed forms and each other.

``fe_reference.fe_transient_exact`` (the FE model exact in time) and
``fe_transient_dissipative`` (Newmark) share the contact law and the damping
matrices, not the time integration; the closed forms are independent of both:

* a stiff free-free beam falling flat on a central spring-dashpot is a mass on
  a Kelvin-Voigt contact: ``x = v/w_d e^{-xi w t} sin(w_d t)``, released where
  ``k x + c x' = 0``, at ``w_d t_c = pi - atan(2 xi sqrt(1 - xi^2) / (1 - 2 xi^2))``,
  while still penetrated, leaving with ``x'(t_c)``;
* a mode released alone decays at ``alpha/2 + beta omega^2/2`` (Rayleigh) or
  ``xi omega`` (free-mode damping);
* the free-mode damping matrix is diagonal, ``2 xi omega``, in the free
  state's modes, and the same matrix in a contact state.

The cached references of ``fe_dissipation.py`` (the engine's dissipation
targets) are checked for what they claim: reproducible, converged to the
quoted measures.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import fe_dissipation as fd
import fe_reference as fr

L_KV, RHOA_KV, EI_KV = 1.0, 2.0, 1e9  # a free-free beam whose first elastic mode is at 80 kHz
K_KV, XI_KV, V_KV = 1e4, 0.15, 0.5


def _kelvin_voigt() -> tuple[float, float, float]:
    """Closed form of the mass on the spring-dashpot: contact time, exit speed / entry speed, penetration at release."""
    m = RHOA_KV * L_KV
    om = math.sqrt(K_KV / m)
    wd = om * math.sqrt(1 - XI_KV**2)
    tc = (math.pi - math.atan(2 * XI_KV * math.sqrt(1 - XI_KV**2) / (1 - 2 * XI_KV**2))) / wd
    e = math.exp(-XI_KV * om * tc)
    x = V_KV / wd * e * math.sin(wd * tc)
    xd = V_KV / wd * e * (wd * math.cos(wd * tc) - XI_KV * om * math.sin(wd * tc))
    return tc, -xd / V_KV, x


def _kv_run(integrator, dt: float):
    c = 2 * XI_KV * math.sqrt(K_KV * RHOA_KV * L_KV)
    return integrator(L_KV, EI_KV, RHOA_KV, left=(0.0, 0.0), right=(0.0, 0.0),
                      contactors=[dict(position=0.5, stiffness=K_KV, gap=0.0, side="below", damping=c)],
                      initial={"w_t": lambda x: -V_KV * np.ones_like(x)}, dt=dt, t_end=0.1, n_elements=8,
                      output_x=[0.5])


@pytest.mark.parametrize("integrator, dt, tol", [
    (fr.fe_transient_exact, 1e-4, 1e-5),
    (fr.fe_transient_dissipative, 5e-5, 3e-5),
])
def test_kelvin_voigt_impact(integrator, dt, tol):
    # Reason: the force-release event against the closed form of a mass on a spring-dashpot (xi = 15 %):
    # contact time, rebound speed (restitution 0.650) and the release while still penetrated (1.38 mm).
    # Measured: the exact integrator 4.4e-6 (contact time) and 1.6e-5 (speed), the same for any output step
    # (the beam's elastic modes, excited by the dashpot's force jump, not the integration); Newmark (dt = 50 us)
    # 1.2e-5 and 1.1e-4. Tolerances: 1e-5 / 3e-5 on the time, 10 x that on the speed.
    tc, e, x_rel = _kelvin_voigt()
    r = _kv_run(integrator, dt)
    kinds = [k for _, k, _ in r.events]
    assert kinds == ["impact", "rebound"]
    assert r.events[0][0] == 0.0
    assert r.events[1][0] == pytest.approx(tc, rel=tol)
    assert r.w_t[-1, 0] / V_KV == pytest.approx(e, rel=10 * tol)
    d, dd, f_before, f_after = r.event_state[1]
    assert d == pytest.approx(x_rel, rel=10 * tol) and f_after == 0.0
    assert abs(f_before) <= 1e-9 * K_KV * x_rel  # released where the force is zero, before d returns to 0


def test_kelvin_voigt_energy_goes_to_the_dashpot():
    # Reason: all the kinetic energy lost, 1/2 m v^2 (1 - e^2), is the dashpot's: its c d'^2 integral and the
    # spring energy left at release. Trapezoidal integration on the 100 us grid: measured 7e-6; tolerance 5e-5.
    tc, e, _ = _kelvin_voigt()
    r = _kv_run(fr.fe_transient_exact, 1e-4)
    lost = 0.5 * RHOA_KV * L_KV * V_KV**2 * (1 - e**2)
    assert r.dashpot[-1] == pytest.approx(lost, rel=5e-5)
    assert r.kinetic[0] - r.kinetic[-1] - r.strain[-1] == pytest.approx(r.dashpot[-1], rel=5e-5)


def test_exact_integrator_does_not_depend_on_the_output_step():
    # Reason: exact in time: the events and the samples common to two grids agree to round-off
    # (measured 1e-14 s and 3e-12 of the peak; tolerances 1e-12 s and 1e-9).
    a = fd.fe_run("dashpot_soft", 20, dt=2e-6)
    b = fd.fe_run("dashpot_soft", 20, dt=1e-6)
    ta, tb = (np.array([ev[0] for ev in r.events]) for r in (a, b))
    assert ta.size == tb.size and np.max(np.abs(ta - tb)) < 1e-12
    assert np.max(np.abs(a.w[:, 0] - b.w[::2, 0])) < 1e-9 * np.max(np.abs(a.w[:, 0]))


def test_exact_and_newmark_agree_without_a_dashpot():
    # Reason: two integrations of one FE model (Case 3 specimen, modal damping 1.1 % / 2 %): Newmark's error is
    # O(dt^2): at dt = 1 us the event times differ by at most 2e-8 s (measured); tolerance 1e-7 s.
    kw = dict(left=(math.inf, math.inf), right=(0.0, 0.0),
              contactors=[dict(position=0.4840 * 0.1092, stiffness=4030.0, gap=0.229e-3, side="above")],
              load=dict(kind="base_acceleration", amplitude=15 * 9.80665, duration=0.015),
              damping={"model": "modal", "free": 0.011, "contact": 0.02}, t_end=0.05, n_elements=20)
    EI = 1834e6 * 9.93e-3 * 3.03e-3**3 / 12
    rhoA = 951.98 * 9.93e-3 * 3.03e-3
    a = fr.fe_transient_exact(0.1092, EI, rhoA, dt=1e-6, **kw)
    b = fr.fe_transient_dissipative(0.1092, EI, rhoA, dt=1e-6, **kw)
    ta, tb = (np.array([ev[0] for ev in r.events]) for r in (a, b))
    assert ta.size == tb.size >= 4
    assert np.max(np.abs(ta - tb)) < 1e-7


@pytest.mark.parametrize("spec, rate", [
    ({"model": "rayleigh", "alpha": 13.5, "beta": 6e-6}, lambda w: 13.5 / 2 + 6e-6 * w**2 / 2),
    ({"model": "free_modes", "free": 0.015}, lambda w: 0.015 * w),
])
def test_a_single_mode_decays_at_its_rate(spec, rate):
    # Reason: released in its first FE mode, the cantilever stays in it and decays at exactly the model's
    # rate (exact integrator). Measured 4.6e-9 of the amplitude after 20 ms: a phase drift, the integrator's
    # eigh frequency and solve_modes' refined one differing by 6e-10; tolerance 2e-8.
    EI = 1834e6 * 9.93e-3 * 3.03e-3**3 / 12
    rhoA = 951.98 * 9.93e-3 * 3.03e-3
    model = fr.assemble(0.1092, EI, rhoA, n_elements=20, left=(math.inf, math.inf), right=(0.0, 0.0))
    om, Phi = fr.solve_modes(model, 1)
    x = model.x
    w1, th1 = Phi[0::2, 0], Phi[1::2, 0]
    r = fr.fe_transient_exact(0.1092, EI, rhoA, left=(math.inf, math.inf), right=(0.0, 0.0), damping=spec,
                              initial={"w": lambda xx: np.interp(xx, x, w1), "w_x": lambda xx: np.interp(xx, x, th1)},
                              dt=1e-5, t_end=0.02, n_elements=20, output_x=[0.1092])
    a, w = rate(om[0]), om[0]
    wd = math.sqrt(w**2 - a**2)
    t = r.t
    expected = w1[-1] * np.exp(-a * t) * (np.cos(wd * t) + a / wd * np.sin(wd * t))
    assert np.max(np.abs(r.w[:, 0] - expected)) < 2e-8 * abs(w1[-1])


def test_free_mode_damping_matrix_is_the_free_states_in_every_state():
    # Reason: the convention of code_aster and FE tools: C = M Phi diag(2 xi omega) Phi^T M of the free modes,
    # unchanged when a stop engages (unlike the per-state modal damping); Rayleigh takes the engaged K.
    model = fr.assemble(0.1092, 0.0422, 0.0286, n_elements=10, left=(math.inf, math.inf), right=(0.0, 0.0),
                        nodes_at=[0.05])
    om, Phi = fr.solve_modes(model)
    P = Phi[model.free]
    C = fr._beam_damping(model, {"model": "free_modes", "free": 0.015}, model.K_r, False, [])
    assert np.allclose(P.T @ C @ P, np.diag(2 * 0.015 * om), atol=1e-9 * om.max())
    i = model.reduced_index(2 * model.node_index(0.05))
    Ks = model.K_r.copy()
    Ks[i, i] += 1e5
    cache: list = []
    assert np.array_equal(fr._beam_damping(model, {"model": "free_modes", "free": 0.015}, Ks, True, cache),
                          fr._beam_damping(model, {"model": "free_modes", "free": 0.015}, model.K_r, False, cache))
    R = fr._beam_damping(model, {"model": "rayleigh", "alpha": 2.0, "beta": 1e-5}, Ks, True, [])
    assert np.array_equal(R, 2.0 * model.M_r + 1e-5 * Ks)


def test_reference_cases_are_the_documented_ones():
    # Reason: the scenarios the engine's tests run are the FE's cases: the same numbers on both sides.
    for name in fd.CASES:
        sc = fd.scenario(name)
        c = sc["contactors"][0]
        model, stop = name.rsplit("_", 1)
        assert c["stiffness"] == fd.STOPS[stop][0]
        assert c.get("damping", 0.0) == (fd.STOPS[stop][1] if model == "dashpot" else 0.0)
    # the damping ratios quoted in fe_dissipation's docstring (Rayleigh on the first three free modes)
    EI = fd.MODULUS * fd.WIDTH * fd.HEIGHT**3 / 12
    om, _ = fr.solve_modes(fr.assemble(fd.LENGTH, EI, fd.DENSITY * fd.WIDTH * fd.HEIGHT, n_elements=80,
                                       left=(math.inf, math.inf), right=(0.0, 0.0)), 3)
    xi = fd.RAYLEIGH[0] / (2 * om) + fd.RAYLEIGH[1] * om / 2
    assert [round(100 * v, 2) for v in xi] == [1.99, 0.97, 1.99]
    assert [round(f, 1) for f in om / (2 * math.pi)] == [57.0, 357.0, 999.7]
    # the dashpots' ratios c W(a)^2 / (2 omega) on the two engaged-state modes holding most of the stop's energy
    a = fd.POSITION_RATIO * fd.LENGTH
    for stop, ratios, freqs in (("soft", [3.7, 12.6], [108, 445]), ("stiff", [5.7, 11.2], [1157, 2415])):
        k, c = fd.STOPS[stop]
        m = fr.assemble(fd.LENGTH, EI, fd.DENSITY * fd.WIDTH * fd.HEIGHT, n_elements=80, left=(math.inf, math.inf),
                        right=(0.0, 0.0), springs=[(a, k)])
        om, Phi = fr.solve_modes(m, 8)
        Wa = Phi[2 * m.node_index(a)]
        top = sorted(np.argsort(k * Wa**2 / om**2)[-2:])
        assert [round(100 * c * Wa[j] ** 2 / (2 * om[j]), 1) for j in top] == ratios
        assert [round(om[j] / (2 * math.pi)) for j in top] == freqs


def test_cached_references_hold_what_they_claim():
    # Reason: the cache the engine's targets compare with: every case present, events alternating impact and
    # rebound from an impact, the first peak force the first contact's, histories on the stated grid.
    meta = json.loads(fd.JSON_FILE.read_text())
    assert meta["meshes"] == list(fd.MESHES)
    for name in fd.CASES:
        ref = fd.reference(name)
        kinds = [e[1] for e in ref["events"]]
        assert kinds[0] == "impact" and all(a != b for a, b in zip(kinds, kinds[1:]))
        assert ref["n_impacts"] == kinds.count("impact") == len(ref["contact_start"])
        assert ref["first_peak_force"] == ref["peak_force"][0][1] > 0
        assert ref["contact_start"][0] < ref["peak_force"][0][0] <= ref["contact_end"][0]
        assert ref["t_history"][-1] == pytest.approx(fd.END_TIME)
        assert ref["w_contactor"].shape == ref["t_history"].shape


@pytest.mark.slow
def test_cached_reference_is_reproducible():
    # Reason: the cache is what the code computes: the coarse mesh rerun reproduces the cached fine result's
    # differences exactly (deterministic; round-off of another BLAS: 1e-12 s allowed).
    name = "rayleigh_soft"
    ref = fd.reference(name)
    coarse = fd.summarise(fd.fe_run(name, fd.MESHES[0]))
    te_c = np.array([e[0] for e in coarse["events"]])
    te_f = np.array([e[0] for e in ref["events"]])
    assert te_c.size == te_f.size
    assert np.max(np.abs(te_c - te_f)) == pytest.approx(ref["convergence"]["event_time_change"], abs=1e-12)
