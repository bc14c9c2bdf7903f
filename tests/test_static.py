"""The exact static solver (impactbeam.modal.static) against independent references.

The moment of the mode-acceleration correction (impactbeam.result.stress) rests on
it. References: the polynomial statics of the uniform beam with end springs
(impactbeam.modal.uniform_static, another formulation: the fourth-order equation
integrated as polynomials with the end conditions as rows), equilibrium of
statically determinate beams, and the Timoshenko propped cantilever by
compatibility of tip deflections.
"""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pytest

from impactbeam.modal import static_moment
from impactbeam.exceptions import ParameterError
from impactbeam.model.beam import Beam, Section, Support
from impactbeam.modal import static_polynomial

L = 0.3
X = np.linspace(0.0, L, 13)
SUPPORTS = [Support.preset("clamped"), Support.preset("pinned"), Support(1e3, 5.0), Support.preset("sliding"),
            Support(1e4, 0.0)]


def _polynomial_moment(beam: Beam, alpha: float | None) -> np.ndarray:
    """M = EI w'' from the polynomial statics: unit force at xi = alpha, or unit uniform load (None)."""
    if alpha is None:
        coef, a, scale = static_polynomial(beam, 0.5, np.array([[1.0], [1.0]]), 0.0), 0.5, L**2
    else:
        coef, a, scale = static_polynomial(beam, alpha, np.zeros((2, 1)), 1.0), alpha, L
    c = [np.polynomial.polynomial.polyder(cc, 2) for cc in coef]
    xi = X / L
    return scale * np.where(xi >= a, np.polynomial.polynomial.polyval(xi, c[1]),
                            np.polynomial.polynomial.polyval(xi, c[0]))


@pytest.mark.parametrize("left, right", [p for p in itertools.product(SUPPORTS, SUPPORTS)
                                         if p != (SUPPORTS[3], SUPPORTS[3])])
def test_uniform_beam_matches_the_polynomial_statics(left, right):
    # 24 support pairs, a force inside, a force at the end, a uniform load: the same moment to
    # 1e-11 of the load's scale (F L or q L^2; round-off of two different solutions)
    beam = Beam.rectangular(L, 0.01, 0.002, 2e11, 7800.0, left, right)
    for alpha in (0.37, 1.0):
        got = static_moment(beam, X, [(alpha * L, 1.0)])
        np.testing.assert_allclose(got, _polynomial_moment(beam, alpha), rtol=0, atol=1e-11 * L)
    got = static_moment(beam, X, (), [1.0])
    np.testing.assert_allclose(got, _polynomial_moment(beam, None), rtol=0, atol=1e-11 * L**2)


def test_stepped_timoshenko_cantilever_is_statically_determinate():
    # whatever the sections and the shear flexibility: M = F (L - x) under a tip force and
    # q (L - x)^2 / 2 under a uniform load q, to round-off
    sections = (Section(0.1, 2e11, 7800.0, 2e-4, 6e-10, 0.01, 0.02), Section(0.2, 7e10, 2700.0, 1e-4, 1e-10, 0.01, 0.01))
    for theory in ({}, {"theory": "timoshenko", "poisson_ratio": 0.3}):
        beam = dataclasses.replace(Beam.rectangular(L, 0.01, 0.02, 2e11, 7800.0), sections=sections, **theory)
        np.testing.assert_allclose(static_moment(beam, X, [(L, 2.0)]), 2.0 * (L - X), rtol=1e-12, atol=1e-15)
        np.testing.assert_allclose(static_moment(beam, X, (), [3.0, 3.0]), 1.5 * (L - X) ** 2, rtol=1e-12,
                                   atol=1e-15)


def test_timoshenko_propped_cantilever_by_compatibility():
    # clamped at 0, pinned at L, uniform q along +w. The prop force R (along -w) makes the tip
    # deflection of the cantilever vanish: R (L^3/3EI + L/kGA) = q (L^4/8EI + L^2/2kGA); then
    # M(x) = q (L - x)^2 / 2 - R (L - x). L/h = 5: shear raises R by 1 % over 3 q L / 8.
    beam = Beam.rectangular(L, 0.02, 0.06, 2e11, 7800.0, "clamped", "pinned")
    beam = dataclasses.replace(beam, theory="timoshenko", poisson_ratio=0.3)
    (p,) = beam.pieces()
    EI, GA, q = p.bending_stiffness, beam.shear_stiffness(p), 5.0
    R = q * (L**4 / (8 * EI) + L**2 / (2 * GA)) / (L**3 / (3 * EI) + L / GA)
    assert R > 1.005 * 3 * q * L / 8
    np.testing.assert_allclose(static_moment(beam, X, (), [q]), q * (L - X) ** 2 / 2 - R * (L - X),
                               rtol=0, atol=1e-12 * q * L**2)


def test_rigid_body_motion_is_refused():
    beam = Beam.rectangular(L, 0.01, 0.002, 2e11, 7800.0, "free", "sliding")
    with pytest.raises(ParameterError, match="rigid body"):
        static_moment(beam, X, [(0.5 * L, 1.0)])
    with pytest.raises(ParameterError, match="one value per section"):
        static_moment(Beam.rectangular(L, 0.01, 0.002, 2e11, 7800.0), X, (), [1.0, 2.0])
