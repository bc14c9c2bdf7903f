"""Compiled closed form of the modal equations on one segment (every damping regime).

Each coordinate ``z`` of a state (a mode, or one block of a state whose
damping its modes do not diagonalise, see :mod:`~impactbeam.solver.blocks`)
obeys (paper eq. 9, generalised to every damping regime)

.. math:: \\ddot z + 2a\\dot z + \\omega^2 z = A + B\\tau + D\\sin\\theta + E\\cos\\theta,
          \\qquad \\theta = \\Omega\\tau + \\varphi,

on a segment ``0 <= tau`` in which the state and the load form do not change.
The solution is ``z = z_h + P`` with the particular part written on eight
real coefficients (``p[0..7]``)

.. math:: P = p_0 + p_1\\tau + p_2\\tau^2 + p_3\\tau^3 + p_4\\sin\\theta
          + p_5\\cos\\theta + p_6\\,\\tau\\cos\\theta + p_7\\,\\tau\\sin\\theta,

(``p_2, p_3`` only for rigid-body coordinates, ``p_6, p_7`` only at exact
undamped resonance) and the homogeneous part from its initial values ``h0, dh0``

.. math:: z_h = (e_C + a e_S) h_0 + e_S \\dot h_0, \\qquad
          \\dot z_h = -\\omega^2 e_S h_0 + (e_C - a e_S) \\dot h_0,

where ``e_C, e_S`` are ``e^{-a tau}`` times ``cos, sin(w tau)/w`` (regime 0,
under-damped), ``1, tau`` (regime 1: critical damping, and rigid-body modes
with ``omega = a = 0``) or ``cosh, sinh(w tau)/w`` (regime 2, over-damped,
which includes a damped rigid-body coordinate, ``omega = 0 < a``), each
evaluated without cancellation or overflow. This is the paper's eq. (10) with
its ``B1, B2`` for every regime and for linear and sinusoidal loads.

A quantity the solver watches (a contactor's opening, a deflection, a
contact force) is a *row*: ``base + v . z + u . (z' - alpha(tau))`` with
coefficient vectors ``v, u`` on the coordinates and their rates (``u = 0``
for a state whose modes diagonalise its damping, where ``z`` are the modal
coordinates) and ``alpha`` the part of the load that acts on a block's first
equation. :func:`project` writes a row on one segment as, per coordinate, the
value ``VH`` and slope ``VD`` of its homogeneous part at ``tau = 0`` plus one
particular part ``PV``; since ``v z_h + u z_h'`` is itself a homogeneous
solution, every bound and evaluation below needs only ``(VH, VD, PV)``.

All functions are compiled with numba (``cache=True``); they run as plain
Python when ``NUMBA_DISABLE_JIT=1``.
"""

from __future__ import annotations

import math

import numpy as np

from ._elementary import REG_CRITICAL, REG_OVER, REG_UNDER, ROW_C, ROW_S, kernel, kernels_at, sincos
from ._jit import njit

__all__ = ["REG_UNDER", "REG_CRITICAL", "REG_OVER", "NP", "sincos", "kernel", "setup", "segment_setup", "state_at",
           "mode_state", "kernels_into", "state_from", "load_phase", "particular_at",
           "project", "integral_of", "derivatives", "curvature_bound", "particular_spread",
           "clear_to_end", "jerk_bound", "workspace",
           "copy_into",
           "ipow"]

EPS = 2.220446049250313e-16
NP = 8  # coefficients of a particular part


@njit(cache=True, nogil=True, _nrt=False)
def particular(p, tau, Om, phi):  # pragma: no cover - compiled
    """Particular part and its derivative from the eight coefficients ``p``."""
    s, c = load_phase(tau, Om, phi)
    return particular_at(p, tau, Om, s, c)


