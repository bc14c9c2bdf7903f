"""Periodic orbits by shooting (:mod:`impactbeam.periodic.shooting`) and ``impactbeam periodic``.

Independent checks:

* linear beam (no contactor): the multipliers are ``exp((-xi w +- i w_d) T)``
  for each mode and the strobe values the classical steady-state modal
  response, both written here from the modes alone;
* with contact: the exact Jacobian of the event-driven map against central
  finite differences of the map, the orbit against a long plain simulation,
  and the quadratic decrease of Newton's residual;
* an unstable orbit: a plain run started on it, displaced along the
  unstable eigenvector, departs at the rate of the largest multiplier.
"""

from __future__ import annotations

import dataclasses
import json
import math
import warnings

import numpy as np
import pytest
from click.testing import CliRunner

import impactbeam as ib
from impactbeam.exceptions import ImpactBeamWarning, ParameterError
from impactbeam.modal import mode_set
from impactbeam.periodic._saltation import to_free
from impactbeam.periodic.shooting import StroboscopicMap, periodic_orbit
from impactbeam.scenario import parse_scenario

BEAM = {
    "length": 0.10920, "width": 9.93e-3, "height": 3.03e-3,
    "youngs_modulus": "1834 MPa", "density": "951.98 kg/m^3",
}
A_CONTACT = 0.484 * 0.10920


def _raw(*, frequency: float = 55.0, amplitude: str = "0.5 g", contact: bool = True, basis: str = "enriched",
         phase: float = 0.0, start: float = 0.0, end: float = 0.5) -> dict:
    """The specimen cantilever of examples/specimen.toml under harmonic base excitation, gap 0.1 mm."""
    raw = {
        "beam": dict(BEAM),
        "supports": {"left": "clamped", "right": "free"},
        "damping": {"free": 0.011, "contact": 0.02},
        "excitation": {"kind": "base_acceleration", "shape": "harmonic", "amplitude": amplitude,
                       "frequency": frequency, "phase": phase, "start": start},
        "solver": {"modes": 6, "end_time": end, "basis": basis},
        "output": {"points": [A_CONTACT, 0.10920]},
    }
    if contact:
        raw["contactors"] = [{"position_ratio": 0.484, "stiffness": 4030, "gap": "0.1 mm", "side": "above"}]
    return raw


def _fd_jacobian(pmap, x: np.ndarray, rel: float = 1e-5) -> np.ndarray:
    """Central differences of the map, step ``rel`` of |x| in the map's energy norm, per coordinate."""
    n = x.size
    J = np.empty((n, n))
    for i in range(n):
        h = rel * pmap.norm(x) / pmap.weights[i]
        e = np.zeros(n)
        e[i] = h
        J[:, i] = (pmap(x + e) - pmap(x - e)) / (2.0 * h)
    return J


def _scaled(pmap, J: np.ndarray) -> np.ndarray:
    """``J`` in the coordinates of the energy norm (``omega eta, eta_t``), where entries are comparable."""
    W = pmap.weights
    return W[:, None] * J / W[None, :]


# --------------------------------------------------------------------------- linear beam


@pytest.mark.parametrize("multiple", [1, 2])
def test_linear_multipliers_and_strobe_are_the_modal_closed_form(multiple):
    phase, start = 0.7, 3e-3
    sc = parse_scenario(_raw(frequency=40.0, amplitude="2 g", contact=False, phase=phase, start=start, end=0.3))
    orbit = periodic_orbit(sc, multiple=multiple)
    assert orbit.converged and orbit.stable and orbit.impacts_per_period == 0
    T = multiple / 40.0
    assert orbit.period == pytest.approx(T, rel=1e-15)
    ms = mode_set(sc.beam, (), 6)
    xi = 0.011
    lam = -xi * ms.omega + 1j * ms.omega * math.sqrt(1 - xi**2)
    expected = np.concatenate([np.exp(lam * T), np.exp(np.conj(lam) * T)])
    got = orbit.multipliers
    # each analytic multiplier is found to round-off (1e-12 of the largest, |mu| ~ 0.9): the
    # transition matrices are the same closed form, evaluated in another way
    for mu in expected:
        assert np.min(np.abs(got - mu)) < 1e-12
    assert got.size == expected.size
    # steady-state modal response eta_n = Im(p_n A e^{i theta} / (w^2 - W^2 + 2 i xi w W)), p_n = -rho A int W_n
    Om = 2 * math.pi * 40.0
    A = 2 * 9.80665
    p = -sc.beam.mass_per_length * ms.integral()
    H = p * A / (ms.omega**2 - Om**2 + 2j * xi * ms.omega * Om)
    theta = 2 * math.pi * 40.0 * (orbit.strobe_times - start) + phase
    w_exact = (ms.shapes([A_CONTACT])[:, 0] * H) @ np.exp(1j * theta[None, :]).repeat(H.size, axis=0)
    # same N-mode model: round-off only (1e-9 of the response leaves room for the modes' own accuracy)
    np.testing.assert_allclose(orbit.strobe, w_exact.imag, rtol=1e-9, atol=1e-9 * np.abs(H).sum())
    assert np.allclose(orbit.strobe_times, start + np.round((orbit.strobe_times - start) * 40.0) / 40.0,
                       rtol=0, atol=1e-12)


# --------------------------------------------------------------------------- with contact


@pytest.fixture(scope="module", params=["enriched", "paper"])
def contact_orbit(request):
    sc = parse_scenario(_raw(basis=request.param))
    return sc, periodic_orbit(sc, settle_periods=30)


