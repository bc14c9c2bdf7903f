"""Brent's method in plain Python (impactbeam.modal.roots) against SciPy's brentq.

Both implement the same algorithm, so on the same bracket and tolerances the
roots agree to the convergence tolerance (here 4 eps relative): functions
with a simple root, a root at an end, a steep and a flat function.
"""

import math

import pytest
from scipy.optimize import brentq as scipy_brentq

from impactbeam.modal.roots import brentq

CASES = [
    (lambda x: math.cos(x) - x, 0.0, 1.0),
    (lambda x: x**3 - 2.0, 0.0, 3.0),
    (lambda x: math.tanh(50 * (x - 0.3)), -1.0, 2.0),
    (lambda x: (x - 1.0) ** 5 + 1e-12, 0.0, 3.0),
    (lambda x: x, 0.0, 1.0),
]


@pytest.mark.parametrize("f, a, b", CASES)
def test_same_root_as_scipy(f, a, b):
    kw = dict(xtol=1e-300, rtol=4 * 2.220446049250313e-16, maxiter=200)
    assert brentq(f, a, b, **kw) == pytest.approx(scipy_brentq(f, a, b, **kw), rel=1e-14, abs=1e-300)


def test_refuses_a_bracket_without_sign_change():
    with pytest.raises(ValueError, match="different signs"):
        brentq(lambda x: x * x + 1.0, -1.0, 1.0)