@njit(cache=True, nogil=True, _nrt=False)
def load_phase(tau, Om, phi):  # pragma: no cover - compiled
    """``(sin, cos)`` of the harmonic load's phase ``Om tau + phi`` (zeros without a harmonic part).

    Every coordinate of a state shares it: computed once per time and passed
    to :func:`particular_at`, the same numbers as :func:`particular`.
    """
    if Om != 0.0:
        return sincos(Om * tau + phi)
    return 0.0, 0.0


@njit(cache=True, nogil=True, _nrt=False)
def particular_at(p, tau, Om, s, c):  # pragma: no cover - compiled
    """:func:`particular` with the load's phase given as ``s, c`` (:func:`load_phase`)."""
    val = p[0] + tau * (p[1] + tau * (p[2] + tau * p[3]))
    der = p[1] + tau * (2.0 * p[2] + 3.0 * p[3] * tau)
    if Om != 0.0:
        val += p[4] * s + p[5] * c + tau * (p[6] * c + p[7] * s)
        der += Om * (p[4] * c - p[5] * s) + p[6] * (c - Om * tau * s) + p[7] * (s + Om * tau * c)
    return val, der


@njit(cache=True, nogil=True, _nrt=False)
def derivative_coefficients(p, Om):  # pragma: no cover - compiled
    """The eight coefficients of the derivative of the particular part ``p`` (a tuple)."""
    return (p[1], 2.0 * p[2], 3.0 * p[3], 0.0, -Om * p[5] + p[7], Om * p[4] + p[6], Om * p[7], -Om * p[6])


@njit(cache=True, nogil=True, _nrt=False)
def setup(reg, a, om, load_A, load_B, load_D, load_E, Om, phi, eta0, deta0, h0, dh0, P):  # pragma: no cover
    """Coefficients of a segment from its loads and initial state.

    Parameters
    ----------
    reg, a, om : ndarray, (n,)
        Regime, decay ``xi omega`` and natural frequency of each coordinate.
    load_A, load_B, load_D, load_E : ndarray, (n,)
        Load ``A + B tau + D sin(theta) + E cos(theta)``.
    eta0, deta0 : ndarray, (n,)
        Coordinates and rates at ``tau = 0``.
    h0, dh0, P : ndarray, (n,), (n,), (n, 8)
        Filled: homogeneous initial values and particular coefficients.
    """
    W2 = Om * Om
    sn, cs = load_phase(0.0, Om, phi)
    for n in range(om.size):
        A = load_A[n]
        B = load_B[n]
        D = load_D[n]
        E = load_E[n]
        for q in range(NP):
            P[n, q] = 0.0
        o = om[n]
        an = a[n]
        if o == 0.0 and an == 0.0:  # undamped rigid-body coordinate: z'' = f
            P[n, 2] = 0.5 * A
            P[n, 3] = B / 6.0
            if D != 0.0 or E != 0.0:
                P[n, 4] = -D / W2
                P[n, 5] = -E / W2
        else:
            if o == 0.0:  # damped rigid-body coordinate: z'' + 2a z' = f
                P[n, 2] = B / (4.0 * an)
                P[n, 1] = (A - 2.0 * P[n, 2]) / (2.0 * an)
            else:
                o2 = o * o
                P[n, 0] = A / o2 - 2.0 * an * B / (o2 * o2)
                P[n, 1] = B / o2
            if D != 0.0 or E != 0.0:
                re = o * o - W2
                im = 2.0 * an * Om
                den = re * re + im * im
                if math.sqrt(den) <= 1e-12 * max(o * o, W2):  # exact undamped resonance
                    P[n, 6] = -D / (2.0 * o)
                    P[n, 7] = E / (2.0 * o)
                else:  # Im and Re of (D - i E)... : the response to exp(i theta) is 1 / (re + i im)
                    P[n, 4] = (D * re + E * im) / den
                    P[n, 5] = (E * re - D * im) / den
        p0, dp0 = particular_at(P[n], 0.0, Om, sn, cs)
        h0[n] = eta0[n] - p0
        dh0[n] = deta0[n] - dp0