def test_newton_converges_quadratically_from_the_settled_state(contact_orbit):
    sc, orbit = contact_orbit
    r = np.array(orbit.residuals)
    assert orbit.converged and orbit.stable and orbit.impacts_per_period >= 1
    assert r[-1] <= 1e-11 and orbit.iterations <= 6
    assert r[0] > 1e-3  # the settled state is a real start, not the answer already
    # quadratic: r_{k+1} <= C r_k^2 for every step above round-off (1e-13); C = 10 from the measured
    # constants 0.1-2.2; a linearly convergent iteration (r_{k+1} ~ q r_k) fails this once r_k < q/10
    asymptotic = [(a, b) for a, b in zip(r[:-1], r[1:]) if b > 1e-13]
    assert len(asymptotic) >= 2
    for a, b in asymptotic:
        assert b <= 10.0 * a * a, (a, b, orbit.residuals)


def test_orbit_reproduces_itself_over_its_period(contact_orbit):
    sc, orbit = contact_orbit
    T = orbit.period
    sol = orbit.map.solve(orbit.state, duration=3 * T)
    tau = np.linspace(0.0, T, 41)
    s = [sol.sample(np.array([A_CONTACT, sc.beam.length]), tau + k * T) for k in range(3)]
    scale = np.abs(s[0].w).max(axis=0)
    vscale = np.abs(s[0].w_t).max(axis=0)
    # 1e-10 relative: the fixed point is solved to 1e-11 in the energy norm (conditioning 1/(1 - |mu|) ~ 10)
    for k in (1, 2):
        assert np.max(np.abs(s[k].w - s[0].w) / scale) < 1e-10
        assert np.max(np.abs(s[k].w_t - s[0].w_t) / vscale) < 1e-10
    assert sum(ev.kind == "impact" for ev in sol.events) == 3 * orbit.impacts_per_period


def test_orbit_is_the_steady_state_of_a_long_simulation(contact_orbit):
    sc, orbit = contact_orbit
    f = 55.0
    n_per = 400  # the slowest multiplier (|mu| < 0.95) has decayed by 1e-9 after 400 periods
    assert abs(orbit.multipliers[0]) ** n_per < 1e-8
    res = ib.simulate(sc.with_values({"solver.end_time": n_per / f}))
    t = n_per / f - orbit.period * np.linspace(0.0, 1.0, 64)
    w_sim = res.solution.sample(np.array([A_CONTACT, sc.beam.length]), t).w
    tau = np.mod(t - orbit.section_time, orbit.period)
    w_orb = orbit.map.solve(orbit.state).sample(np.array([A_CONTACT, sc.beam.length]), tau).w
    scale = np.abs(w_orb).max(axis=0)
    assert np.max(np.abs(w_sim - w_orb) / scale) < 1e-8
    k = np.round((orbit.strobe_times - sc.excitation.start) * f)
    assert np.allclose(orbit.strobe_times, k / f, rtol=0, atol=1e-12)
    np.testing.assert_allclose(res.solution.sample(np.array([A_CONTACT]), np.array([n_per / f])).w[0, 0],
                               orbit.strobe[-1], rtol=0, atol=1e-8 * scale[0])


def test_multipliers_match_finite_differences_of_the_map(contact_orbit):
    sc, orbit = contact_orbit
    pmap, x = orbit.map, orbit.state
    J_fd = _fd_jacobian(pmap, x)
    A, B = _scaled(pmap, orbit.jacobian), _scaled(pmap, J_fd)
    # step 1e-5 of |x|: central-difference truncation ~1e-10 (measured 8e-8 at 1e-4, falling as h^2)
    # and the map's round-off (1e-14) / h ~ 1e-9; 1e-7 leaves a factor ~100. Leaving out the
    # event-time terms of the saltation matrices (the damping changes at a switch) gives 2e-2.
    assert np.linalg.norm(A - B) / np.linalg.norm(A) < 1e-7
    mu_fd = np.linalg.eigvals(J_fd)
    for mu in orbit.multipliers:
        assert np.min(np.abs(mu_fd - mu)) < 1e-6  # |mu| <= 1: absolute is relative to the largest
    assert orbit.stable == (np.abs(mu_fd).max() < 1.0)


def test_several_contactors_overlapping_contacts_match_finite_differences():
    """Stops on both sides at the contact point and one at the tip: states with two contactors engaged."""
    raw = _raw(frequency=55.0, amplitude="1 g")
    raw["contactors"] += [
        {"position_ratio": 0.484, "stiffness": 4030, "gap": "0.1 mm", "side": "below"},
        {"position_ratio": 1.0, "stiffness": 2000, "gap": "0.3 mm", "side": "below"},
    ]
    orbit = periodic_orbit(parse_scenario(raw), settle_periods=40)
    assert orbit.converged and orbit.stable
    events = orbit.map.solve(orbit.state).events
    assert {ev.contactor for ev in events} == {0, 1, 2} and orbit.impacts_per_period == 4
    J_fd = _fd_jacobian(orbit.map, orbit.state, rel=3e-6)
    A, B = _scaled(orbit.map, orbit.jacobian), _scaled(orbit.map, J_fd)
    # eight events make the map's second derivative larger: truncation 2e-6 at a step of 1e-4,
    # falling as h^2 to 3e-9 at 3e-6 (measured); 1e-7 leaves a factor ~30
    assert np.linalg.norm(A - B) / np.linalg.norm(A) < 1e-7
    mu_fd = np.linalg.eigvals(J_fd)
    for mu in orbit.multipliers:
        assert np.min(np.abs(mu_fd - mu)) < 1e-6


