"""Initial states (``[initial]``): fields projected onto the run's basis in the kinetic inner product.

The one rule is :func:`impactbeam.solver.initial.initial_coordinates`, for the
paper's per-state modes and the shared Ritz basis. Checks against
independent truths: a field made of modes comes back exactly; a rigid
rotation of a beam that can turn about its pin is represented to round-off
(with point masses and rotary inertia, and for a Timoshenko beam: a missing
``J`` or ``rho I`` term in the inner product would leave a residual); the
residual of a uniform velocity of a cantilever against Blevins' closed-form
effective masses; the static shape's coordinates against the modal identity
``eta_n = F W_n(a) / omega_n^2``; bad input named by its key.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import impactbeam as ib
from impactbeam.exceptions import ImpactBeamWarning, ParameterError, ScenarioError
from impactbeam.modal import static_state
from impactbeam.model import Damping, Excitation, InitialCondition, PointMass, Profile, SolverOptions, Support
from impactbeam.solver import engine
from impactbeam.solver.initial import RESIDUAL_WARNING, initial_coordinates

SPECIMEN = ib.Beam.rectangular(0.1092, 9.93e-3, 3.03e-3, 1834e6, 951.98)
CONTACTOR = ib.Contactor(0.4840 * 0.1092, 4030.0, 0.229e-3, "above")
PINNED_FREE = ib.Beam.rectangular(0.783, 0.014, 0.014, 6.7e10, 2400.0, "pinned", "free")


def _space(beam, basis: str, contactors=(CONTACTOR,), modes: int = 8):
    return engine.make_space(beam, contactors, Damping(), Excitation(), SolverOptions(modes=modes, basis=basis),
                             np.zeros(0))


def _field(space, eta, x):
    return space.state(()).modes.shapes(x).T @ eta


@pytest.mark.parametrize("basis", ["paper", "enriched"])
def test_a_field_made_of_modes_comes_back_exactly(basis):
    # Reason: the projection is the inverse of the modal sum: 2 W_1 - 0.5 W_3 (and its rate) must come back as
    # those coordinates, with no residual (round-off of the quadrature: 1e-13 measured, tolerance 1e-10).
    sp = _space(SPECIMEN, basis)
    ms = sp.state(()).modes
    x = np.linspace(0.0, SPECIMEN.length, 41)
    c = np.zeros(ms.count)
    c[0], c[2] = 2.0, -0.5
    w = ms.shapes(x).T @ c
    prof = Profile(x, w, "initial.displacement")
    with warnings.catch_warnings():
        warnings.simplefilter("error", ImpactBeamWarning)
        eta, deta = initial_coordinates(sp, SPECIMEN, InitialCondition(displacement_profile=Profile(
            np.linspace(0.0, SPECIMEN.length, 4001), ms.shapes(np.linspace(0.0, SPECIMEN.length, 4001)).T @ c)))
    # the 4001-row linear interpolation of the modes misses (h^2/8) w'' ~ 1e-7 of them
    assert np.max(np.abs(eta - c)) < 2e-6 * np.max(np.abs(c))
    assert not np.any(deta)
    assert prof(x[3]) == pytest.approx(w[3])


@pytest.mark.parametrize("basis", ["paper", "enriched"])
def test_rigid_rotation_of_a_pinned_beam_is_exact(basis):
    # Reason: the pinned-free beam's rigid mode is W_0 = x / sqrt(rho A L^3 / 3): the rotation about the pin
    # must be that mode alone, reconstructed to round-off: measured 9e-16 of the tip speed in the paper's
    # basis, 4e-12 in the shared basis (its inertia-relief attachment shape is orthogonal to the rigid mode
    # to ~1e-12 on its own quadrature); tolerance 1e-10.
    sp = _space(PINNED_FREE, basis, (ib.Contactor(0.783, 18000.0, 0.0, "below"),), modes=10)
    eta, deta = initial_coordinates(sp, PINNED_FREE, InitialCondition(angular_velocity=-3.8, pivot=0.0))
    x = np.linspace(0.0, 0.783, 9)
    assert np.allclose(_field(sp, deta, x), -3.8 * x, rtol=0, atol=1e-10 * 3.8 * 0.783)
    rho_a = PINNED_FREE.mass_per_length
    k = int(np.argmax(np.abs(deta)))
    assert abs(deta[k]) == pytest.approx(3.8 * math.sqrt(rho_a * 0.783**3 / 3.0), rel=1e-10)
    assert not np.any(eta)


def test_rigid_rotation_with_a_rotary_mass_and_a_timoshenko_beam():
    # Reason: the kinetic inner product has m and J at the point masses and rho I on a Timoshenko beam's
    # rotations; leaving one out gives the rigid mode a wrong amplitude and a residual of order J / (total
    # rotary inertia), here ~10 %. Exact to round-off (tolerance 1e-10 on the field and on the residual).
    tip = PointMass(0.783, 0.2, 2e-3)
    for beam in (
        ib.Beam(0.783, 6.7e10, 2400.0, 1.96e-4, 3.2013e-9, Support.preset("pinned"), Support.preset("free"),
                masses=(tip,)),
        ib.Beam(0.783, 6.7e10, 2400.0, 1.96e-4, 3.2013e-9, Support.preset("pinned"), Support.preset("free"),
                masses=(tip,), theory="timoshenko", poisson_ratio=0.0, shear_coefficient=5 / 6),
    ):
        sp = _space(beam, "paper", (), modes=6)
        with warnings.catch_warnings():
            warnings.simplefilter("error", ImpactBeamWarning)
            _, deta = initial_coordinates(sp, beam, InitialCondition(angular_velocity=2.0, pivot=0.0))
        x = np.linspace(0.0, 0.783, 7)
        assert np.allclose(_field(sp, deta, x), 2.0 * x, rtol=0, atol=1e-10)
        assert np.allclose(sp.state(()).modes.rotations(x).T @ deta, 2.0, rtol=0, atol=1e-10)


def _cantilever_effective_mass(n: int) -> float:
    """Blevins: effective mass fraction of cantilever mode n, (2 sigma_n / lambda_n)^2, from the frequency equation."""
    lam = [1.875104069, 4.694091133, 7.854757438, 10.99554073, 14.13716839][n] if n < 5 else (2 * n + 1) * math.pi / 2
    sigma = (math.sinh(lam) - math.sin(lam)) / (math.cosh(lam) + math.cos(lam))
    return (2.0 * sigma / lam) ** 2


@pytest.mark.parametrize("basis", ["paper", "enriched"])
def test_uniform_velocity_of_a_cantilever_warns_with_its_residual(basis):
    # Reason: a uniform velocity violates the clamp; N modes hold the fraction sum (2 sigma_n / lambda_n)^2 of
    # it (Blevins' effective masses), so the residual is sqrt(1 - that sum): 22.5 % for 8 modes. The enriched
    # basis adds the contactor's attachment shape, which holds a little more (measured 22.2 %).
    sp = _space(SPECIMEN, basis)
    with pytest.warns(ImpactBeamWarning, match=r"initial\.velocity: .* misses ([0-9.]+) %") as rec:
        initial_coordinates(sp, SPECIMEN, InitialCondition(velocity=1.0))
    got = float(str(rec[0].message).split("misses ")[1].split(" %")[0]) / 100
    expected = math.sqrt(1.0 - sum(_cantilever_effective_mass(n) for n in range(8)))
    if basis == "paper":
        assert got == pytest.approx(expected, rel=2e-3)  # the message's 3 digits
    else:
        assert expected - 0.01 < got <= expected * (1 + 2e-3)


@pytest.mark.parametrize("basis", ["paper", "enriched"])
def test_tip_displacement_is_the_projected_static_shape(basis):
    # Reason: the static shape g of a tip force is K^-1 delta_L, so its projection is eta_n = F W_n(L) / omega_n^2
    # (a modal identity, independent of the quadrature) with F = d / g(L) from the static solver.
    sp = _space(SPECIMEN, basis)
    eta, _ = initial_coordinates(sp, SPECIMEN, InitialCondition(tip_displacement=2e-3))
    L = SPECIMEN.length
    F = 2e-3 / float(static_state(SPECIMEN, [L], [(L, 1.0)])[0][0])
    if basis == "paper":
        ms = sp.state(()).modes
        assert np.allclose(eta, F * ms.shapes([L])[:, 0] / ms.omega**2, rtol=0, atol=1e-10 * np.abs(eta).max())
    # either basis: the deflection at the tip within the truncation of 8 modes (measured 8e-5 and 6e-5)
    assert _field(sp, eta, [L])[0] == pytest.approx(2e-3, rel=2e-4)


def test_velocity_rows_of_a_rotation_equal_the_rotation():
    # Reason: two inputs of one field (rows of a linear field, and angular_velocity) must give one state.
    sp = _space(PINNED_FREE, "enriched", (ib.Contactor(0.783, 18000.0, 0.0, "below"),), modes=10)
    a = initial_coordinates(sp, PINNED_FREE, InitialCondition(angular_velocity=-3.8, pivot=0.0))[1]
    b = initial_coordinates(sp, PINNED_FREE, InitialCondition(
        velocity_profile=Profile(np.array([0.0, 0.3, 0.783]), -3.8 * np.array([0.0, 0.3, 0.783]), "initial.velocity")))[1]
    assert np.allclose(a, b, rtol=0, atol=1e-12 * np.abs(a).max())


def test_translation_and_rotation_add_up():
    # Reason: a uniform velocity plus a rotation about the pivot is the rigid motion v0 + Omega (x - p).
    beam = ib.Beam.rectangular(1.0, 0.01, 0.01, 2e11, 7800.0, "free", "free")
    sp = _space(beam, "paper", (), modes=6)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ImpactBeamWarning)
        _, deta = initial_coordinates(sp, beam, InitialCondition(velocity=0.5, angular_velocity=2.0, pivot=0.25))
    x = np.linspace(0.0, 1.0, 5)
    assert np.allclose(_field(sp, deta, x), 0.5 + 2.0 * (x - 0.25), rtol=0, atol=1e-12)


def test_profile_checks():
    # Reason: a field off the beam, not spanning it, or badly ordered is refused, naming the key.
    p = Profile(np.array([0.0, 0.05]), np.array([0.0, 1e-3]), "initial.displacement")
    with pytest.raises(ParameterError, match=r"^initial\.displacement: the rows cover 0 \.\. 0\.05 m"):
        p.check_on(0.1092)
    with pytest.raises(ParameterError, match=r"^initial\.velocity: rows at 0 \.\. 0\.2 m, off the beam"):
        Profile(np.array([0.0, 0.2]), np.array([0.0, 1.0]), "initial.velocity").check_on(0.1092)
    with pytest.raises(ParameterError, match="strictly increasing"):
        Profile(np.array([0.0, 0.0]), np.array([0.0, 1.0]))
    with pytest.raises(ParameterError, match="at least two"):
        Profile(np.array([0.0]), np.array([0.0]))
    sp = _space(SPECIMEN, "paper")
    with pytest.raises(ParameterError, match="rows cover"):
        initial_coordinates(sp, SPECIMEN, InitialCondition(displacement_profile=p))
    # the slope at a row is the mean of its neighbours' (a point mass's J sees that)
    q = Profile(np.array([0.0, 1.0, 2.0]), np.array([0.0, 1.0, 3.0]))
    assert list(q.slope(np.array([0.5, 1.0, 1.5]))) == [1.0, 1.5, 2.0]


def test_initial_condition_combinations():
    with pytest.raises(ParameterError, match="^initial.pivot: give angular_velocity and pivot together"):
        InitialCondition(angular_velocity=1.0)
    with pytest.raises(ParameterError, match="^initial.tip_displacement: cannot be combined with initial.equilibrium"):
        InitialCondition(tip_displacement=1e-3, equilibrium=True)
    with pytest.raises(ParameterError, match="^initial.velocity: give a uniform velocity or a velocity profile"):
        InitialCondition(velocity=1.0, velocity_profile=Profile(np.array([0.0, 1.0]), np.array([0.0, 1.0])))
    assert not InitialCondition(velocity=1.0).at_rest
    assert InitialCondition(velocity=0.0).at_rest


def test_residual_threshold_is_quiet_for_a_good_field():
    # Reason: the warning is for fields the basis cannot hold, not for round-off: the static tip shape with
    # 8 modes misses 2e-5 of its norm (far below the threshold) and must not warn.
    assert RESIDUAL_WARNING == 1e-3
    sp = _space(SPECIMEN, "paper")
    with warnings.catch_warnings():
        warnings.simplefilter("error", ImpactBeamWarning)
        initial_coordinates(sp, SPECIMEN, InitialCondition(tip_displacement=1e-3))


# --------------------------------------------------------------------------- scenario keys


def _parse(extra: str, tmp_path=None):
    import tomllib

    from specimen import BEAM, CONTACTOR as CTEXT

    return ib.parse_scenario(tomllib.loads(BEAM + CTEXT + extra), base_dir=tmp_path)


def test_scenario_keys_with_units(tmp_path):
    assert _parse('[initial]\nvelocity = "2 mm/s"\n').initial.velocity == pytest.approx(2e-3)
    ini = _parse('[initial]\nangular_velocity = "36 deg/s"\npivot = "10 mm"\n').initial
    assert ini.angular_velocity == pytest.approx(math.pi / 5) and ini.pivot == pytest.approx(0.01)
    rows = _parse('[initial]\nvelocity = [[0, 0], ["109.2 mm", "2 m/s"]]\n').initial.velocity_profile
    assert list(rows.positions) == [0.0, 0.1092] and list(rows.values) == [0.0, 2.0]
    (tmp_path / "w.csv").write_text("x [mm],w [um]\n0,0\n54.6,10\n109.2,30\n")
    prof = _parse('[initial]\ndisplacement_file = "w.csv"\n', tmp_path).initial.displacement_profile
    assert np.allclose(prof.values, [0.0, 1e-5, 3e-5]) and np.allclose(prof.positions, [0.0, 0.0546, 0.1092])
    pre = _parse('[preload]\nkind = "point_force"\namplitude = "2 N"\nposition_ratio = 1\n').preload
    assert (pre.kind, pre.amplitude, pre.position) == ("point_force", 2.0, 0.1092)
    assert _parse('[initial]\nequilibrium = true\n[preload]\nkind = "gravity"\namplitude = "-1 g"\n').preload.amplitude \
        == -9.80665


@pytest.mark.parametrize("extra, match", [
    ('[initial]\ndisplacement = [[0, 0], ["209.2 mm", "2 mm"]]\n', r"^initial\.displacement: rows at 0 \.\. 0\.2092 m"),
    ('[initial]\ndisplacement = [[0, 0], ["50 mm", "1 mm"]]\n', r"^initial\.displacement: the rows cover"),
    ('[initial]\ndisplacement = [[0, 0, 1], ["50 mm", "1 mm"]]\n', r"^initial\.displacement\.0: expected a row"),
    ('[initial]\ndisplacement = "2 mm"\n', r"^initial\.displacement: expected a list"),
    ('[initial]\nvelocity = "2 mm"\n', r"^initial\.velocity: \"2 mm\" is a length, expected a velocity"),
    ('[initial]\nvelocity = [["0 m", "1 m/s"], ["0.1092 m", "x"]]\n', r"^initial\.velocity\.1\.1: cannot read"),
    ('[initial]\nangular_velocity = 3\n', r"^initial\.pivot: required with initial\.angular_velocity"),
    ('[initial]\npivot = 0\n', r"^initial\.angular_velocity: required with initial\.pivot"),
    ('[initial]\nangular_velocity = 3\npivot = 3\n', r"^initial\.pivot: 3 m is off the beam"),
    ('[initial]\nangular_velocity = "3 m/s"\npivot = 0\n', r"^initial\.angular_velocity: .* expected an angular velocity"),
    ('[initial]\nequilibrium = true\n', r"^initial\.equilibrium: needs a \[preload\] table"),
    ('[initial]\nequilibrium = "yes"\n', r"^initial\.equilibrium: expected true or false"),
    ('[initial]\nvelocity_file = "nope.csv"\n', r"^initial\.velocity_file: \"nope\.csv\" not found"),
    ('[preload]\nkind = "point_force"\namplitude = "2 N"\n', r"^preload\.position: required"),
    ('[preload]\nkind = "gravity"\namplitude = "2 N"\n', r"^preload\.amplitude: \"2 N\" is a force, expected an acceleration"),
    ('[preload]\nkind = "gravity"\namplitude = "1 g"\nposition = 0.1\n', r"^preload\.position: has no effect"),
    ('[preload]\nkind = "grav"\namplitude = "1 g"\n', r"^preload\.kind: must be one of"),
    ('[preload]\namplitude = "1 g"\n', r"^preload\.kind: required"),
    ('[preload]\nkind = "gravity"\n', r"^preload\.amplitude: required"),
])
def test_bad_initial_and_preload_input_names_the_key(extra, match, tmp_path):
    with pytest.raises(ScenarioError, match=match):
        _parse(extra, tmp_path)


def test_bad_input_exits_2_on_the_command_line(tmp_path):
    import subprocess
    import sys

    from specimen import BEAM, CONTACTOR as CTEXT, write_scenario

    path = write_scenario(tmp_path, BEAM + CTEXT + '[initial]\ndisplacement = [[0, 0], ["50 mm", "1 mm"]]\n')
    out = subprocess.run([sys.executable, "-m", "impactbeam", "simulate", str(path)], capture_output=True, text=True)
    assert out.returncode == 2
    assert out.stderr.strip().startswith("error: initial.displacement: the rows cover") and "Traceback" not in out.stderr


@pytest.mark.parametrize("extra", [
    '[initial]\nvelocity = "-0.2 m/s"\n',
    '[initial]\nangular_velocity = "2 rad/s"\npivot = 0\n',
    '[initial]\nvelocity = [[0, 0], ["109.2 mm", "0.3 m/s"]]\n',
    '[preload]\nkind = "gravity"\namplitude = "20 g"\n[initial]\nequilibrium = true\n',
])
def test_runs_from_the_new_starting_states_agree_with_solve_ivp(extra):
    # The engine takes its state at t = 0 from solver.initial (and the preload's constant load in every
    # segment): the exact run and the solve_ivp run (which share only the modal data and the initial
    # coordinates) give the same events (1e-9 s) and deflections (1e-7 of the largest), as in test_engine.
    sc = _parse(extra + '[solver]\nend_time = "40 ms"\n[excitation]\nkind = "none"\n')
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ImpactBeamWarning)  # the cantilever's 8 modes miss part of a field
        ex, iv = ib.simulate(sc), ib.simulate(sc, method="ivp")
    assert [(e.kind, e.contactor) for e in ex.events] == [(e.kind, e.contactor) for e in iv.events]
    assert max((abs(a.time - b.time) for a, b in zip(ex.events, iv.events)), default=0.0) <= 1e-9
    t = np.linspace(0.0, 0.04, 81)
    we, wi = ex.displacement(list(sc.output_points), t), iv.displacement(list(sc.output_points), t)
    assert np.abs(we - wi).max() <= 1e-7 * max(np.abs(wi).max(), 1e-12)


def test_a_beam_resting_on_its_stop_under_gravity_stays_at_rest():
    # initial.equilibrium under the preload: the model's static contact solution, held by the preload's
    # constant load in every segment, does not move (round-off: 1e-12 of the static deflection)
    sc = _parse('[preload]\nkind = "gravity"\namplitude = "20 g"\n[initial]\nequilibrium = true\n'
                '[solver]\nend_time = "50 ms"\n[excitation]\nkind = "none"\n')
    res = ib.simulate(sc)
    x = list(sc.output_points)
    w = res.displacement(x, np.linspace(0.0, 0.05, 51))
    assert res.events and res.events[0].time == 0.0 and len(res.events) == 1  # engaged from the start, for good
    assert np.abs(w - w[:, :1]).max() <= 1e-12 * np.abs(w).max()


def test_the_convergence_estimates_coarser_runs_keep_their_warnings():
    # A 1 mm tip deflection is represented by 4 modes within the 0.1 % residual, by 2 modes not: the run's
    # convergence estimate re-runs it with 2 and 3 modes, whose projection warnings were reported as this
    # run's ("the projection onto the run's 2-function basis misses 0.337 %").
    sc = ib.parse_scenario({
        "beam": {"length": 0.1092, "width": 0.00993, "height": 0.00303, "youngs_modulus": 1834e6, "density": 951.98},
        "initial": {"tip_displacement": "1 mm"}, "solver": {"modes": 4, "time_step": "0.1 ms", "end_time": "10 ms"}})
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ImpactBeamWarning)
        res = ib.simulate(sc)
        res.convergence
    texts = [str(w.message) for w in caught]
    assert texts and all("-function basis misses" not in t for t in texts), texts
    with pytest.warns(ImpactBeamWarning, match="2-function basis misses"):  # what the 2-mode run itself says
        ib.simulate(sc.with_values({"solver.modes": 2}))