@njit(cache=True, nogil=True, _nrt=False)
def mode_state(eC, eS, a, o, h, dh):  # pragma: no cover - compiled
    """A homogeneous solution and its rate from its kernels and its initial value ``h`` and slope ``dh``."""
    return (eC + a * eS) * h + eS * dh, -o * o * eS * h + (eC - a * eS) * dh


@njit(cache=True, nogil=True, _nrt=False)
def state_at(tau, reg, a, w, om, h0, dh0, P, Om, phi, e, d, kw):  # pragma: no cover - compiled
    """Coordinates ``e`` and rates ``d`` at ``tau`` (filled in place; ``kw`` from :func:`kernel_work`)."""
    kernels_at(tau, reg, a, w, kw)
    state_from(tau, kw[ROW_C], kw[ROW_S], a, om, h0, dh0, P, Om, phi, e, d)


@njit(cache=True, nogil=True, _nrt=False)
def kernels_into(tau, reg, a, w, kc, ks, kw):  # pragma: no cover - compiled
    """Every coordinate's kernels ``(e_C, e_S)`` at ``tau`` into ``kc, ks`` (:func:`kernels_at` in ``kw``)."""
    kernels_at(tau, reg, a, w, kw)
    for n in range(a.size):
        kc[n] = kw[ROW_C, n]
        ks[n] = kw[ROW_S, n]


@njit(cache=True, nogil=True, _nrt=False)
def state_from(tau, kc, ks, a, om, h0, dh0, P, Om, phi, e, d):  # pragma: no cover - compiled
    """:func:`state_at` with the kernels at ``tau`` given (:func:`kernels_into`): the same numbers."""
    sn, cs = load_phase(tau, Om, phi)
    for n in range(om.size):
        pv, pd = particular_at(P[n], tau, Om, sn, cs)
        zh, dzh = mode_state(kc[n], ks[n], a[n], om[n], h0[n], dh0[n])
        e[n] = zh + pv
        d[n] = dzh + pd


@njit(cache=True, nogil=True, _nrt=False)
def project(V, U, base, a, om, h0, dh0, P, AL, Om, VH, VD, PV, rows):  # pragma: no cover - compiled
    """Write the rows ``base + V z + U (z' - alpha)`` of one segment as ``(VH, VD, PV)``.

    ``AL[n] = (alpha_0, alpha_1, alpha_sin)``: ``alpha_n(tau) = alpha_0 +
    alpha_1 tau + alpha_sin sin(theta)``. ``VH[c, n]``, ``VD[c, n]`` are the
    value and slope at 0 of coordinate ``n``'s homogeneous contribution to row
    ``c``; ``PV[c]`` the coefficients of the row's particular part (without
    ``base``). Only the first ``rows`` rows are written.
    """
    for c in range(rows):
        for q in range(NP):
            PV[c, q] = 0.0
    for n in range(h0.size):
        o2 = om[n] * om[n]
        ddh = -2.0 * a[n] * dh0[n] - o2 * h0[n]
        d0, d1, d2, d3, d4, d5, d6, d7 = derivative_coefficients(P[n], Om)
        d0 -= AL[n, 0]
        d1 -= AL[n, 1]
        d4 -= AL[n, 2]
        for c in range(rows):
            v = V[c, n]
            u = U[c, n]
            VH[c, n] = v * h0[n] + u * dh0[n]
            VD[c, n] = v * dh0[n] + u * ddh
            if v != 0.0 or u != 0.0:
                PV[c, 0] += v * P[n, 0] + u * d0
                PV[c, 1] += v * P[n, 1] + u * d1
                PV[c, 2] += v * P[n, 2] + u * d2
                PV[c, 3] += v * P[n, 3] + u * d3
                PV[c, 4] += v * P[n, 4] + u * d4
                PV[c, 5] += v * P[n, 5] + u * d5
                PV[c, 6] += v * P[n, 6] + u * d6
                PV[c, 7] += v * P[n, 7] + u * d7