def _with_law(law: str) -> dict:
    raw = _raw(frequency=55.0, amplitude="0.5 g", basis="paper" if law == "dashpot, paper basis" else "enriched")
    if law.startswith("dashpot"):
        raw["contactors"][0]["damping"] = 0.5
    elif law == "restitution":
        raw["contactors"][0]["restitution"] = 0.7
    elif law == "free_modes":
        raw["damping"] = {"model": "free_modes", "free": 0.011}
    elif law == "rayleigh":
        raw["damping"] = {"model": "rayleigh", "alpha": 5.0, "beta": 1e-5}
    return raw


@pytest.mark.parametrize("law", ["dashpot", "restitution", "free_modes", "rayleigh", "dashpot, paper basis"])
def test_every_damping_law_matches_finite_differences(law):
    """Contact states whose modes do not diagonalise their damping (dashpots, free-mode damping): the segment
    transition through the state's 2 x 2 blocks, the vector field with its damping matrix, and a dashpot's
    release where its force k d + c d' vanishes (a switching function of the velocity too)."""
    orbit = periodic_orbit(parse_scenario(_with_law(law)), settle_periods=40)
    assert orbit.converged and orbit.stable and orbit.impacts_per_period == 1
    J_fd = _fd_jacobian(orbit.map, orbit.state)
    A, B = _scaled(orbit.map, orbit.jacobian), _scaled(orbit.map, J_fd)
    # as test_multipliers_match_finite_differences_of_the_map: measured 5e-10 to 2.4e-9; the release's
    # gradient without its velocity term gives 3.5e-3 (dashpot) and 1.6e-2 (restitution)
    assert np.linalg.norm(A - B) / np.linalg.norm(A) < 1e-7
    mu_fd = np.linalg.eigvals(J_fd)
    for mu in orbit.multipliers:
        assert np.min(np.abs(mu_fd - mu)) < 1e-6


def test_dashpot_orbit_is_the_steady_state_of_a_long_simulation():
    """The orbit found with a dashpot stop is where a plain run from rest settles (an independent check)."""
    sc = parse_scenario(_with_law("dashpot"))
    orbit = periodic_orbit(sc, settle_periods=40)
    n_per = 300  # |mu| <= 0.88: decayed by 1e-17
    assert np.abs(orbit.multipliers).max() ** n_per < 1e-12
    res = ib.simulate(sc.with_values({"solver.end_time": n_per / 55.0}))
    t = n_per / 55.0 - orbit.period * np.linspace(0.0, 1.0, 64)
    pts = np.array([A_CONTACT, sc.beam.length])
    w_sim = res.solution.sample(pts, t).w
    w_orb = orbit.map.solve(orbit.state).sample(pts, np.mod(t - orbit.section_time, orbit.period)).w
    # as test_orbit_is_the_steady_state_of_a_long_simulation: 1e-8 of the amplitude (measured 5e-13)
    assert np.max(np.abs(w_sim - w_orb) / np.abs(w_orb).max(axis=0)) < 1e-8


def test_dashpot_re_engaged_by_its_force_while_still_compressed():
    """A dashpot stop released while still compressed (its force k d + c d' reached zero first) is engaged
    again by that force before its compression is gone: that switch's function is the force too."""
    raw = _raw(frequency=45.0, amplitude="1 g")
    raw["contactors"][0]["damping"] = 5.0
    raw["contactors"].append({"position_ratio": 1.0, "stiffness": 3000, "gap": "0.2 mm", "side": "below",
                              "damping": 2.5})
    orbit = periodic_orbit(parse_scenario(raw), settle_periods=40)
    assert orbit.converged and orbit.stable
    sol = orbit.map.solve(orbit.state)
    kinds, depth = sol.event_arrays[1], sol.event_penetrations
    assert np.any((kinds == 1) & (depth > 1e-6))  # an impact 2.6 um deep: the released phase's re-engagement
    J_fd = _fd_jacobian(orbit.map, orbit.state)
    A, B = _scaled(orbit.map, orbit.jacobian), _scaled(orbit.map, J_fd)
    # measured 3.6e-9; taking that re-engagement's function for the opening gives 3.2e-2
    assert np.linalg.norm(A - B) / np.linalg.norm(A) < 1e-7


def test_multipliers_do_not_depend_on_the_section():
    """Shared Ritz basis: a section in the middle of the contact gives the same orbit and multipliers.

    The map then starts inside the contact state (the solver switches at t = 0) and ends in it, so the
    transfers into and out of the free state's coordinates enter the Jacobian; the multipliers of the
    conjugate map are the same (to round-off: 1e-12) and so is the strobe.
    """
    sc = parse_scenario(_raw(basis="enriched"))
    orbit = periodic_orbit(sc, settle_periods=30)
    sol = orbit.map.solve(orbit.state)
    t_in = [ev.time for ev in sol.events if ev.kind == "impact"][0]
    t_out = [ev.time for ev in sol.events if ev.kind == "rebound" and ev.time > t_in][0]
    tc = 0.5 * (t_in + t_out)
    j = int(sol.segment_index(np.array([tc]))[0])
    assert sol.engaged(j) == (0,)
    smp = sol.sample(np.array([0.0]), np.array([tc]), modal=True)
    x = to_free(sol.packed, int(sol.slot[j])) @ np.concatenate([smp.eta[0], smp.eta_t[0]])
    pmap = StroboscopicMap(sc, 1, (orbit.map.phase + tc * 55.0) % 1.0, orbit.map.options.modes)
    moved = periodic_orbit(sc, guess=dataclasses.replace(orbit, map=pmap, state=x, section_time=orbit.section_time + tc))
    assert moved.converged and moved.impacts_per_period == orbit.impacts_per_period
    for mu in orbit.multipliers:
        assert np.min(np.abs(moved.multipliers - mu)) < 1e-12
    np.testing.assert_allclose(moved.strobe, orbit.strobe, rtol=1e-10)
    assert moved.section_time == pytest.approx(orbit.section_time + tc, rel=1e-12)
    assert moved.section_time < moved.strobe_times[0] <= moved.section_time + moved.period


