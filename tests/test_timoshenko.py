"""Timoshenko beams (issue: real structures, item 4).

Independent references: the closed-form frequency equation of a simply
supported Timoshenko beam (both spectra), the Rayleigh-beam limit of infinite
shear stiffness, the Euler-Bernoulli limit of a slender beam, and a converged
finite-element solution with interdependent-interpolation Timoshenko elements
(``tests/fe_timoshenko.py``, which imports nothing from impactbeam).
"""

from __future__ import annotations

import dataclasses
import math
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import impactbeam as ib
from impactbeam.exceptions import ImpactBeamWarning, ParameterError, ScenarioError
from impactbeam.model.beam import Beam, InteriorSpring, PointMass, Section, Support
from impactbeam.modal import count_below, mode_set

import fe_timoshenko as fe

E, RHO, NU = 2.1e11, 7850.0, 0.3
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _thick(left: str | Support = "clamped", right: str | Support = "free", length: float = 1.0, height: float = 0.2,
           **extra) -> Beam:
    """A steel beam 50 mm wide; L / h = 5 by default."""
    beam = Beam.rectangular(length, 0.05, height, E, RHO, left, right)
    return dataclasses.replace(beam, theory="timoshenko", poisson_ratio=NU, **extra)


def _piece(beam: Beam, p: Section) -> tuple[float, float, float, float, float]:
    return (p.length, p.bending_stiffness, beam.shear_stiffness(p), p.mass_per_length, p.density * p.second_moment)


def _simply_supported_exact(beam: Beam, count: int) -> np.ndarray:
    """Both spectra of a pinned-pinned Timoshenko beam: W = sin(k x), Psi = B cos(k x), k = n pi / L.

    det [[kGA k^2 - rhoA w^2, -kGA k], [kGA k, -(EI k^2 + kGA - rhoI w^2)]] = 0 is a
    quadratic in w^2 for each n; n = 0 gives the pure-rotation mode at the cut-off
    w^2 = kGA / rhoI (W = 0, Psi = const).
    """
    (p,) = beam.pieces()
    _, EI, GA, rA, rI = _piece(beam, p)
    out = [GA / rI]
    for n in range(1, count + 1):
        k = n * math.pi / beam.length
        roots = np.roots([rA * rI, -(GA * k * k * rI + rA * (EI * k * k + GA)), GA * k * k * EI * k * k])
        out.extend(np.sort(roots.real))
    return np.sqrt(np.sort(out)[:count])


def test_simply_supported_both_spectra_closed_form():
    # 16 modes of an L/h = 5 beam reach past the cut-off (mode 7 sits on it). The exact
    # frequencies agree to round-off (5e-13 seen); 1e-10 leaves room for the root refinement.
    beam = _thick("pinned", "pinned")
    ms = mode_set(beam, count=16)
    exact = _simply_supported_exact(beam, 16)
    np.testing.assert_allclose(ms.omega, exact, rtol=1e-10)
    (p,) = beam.pieces()
    cutoff = math.sqrt(beam.shear_stiffness(p) / (p.density * p.second_moment))
    assert np.sum(ms.omega < cutoff * (1 - 1e-9)) == 6 and ms.omega[6] == pytest.approx(cutoff, rel=1e-10)