@njit(cache=True, nogil=True, _nrt=False)
def _particular_curvature(p, Om, tmax):  # pragma: no cover - compiled
    """Bound on the second derivative of the particular part ``p`` on ``[0, tmax]``."""
    W = abs(Om)
    m = 2.0 * abs(p[2]) + 6.0 * abs(p[3]) * tmax
    if Om != 0.0:
        m += W * W * (abs(p[4]) + abs(p[5])) + (abs(p[6]) + abs(p[7])) * (2.0 * W + W * W * tmax)
    return m


@njit(cache=True, nogil=True, _nrt=False)
def _particular_jerk(p, Om, tmax):  # pragma: no cover - compiled
    """Bound on the third derivative of the particular part ``p`` on ``[0, tmax]``."""
    W = abs(Om)
    m = 6.0 * abs(p[3])
    if Om != 0.0:
        W3 = W * W * W  # as numba's constant power: one rounding per product
        m += W3 * (abs(p[4]) + abs(p[5])) + (abs(p[6]) + abs(p[7])) * (3.0 * W * W + W3 * tmax)
    return m


@njit(cache=True, nogil=True, _nrt=False)
def curvature_bound(VH, VD, a, om, PV, Om, tau_end, out):  # pragma: no cover - compiled
    """Bound on the second derivative of each row over ``[0, tau_end]``.

    Each coordinate's homogeneous contribution ``f`` to a row solves
    ``f'' + 2a f' + omega^2 f = 0`` with ``f(0) = VH``, ``f'(0) = VD``; for
    ``a >= 0`` its energy ``(f'^2 + omega^2 f^2)/2`` never grows, so
    ``|f''| <= (2a + omega) sqrt(f'(0)^2 + omega^2 f(0)^2)`` for all
    ``tau >= 0``. The particular part is bounded term by term.
    """
    tmax = max(tau_end, 0.0)
    for c in range(out.size):
        out[c] = _particular_curvature(PV[c], Om, tmax)
    for n in range(om.size):
        o = om[n]
        k = 2.0 * a[n] + o
        if k != 0.0:
            for c in range(out.size):
                vh = VH[c, n]
                vd = VD[c, n]
                out[c] += k * math.sqrt(vd * vd + o * o * vh * vh)
    for c in range(out.size):
        out[c] *= 1.0 + 1e-12  # round-off margin


@njit(cache=True, nogil=True, _nrt=False)
def jerk_bound(VH, VD, a, om, PV, Om, tau_end, out):  # pragma: no cover - compiled
    """Bound on the third derivative of each row over ``[0, tau_end]``.

    The slope of a homogeneous solution is a homogeneous solution too, so
    :func:`curvature_bound`'s argument applies to it, from ``(f'(0), f''(0))``.
    """
    tmax = max(tau_end, 0.0)
    for c in range(out.size):
        out[c] = _particular_jerk(PV[c], Om, tmax)
    for n in range(om.size):
        o = om[n]
        k = 2.0 * a[n] + o
        if k != 0.0:
            for c in range(out.size):
                vd = VD[c, n]
                dd = -2.0 * a[n] * vd - o * o * VH[c, n]
                out[c] += k * math.sqrt(dd * dd + o * o * vd * vd)
    for c in range(out.size):
        out[c] *= 1.0 + 1e-12


@njit(cache=True, nogil=True, _nrt=False)
def particular_spread(p, L):  # pragma: no cover - compiled
    """Bound on ``|P(tau) - p[0]|`` over ``0 <= tau <= L`` for the particular part ``p``, term by term."""
    return (L * (abs(p[1]) + L * (abs(p[2]) + L * abs(p[3]))) + math.sqrt(p[4] * p[4] + p[5] * p[5])
            + L * math.sqrt(p[6] * p[6] + p[7] * p[7]))