def test_unstable_orbit_past_the_fold_is_reported_unstable():
    """Continue the impacting orbit up in frequency, then search between it and the non-impacting one.

    The resonance of the contacting beam bends to higher frequency (the contact stiffens it): beyond
    ~72 Hz the impacting orbit coexists with a non-impacting one, separated by a saddle that Newton
    finds from a guess between the two.
    """
    raw = _raw(frequency=65.0, amplitude="1 g")
    orbit = periodic_orbit(parse_scenario(raw), settle_periods=30)
    for f in (66.0, 67.0, 68.0, 69.0, 70.0, 71.0, 72.0):
        raw["excitation"]["frequency"] = f
        orbit = periodic_orbit(parse_scenario(raw), guess=orbit, max_iterations=30)
        assert orbit.converged and orbit.stable and orbit.impacts_per_period == 1
    sc = parse_scenario(raw)
    low = periodic_orbit(sc, guess=dataclasses.replace(orbit, state=0.0 * orbit.state))
    assert low.converged and low.stable and low.impacts_per_period == 0
    saddle = periodic_orbit(sc, guess=dataclasses.replace(orbit, state=0.1 * orbit.state + 0.9 * low.state),
                            max_iterations=40)
    assert saddle.converged and not saddle.stable
    mu = saddle.multipliers[0]
    assert abs(mu.imag) < 1e-12 and mu.real > 1.0 + 1e-3  # a saddle: one real multiplier outside
    pmap, x = saddle.map, saddle.state
    for other in (orbit, low):
        assert pmap.norm(other.state - x) > 1e-3 * pmap.norm(x)
    # a plain run from the saddle displaced along the unstable eigenvector departs like mu^k
    w, V = np.linalg.eig(saddle.jacobian)
    v = np.real(V[:, np.argmax(np.abs(w))])
    v *= 1e-9 * pmap.norm(x) / pmap.norm(v)
    n = 20
    t = saddle.period * np.arange(n + 1)
    xc = np.array([A_CONTACT])
    base = pmap.solve(x, duration=n * saddle.period).sample(xc, t).w[:, 0]
    moved = pmap.solve(x + v, duration=n * saddle.period).sample(xc, t).w[:, 0]
    d = np.abs(moved - base)
    rate = (d[n] / d[10]) ** (1.0 / (n - 10))
    # the other modes' share decays like 0.95^k: after 10 periods it biases the rate by < 1e-3
    assert rate == pytest.approx(mu.real, rel=2e-3)


def test_grazing_contact_is_warned_about():
    """Scale the forcing so that the linear orbit just reaches the contactor: a grazing impact."""
    raw = _raw(frequency=50.0, amplitude=1.0)
    raw["contactors"][0]["gap"] = 1.0  # never reached: the linear orbit, in the same basis
    lin = periodic_orbit(parse_scenario(raw))
    w_max, _ = lin.map.solve(lin.state).extremum(A_CONTACT, 0.0, lin.period)
    # penetration 3e-9 of the gap: normal velocity ~ sqrt(2 * 3e-9) ~ 8e-5 of the orbit's scale, below 1e-4
    raw = _raw(frequency=50.0, amplitude=1e-4 / w_max * (1 + 3e-9))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ImpactBeamWarning)
        orbit = periodic_orbit(parse_scenario(raw), settle_periods=200)
    texts = [str(w.message) for w in caught if issubclass(w.category, ImpactBeamWarning)]
    assert any("grazing" in t for t in texts), texts
    assert orbit.impacts_per_period == 1
    assert any("grazing" in t for t in orbit.warnings)


# --------------------------------------------------------------------------- bad input


@pytest.mark.parametrize("multiple", [0, -1, 1.5, True])
def test_multiple_must_be_a_whole_number_of_periods(multiple):
    with pytest.raises(ParameterError, match="multiple"):
        periodic_orbit(parse_scenario(_raw()), multiple=multiple)


def test_without_harmonic_excitation_the_field_is_named():
    raw = _raw()
    raw["excitation"] = {"kind": "base_acceleration", "shape": "half_sine", "amplitude": "15 g",
                         "duration": "15 ms"}
    with pytest.raises(ParameterError, match="excitation.shape"):
        periodic_orbit(parse_scenario(raw))
    raw["excitation"] = {"kind": "none"}
    with pytest.raises(ParameterError, match="excitation.kind"):
        periodic_orbit(parse_scenario(raw))


def test_too_short_a_settling_run_names_the_field():
    with pytest.raises(ParameterError, match="solver.end_time"):
        periodic_orbit(parse_scenario(_raw(end=0.01)), multiple=1)