@pytest.mark.parametrize("case", ["cantilever", "stepped_mass_spring", "free_free"])
def test_thick_beam_against_timoshenko_elements(case):
    # Converged FE (three meshes, h^2 and h^4 removed; 1e-9 agreement seen) against the exact
    # modes; the bar is 1e-6.
    if case == "cantilever":
        beam, attach = _thick(), []
    elif case == "stepped_mass_spring":
        sections = (Section(0.4, E, RHO, 0.05 * 0.2, 0.05 * 0.2**3 / 12, 0.05, 0.2),
                    Section(0.6, E, RHO, 0.05 * 0.12, 0.05 * 0.12**3 / 12, 0.05, 0.12))
        beam = _thick("clamped", "pinned", sections=sections, masses=(PointMass(0.7, 3.0, 0.01),),
                      springs=(InteriorSpring(0.25, 5e7, 1e5),))
        attach = [(0.7, 0.0, 0.0, 3.0, 0.01), (0.25, 5e7, 1e5, 0.0, 0.0)]
    else:
        beam, attach = _thick("free", "free"), []
    ms = mode_set(beam, count=10)
    ends = tuple((s.translational, s.rotational) for s in (beam.left, beam.right))
    ref = fe.extrapolated_frequencies([_piece(beam, p) for p in beam.pieces()], ends, n_elements=100, n_modes=10,
                                      attachments=attach)
    r = ms.n_rigid
    assert r == (2 if case == "free_free" else 0)
    np.testing.assert_allclose(ms.omega[:r], 0.0)
    np.testing.assert_allclose(ms.omega[r:], ref[r:], rtol=1e-6)


def test_counts_above_the_cut_off_match_the_elements():
    # Wittrick-Williams count of both spectra, at frequencies half-way between roots (far from
    # any root, so a 400-element FE count is exact): counts must be equal, not close.
    beam = _thick(height=0.25)
    ms = mode_set(beam, count=14)
    (p,) = beam.pieces()
    cutoff = math.sqrt(beam.shear_stiffness(p) / (p.density * p.second_moment))
    assert ms.omega[-1] > 1.5 * cutoff
    ends = ((math.inf, math.inf), (0.0, 0.0))
    for i in (0, 5, 9, 12):
        mid = 0.5 * (ms.omega[i] + ms.omega[i + 1])
        assert count_below(beam, mid) == i + 1
        assert fe.count_below([_piece(beam, p)], ends, omega=mid) == i + 1


def test_rayleigh_limit_of_infinite_shear_stiffness():
    # kappa -> inf leaves rotary inertia: the Rayleigh beam, w^2 = EI k^4 / (rhoA + rhoI k^2) for a
    # pinned-pinned beam. kappa = 1e9 leaves a shear term ~ EI k^2 / (kappa G A) < 1e-9.
    beam = _thick("pinned", "pinned", shear_coefficient=1e9)
    ms = mode_set(beam, count=6)
    (p,) = beam.pieces()
    k = np.arange(1, 7) * math.pi / beam.length
    rayleigh = np.sqrt(p.bending_stiffness * k**4 / (p.mass_per_length + p.density * p.second_moment * k**2))
    np.testing.assert_allclose(ms.omega, rayleigh, rtol=1e-8)


def test_slender_limit_is_euler_bernoulli():
    # Shear and rotary inertia lower the frequencies by O((h/L)^2): at L/h = 1000 the first
    # four cantilever modes are within 1e-4 of Euler-Bernoulli (relative), the shapes too, and
    # the gap shrinks 100-fold from L/h = 100 to 1000 (within 2 %: the next term is (h/L)^4).
    gaps = []
    for h in (0.01, 0.001):
        eb = Beam.rectangular(1.0, 0.01, h, E, RHO, "clamped", "free")
        tb = dataclasses.replace(eb, theory="timoshenko", poisson_ratio=NU)
        a, b = mode_set(eb, count=4), mode_set(tb, count=4)
        gaps.append(1.0 - b.omega / a.omega)
        if h == 0.001:
            x = np.linspace(0.0, 1.0, 9)
            for d in (0, 1, 2):
                scale = np.abs(a.shapes(x, d)).max()
                assert np.abs(a.shapes(x, d) - b.shapes(x, d)).max() < 1e-3 * scale
    assert np.all(gaps[1] > 0) and np.all(gaps[1] < 1e-4)
    np.testing.assert_allclose(gaps[0] / gaps[1], 100.0, rtol=0.02)


