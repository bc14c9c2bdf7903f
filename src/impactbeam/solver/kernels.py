"""Compiled inner loops of the exact solver (numba).

Two kernels do the per-segment arithmetic of :mod:`~impactbeam.solver.engine`
for states whose modes are all under-damped (the common case); the event
logic (which contactor switches, consistency at segment starts, projection)
stays in Python. Both evaluate the same closed form as
:meth:`ClosedFormSegment.evaluate_grid`:

.. math:: \\eta_n(\\tau) = \\mathrm{Re}(A_n e^{\\mu_n \\tau}) + P_n(\\tau),
          \\qquad \\mu_n = -\\xi_n\\omega_n + i\\omega_{dn},

with the particular part ``P_n`` on the basis ``1, tau, tau^2, tau^3,
Im(z), Im(z), tau Re(z)`` (``z = exp(i(Omega tau + phi))``). On the uniform
grid ``e^{mu tau}`` advances by one complex product per step and is
recomputed exactly every 128 steps, so round-off stays below ~1e-14
relative.

* :func:`scan` walks the grid, detects a crossing of a contactor opening (or
  a grazing dip, or a release in tension, as documented in the engine) and
  refines it with Brent's method (the algorithm of SciPy's ``brentq``).
* :func:`output` evaluates the modal state on the sampling grid and writes
  deflections, velocities, energies and powers.
"""

from __future__ import annotations

import math

import numpy as np

try:  # numba is a declared dependency; the numpy path remains as a fallback
    from numba import njit

    AVAILABLE = True
except ImportError:  # pragma: no cover
    AVAILABLE = False

    def njit(*args, **kwargs):  # type: ignore[no-redef]
        def wrap(f):
            return f

        return wrap if not args or not callable(args[0]) else args[0]


__all__ = ["AVAILABLE", "scan", "output"]

_RESYNC = 128


@njit(cache=True)
def _part(C, i, tau, Om, phi, has_sin):  # pragma: no cover - compiled
    """Particular part (row ``i`` of C) and its derivative at ``tau``."""
    c0 = C[i, 0].real
    c1 = C[i, 1].real
    c2 = C[i, 2].real
    c3 = C[i, 3].real
    val = c0 + tau * (c1 + tau * (c2 + tau * c3))
    der = c1 + tau * (2.0 * c2 + 3.0 * c3 * tau)
    if has_sin:
        th = Om * tau + phi
        zr = math.cos(th)
        zi = math.sin(th)
        c4 = C[i, 4]
        czr = c4.real * zr - c4.imag * zi
        czi = c4.real * zi + c4.imag * zr
        c5 = C[i, 5].real
        c6 = C[i, 6].real
        val += czi + c5 * zi + c6 * tau * zr
        der += Om * czr + Om * c5 * zr + c6 * (zr - Om * tau * zi)
    return val, der


@njit(cache=True)
def _part_z(C, i, tau, Om, zr, zi, has_sin):  # pragma: no cover - compiled
    """:func:`_part` with ``z = exp(i theta)`` given (shared by all modes at one time)."""
    c0 = C[i, 0].real
    c1 = C[i, 1].real
    c2 = C[i, 2].real
    c3 = C[i, 3].real
    val = c0 + tau * (c1 + tau * (c2 + tau * c3))
    der = c1 + tau * (2.0 * c2 + 3.0 * c3 * tau)
    if has_sin:
        c4 = C[i, 4]
        czr = c4.real * zr - c4.imag * zi
        czi = c4.real * zi + c4.imag * zr
        c5 = C[i, 5].real
        c6 = C[i, 6].real
        val += czi + c5 * zi + c6 * tau * zr
        der += Om * czr + Om * c5 * zr + c6 * (zr - Om * tau * zi)
    return val, der


@njit(cache=True)
def _h(c, tau, mu, VA, VB, base, PC, Om, phi, has_sin):  # pragma: no cover - compiled
    """Opening function of contactor ``c`` (oriented) and its derivative at ``tau``."""
    val = base[c]
    der = 0.0
    for n in range(mu.size):
        e = np.exp(mu[n] * tau)
        val += (VA[c, n] * e).real
        der += (VB[c, n] * e).real
    pv, pd = _part(PC, c, tau, Om, phi, has_sin)
    return val + pv, der + pd


@njit(cache=True)
def _f(which, c, tau, mu, VA, VB, base, PC, Om, phi, has_sin):  # pragma: no cover - compiled
    v, d = _h(c, tau, mu, VA, VB, base, PC, Om, phi, has_sin)
    return v if which == 0 else d


