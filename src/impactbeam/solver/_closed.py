"""Compiled closed form of the modal equations on one segment (every damping regime).

Each mode of a state obeys (paper eq. 9, generalised to every damping regime)

.. math:: \\ddot\\eta + 2a\\dot\\eta + \\omega^2\\eta = A + B\\tau + D\\sin(\\Omega\\tau + \\varphi),
          \\qquad a = \\xi\\omega,

on a segment ``0 <= tau`` in which the state and the load form do not change.
The solution is ``eta = eta_h + P`` with the particular part written on seven
real coefficients (``p[0..6]``)

.. math:: P = p_0 + p_1\\tau + p_2\\tau^2 + p_3\\tau^3 + p_4\\sin\\theta
          + p_5\\cos\\theta + p_6\\,\\tau\\cos\\theta,\\qquad \\theta = \\Omega\\tau + \\varphi,

(``p_2, p_3`` only for rigid-body modes, ``p_6`` only at exact undamped
resonance) and the homogeneous part from its initial values ``h0, dh0``

.. math:: \\eta_h = (e_C + a e_S) h_0 + e_S \\dot h_0, \\qquad
          \\dot\\eta_h = -\\omega^2 e_S h_0 + (e_C - a e_S) \\dot h_0,

where ``e_C, e_S`` are ``e^{-a tau}`` times ``cos, sin(w tau)/w`` (regime 0,
under-damped), ``1, tau`` (regime 1: critical damping, and rigid-body modes
with ``omega = a = 0``) or ``cosh, sinh(w tau)/w`` (regime 2, over-damped),
each evaluated without cancellation or overflow. This is the paper's eq. (10)
with its ``B1, B2`` for every regime and for linear and sinusoidal loads.

All functions are compiled with numba (``cache=True``); they run as plain
Python when ``NUMBA_DISABLE_JIT=1``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["REG_UNDER", "REG_CRITICAL", "REG_OVER", "kernel", "setup", "segment_setup", "state_at", "openings_at", "integral_of"]

REG_UNDER = 0
REG_CRITICAL = 1
REG_OVER = 2
EPS = 2.220446049250313e-16


@njit(cache=True, nogil=True)
def kernel(reg, a, w, tau):  # pragma: no cover - compiled
    """``(e_C, e_S)`` of one mode at ``tau >= 0`` (see the module docstring)."""
    if reg == REG_UNDER:
        e = math.exp(-a * tau)
        return e * math.cos(w * tau), e * math.sin(w * tau) / w
    if reg == REG_CRITICAL:
        e = math.exp(-a * tau)
        return e, e * tau
    ep = math.exp((w - a) * tau)
    x = -2.0 * w * tau
    return 0.5 * ep * (1.0 + math.exp(x)), -0.5 * ep * math.expm1(x) / w


@njit(cache=True, nogil=True)
def particular(p, tau, Om, phi):  # pragma: no cover - compiled
    """Particular part and its derivative from the seven coefficients ``p``."""
    val = p[0] + tau * (p[1] + tau * (p[2] + tau * p[3]))
    der = p[1] + tau * (2.0 * p[2] + 3.0 * p[3] * tau)
    if Om != 0.0:
        th = Om * tau + phi
        s = math.sin(th)
        c = math.cos(th)
        val += p[4] * s + p[5] * c + p[6] * tau * c
        der += Om * (p[4] * c - p[5] * s) + p[6] * (c - Om * tau * s)
    return val, der


@njit(cache=True, nogil=True)
def setup(reg, a, om, load_A, load_B, load_D, Om, phi, eta0, deta0, h0, dh0, P):  # pragma: no cover - compiled
    """Coefficients of a segment from its modal load and initial state.

    Parameters
    ----------
    reg, a, om : ndarray, (n,)
        Regime, decay ``xi omega`` and natural frequency of each mode.
    load_A, load_B, load_D : ndarray, (n,)
        Modal load ``A + B tau + D sin(Om tau + phi)``.
    eta0, deta0 : ndarray, (n,)
        Modal displacement and velocity at ``tau = 0``.
    h0, dh0, P : ndarray, (n,), (n,), (n, 7)
        Filled: homogeneous initial values and particular coefficients.
    """
    W2 = Om * Om
    for n in range(om.size):
        A = load_A[n]
        B = load_B[n]
        D = load_D[n]
        for q in range(7):
            P[n, q] = 0.0
        o = om[n]
        if o == 0.0:  # rigid-body mode: eta'' = f
            P[n, 2] = 0.5 * A
            P[n, 3] = B / 6.0
            if D != 0.0:
                P[n, 4] = -D / W2
        else:
            o2 = o * o
            P[n, 0] = A / o2 - 2.0 * a[n] * B / (o2 * o2)
            P[n, 1] = B / o2
            if D != 0.0:
                re = o2 - W2
                im = 2.0 * a[n] * Om
                den = re * re + im * im
                if math.sqrt(den) <= 1e-12 * max(o2, W2):  # exact undamped resonance
                    P[n, 6] = -D / (2.0 * o)
                else:  # Im(D z / (re + i im)), z = exp(i theta)
                    P[n, 4] = D * re / den
                    P[n, 5] = -D * im / den
        p0, dp0 = particular(P[n], 0.0, Om, phi)
        h0[n] = eta0[n] - p0
        dh0[n] = deta0[n] - dp0


@njit(cache=True, nogil=True)
def state_at(tau, reg, a, w, om, h0, dh0, P, Om, phi, e, d):  # pragma: no cover - compiled
    """Modal displacement ``e`` and velocity ``d`` at ``tau`` (filled in place)."""
    for n in range(om.size):
        eC, eS = kernel(reg[n], a[n], w[n], tau)
        pv, pd = particular(P[n], tau, Om, phi)
        e[n] = (eC + a[n] * eS) * h0[n] + eS * dh0[n] + pv
        d[n] = -om[n] * om[n] * eS * h0[n] + (eC - a[n] * eS) * dh0[n] + pd


@njit(cache=True, nogil=True)
def openings_at(tau, reg, a, w, om, VH, VD, base, PV, Om, phi, g, dg):  # pragma: no cover - compiled
    """Projected response ``g = base + V eta`` and ``dg = V eta'`` of several rows at ``tau``.

    ``VH[c, n] = V[c, n] h0[n]``, ``VD[c, n] = V[c, n] dh0[n]`` and ``PV = V @ P``
    are prepared once per segment, so one evaluation costs one kernel per mode.
    """
    nc = g.size
    for c in range(nc):
        pv, pd = particular(PV[c], tau, Om, phi)
        g[c] = base[c] + pv
        dg[c] = pd
    for n in range(om.size):
        eC, eS = kernel(reg[n], a[n], w[n], tau)
        an = a[n]
        k1 = eC + an * eS
        k2 = -om[n] * om[n] * eS
        k3 = eC - an * eS
        for c in range(nc):
            g[c] += k1 * VH[c, n] + eS * VD[c, n]
            dg[c] += k2 * VH[c, n] + k3 * VD[c, n]


@njit(cache=True, nogil=True)
def project(V, base, h0, dh0, P, VH, VD, PV, rows):  # pragma: no cover - compiled
    """Prepare :func:`openings_at` for the rows ``V`` (shape (m, n)); ``rows`` of them used."""
    for c in range(rows):
        for q in range(7):
            s = 0.0
            for n in range(h0.size):
                s += V[c, n] * P[n, q]
            PV[c, q] = s
        for n in range(h0.size):
            VH[c, n] = V[c, n] * h0[n]
            VD[c, n] = V[c, n] * dh0[n]


@njit(cache=True, nogil=True)
def curvature_bound(V, a, om, h0, dh0, PV, Om, tau_end, out):  # pragma: no cover - compiled
    """Bound on ``|d^2/dtau^2 (V eta)|`` over ``[0, tau_end]`` for each row of ``V``.

    The homogeneous energy ``(eta_h'^2 + omega^2 eta_h^2)/2`` of a mode with
    ``a >= 0`` never grows, and ``eta_h'' = -2a eta_h' - omega^2 eta_h``, so
    ``|eta_h''| <= (2a + omega) sqrt(eta_h'(0)^2 + omega^2 eta_h(0)^2)`` for
    all ``tau >= 0``. The particular part is bounded term by term.
    """
    tmax = max(tau_end, 0.0)
    for c in range(out.size):
        p = PV[c]
        m = 2.0 * abs(p[2]) + 6.0 * abs(p[3]) * tmax
        if Om != 0.0:
            m += Om * Om * (abs(p[4]) + abs(p[5])) + abs(p[6]) * (2.0 * abs(Om) + Om * Om * tmax)
        out[c] = m
    for n in range(om.size):
        o = om[n]
        amp = (2.0 * a[n] + o) * math.sqrt(dh0[n] * dh0[n] + o * o * h0[n] * h0[n])
        if amp != 0.0:
            for c in range(out.size):
                out[c] += abs(V[c, n]) * amp
    for c in range(out.size):
        out[c] *= 1.0 + 1e-12  # round-off margin


@njit(cache=True, nogil=True)
def derivatives(v, base, a, om, eta0, deta0, load_A, load_B, load_D, Om, phi, kmax, out, mag):  # pragma: no cover
    """Exact derivatives ``d^k/dtau^k (base + v eta)`` at ``tau = 0``, k = 0..kmax.

    From the equation of motion, ``eta^(k+2) = f^(k) - 2a eta^(k+1) - omega^2
    eta^(k)``; ``mag[k]`` is the same sum taken with absolute values (the scale
    against which a derivative counts as zero up to round-off).
    """
    sphi = math.sin(phi)
    cphi = math.cos(phi)
    for k in range(kmax + 1):
        out[k] = 0.0
        mag[k] = 0.0
    out[0] = base
    mag[0] = abs(base)
    hist = np.empty(kmax + 1)
    habs = np.empty(kmax + 1)
    for n in range(om.size):
        hist[0] = eta0[n]
        habs[0] = abs(eta0[n])
        if kmax >= 1:
            hist[1] = deta0[n]
            habs[1] = abs(deta0[n])
        for k in range(2, kmax + 1):
            j = k - 2  # derivative order of the load
            D = load_D[n]
            if j == 0:
                f = load_A[n] + D * sphi
            elif j == 1:
                f = load_B[n] + D * Om * cphi
            else:
                r = j % 4
                s = Om**j
                f = D * s * (sphi if r == 0 else cphi if r == 1 else -sphi if r == 2 else -cphi)
            hist[k] = f - 2.0 * a[n] * hist[k - 1] - om[n] * om[n] * hist[k - 2]
            habs[k] = abs(f) + 2.0 * a[n] * habs[k - 1] + om[n] * om[n] * habs[k - 2]
        for k in range(kmax + 1):
            out[k] += v[n] * hist[k]
            mag[k] += abs(v[n]) * habs[k]


@njit(cache=True, nogil=True)
def integral_of(v, reg, a, w, om, h0, dh0, P, Om, phi, T):  # pragma: no cover - compiled
    """``int_0^T v . eta(tau) dtau`` in closed form.

    For ``omega > 0`` the equation of motion gives ``int eta = (int f - [eta'] -
    2a [eta]) / omega^2``, with ``[.]`` the change over the interval; rigid-body
    modes integrate their polynomial and sine directly.
    """
    total = 0.0
    for n in range(om.size):
        if v[n] == 0.0:
            continue
        eC, eS = kernel(reg[n], a[n], w[n], T)
        hT = (eC + a[n] * eS) * h0[n] + eS * dh0[n]
        dhT = -om[n] * om[n] * eS * h0[n] + (eC - a[n] * eS) * dh0[n]
        p = P[n]
        o = om[n]
        if o == 0.0:
            ih = h0[n] * T + 0.5 * dh0[n] * T * T
        else:
            ih = -((dhT - dh0[n]) + 2.0 * a[n] * (hT - h0[n])) / (o * o)
        ip = T * (p[0] + T * (p[1] / 2.0 + T * (p[2] / 3.0 + T * p[3] / 4.0)))
        if Om != 0.0:
            th1 = Om * T + phi
            ip += p[4] * (math.cos(phi) - math.cos(th1)) / Om + p[5] * (math.sin(th1) - math.sin(phi)) / Om
            if p[6] != 0.0:  # int tau cos(theta) = [tau sin/Om + cos/Om^2]
                ip += p[6] * (T * math.sin(th1) / Om + (math.cos(th1) - math.cos(phi)) / (Om * Om))
        total += v[n] * (ih + ip)
    return total


@njit(cache=True, nogil=True)
def segment_setup(s, kp, t, eta, deta, reg, dec, om, pw, Wc, smask, gap, side, kst,
                  pt0, pconst, pslope, pamp, pOm, pphase, h0, dh0, P, lA, lB, lD):  # pragma: no cover - compiled
    """Closed-form coefficients of a segment starting at ``t`` in state slot ``s``, load piece ``kp``.

    The modal load is ``p_n u(t)`` (paper eq. 8, ``u`` the piece's time law)
    plus, for every engaged contactor with a gap, the constant point force
    ``side k gap`` at the contactor (the sign convention of the model). Fills ``h0, dh0, P``
    and the load coefficients ``lA, lB, lD``; returns ``(Omega, phi)``.
    """
    tau_p = t - pt0[kp]
    u = pconst[kp] + pslope[kp] * tau_p
    nm = eta.size
    for n in range(nm):
        lA[n] = pw[s, n] * u
        lB[n] = pw[s, n] * pslope[kp]
        lD[n] = pw[s, n] * pamp[kp]
    mask = smask[s]
    for c in range(gap.size):
        if (mask >> c) & 1 and gap[c] != 0.0:
            f = side[c] * kst[c] * gap[c]
            for n in range(nm):
                lA[n] += f * Wc[s, c, n]
    Om = pOm[kp]
    phi = pphase[kp] + Om * tau_p
    setup(reg[s], dec[s], om[s], lA, lB, lD, Om, phi, eta, deta, h0, dh0, P)
    return Om, phi


@njit(cache=True, nogil=True)
def jerk_bound(V, a, om, h0, dh0, PV, Om, tau_end, out):  # pragma: no cover - compiled
    """Bound on the third derivative of ``V eta`` over ``[0, tau_end]`` for each row of ``V``.

    The velocity of the homogeneous part obeys the same homogeneous equation,
    so its energy never grows and the third derivative is bounded by
    ``(2a + omega) sqrt(eta_h2(0)^2 + omega^2 eta_h1(0)^2)`` (``eta_h1``,
    ``eta_h2`` the first and second derivatives); the particular part term by term.
    """
    tmax = max(tau_end, 0.0)
    W = abs(Om)
    for c in range(out.size):
        p = PV[c]
        m = 6.0 * abs(p[3])
        if Om != 0.0:
            m += W**3 * (abs(p[4]) + abs(p[5])) + abs(p[6]) * (3.0 * W * W + W**3 * tmax)
        out[c] = m
    for n in range(om.size):
        o = om[n]
        dd = -2.0 * a[n] * dh0[n] - o * o * h0[n]
        amp = (2.0 * a[n] + o) * math.sqrt(dd * dd + o * o * dh0[n] * dh0[n])
        if amp != 0.0:
            for c in range(out.size):
                out[c] += abs(V[c, n]) * amp
    for c in range(out.size):
        out[c] *= 1.0 + 1e-12


@njit(cache=True, nogil=True)
def curvature_bound_at(tau, V, reg, a, w, om, h0, dh0, PV, Om, tau_end, out):  # pragma: no cover - compiled
    """:func:`curvature_bound` valid on ``[tau, tau_end]``, from the homogeneous state at ``tau``.

    The homogeneous energy only decreases, so the bound tightens as a damped
    response decays; the scan refreshes it as it goes.
    """
    hh = np.empty(om.size)
    dd = np.empty(om.size)
    for n in range(om.size):
        eC, eS = kernel(reg[n], a[n], w[n], tau)
        hh[n] = (eC + a[n] * eS) * h0[n] + eS * dh0[n]
        dd[n] = -om[n] * om[n] * eS * h0[n] + (eC - a[n] * eS) * dh0[n]
    curvature_bound(V, a, om, hh, dd, PV, Om, tau_end, out)


@njit(cache=True, nogil=True)
def workspace(nm):  # pragma: no cover - compiled
    """Work arrays of :func:`segment_setup`: ``h0, dh0, P, lA, lB, lD`` for ``nm`` modes."""
    return np.empty(nm), np.empty(nm), np.empty((nm, 7)), np.empty(nm), np.empty(nm), np.empty(nm)