def test_orthonormal_with_steps_masses_and_springs():
    # 50 modes in the kinetic inner product int rhoA W^2 + rhoI Psi^2 + m W^2 + J Psi^2: the
    # identity to 1e-9 (round-off of 20-point Gauss per half wave; 7e-14 seen).
    sections = (Section(0.5, E, RHO, 0.05 * 0.1, 0.05 * 0.1**3 / 12, 0.05, 0.1),
                Section(0.5, 0.7 * E, RHO, 0.05 * 0.15, 0.05 * 0.15**3 / 12, 0.05, 0.15))
    beam = _thick("clamped", "free", sections=sections, masses=(PointMass(1.0, 2.0, 0.002),),
                  springs=(InteriorSpring(0.6, 1e7, 0.0),))
    ms = mode_set(beam, count=50, springs=[(0.8, 3e7)])
    np.testing.assert_allclose(ms.mass_matrix(), np.eye(50), atol=1e-9)


def test_moment_is_EI_times_rotation_gradient():
    # M = EI Psi' (not EI W''): check against a central difference of the rotations, and the
    # free end's zero moment and shear-free W'' relation W'' = M/EI - rhoA w^2 W / kGA.
    beam = _thick()
    ms = mode_set(beam, count=5)
    x = np.array([0.2, 0.5, 0.8])
    d = 1e-6
    dpsi = (ms.rotations(x + d) - ms.rotations(x - d)) / (2 * d)
    np.testing.assert_allclose(ms.moment_shapes(x), beam.bending_stiffness * dpsi, rtol=1e-6)
    assert np.abs(ms.moment_shapes([1.0])).max() < 1e-8 * np.abs(ms.moment_shapes([0.0])).max()
    (p,) = beam.pieces()
    w2 = ms.omega[:, None] ** 2
    lhs = ms.shapes(x, 2)
    rhs = ms.moment_shapes(x) / beam.bending_stiffness - p.mass_per_length * w2 * ms.shapes(x) / beam.shear_stiffness(p)
    np.testing.assert_allclose(lhs, rhs, rtol=1e-9, atol=1e-12 * np.abs(lhs).max())


TIMOSHENKO = 'theory = "timoshenko"\npoisson_ratio = 0.3\n'


def _scenario(tmp_path, theory: str = TIMOSHENKO, tail: str = "") -> Path:
    """A thick steel cantilever (L/h = 5) with a stiff stop at its tip, under a half-sine shock."""
    path = tmp_path / "thick.toml"
    path.write_text(
        '[beam]\nlength = "0.3 m"\nwidth = "20 mm"\nheight = "60 mm"\nyoungs_modulus = "210 GPa"\n'
        'density = "7850 kg/m^3"\n' + theory +
        '[supports]\nleft = "clamped"\nright = "free"\n'
        '[[contactors]]\nposition = "0.3 m"\nstiffness = "1e7 N/m"\ngap = "0.01 mm"\n'
        '[excitation]\nkind = "base_acceleration"\nshape = "half_sine"\namplitude = "200 g"\nduration = "0.5 ms"\n'
        '[solver]\nmodes = 8\nend_time = "5 ms"\ntime_step = "1e-5 s"\n' + tail
    )
    return path


def test_transient_on_a_slender_timoshenko_beam_is_the_euler_bernoulli_one():
    # The transient solver is unchanged on top of the modes. Case 3 (h / L = 0.028) as a
    # Timoshenko beam: the same impacts, and metrics within 5e-3 of Euler-Bernoulli (1.8e-3
    # measured: shear and rotary inertia act at O((h/L)^2) = 8e-4 times mode-dependent factors).
    sc = ib.load_scenario(EXAMPLES / "case03.toml").with_values({"solver.basis": "paper"})
    tb = sc.with_values({"beam.theory": "timoshenko", "beam.poisson_ratio": 0.33})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ImpactBeamWarning)
        a, b = ib.simulate(sc).metrics(), ib.simulate(tb).metrics()
    assert a["n_impacts"] == b["n_impacts"]
    for key in ("max_response", "max_penetration", "first_impact_time", "contact_duration"):
        assert b[key] == pytest.approx(a[key], rel=5e-3)
    assert b["max_response"] > a["max_response"]  # the Timoshenko beam is the more flexible