@njit(cache=True)
def _brent(which, c, xa, xb, xtol, rtol, mu, VA, VB, base, PC, Om, phi, has_sin):  # pragma: no cover
    """Root of h (which=0) or h' (which=1) in [xa, xb]: SciPy's brentq algorithm."""
    xpre = xa
    xcur = xb
    fpre = _f(which, c, xpre, mu, VA, VB, base, PC, Om, phi, has_sin)
    fcur = _f(which, c, xcur, mu, VA, VB, base, PC, Om, phi, has_sin)
    if fpre * fcur > 0.0:
        return np.nan
    if fpre == 0.0:
        return xpre
    if fcur == 0.0:
        return xcur
    xblk = 0.0
    fblk = 0.0
    spre = 0.0
    scur = 0.0
    for _ in range(200):
        if fpre != 0.0 and fcur != 0.0 and ((fpre < 0.0) != (fcur < 0.0)):
            xblk = xpre
            fblk = fpre
            spre = xcur - xpre
            scur = spre
        if abs(fblk) < abs(fcur):
            xpre = xcur
            xcur = xblk
            xblk = xpre
            fpre = fcur
            fcur = fblk
            fblk = fpre
        delta = (xtol + rtol * abs(xcur)) / 2.0
        sbis = (xblk - xcur) / 2.0
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - delta):
                spre = scur
                scur = stry
            else:
                spre = sbis
                scur = sbis
        else:
            spre = sbis
            scur = sbis
        xpre = xcur
        fpre = fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0.0 else -delta
        fcur = _f(which, c, xcur, mu, VA, VB, base, PC, Om, phi, has_sin)
    return xcur


@njit(cache=True)
def _locate(c, lo, hi, hlo, dlo, dhi, tol_h, xtol, mu, VA, VB, base, PC, Om, phi, has_sin):  # pragma: no cover
    """Crossing time of contactor ``c`` in (lo, hi] (mirrors engine._Integrator._locate); NaN if none."""
    rtol = 4.0 * 2.220446049250313e-16
    hh = _f(0, c, hi, mu, VA, VB, base, PC, Om, phi, has_sin)
    if hlo <= tol_h:
        if dlo > 0.0 and _f(1, c, hi, mu, VA, VB, base, PC, Om, phi, has_sin) < 0.0:
            lo = _brent(1, c, lo, hi, xtol, rtol, mu, VA, VB, base, PC, Om, phi, has_sin)
            hlo = _f(0, c, lo, mu, VA, VB, base, PC, Om, phi, has_sin)
        if hlo <= 0.0:
            return np.nan
    if hh > 0.0:
        if not (dlo < 0.0 < dhi):
            return np.nan
        tmin = _brent(1, c, lo, hi, xtol, rtol, mu, VA, VB, base, PC, Om, phi, has_sin)
        if _f(0, c, tmin, mu, VA, VB, base, PC, Om, phi, has_sin) > 0.0:
            return np.nan
        hi = tmin
        if _f(0, c, hi, mu, VA, VB, base, PC, Om, phi, has_sin) == 0.0:
            return hi
    return _brent(0, c, lo, hi, xtol, rtol, mu, VA, VB, base, PC, Om, phi, has_sin)