def test_no_convergence_warns_and_says_so():
    sc = parse_scenario(_raw())
    with pytest.warns(ImpactBeamWarning, match="did not converge"):
        orbit = periodic_orbit(sc, settle_periods=2, max_iterations=1)
    assert not orbit.converged and not orbit.stable
    assert orbit.residuals[-1] > 1e-11
    assert orbit.to_dict()["converged"] is False


# --------------------------------------------------------------------------- command line


def _toml(raw: dict) -> str:
    lines = []
    for table, body in raw.items():
        if isinstance(body, list):
            for item in body:
                lines.append(f"[[{table}]]")
                lines += [f"{k} = {json.dumps(v)}" for k, v in item.items()]
        else:
            lines.append(f"[{table}]")
            lines += [f"{k} = {json.dumps(v)}" for k, v in body.items()]
    return "\n".join(lines) + "\n"


def _cli(args: list[str]):
    from impactbeam.cli import main

    return CliRunner().invoke(main, args, catch_exceptions=False)


def test_cli_json(tmp_path):
    path = tmp_path / "h.toml"
    path.write_text(_toml(_raw(frequency=60.0)))
    out = _cli(["periodic", str(path), "--json"])
    assert out.exit_code == 0, out.output
    data = json.loads(out.stdout)
    for key in ("converged", "multiple", "period", "strobe", "multipliers", "stable", "impacts_per_period",
                "warnings"):
        assert key in data
    assert data["converged"] is True and data["multiple"] == 1 and data["warnings"] == []
    assert data["period"] == pytest.approx(1 / 60.0, rel=1e-15)
    assert len(data["strobe"]) == 1 and all(len(m) == 2 for m in data["multipliers"])
    assert data["stable"] == (max(math.hypot(*m) for m in data["multipliers"]) < 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ImpactBeamWarning)
        api = periodic_orbit(parse_scenario(_raw(frequency=60.0)))
    assert data["strobe"][0] == pytest.approx(float(api.strobe[0]), rel=1e-12)


def test_cli_bad_input_exits_2(tmp_path):
    path = tmp_path / "h.toml"
    path.write_text(_toml(_raw()))
    out = _cli(["periodic", str(path), "--multiple", "0"])
    assert out.exit_code == 2 and out.stderr.startswith("error: --multiple: ") and "Traceback" not in out.output
    out = _cli(["periodic", str(path), "--max-iterations", "-1"])  # the option as typed, not the API's max_iterations
    assert out.exit_code == 2 and out.stderr.startswith("error: --max-iterations: ")
    raw = _raw()
    raw["excitation"] = {"kind": "base_acceleration", "shape": "step", "amplitude": 1.0}
    path.write_text(_toml(raw))
    out = _cli(["periodic", str(path)])
    assert out.exit_code == 2 and "excitation.shape" in out.stderr


def test_cli_not_converged_reports_false_with_a_warning(tmp_path):
    path = tmp_path / "h.toml"
    path.write_text(_toml(_raw()))
    out = _cli(["periodic", str(path), "--settle-periods", "2", "--max-iterations", "1", "--json"])
    assert out.exit_code == 0
    data = json.loads(out.stdout)
    assert data["converged"] is False and data["stable"] is False
    assert any("did not converge" in w for w in data["warnings"])


def test_a_switch_made_at_once_by_the_one_before_moves_with_its_instant():
    # Found by a random hunt (harmonic loads on the random systems of the tests, exact Jacobian against
    # central differences): with the paper's basis an impact's projection can leave a restitution stop's force
    # negative, and the engine releases it at the same instant (c0 strikes, c1 lets go, at 19.1 ms). The
    # saltation took that release as a crossing of its own function: multipliers 0.133 where the map's are
    # 0.0988, the Jacobian 0.73 off. The instant is set by the first switch; the whole jump moves with it.
    # Tolerance: measured 1.1e-7 at a step of 1e-5 (3.3e-7 at 1e-6: central differences' round-off); 1e-6
    # leaves a factor 9. (A residual of 2.5e-6 was left until the switch undone at its instant, at 15.19 ms,
    # was restored: test_switches_undone_at_their_instant_are_in_the_jacobian.)
    raw = {"beam": {"length": 0.1092, "width": 0.00993, "height": 0.00303, "youngs_modulus": 1834e6,
                    "density": 951.98, "sections": [{"length": 0.04, "height": 0.004}, {"length": 0.0692}]},
           "supports": {"left": {"translational": "inf", "rotational": 50.0}, "right": "sliding"},
           "masses": [{"position_ratio": 0.44, "mass": 0.005}],
           "contactors": [{"position_ratio": 0.755, "stiffness": 18532.06, "gap": 1e-4, "side": "below",
                           "restitution": 0.95},
                          {"position_ratio": 0.586, "stiffness": 2671.699, "gap": 1e-5, "side": "above",
                           "restitution": 0.3}],
           "damping": {"free": 1.0, "contact": 0.0},
           "excitation": {"kind": "base_acceleration", "shape": "harmonic", "amplitude": 147.15, "frequency": 30.0},
           "preload": {"kind": "base_acceleration", "amplitude": 9.81},
           "solver": {"modes": 16, "end_time": 1.0, "basis": "paper"}}
    orbit = periodic_orbit(parse_scenario(raw), settle_periods=60)
    assert orbit.converged and orbit.stable
    events = [(ev.kind, ev.contactor, ev.time) for ev in orbit.map.solve(orbit.state).events]
    assert any(a[2] == b[2] and a[1] != b[1] for a, b in zip(events, events[1:]))  # two switches at one instant
    J_fd = _fd_jacobian(orbit.map, orbit.state)
    A, B = _scaled(orbit.map, orbit.jacobian), _scaled(orbit.map, J_fd)
    assert np.linalg.norm(A - B) / np.linalg.norm(A) < 1e-6
    mu_fd = np.linalg.eigvals(J_fd)
    # the largest multiplier: measured 3.6e-9 apart; the old code's was 0.034 off
    assert abs(np.abs(orbit.multipliers).max() - np.abs(mu_fd).max()) < 1e-7