def test_thick_beam_transient_with_a_stiff_stop(tmp_path):
    # L/h = 5 against a stiff stop, in the enriched basis (attachment shape from the exact
    # Timoshenko statics): 8 modes give the 32-mode peak penetration to 1e-5 (4e-7 measured)
    # with the same impacts; the paper's basis with 8 modes is 7e-5 off.
    sc = ib.load_scenario(_scenario(tmp_path, tail="[damping]\nfree = 0.0\ncontact = 0.0\n"))
    with warnings.catch_warnings():
        warnings.simplefilter("error", ImpactBeamWarning)  # the enriched basis covers it: no fallback
        m8 = ib.simulate(sc).metrics()
    m32 = ib.simulate(sc.with_values({"solver.modes": 32})).metrics()
    assert m8["n_impacts"] == m32["n_impacts"] >= 2
    assert m8["max_penetration"] == pytest.approx(m32["max_penetration"], rel=1e-5)


@pytest.mark.parametrize("theory, key", [
    ('theory = "timoshenko"\npoisson_ratio = 0.5\n', "beam.poisson_ratio"),
    ('theory = "timoshenko"\npoisson_ratio = -1.2\n', "beam.poisson_ratio"),
    ('theory = "timoshenko"\npoisson_ratio = "0.3 m"\n', "beam.poisson_ratio"),
    ('theory = "timoshenko"\n', "beam.poisson_ratio"),
    ('theory = "timoshenko"\nshear_modulus = "50 GPa"\n', "beam.shear_modulus"),  # nu = E / 2G - 1 = 1.1
    ('theory = "timoshenko"\npoisson_ratio = 0.3\nshear_modulus = "80 GPa"\n', "beam.shear_modulus"),
    ('theory = "timoshenko"\npoisson_ratio = 0.3\nshear_coefficient = -0.8\n', "beam.shear_coefficient"),
    ('theory = "timoshenk"\npoisson_ratio = 0.3\n', "beam.theory"),
    ("poisson_ratio = 0.3\n", "beam.poisson_ratio"),  # an Euler-Bernoulli beam refuses it, never ignores it
])
def test_bad_timoshenko_input_names_the_key(tmp_path, theory, key):
    path = _scenario(tmp_path, theory)
    with pytest.raises(ScenarioError) as info:
        ib.load_scenario(path)
    assert info.value.key == key and str(info.value).startswith(key)
    out = subprocess.run([sys.executable, "-m", "impactbeam", "modes", str(path)], capture_output=True, text=True)
    assert out.returncode == 2 and key in out.stderr and "Traceback" not in out.stderr


def test_shear_modulus_gives_the_poisson_ratio(tmp_path):
    sc = ib.load_scenario(_scenario(tmp_path, 'theory = "timoshenko"\nshear_modulus = "80 GPa"\n'))
    assert sc.beam.poisson_ratio == pytest.approx(210.0 / 160.0 - 1.0, rel=1e-12)
    assert sc.beam.kappa == pytest.approx(10 * (1 + sc.beam.poisson_ratio) / (12 + 11 * sc.beam.poisson_ratio))


def test_section_without_a_shape_needs_a_shear_coefficient():
    with pytest.raises(ParameterError, match="beam.shear_coefficient"):
        Beam(1.0, E, RHO, 0.01, 1e-5, theory="timoshenko", poisson_ratio=NU)
    beam = Beam(1.0, E, RHO, 0.01, 1e-5, theory="timoshenko", poisson_ratio=NU, shear_coefficient=0.5)
    assert beam.kappa == 0.5 and not beam.is_uniform