@njit(cache=True, nogil=True, _nrt=False)
def clear_to_end(VH, VD, om, base, PV, tau_end):  # pragma: no cover - compiled
    """True when every row is proven positive from where ``VH, VD`` hold up to ``tau_end``.

    ``VH, VD``: each coordinate's homogeneous contribution to each row and its
    slope at some ``tau`` of the segment. By :func:`curvature_bound`'s energy
    argument a contribution never exceeds ``sqrt(VD^2 + omega^2 VH^2) / omega``
    after ``tau`` (``omega > 0``; a row with a frequency-free contribution is
    not proven); the particular part by :func:`particular_spread` on ``[0,
    tau_end]``. A row proven positive throughout cannot switch, so the scan
    may skip to the segment's end: the same event-free segment, found in one
    step instead of one every few periods.
    """
    tmax = max(tau_end, 0.0)
    for c in range(base.size):
        p = PV[c]
        poly = particular_spread(p, tmax)
        low = base[c] + p[0] - poly
        spread = abs(base[c]) + abs(p[0]) + poly
        for n in range(om.size):
            vh = VH[c, n]
            vd = VD[c, n]
            if vh != 0.0 or vd != 0.0:
                o = om[n]
                if o <= 0.0:
                    return False
                env = math.sqrt(vd * vd + o * o * vh * vh) / o
                low -= env
                spread += env
        if low <= 1e-12 * spread:  # round-off margin
            return False
    return True


@njit(cache=True, nogil=True, _nrt=False)
def curvature_bound_at(tau, VH, VD, reg, a, w, om, PV, Om, tau_end, out, work_h, work_d, kw):  # pragma: no cover
    """:func:`curvature_bound` valid on ``[tau, tau_end]``, from the homogeneous parts at ``tau``.

    The homogeneous energy only decreases, so the bound tightens as a damped
    response decays; the scan refreshes it as it goes. ``work_h, work_d``
    are scratch arrays of the shape of ``VH``, ``kw`` that of :func:`kernels_at`.
    """
    rows = out.size
    kernels_at(tau, reg, a, w, kw)
    for n in range(om.size):
        eC = kw[ROW_C, n]
        eS = kw[ROW_S, n]
        k1 = eC + a[n] * eS
        k2 = -om[n] * om[n] * eS
        k3 = eC - a[n] * eS
        for c in range(rows):
            work_h[c, n] = k1 * VH[c, n] + eS * VD[c, n]
            work_d[c, n] = k2 * VH[c, n] + k3 * VD[c, n]
    curvature_bound(work_h, work_d, a, om, PV, Om, tau_end, out)


@njit(cache=True, nogil=True, _nrt=False)
def ipow(x, n):  # pragma: no cover - compiled
    """``x**n`` for an integer ``n >= 0`` by repeated squaring, as numba computes a float to an integer power.

    Written out so that the interpreted kernels (:mod:`~impactbeam.solver.kernels`)
    round exactly as the compiled ones (Python's ``**`` calls ``pow``).
    """
    r = 1.0
    while n != 0:
        if n & 1:
            r *= x
        n >>= 1
        x *= x
    return r


@njit(cache=True, nogil=True, _nrt=False)
def _load_derivative(A, B, D, E, Om, sphi, cphi, j):  # pragma: no cover - compiled
    """``d^j/dtau^j (A + B tau + D sin theta + E cos theta)`` at ``tau = 0``."""
    if j == 0:
        return A + D * sphi + E * cphi
    if j == 1:
        return B + Om * (D * cphi - E * sphi)
    s = ipow(Om, j)
    r = j % 4
    if r == 0:
        return s * (D * sphi + E * cphi)
    if r == 1:
        return s * (D * cphi - E * sphi)
    if r == 2:
        return -s * (D * sphi + E * cphi)
    return -s * (D * cphi - E * sphi)