_TURN_BACK = {  # the paper's basis, 4 modes, a stiff dashpot stop (its projection warned at every switch)
    "beam": {"length": 0.1092, "width": 0.00993, "height": 0.00303, "youngs_modulus": 1834e6, "density": 951.98,
             "sections": [{"length": 0.04, "height": 0.004}, {"length": 0.0692}]},
    "supports": {"left": "clamped", "right": {"translational": "inf", "rotational": 50.0}},
    "contactors": [{"position_ratio": 0.353, "stiffness": 285673.5, "gap": 5e-05, "side": "below", "damping": 0.3837},
                   {"position_ratio": 0.959, "stiffness": 708.29, "gap": 0.0001, "side": "below", "damping": 0.5707}],
    "damping": {"free": 0.01, "contact": 2.0},
    "excitation": {"kind": "point_force", "shape": "harmonic", "amplitude": 1.0, "position": 0.07051,
                   "frequency": 60.0},
    "solver": {"modes": 4, "end_time": 1.0, "basis": "paper"}}


def test_a_turn_back_switch_is_timed_by_the_rate_of_its_function():
    # Found by a random hunt: each impact's projection leaves the stop on the wrong side (penetration -1.2e-5 m
    # while engaged), and the engine releases it where the penetration's rate vanishes (paper eq. 12's rule).
    # The saltation took those releases as crossings of the penetration, dividing by its rate, a round-off
    # there (3e-15 of the scale): the Jacobian was not finite and numpy's eigvals raised LinAlgError out of
    # periodic_orbit. Its instant is set by the rate: the rate's gradient and its own derivative along the
    # flow. Against central differences: measured 1.1e-7 at a step of 1e-5 falling as h^2 (1.4e-8 at 1e-6);
    # 1e-6 leaves a factor 9.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ImpactBeamWarning)  # the projection's warning, which is the point here
        orbit = periodic_orbit(parse_scenario(_TURN_BACK), settle_periods=60)
    assert orbit.converged and orbit.stable and np.all(np.isfinite(orbit.jacobian))
    J_fd = _fd_jacobian(orbit.map, orbit.state)
    A, B = _scaled(orbit.map, orbit.jacobian), _scaled(orbit.map, J_fd)
    assert np.linalg.norm(A - B) / np.linalg.norm(A) < 1e-6
    assert abs(np.abs(orbit.multipliers).max() - np.abs(np.linalg.eigvals(J_fd)).max()) < 1e-6


_UNDONE = {  # the paper's basis, 4 modes: two stiff stops at one point, above and below, and a dashpot stop
    "beam": {"length": 0.1092, "width": 0.00993, "height": 0.00303, "youngs_modulus": 1834e6, "density": 951.98},
    "supports": {"left": "clamped", "right": "pinned"}, "masses": [{"position_ratio": 0.58, "mass": 0.0001}],
    "contactors": [{"position_ratio": 0.447, "stiffness": 136599.33, "gap": 5e-05, "side": "above"},
                   {"position_ratio": 0.289, "stiffness": 1680.63, "gap": 0.0003, "side": "below", "damping": 2.4792},
                   {"position_ratio": 0.447, "stiffness": 136599.33, "gap": 5e-05, "side": "below"}],
    "damping": {"model": "rayleigh", "alpha": 50.0, "beta": 0.0001},
    "excitation": {"kind": "base_acceleration", "shape": "harmonic", "amplitude": -147.15, "frequency": 250.0,
                   "phase": 0.7},
    "solver": {"modes": 4, "end_time": 1.0, "basis": "paper"}}

_PHASED = {  # the paper's basis, 6 modes, three stops with dashpots (one by restitution), 79 impacts a period
    "beam": {"length": 0.1092, "width": 0.00993, "height": 0.00303, "youngs_modulus": 1834e6, "density": 951.98},
    "supports": {"left": "clamped", "right": "free"},
    "contactors": [{"position_ratio": 0.374, "stiffness": 1170.89, "gap": 0.0001, "side": "above", "damping": 2.3685},
                   {"position_ratio": 0.76, "stiffness": 4173.03, "gap": 5e-05, "side": "above", "restitution": 0.3},
                   {"position_ratio": 0.554, "stiffness": 303213.9, "gap": 5e-05, "side": "above", "damping": 0.21954}],
    "damping": {"free": 0.02, "contact": 0.05},
    "excitation": {"kind": "point_force", "shape": "harmonic", "amplitude": 0.2, "position": 0.06712,
                   "frequency": 30.0},
    "solver": {"modes": 6, "end_time": 1.0, "basis": "paper"}}