@njit(cache=True)
def scan(t0, h, k0, k_last, t_end, mu, VA, VB, base, PC, Om, phi, has_sin, engaged, tol_h, xtol):  # pragma: no cover
    """First event of a segment: returns (tau, contactor) or (nan, -1).

    ``engaged[c]`` is True for an engaged contactor (its opening is oriented so
    that it is positive while the state is consistent).
    """
    nc = VA.shape[0]
    nm = mu.size
    rh = np.exp(mu * h)
    E = np.empty(nm, dtype=np.complex128)
    Hp = np.empty(nc)
    dHp = np.empty(nc)
    H = np.empty(nc)
    dH = np.empty(nc)
    for c in range(nc):
        Hp[c], dHp[c] = _h(c, 0.0, mu, VA, VB, base, PC, Om, phi, has_sin)
    tprev = 0.0
    n_grid = max(0, k_last - k0 + 1)
    tau_end = t_end - t0
    j = 0
    while True:
        if j < n_grid:
            tau = (k0 + j) * h - t0
            if j % _RESYNC == 0:
                for n in range(nm):
                    E[n] = np.exp(mu[n] * tau)
            else:
                for n in range(nm):
                    E[n] = E[n] * rh[n]
            for c in range(nc):
                v = base[c]
                d = 0.0
                for n in range(nm):
                    v += (VA[c, n] * E[n]).real
                    d += (VB[c, n] * E[n]).real
                pv, pd = _part(PC, c, tau, Om, phi, has_sin)
                H[c] = v + pv
                dH[c] = d + pd
        else:
            last_tau = (k0 + n_grid - 1) * h - t0 if n_grid > 0 else 0.0
            if not (tau_end > last_tau + 1e-15):
                break
            tau = tau_end
            for c in range(nc):
                H[c], dH[c] = _h(c, tau, mu, VA, VB, base, PC, Om, phi, has_sin)
        dtau = tau - tprev
        if dtau > 0.0:
            best_t = np.inf
            best_c = -1
            for c in range(nc):
                hp = Hp[c]
                dhp = dHp[c]
                touch = abs(hp) <= tol_h
                cross = H[c] <= 0.0 and (hp > 0.0 or (touch and dhp > 0.0))
                graze = hp > 0.0 and H[c] > 0.0 and dhp < 0.0 and dH[c] > 0.0
                graze = graze and (hp < abs(dhp) * dtau or H[c] < abs(dH[c]) * dtau)
                tension = hp <= 0.0 and H[c] < 0.0 and dhp > 0.0 and dH[c] <= 0.0
                r = np.nan
                if tension and not cross:
                    r = _brent(1, c, tprev, tau, xtol, 4.0 * 2.220446049250313e-16, mu, VA, VB, base, PC, Om, phi, has_sin)
                elif cross or graze:
                    r = _locate(c, tprev, tau, hp, dhp, dH[c], tol_h, xtol, mu, VA, VB, base, PC, Om, phi, has_sin)
                if not np.isnan(r) and r < best_t:
                    best_t = r
                    best_c = c
            if best_c >= 0:
                return best_t, best_c
        for c in range(nc):
            Hp[c] = H[c]
            dHp[c] = dH[c]
        tprev = tau
        if j >= n_grid:
            break
        j += 1
    return np.nan, -1


@njit(cache=True)
def output(
    t0, dt, i0, i1, mu, A, B, C, Om, phi, has_sin, fa, fb, fd, omega, damp2, Wout, Wc,
    w, w_t, wc, wtc, kin, strain, lpow, dpow, eta, eta_t,
):  # pragma: no cover - compiled
    """Write the exact response at samples i0..i1-1 (``tau = i dt - t0``) into the output arrays.

    ``fa + fb tau + fd sin(Omega tau + phi)`` is the external modal force (for the input power).
    """
    nm = mu.size
    np_ = Wout.shape[0]
    nc = Wc.shape[0]
    rd = np.exp(mu * dt)
    E = np.empty(nm, dtype=np.complex128)
    e = np.empty(nm)
    de = np.empty(nm)
    for j in range(i1 - i0):
        i = i0 + j
        tau = i * dt - t0
        if j % _RESYNC == 0:
            for n in range(nm):
                E[n] = np.exp(mu[n] * tau)
        else:
            for n in range(nm):
                E[n] = E[n] * rd[n]
        zr = 0.0
        zi = 0.0
        if has_sin:
            zr = math.cos(Om * tau + phi)
            zi = math.sin(Om * tau + phi)
        s_sin = zi
        k_ = 0.0
        s_ = 0.0
        lp = 0.0
        dp = 0.0
        for n in range(nm):
            pv, pd = _part_z(C, n, tau, Om, zr, zi, has_sin)
            v = (A[n] * E[n]).real + pv
            d = (B[n] * E[n]).real + pd
            e[n] = v
            de[n] = d
            eta[i, n] = v
            eta_t[i, n] = d
            k_ += d * d
            s_ += (omega[n] * v) ** 2
            lp += (fa[n] + fb[n] * tau + fd[n] * s_sin) * d
            dp += damp2[n] * d * d
        kin[i] = 0.5 * k_
        strain[i] = 0.5 * s_
        lpow[i] = lp
        dpow[i] = dp
        for p in range(np_):
            a = 0.0
            b = 0.0
            for n in range(nm):
                a += Wout[p, n] * e[n]
                b += Wout[p, n] * de[n]
            w[i, p] = a
            w_t[i, p] = b
        for c in range(nc):
            a = 0.0
            b = 0.0
            for n in range(nm):
                a += Wc[c, n] * e[n]
                b += Wc[c, n] * de[n]
            wc[i, c] = a
            wtc[i, c] = b