@njit(cache=True, nogil=True, _nrt=False)
def derivatives(v, u, base, a, om, eta0, deta0, load_A, load_B, load_D, load_E, AL, Om, phi, kmax, out, mag, work):
    # pragma: no cover - compiled
    """Exact derivatives ``d^k/dtau^k (base + v z + u (z' - alpha))`` at ``tau = 0``, k = 0..kmax.

    From the equation of motion, ``z^(k+2) = f^(k) - 2a z^(k+1) - omega^2
    z^(k)``; ``mag[k]`` is the same sum taken with absolute values (the scale
    against which a derivative counts as zero up to round-off). ``work``: a
    scratch array of shape ``(2, kmax + 2)``.
    """
    sphi, cphi = sincos(phi)
    for k in range(kmax + 1):
        out[k] = 0.0
        mag[k] = 0.0
    out[0] = base
    mag[0] = abs(base)
    hist = work[0]
    habs = work[1]
    for n in range(om.size):
        vn = v[n]
        un = u[n]
        if vn == 0.0 and un == 0.0:
            continue
        hist[0] = eta0[n]
        habs[0] = abs(eta0[n])
        hist[1] = deta0[n]
        habs[1] = abs(deta0[n])
        for k in range(2, kmax + 2):
            f = _load_derivative(load_A[n], load_B[n], load_D[n], load_E[n], Om, sphi, cphi, k - 2)
            hist[k] = f - 2.0 * a[n] * hist[k - 1] - om[n] * om[n] * hist[k - 2]
            habs[k] = abs(f) + 2.0 * a[n] * habs[k - 1] + om[n] * om[n] * habs[k - 2]
        for k in range(kmax + 1):
            al = 0.0
            if un != 0.0:
                al = _load_derivative(AL[n, 0], AL[n, 1], AL[n, 2], 0.0, Om, sphi, cphi, k)
            out[k] += vn * hist[k] + un * (hist[k + 1] - al)
            mag[k] += abs(vn) * habs[k] + abs(un) * (habs[k + 1] + abs(al))


@njit(cache=True, nogil=True, _nrt=False)
def _integral_particular(p, Om, phi, T):  # pragma: no cover - compiled
    """``int_0^T`` of the particular part ``p``."""
    ip = T * (p[0] + T * (p[1] / 2.0 + T * (p[2] / 3.0 + T * p[3] / 4.0)))
    if Om != 0.0:
        th1 = Om * T + phi
        s0, c0 = sincos(phi)
        s1, c1 = sincos(th1)
        ip += p[4] * (c0 - c1) / Om + p[5] * (s1 - s0) / Om
        if p[6] != 0.0:  # int tau cos(theta) = [tau sin/Om + cos/Om^2]
            ip += p[6] * (T * s1 / Om + (c1 - c0) / (Om * Om))
        if p[7] != 0.0:  # int tau sin(theta) = [-tau cos/Om + sin/Om^2]
            ip += p[7] * (-T * c1 / Om + (s1 - s0) / (Om * Om))
    return ip


@njit(cache=True, nogil=True, _nrt=False)
def integral_of(VH, VD, PV, reg, a, w, om, Om, phi, T):  # pragma: no cover - compiled
    """``int_0^T`` of row 0 of a projection (:func:`project`), without its base, in closed form.

    For ``omega > 0`` a homogeneous solution integrates through its equation,
    ``int f = -([f'] + 2a [f]) / omega^2`` (``[.]`` the change over the
    interval); a rigid-body coordinate integrates its kernel directly.
    """
    total = _integral_particular(PV[0], Om, phi, T)
    for n in range(om.size):
        vh = VH[0, n]
        vd = VD[0, n]
        if vh == 0.0 and vd == 0.0:
            continue
        eC, eS = kernel(reg[n], a[n], w[n], T)
        an = a[n]
        o = om[n]
        fT = (eC + an * eS) * vh + eS * vd
        dfT = -o * o * eS * vh + (eC - an * eS) * vd
        if o != 0.0:
            total += -((dfT - vd) + 2.0 * an * (fT - vh)) / (o * o)
        elif an == 0.0:
            total += vh * T + 0.5 * vd * T * T
        else:  # f = vh + vd (1 - exp(-2 a tau)) / (2 a)
            total += vh * T + vd / (2.0 * an) * (T + math.expm1(-2.0 * an * T) / (2.0 * an))
    return total