def _jacobian_error(raw: dict) -> tuple[float, float]:
    """The orbit's Jacobian and largest multiplier against central differences of its map (step 1e-5)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ImpactBeamWarning)  # the projection's warning (the paper's basis)
        orbit = periodic_orbit(parse_scenario(raw), settle_periods=60)
        assert orbit.converged and np.all(np.isfinite(orbit.jacobian))
        J_fd = _fd_jacobian(orbit.map, orbit.state)
    A, B = _scaled(orbit.map, orbit.jacobian), _scaled(orbit.map, J_fd)
    mu = abs(np.abs(orbit.multipliers).max() - np.abs(np.linalg.eigvals(J_fd)).max())
    return float(np.linalg.norm(A - B) / np.linalg.norm(A)), float(mu)


def test_switches_undone_at_their_instant_are_in_the_jacobian():
    # Found by a random hunt: a stop struck or left where the paper's projection puts it on the wrong side is
    # switched back at once; the engine records the pair as no event (it cancels), but the two projections
    # move the state. The Jacobian, built from the events, left them out (0.17 off central differences; Newton
    # did not converge). Restored from the states either side of the instant: measured 3.5e-9 at a step of
    # 1e-5 (3.4e-8 at 1e-6: central differences' round-off); 1e-6 leaves a factor 280.
    jac, mu = _jacobian_error(_UNDONE)
    assert jac < 1e-6
    assert mu < 1e-7  # measured 1.1e-11


def test_the_section_avoids_a_contactor_left_on_the_wrong_side():
    # Found by a random hunt (orbits against plain simulations): with the paper's basis a projection can leave a
    # released contactor pressed into its stop until it turns back; a section placed there made the map's
    # run switch it at once, where the simulation does not: an orbit of another map, its strobe 0.34 of the
    # amplitude off the simulation's. Against a plain run from rest, 100 periods past the settling run
    # (multipliers 0.089: the transient is gone): measured 2.2e-12.
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ImpactBeamWarning)  # the projection's warning (the paper's basis)
        sc = parse_scenario(_UNDONE)
        orbit = periodic_orbit(sc, settle_periods=60)
        T = 1 / 250.0
        plain = ib.simulate(sc.with_values({"solver.end_time": float(orbit.strobe_times[-1] + 100 * T)}))
    w = plain.displacement([sc.contactors[0].position], orbit.strobe_times + 100 * T)[0]
    assert orbit.converged and np.max(np.abs(w - orbit.strobe)) < 1e-9 * np.max(np.abs(w))


def test_a_section_inside_a_contact_is_said():
    # The beam rests on a stop the whole period (a preload holds it there): no free flight for the section, so
    # with the paper's basis the map starts from the free state's modal coordinates, a projection of the
    # engaged state: its orbit is slightly off the simulation's (3e-6 of the amplitude in the random hunt's case,
    # which had a third stop).
    raw = {"beam": {"length": 0.1092, "width": 0.00993, "height": 0.00303, "youngs_modulus": 1834e6,
                    "density": 951.98},
           "supports": {"left": "pinned", "right": "free"}, "masses": [{"position_ratio": 0.388, "mass": 0.005}],
           "contactors": [{"position_ratio": 0.917, "stiffness": 2287.36, "gap": 0.0001, "side": "below"},
                          {"position_ratio": 0.837, "stiffness": 174.06, "gap": 0.0001, "side": "above"}],
           "damping": {"model": "rayleigh", "alpha": 5.0, "beta": 1e-05},
           "excitation": {"kind": "point_force", "shape": "harmonic", "amplitude": -0.01, "position": 0.03082,
                          "frequency": 30.0},
           "preload": {"kind": "base_acceleration", "amplitude": 9.81},
           "solver": {"modes": 4, "end_time": 1.0, "basis": "paper"}}
    with pytest.warns(ImpactBeamWarning, match="no free flight in its last 1 forcing period"):
        orbit = periodic_orbit(parse_scenario(raw), settle_periods=60)
    assert orbit.converged and any("section lies inside a contact" in w for w in orbit.warnings)
    assert [ev.kind for ev in orbit.map.solve(orbit.state).events] == ["impact"]  # engaged at the start, held


def test_a_dashpot_released_phase_is_tracked_as_the_engine_does():
    # Found by a random hunt: a dashpot stop released while compressed is re-engaged by its force; one released
    # at zero compression whose projection leaves it compressed is re-engaged where its opening turns back. The
    # Jacobian judged the phase from the compression after the projection (the force where the engine used the
    # opening) and kept it past the compression's return to zero; it also dropped switches at one instant that
    # end in the state they began from (four of them at 16.76 ms). Largest multiplier 0.1526 against the map's
    # 0.0242, the Jacobian 0.84 off. Measured now: 2.6e-8 at a step of 1e-5 (3.9e-8 at 1e-6).
    jac, mu = _jacobian_error(_PHASED)
    assert jac < 1e-6
    assert mu < 1e-7  # measured 6.8e-10


_COEXISTING = {  # a period-1 and a period-4 orbit, both stable: a simulation from rest settles on the second
    "beam": {"length": 0.1092, "width": 0.00993, "height": 0.00303, "youngs_modulus": 1834e6, "density": 951.98},
    "supports": {"left": {"translational": "inf", "rotational": 50.0}, "right": "free"},
    "contactors": [{"position_ratio": 0.191, "stiffness": 1516.193, "gap": 1e-05, "side": "above"},
                   {"position_ratio": 0.994, "stiffness": 900580.5, "gap": 1e-05, "side": "above", "damping": 0.20312}],
    "damping": {"model": "free_modes", "free": 0.05},
    "excitation": {"kind": "point_force", "shape": "harmonic", "amplitude": 0.05, "position": 0.05037,
                   "frequency": 120.0, "phase": 0.7},
    "solver": {"modes": 4, "end_time": 1.0}}


def test_a_settled_response_of_another_period_is_said():
    # Found by a random hunt (orbits against plain simulations): the simulation settles on a period-4 response,
    # and Newton with multiple = 1 from its state converges, in 3 steps, to a coexisting stable period-1 orbit
    # (its strobe 9 % of the amplitude off the simulation's), which was reported without a word. The settling
    # run's own period is read now, and a multiple it does not divide is warned about.
    sc = parse_scenario(_COEXISTING)
    with pytest.warns(ImpactBeamWarning, match=r"the settling run repeats after 4 forcing period\(s\), not after "
                                               r"multiple = 1"):
        one = periodic_orbit(sc, settle_periods=120)
    assert one.converged and one.stable and one.least_period == 1
    assert any("repeats after 4" in w for w in one.warnings)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ImpactBeamWarning)  # the settled period: nothing to say
        four = periodic_orbit(sc, settle_periods=120, multiple=4)
    assert four.converged and four.stable and four.least_period == 4
    # the period-4 orbit is the simulation's: a plain run from rest, 160 periods past the settling run, at the
    # orbit's strobe times (measured 4.5e-12 of the amplitude: the transient decays as 0.33 per 4 periods)
    T = 4 / 120.0
    plain = ib.simulate(sc.with_values({"solver.end_time": float(four.strobe_times[-1] + 40 * T)}))
    w = plain.displacement([sc.contactors[0].position], four.strobe_times + 40 * T)[0]
    assert np.max(np.abs(w - four.strobe)) < 1e-9 * np.max(np.abs(four.strobe))
    assert np.max(np.abs(w - one.strobe[0])) > 0.05 * np.max(np.abs(four.strobe))  # measured 0.091


_PRELOADED = {  # a gravity-like preload (base acceleration 1 g) on a beam driven against two stops
    "beam": {"length": 0.1092, "width": 0.00993, "height": 0.00303, "youngs_modulus": 1834e6, "density": 951.98},
    "supports": {"left": {"translational": "inf", "rotational": 50.0}, "right": "pinned"},
    "contactors": [{"position_ratio": 0.774, "stiffness": 58089.08, "gap": 5e-05, "side": "above"},
                   {"position_ratio": 0.442, "stiffness": 121.2246, "gap": 5e-05, "side": "above", "damping": 0.27936}],
    "damping": {"free": 0.01, "contact": 0.01},
    "excitation": {"kind": "point_force", "shape": "harmonic", "amplitude": -1.0, "position": 0.0612,
                   "frequency": 120.0, "phase": 0.7},
    "preload": {"kind": "base_acceleration", "amplitude": 9.81},
    "solver": {"modes": 6, "end_time": 1.0}}


def test_the_map_carries_the_preload():
    # Found by a random hunt (orbits against plain simulations): the stroboscopic map was built and run
    # without the scenario's preload, so Newton found the orbit of another load: its strobe 2.5 % of the
    # amplitude off the simulation's, multipliers of that other orbit, no warning. Against a plain run from rest
    # (the transient decays as 0.67 per period over 300 periods past the settling run): measured 2.5e-13.
    sc = parse_scenario(_PRELOADED)
    orbit = periodic_orbit(sc, settle_periods=60)
    assert orbit.converged and orbit.stable
    T = 1 / 120.0
    plain = ib.simulate(sc.with_values({"solver.end_time": float(orbit.strobe_times[-1] + 300 * T)}))
    w = plain.displacement([sc.contactors[0].position], orbit.strobe_times + 300 * T)[0]
    assert np.max(np.abs(w - orbit.strobe)) < 1e-9 * np.max(np.abs(w))


def test_a_jacobian_that_is_not_finite_gives_no_multipliers_and_says_why(tmp_path, monkeypatch):
    # A saltation that overflows (a switch whose normal velocity is a round-off) must not end in numpy's
    # LinAlgError, as it did before the turn-back switches above were timed by their rate: the orbit is reported
    # converged, without multipliers, not called stable, with a warning saying why. The Jacobian is made
    # infinite here to reach that path whatever case produces it.
    from impactbeam.periodic import shooting

    real = shooting.flow_jacobian

    def overflowing(sol):
        fj = real(sol)
        return dataclasses.replace(fj, matrix=np.full_like(fj.matrix, np.inf))

    monkeypatch.setattr(shooting, "flow_jacobian", overflowing)
    raw = _raw(frequency=60.0)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        orbit = periodic_orbit(parse_scenario(raw), settle_periods=40)
    texts = [str(w.message) for w in caught]
    assert orbit.multipliers.size == 0 and orbit.stable is False
    assert any("Jacobian is not finite" in t for t in texts)
    assert not any(issubclass(w.category, RuntimeWarning) for w in caught)
    path = tmp_path / "g.toml"
    path.write_text(parse_scenario(raw).to_toml())
    out = _cli(["periodic", str(path), "--settle-periods", "40", "--json"])
    assert out.exit_code == 0
    data = json.loads(out.stdout)
    assert data["multipliers"] == [] and data["stable"] is False
    assert any("Jacobian is not finite" in t for t in data["warnings"])
    out = _cli(["periodic", str(path), "--settle-periods", "40"])
    assert out.exit_code == 0 and "multipliers not defined" in out.stdout
