"""The compiled closed-form modal propagator (solver/_closed.py) against independent references.

Each mode obeys (paper eq. 9, generalised)

    eta'' + 2 xi omega eta' + omega^2 eta = a + b tau + d sin(Omega tau + phi).

The reference is :func:`scipy.integrate.solve_ivp` (DOP853, rtol 1e-12) on
each oscillator alone, plus a few textbook closed forms (resonance, rigid
body, static limit). Every regime is covered: undamped, light damping,
nearly critical, critical, over-damped and rigid-body (omega = 0) modes.

Tolerance: DOP853 at rtol 1e-12 / atol 1e-15 of the amplitude has a global
error of ~1e-11 of the amplitude over a few periods (measured ~1e-12 here);
we require 1e-9 of the largest |eta| (or |eta'|) of the run, which leaves a
factor of ~100 for the reference's own error while any wrong term in the
closed form (a sign, a missing factor) shows up at 1e-3 or more.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from impactbeam.solver import _closed, _elementary, kernels
from impactbeam.solver._dense import _row3
from impactbeam.solver._elementary import kernel_work
from impactbeam.solver._events import row_at
from impactbeam.solver.states import ModalDynamics

REL_TOL = 1e-9

# (omega [rad/s], xi): every damping regime, and a rigid-body mode
REGIMES = [
    (7.0, 0.0),
    (7.0, 0.02),
    (7.0, 0.9999),
    (7.0, 1.0),
    (7.0, 2.5),
    (0.0, 0.0),
    (0.0, 0.3),  # xi has no effect on a rigid-body mode (decay = xi * omega = 0)
]

# load forms: (a, b, d, Omega, phi)
LOADS = {
    "none": (0.0, None, None, 0.0, 0.0),
    "constant": (1.3, None, None, 0.0, 0.0),
    "linear": (0.4, -0.9, None, 0.0, 0.0),
    "sine": (0.0, None, 2.0, 11.0, 0.0),
    "sine_phase": (0.0, None, 2.0, 4.1, 0.7),
    "all": (-0.5, 0.6, 1.5, 3.3, -1.1),
}


def _reference(omega, xi, load, eta0, deta0, taus):
    """Single oscillator by DOP853 at rtol 1e-12 (independent of the closed form)."""
    a, b, d, Om, phi = load
    b = b or 0.0
    d = d or 0.0

    def rhs(t, y):
        f = a + b * t + d * math.sin(Om * t + phi)
        return [y[1], f - 2 * xi * omega * y[1] - omega**2 * y[0]]

    scale = max(abs(eta0), abs(deta0), abs(a) + abs(b) + abs(d), 1.0)
    sol = solve_ivp(rhs, (0.0, taus[-1]), [eta0, deta0], method="DOP853", rtol=1e-12,
                    atol=1e-15 * scale, t_eval=taus, dense_output=False)
    assert sol.success
    return sol.y[0], sol.y[1]


class _Segment:
    """One segment of the compiled closed form (setup once, evaluate anywhere)."""

    def __init__(self, omegas, xis, load, eta0, deta0, decays=None, cosine=0.0):
        omegas = np.asarray(omegas, float)
        decay = np.asarray(xis, float) * omegas if decays is None else np.asarray(decays, float)
        dyn = ModalDynamics(omegas, decay)
        n = len(omegas)
        a, b, d, Om, phi = load
        self.reg = np.where(dyn.under, 0, np.where(dyn.over, 2, 1)).astype(np.int64)
        self.a = dyn.decay
        self.w = np.where(dyn.under, dyn.wd, dyn.wh)
        self.om = dyn.omega
        self.load = (np.full(n, a), np.full(n, b or 0.0), np.full(n, d or 0.0), np.full(n, cosine))
        self.Om, self.phi = Om, phi
        self.eta0, self.deta0 = np.asarray(eta0, float), np.asarray(deta0, float)
        self.h0, self.dh0, self.P = np.empty(n), np.empty(n), np.empty((n, _closed.NP))
        _closed.setup(self.reg, self.a, self.om, *self.load, Om, phi, self.eta0, self.deta0, self.h0, self.dh0, self.P)

    def project(self, v, u=None, alpha=(0.0, 0.0, 0.0)):
        """Row ``v . z + u . (z' - alpha)`` as (VH, VD, PV), one row."""
        n = self.om.size
        u = np.zeros(n) if u is None else np.asarray(u, float)
        AL = np.tile(np.asarray(alpha, float), (n, 1))
        VH, VD, PV = np.empty((1, n)), np.empty((1, n)), np.empty((1, _closed.NP))
        _closed.project(np.asarray(v, float)[None], u[None], np.zeros(1), self.a, self.om, self.h0, self.dh0,
                        self.P, AL, self.Om, VH, VD, PV, 1)
        return VH, VD, PV

    def integral(self, v, T):
        VH, VD, PV = self.project(v)
        return _closed.integral_of(VH, VD, PV, self.reg, self.a, self.w, self.om, self.Om, self.phi, T)

    def evaluate(self, taus):
        n = self.om.size
        eta, deta = np.empty((n, len(taus))), np.empty((n, len(taus)))
        e, d = np.empty(n), np.empty(n)
        for k, tau in enumerate(taus):
            _closed.state_at(float(tau), self.reg, self.a, self.w, self.om, self.h0, self.dh0, self.P, self.Om,
                             self.phi, e, d, kernel_work(n))
            eta[:, k], deta[:, k] = e, d
        return eta, deta


def _evaluate(omegas, xis, load, eta0, deta0, taus):
    seg = _Segment(omegas, xis, load, eta0, deta0)
    return seg.evaluate(taus), seg


@pytest.mark.parametrize("load_name", list(LOADS))
def test_every_regime_matches_solve_ivp(load_name):
    load = LOADS[load_name]
    taus = np.linspace(0.0, 3.0, 301)  # about 3.3 periods of omega = 7
    omegas = [r[0] for r in REGIMES]
    xis = [r[1] for r in REGIMES]
    eta0 = np.linspace(-0.7, 0.9, len(REGIMES))
    deta0 = np.linspace(1.1, -0.4, len(REGIMES))
    (eta, deta), _ = _evaluate(omegas, xis, load, eta0, deta0, taus)
    for i, (om, xi) in enumerate(REGIMES):
        ref_e, ref_d = _reference(om, xi, load, eta0[i], deta0[i], taus)
        se = np.abs(ref_e).max()
        sd = np.abs(ref_d).max()
        assert np.abs(eta[i] - ref_e).max() <= REL_TOL * se, (om, xi, load_name)
        assert np.abs(deta[i] - ref_d).max() <= REL_TOL * sd, (om, xi, load_name)


@pytest.mark.parametrize("xi", [0.0, 0.02, 1.0, 2.5])
def test_start_values_reproduced_exactly(xi):
    # At tau = 0 the closed form must return its initial state up to round-off
    # of the particular part subtracted and added back (a few ulp).
    (eta, deta), _ = _evaluate([7.0, 0.0], [xi, xi], LOADS["all"], [0.3, -0.2], [-1.0, 0.5], np.zeros(1))
    np.testing.assert_allclose(eta[:, 0], [0.3, -0.2], rtol=0, atol=1e-15)
    np.testing.assert_allclose(deta[:, 0], [-1.0, 0.5], rtol=0, atol=1e-15)


def test_exact_resonance_undamped():
    # xi = 0, Omega = omega, from rest: eta = d/(2 w^2) (sin wt - w t cos wt),
    # the textbook secular solution. Relative 1e-12: only round-off separates them.
    w, d = 7.0, 2.0
    taus = np.linspace(0.0, 10.0, 501)
    (eta, deta), _ = _evaluate([w], [0.0], (0.0, None, d, w, 0.0), [0.0], [0.0], taus)
    exact = d / (2 * w**2) * (np.sin(w * taus) - w * taus * np.cos(w * taus))
    dexact = d / 2 * taus * np.sin(w * taus)
    assert np.abs(eta[0] - exact).max() <= 1e-12 * np.abs(exact).max()
    assert np.abs(deta[0] - dexact).max() <= 1e-12 * np.abs(dexact).max()
    # and the secular growth is there: amplitude ~ d t / (2 w) at the end
    assert np.abs(eta[0][-60:]).max() == pytest.approx(d * 10.0 / (2 * w**2) * w, rel=0.02)


def test_resonance_against_solve_ivp_with_phase():
    load = (0.2, None, 1.0, 7.0, 0.4)
    taus = np.linspace(0.0, 4.0, 201)
    (eta, deta), _ = _evaluate([7.0], [0.0], load, [0.1], [-0.3], taus)
    ref_e, ref_d = _reference(7.0, 0.0, load, 0.1, -0.3, taus)
    assert np.abs(eta[0] - ref_e).max() <= REL_TOL * np.abs(ref_e).max()
    assert np.abs(deta[0] - ref_d).max() <= REL_TOL * np.abs(ref_d).max()


def test_rigid_body_mode_polynomials():
    # omega = 0: eta = eta0 + v0 t + a t^2/2 + b t^3/6 + d (phi-terms) exactly.
    a, b, d, Om, phi = 0.7, -0.2, 0.5, 3.0, 0.3
    taus = np.linspace(0.0, 5.0, 101)
    (eta, deta), _ = _evaluate([0.0], [0.0], (a, b, d, Om, phi), [0.4], [-0.1], taus)
    # sine part: particular -d sin(Om t + phi)/Om^2, plus the homogeneous line fixing the start
    s = lambda t: -d * np.sin(Om * t + phi) / Om**2  # noqa: E731
    ds = lambda t: -d * np.cos(Om * t + phi) / Om  # noqa: E731
    exact = 0.4 + (-0.1 - ds(0.0)) * taus - s(0.0) + s(taus) + a * taus**2 / 2 + b * taus**3 / 6
    dexact = (-0.1 - ds(0.0)) + ds(taus) + a * taus + b * taus**2 / 2
    np.testing.assert_allclose(eta[0], exact, rtol=0, atol=1e-13 * np.abs(exact).max())
    np.testing.assert_allclose(deta[0], dexact, rtol=0, atol=1e-13 * np.abs(dexact).max())


@pytest.mark.parametrize("xi", [0.02, 0.9999, 1.0, 2.5])
def test_static_limit_and_no_overflow(xi):
    # A constant load a settles to a / omega^2; with xi = 2.5 and omega = 1e4 the
    # slow over-damped root is omega (xi - sqrt(xi^2 - 1)) = 2.1e3 /s, so after
    # 0.05 s every transient is below e^-100: the static value to round-off.
    # The fast root's exponential e^{-(a + w_h) tau} must not overflow or give NaN.
    w = 1e4
    taus = np.array([0.0, 1e-3, 0.05, 10.0, 1e4])
    (eta, deta), _ = _evaluate([w], [xi], (3.0, None, None, 0.0, 0.0), [1e-4], [2.0], taus)
    assert np.all(np.isfinite(eta)) and np.all(np.isfinite(deta))
    if xi >= 0.9999:
        assert eta[0, 2] == pytest.approx(3.0 / w**2, rel=1e-12)
    assert eta[0, -1] == pytest.approx(3.0 / w**2, rel=1e-12)
    assert abs(deta[0, -1]) <= 1e-12


def test_near_critical_is_continuous_across_xi_equals_one():
    # The three kernels (under, critical, over) must join: the response is an
    # analytic function of xi. Between xi = 1 - 1e-7 and 1 + 1e-7 the change is
    # O(1e-7) of the amplitude; cancellation in a bad formula would give O(1).
    taus = np.linspace(0.0, 3.0, 61)
    outs = []
    for xi in (1 - 1e-7, 1.0, 1 + 1e-7):
        (eta, _), _ = _evaluate([7.0], [xi], LOADS["all"], [0.5], [-0.8], taus)
        outs.append(eta[0])
    amp = np.abs(outs[1]).max()
    assert np.abs(outs[0] - outs[1]).max() < 1e-6 * amp
    assert np.abs(outs[2] - outs[1]).max() < 1e-6 * amp


def test_derivatives_are_those_of_the_closed_form():
    # _closed.derivatives gives d^k/dtau^k (v . eta) at 0 from the equation of
    # motion; compare orders 1-3 with central differences of the closed form
    # (h = 1e-3: truncation ~h^2 of the next derivative, ~1e-6 relative here).
    seg = _Segment([7.0, 0.0, 3.0], [0.05, 0.0, 1.5], LOADS["all"], [0.3, 0.1, -0.2], [0.2, -0.4, 0.6])
    v = np.array([0.7, -1.1, 0.4])
    out, mag = np.empty(4), np.empty(4)
    _closed.derivatives(v, np.zeros(3), 0.25, seg.a, seg.om, seg.eta0, seg.deta0, *seg.load, np.zeros((3, 3)),
                        seg.Om, seg.phi, 3, out, mag, np.empty((2, 5)))
    h = 1e-3
    taus = np.array([0.0, h, 2 * h, 3 * h, 4 * h])
    eta, deta = seg.evaluate(taus)
    g = 0.25 + v @ eta
    dg = v @ deta
    assert out[0] == pytest.approx(g[0], abs=1e-15)
    assert out[1] == pytest.approx(dg[0], abs=1e-15)
    # one-sided 4th-order differences of the velocity for orders 2 and 3
    d2 = (-25 * dg[0] + 48 * dg[1] - 36 * dg[2] + 16 * dg[3] - 3 * dg[4]) / (12 * h)
    d3 = (35 * dg[0] - 104 * dg[1] + 114 * dg[2] - 56 * dg[3] + 11 * dg[4]) / (12 * h * h)
    assert out[2] == pytest.approx(d2, rel=1e-6)
    assert out[3] == pytest.approx(d3, rel=1e-3)
    assert np.all(mag >= np.abs(out) * (1 - 1e-12))


@pytest.mark.parametrize("load_name", list(LOADS))
def test_integral_in_closed_form_matches_quadrature(load_name):
    # _closed.integral_of: int_0^T v . eta dtau; Gauss-Legendre with 200 points
    # per unit time integrates these smooth functions to ~1e-14 relative.
    seg = _Segment([o for o, _ in REGIMES], [x for _, x in REGIMES], LOADS[load_name],
                   np.linspace(-0.7, 0.9, len(REGIMES)), np.linspace(1.1, -0.4, len(REGIMES)))
    v = np.linspace(0.5, -1.5, len(REGIMES))
    T = 2.3
    exact = seg.integral(v, T)
    x, w = np.polynomial.legendre.leggauss(460)
    taus = 0.5 * T * (x + 1)
    eta, _ = seg.evaluate(taus)
    quad = 0.5 * T * float((v @ eta) @ w)
    assert exact == pytest.approx(quad, rel=1e-12, abs=1e-13)


def test_exact_resonance_integral():
    # the resonant tau cos(theta) term has its own antiderivative
    seg = _Segment([7.0], [0.0], (0.0, None, 2.0, 7.0, 0.3), [0.1], [0.0])
    T = 3.0
    exact = seg.integral(np.ones(1), T)
    x, w = np.polynomial.legendre.leggauss(400)
    eta, _ = seg.evaluate(0.5 * T * (x + 1))
    assert exact == pytest.approx(0.5 * T * float(eta[0] @ w), rel=1e-12)


# --------------------------------------------------------------------------- the generalised closed form
# (states whose modes do not diagonalise their damping: cosine loads, rows on z and z', damped rigid modes)

def _reference_general(omega, decay, load, cosine, eta0, deta0, taus):
    a, b, d, Om, phi = load
    b = b or 0.0
    d = d or 0.0

    def rhs(t, y):
        f = a + b * t + d * math.sin(Om * t + phi) + cosine * math.cos(Om * t + phi)
        return [y[1], f - 2 * decay * y[1] - omega**2 * y[0]]

    sol = solve_ivp(rhs, (0.0, taus[-1]), [eta0, deta0], method="DOP853", rtol=1e-12,
                    atol=1e-15 * max(abs(eta0), abs(deta0), 1.0), t_eval=taus)
    assert sol.success
    return sol.y[0], sol.y[1]


@pytest.mark.parametrize("omega,decay", [(7.0, 0.0), (7.0, 0.3), (7.0, 7.0), (7.0, 12.0), (0.0, 0.8), (0.0, 0.0)])
def test_cosine_loads_and_damped_rigid_coordinates(omega, decay):
    # A cosine term (the rate of a load acting on a block's first equation) and a
    # rigid-body coordinate with damping (Rayleigh's alpha, z'' + 2a z' = f): the
    # closed form against DOP853 (tolerance as for every regime above).
    load, cosine = LOADS["all"], 0.9
    taus = np.linspace(0.0, 3.0, 121)
    seg = _Segment([omega], [0.0], load, [0.4], [-0.3], decays=[decay], cosine=cosine)
    eta, deta = seg.evaluate(taus)
    ref, dref = _reference_general(omega, decay, load, cosine, 0.4, -0.3, taus)
    assert np.abs(eta[0] - ref).max() <= REL_TOL * np.abs(ref).max()
    assert np.abs(deta[0] - dref).max() <= REL_TOL * np.abs(dref).max()


def test_rows_on_rates_project_exactly():
    # A row v z + u (z' - alpha(tau)) written as (VH, VD, PV) evaluates to the same
    # function as the closed form itself (values and slopes, every regime; alpha a
    # load-shaped function), and its integral and derivatives follow.
    omegas = [o for o, _ in REGIMES] + [0.0]
    xis = [x for _, x in REGIMES] + [0.0]
    decays = np.asarray(xis) * np.asarray(omegas)
    decays[-1] = 0.6  # a damped rigid-body coordinate
    n = len(omegas)
    seg = _Segment(omegas, xis, LOADS["all"], np.linspace(-0.7, 0.9, n), np.linspace(1.1, -0.4, n), decays=decays,
                   cosine=0.35)
    v, u = np.linspace(0.5, -1.5, n), np.linspace(-0.3, 0.8, n)
    alpha = (0.2, -0.1, 0.45)
    VH, VD, PV = seg.project(v, u, alpha)
    taus = np.linspace(0.0, 2.3, 47)
    eta, deta = seg.evaluate(taus)
    _, Om, phi = LOADS["all"][2], seg.Om, seg.phi
    al = alpha[0] + alpha[1] * taus + alpha[2] * np.sin(Om * taus + phi)
    direct = v @ eta + u @ (deta - al[None, :])
    kw = kernel_work(n)
    rows = np.array([row_at(0, t, seg.reg, seg.a, seg.w, seg.om, VH, VD, np.zeros(1), PV, Om, phi, kw)[0] for t in taus])
    assert np.abs(rows - direct).max() <= 1e-12 * np.abs(direct).max()
    T = 2.3
    exact = _closed.integral_of(VH, VD, PV, seg.reg, seg.a, seg.w, seg.om, Om, phi, T)
    x, w = np.polynomial.legendre.leggauss(460)
    tq = 0.5 * T * (x + 1)
    e, d = seg.evaluate(tq)
    alq = alpha[0] + alpha[1] * tq + alpha[2] * np.sin(Om * tq + phi)
    quad = 0.5 * T * float((v @ e + u @ (d - alq[None, :])) @ w)
    assert exact == pytest.approx(quad, rel=1e-12, abs=1e-13)
    out, mag = np.empty(4), np.empty(4)
    AL = np.tile(np.asarray(alpha), (n, 1))
    _closed.derivatives(v, u, 0.0, seg.a, seg.om, seg.eta0, seg.deta0, *seg.load, AL, Om, phi, 3, out, mag, np.empty((2, 5)))
    assert out[0] == pytest.approx(direct[0], rel=1e-13)
    # the second derivative from the equation of motion against the one from the kernels (another formula)
    _, d1, d2 = _row3(0.0, seg.reg, seg.a, seg.w, seg.om, VH, VD, np.zeros(1), PV, Om, phi, kw)
    assert out[1] == pytest.approx(d1, rel=1e-12)
    assert out[2] == pytest.approx(d2, rel=1e-12)
    # and a finite difference of the slope: h = 1e-4, truncation h^2 f^(4) / 3, 1e-5 relative (fast root 34/s)
    h = 1e-4
    g1 = [row_at(0, t, seg.reg, seg.a, seg.w, seg.om, VH, VD, np.zeros(1), PV, Om, phi, kw)[1] for t in (0.0, h, 2 * h)]
    assert out[2] == pytest.approx((-3 * g1[0] + 4 * g1[1] - g1[2]) / (2 * h), rel=1e-4)


def _ulps(got: np.ndarray, ref: np.ndarray) -> float:
    """Largest difference in units in the last place of the reference value."""
    return float(np.max(np.abs(got - ref) / np.spacing(np.abs(ref))))


@pytest.mark.parametrize(("lo", "hi"), [(0.0, 1.0), (1.0, 1e2), (1e2, 1e4), (1e4, 1e6), (1e6, 1e8), (1e8, 2.0**28)])
def test_sincos_is_the_library_to_three_ulps(lo, hi):
    # the closed form's own sin and cos (a polynomial after a three-part reduction by pi/4) against the C
    # library's (math.sin and math.cos, not NumPy's, whose SIMD loops differ by CPU): measured at most 2 ulps over
    # 400,000 arguments per range; the library itself is within 1 ulp of the truth, hence 3. A wrong coefficient
    # or reduction constant is off by 1e-9 or more.
    rng = np.random.default_rng(int(hi) % 1000 + 3)
    x = rng.uniform(lo, hi, 200_000)
    x = np.concatenate([x, -x])
    twin = kernels.interpreted().sincos  # the same source run by Python (a short run's first kernels)
    got = np.array([twin(float(v)) for v in x[:2000]])
    s, c = _many(_closed.sincos, x)
    assert np.array_equal(s[:2000], got[:, 0]) and np.array_equal(c[:2000], got[:, 1])  # same bits as compiled
    ref_s, ref_c = _many(_library_sincos, x)
    assert _ulps(s, ref_s) <= 3 and _ulps(c, ref_c) <= 3


def test_sincos_at_the_edges():
    k = np.arange(1, 100_000) * (np.pi / 2)  # the zeros of sin and cos: absolute error below 1e-24 there
    s, c = _many(_closed.sincos, k)
    ref_s, ref_c = _many(_library_sincos, k)
    assert np.max(np.abs(s - ref_s)) < 1e-20 and np.max(np.abs(c - ref_c)) < 1e-20
    assert _closed.sincos(0.0) == (0.0, 1.0)
    for x in (2.0**28 * 1.5, 1e12, -3e15):  # beyond the reduction's range: the library's values
        assert _closed.sincos(x) == (math.sin(x), math.cos(x))
    for x in (math.inf, -math.inf, math.nan):
        assert all(math.isnan(v) for v in _closed.sincos(x))


@pytest.mark.parametrize(("lo", "hi"), [(-1e-6, 0.0), (-1.0, 0.0), (-30.0, -1.0), (-708.0, -30.0), (0.0, 709.0)])
def test_exponential_is_the_library_to_two_ulps(lo, hi):
    # the kernels' own e^x (2^k times the degree-13 Taylor polynomial of e^r, |r| <= ln2/2, truncation 4e-18)
    # against the C library's math.exp: measured at most 1 ulp over 400,000 arguments per range (a tenth of
    # them differ); the library is within 1 ulp of the truth, hence 2. A wrong coefficient is off by far more.
    rng = np.random.default_rng(int(abs(lo)) + 11)
    x = rng.uniform(lo, hi, 400_000)
    got, _ = _many(_pair(_elementary.exponential), x)
    ref, _ = _many(_pair(math.exp), x)
    assert _ulps(got, ref) <= 2
    twin = kernels.interpreted().exponential
    assert np.array_equal(got[:2000], [twin(float(v)) for v in x[:2000]])  # same bits as compiled
    assert _elementary.exponential(0.0) == 1.0
    for v in (-709.5, -745.0, -800.0, 710.0, -math.inf, math.inf):  # beyond the reduction: the library's values
        assert _elementary.exponential(v) == math.exp(v) if v < 709.8 else math.isinf(_elementary.exponential(v))
    assert math.isnan(_elementary.exponential(math.nan))


def test_all_kernels_at_once_are_each_modes_kernel():
    # kernels_at evaluates every under-damped mode's kernels in loops the compiler vectorises (padded to a
    # multiple of four) and redoes the others with kernel(): the same bits as kernel(), mode by mode, for
    # every regime, at tau = 0, beyond the reduced ranges (w tau > 2**28, a tau > 708) and for 1 to 13 modes
    rng = np.random.default_rng(5)
    for n in range(1, 14):
        reg = rng.choice([0, 0, 0, 1, 2], n)
        a = rng.uniform(0.0, 50.0, n)
        w = np.where(reg == 1, 0.0, rng.uniform(1.0, 3e4, n))
        kw = _elementary.kernel_work(n)
        for tau in (0.0, 1e-7, 3.3e-3, 0.71, 2e4, 1e5):
            _elementary.kernels_at(tau, reg, a, w, kw)
            for m in range(n):
                assert (kw[2, m], kw[3, m]) == _elementary.kernel(reg[m], a[m], w[m], tau), (n, tau, m)


def _pair(fn):
    """``x -> (fn(x), 0.0)`` compiled, for :func:`_many`."""
    from numba import njit

    @njit
    def pair(x):
        return fn(x), 0.0

    return pair


def _library_sincos(x: float) -> tuple[float, float]:
    return math.sin(x), math.cos(x)


def _many(fn, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``fn`` (a compiled ``x -> (sin, cos)``) at every ``x``, in a compiled loop."""
    from numba import njit

    kernel = njit(fn) if not hasattr(fn, "py_func") else fn

    @njit
    def run(x, s, c):
        for i in range(x.size):
            s[i], c[i] = kernel(x[i])

    s, c = np.empty_like(x), np.empty_like(x)
    run(x, s, c)
    return s, c