@njit(cache=True, nogil=True, _nrt=False)
def segment_setup(s, kp, t, eta, deta, reg, dec, om, bu, au, Bc, Ac, bp, ap, smask, gap, side, kst,
                  pt0, pconst, pslope, pamp, pOm, pphase, h0, dh0, P, lA, lB, lD, lE, AL):
    # pragma: no cover - compiled
    """Closed-form coefficients of a segment starting at ``t`` in state slot ``s``, load piece ``kp``.

    The load on each coordinate's two equations (:mod:`~impactbeam.solver.blocks`):
    ``alpha = au u(t) + sum_c g_c Ac[c] + ap`` on the first and ``beta = bu u(t)
    + sum_c g_c Bc[c] + bp`` on the second, with ``u`` the piece's time law
    (paper eq. 8), ``g_c = side k gap`` the constant point force of every
    engaged contactor with a gap (the sign convention of the model) and
    ``ap, bp`` the preload. A coordinate then obeys its oscillator equation
    with the load ``beta + 2a alpha + alpha'``. For a state whose modes
    diagonalise its damping ``au = Ac = ap = 0``, ``bu`` is the paper's
    ``p_n`` and ``Bc`` the mode shapes at the contactors. Fills ``h0, dh0, P``,
    the loads ``lA, lB, lD, lE`` and ``AL`` (``alpha``'s coefficients);
    returns ``(Omega, phi)``.
    """
    tau_p = t - pt0[kp]
    Om = pOm[kp]
    phi = pphase[kp] + Om * tau_p
    u0 = pconst[kp] + pslope[kp] * tau_p
    u1 = pslope[kp]
    uD = pamp[kp]
    nm = eta.size
    mask = smask[s]
    for n in range(nm):
        ac = ap[s, n]
        bc = bp[s, n]
        for c in range(gap.size):
            if (mask >> c) & 1 and gap[c] != 0.0:
                f = side[c] * kst[c] * gap[c]
                ac += f * Ac[s, c, n]
                bc += f * Bc[s, c, n]
        an = dec[s, n]
        x = au[s, n]
        y = bu[s, n] + 2.0 * an * x
        lA[n] = y * u0 + bc + 2.0 * an * ac + x * u1
        lB[n] = y * u1
        lD[n] = y * uD
        lE[n] = x * uD * Om
        AL[n, 0] = x * u0 + ac
        AL[n, 1] = x * u1
        AL[n, 2] = x * uD
    setup(reg[s], dec[s], om[s], lA, lB, lD, lE, Om, phi, eta, deta, h0, dh0, P)
    return Om, phi


@njit(cache=True, nogil=True, _nrt=False)
def alpha_at(AL, tau, Om, phi, out):  # pragma: no cover - compiled
    """``alpha_n(tau)`` of every coordinate (:func:`segment_setup`)."""
    s = math.sin(Om * tau + phi) if Om != 0.0 else math.sin(phi)
    for n in range(out.size):
        out[n] = AL[n, 0] + AL[n, 1] * tau + AL[n, 2] * s


@njit(cache=True, nogil=True, _nrt=False)
def copy_into(dst, src):  # pragma: no cover - compiled
    """``dst[:] = src`` for two 1-D arrays of one length, as a loop.

    (A slice assignment compiles numba's shape check and its error message,
    string formatting included: seconds of compile time for nothing.)
    """
    for i in range(dst.size):
        dst[i] = src[i]


@njit(cache=True, nogil=True)
def workspace(nm):  # pragma: no cover - compiled
    """Work arrays of :func:`segment_setup`: ``h0, dh0, P, lA, lB, lD, lE, AL`` for ``nm`` coordinates."""
    return (np.empty(nm), np.empty(nm), np.empty((nm, NP)), np.empty(nm), np.empty(nm), np.empty(nm),
            np.empty(nm), np.empty((nm, 3)))
