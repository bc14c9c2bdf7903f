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
* :func:`run` is the whole event loop in one compiled function (used by
  :mod:`~impactbeam.solver.fast` for problems whose states are all under-damped).
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


__all__ = ["AVAILABLE", "BLOCK", "scan", "output", "run"]

_RESYNC = 128


@njit(cache=True)
def _part(C, i, tau, Om, phi, has_sin):  # pragma: no cover - compiled
    """Particular part (row ``i`` of C) and its derivative at ``tau``."""
    zr = 0.0
    zi = 0.0
    if has_sin:
        zr = math.cos(Om * tau + phi)
        zi = math.sin(Om * tau + phi)
    return _part_z(C, i, tau, Om, zr, zi, has_sin)


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


# =========================================================================== whole event loop
# :func:`run` is a line-by-line port of ``engine._Integrator._run_from`` (with
# ``_segment``, ``ClosedFormSegment.__init__``, ``_desired_switch``,
# ``_advance``/``_scan``/``_output``, ``_switch`` and ``_energy``) for problems whose
# every state has only under-damped modes; :mod:`impactbeam.solver.fast` wraps it.
# On the scan and output grids ``exp(mu tau)`` is the block start (exact) times a
# table ``exp(mu m h)`` (exact, m < BLOCK), which keeps round-off at 1e-16 and lets
# the compiler vectorise. It shares the closed form and Brent functions above (one
# module, so numba's disk cache is invalidated with any of them). Any change to the
# event rules of the engine must be mirrored here; tests/test_fast_engine.py
# compares the two paths.

BLOCK = 128
_RTOL = 4.0 * 2.220446049250313e-16


# --------------------------------------------------------------------------- helpers
@njit(cache=True)
def _grow1(a, need):  # pragma: no cover - compiled
    if need <= a.shape[0]:
        return a
    b = np.empty(max(2 * a.shape[0], need), dtype=a.dtype)
    b[: a.shape[0]] = a
    return b


@njit(cache=True)
def _grow2(a, need):  # pragma: no cover - compiled
    if need <= a.shape[0]:
        return a
    b = np.empty((max(2 * a.shape[0], need), a.shape[1]), dtype=a.dtype)
    b[: a.shape[0]] = a
    return b


@njit(cache=True)
def _table(mu, g, Rr, Ri):  # pragma: no cover - compiled
    """``Rr + i Ri = exp(mu_n m g)``, m < BLOCK (shape (n, BLOCK))."""
    for n in range(mu.size):
        for m in range(Rr.shape[1]):
            e = np.exp(mu[n] * (m * g))
            Rr[n, m] = e.real
            Ri[n, m] = e.imag


@njit(cache=True)
def _setup(om, xi, dec, wd, pw, gf, const, slope, amp, Om_piece, phase, tau, eta0, deta0, A, B, C, fa, fb, fd):
    # pragma: no cover - compiled
    """``engine._segment`` + ``ClosedFormSegment.__init__`` for an all-under-damped state.

    Fills A, B (homogeneous coefficients), C (particular coefficients, (n, 7)),
    and fa, fb, fd (external modal force ``fa + fb tau + fd sin``). Returns
    (has_sin, Omega, phi).
    """
    nm = om.size
    has_b = slope != 0.0
    has_sin = amp != 0.0
    Om = Om_piece
    phi = phase + Om_piece * tau
    u = const + slope * tau
    W2 = Om * Om
    for n in range(nm):
        a_n = pw[n] * u + gf[n]
        b_n = pw[n] * slope if has_b else 0.0
        d_n = pw[n] * amp if has_sin else 0.0
        o = om[n]
        om2 = o * o
        c0 = a_n / om2
        c1 = 0.0
        if has_b:
            c0 += -2.0 * xi[n] * b_n / (o * om2)
            c1 = b_n / om2
        c4 = 0j
        c6 = 0.0
        if has_sin:
            den = complex(om2 - W2, 2.0 * xi[n] * o * Om)
            if abs(den) <= 1e-12 * max(om2, W2):
                c6 = -d_n / (2.0 * o)
            else:
                c4 = d_n * (1.0 / den)
        C[n, 0] = c0
        C[n, 1] = c1
        C[n, 2] = 0.0
        C[n, 3] = 0.0
        C[n, 4] = c4
        C[n, 5] = 0.0
        C[n, 6] = c6
        fa[n] = a_n - gf[n]
        fb[n] = b_n
        fd[n] = d_n
        # particular part at tau = 0 (ClosedFormSegment._particular_at)
        p0, dp0 = _part(C, n, 0.0, Om, phi, has_sin)
        h0 = eta0[n] - p0
        dh0 = deta0[n] - dp0
        a = dec[n]
        A[n] = complex(h0, -((a * h0 + dh0) * (1.0 / wd[n])))
        B[n] = complex(dh0, -((-om2 * h0 - a * dh0) * (1.0 / wd[n])))
    return has_sin, Om, phi


@njit(cache=True)
def _state_at(tau, mu, A, B, C, has_sin, Om, phi, e, d):  # pragma: no cover - compiled
    """``ClosedFormSegment.state_at`` (all under-damped) into e, d."""
    zr = 0.0
    zi = 0.0
    if has_sin:
        th = Om * tau + phi
        zr = math.cos(th)
        zi = math.sin(th)
    for n in range(mu.size):
        E = np.exp(mu[n] * tau)
        val, der = _part_z(C, n, tau, Om, zr, zi, has_sin)
        e[n] = (A[n] * E).real + val
        d[n] = (B[n] * E).real + der


@njit(cache=True)
def _dot(a, b):  # pragma: no cover - compiled
    s = 0.0
    for n in range(a.size):
        s += a[n] * b[n]
    return s


@njit(cache=True)
def _energy(s, eta, deta, om, Wc, gap, side, kst):  # pragma: no cover - compiled
    """``engine._Integrator._energy``: beam + supports + engaged contactors."""
    E1 = 0.0
    E2 = 0.0
    for n in range(eta.size):
        E1 += deta[n] * deta[n]
        E2 += om[n] ** 2 * eta[n] ** 2
    E = 0.5 * E1 + 0.5 * E2
    for i in range(gap.size):
        if (s >> i) & 1:
            wc = _dot(Wc[i], eta)
            g = gap[i] - side[i] * wc
            E += 0.5 * kst[i] * (g**2 - wc**2)
    return E


@njit(cache=True)
def _opening(s, Wc, gap, side, e, d, hv, dhv):  # pragma: no cover - compiled
    """Oriented openings and their rates (``engine._Integrator._h``)."""
    for c in range(gap.size):
        o = -1.0 if (s >> c) & 1 else 1.0
        wc = _dot(Wc[c], e)
        dwc = _dot(Wc[c], d)
        hv[c] = o * (gap[c] - side[c] * wc)
        dhv[c] = o * (-side[c] * dwc)


# --------------------------------------------------------------------------- scan
@njit(cache=True)
def _check(c, H, dH, hp, dhp, tprev, tau, tol_h, xtol, mu, VA, VB, base, PC, Om, phi, has_sin):
    # pragma: no cover - compiled
    """Event of contactor c in (tprev, tau] by the rules of ``kernels.scan``; NaN if none."""
    dtau = tau - tprev
    touch = abs(hp) <= tol_h
    cross = H <= 0.0 and (hp > 0.0 or (touch and dhp > 0.0))
    graze = hp > 0.0 and H > 0.0 and dhp < 0.0 and dH > 0.0
    graze = graze and (hp < abs(dhp) * dtau or H < abs(dH) * dtau)
    # a contactor left on the wrong side of its state by the projection (engaged but
    # open, or free but penetrated) switches where its opening turns back
    tension = hp <= 0.0 and H < 0.0 and dhp > 0.0 and dH <= 0.0
    if tension and not cross:
        return _brent(1, c, tprev, tau, xtol, _RTOL, mu, VA, VB, base, PC, Om, phi, has_sin)
    if cross or graze:
        return _locate(c, tprev, tau, hp, dhp, dH, tol_h, xtol, mu, VA, VB, base, PC, Om, phi, has_sin)
    return np.nan


@njit(cache=True)
def _scan(t0, h, k0, k_last, t_end, mu, VA, VB, base, PC, Om, phi, has_sin, s, tol_h, xtol, Rr, Ri, Hb, dHb, taub,
          Hp, dHp, Eb):  # pragma: no cover - compiled
    """``kernels.scan`` with block tables: first event (tau, contactor) or (nan, -1)."""
    nc = VA.shape[0]
    nm = mu.size
    for c in range(nc):
        Hp[c], dHp[c] = _h(c, 0.0, mu, VA, VB, base, PC, Om, phi, has_sin)
    tprev = 0.0
    n_grid = max(0, k_last - k0 + 1)
    tau_end = t_end - t0
    j = 0
    while j < n_grid:
        nb = min(Rr.shape[1], n_grid - j)
        for m in range(nb):
            taub[m] = (k0 + j + m) * h - t0
        for n in range(nm):
            Eb[n] = np.exp(mu[n] * taub[0])
        for c in range(nc):
            Hc = Hb[c]
            dHc = dHb[c]
            for m in range(nb):
                Hc[m] = base[c]
                dHc[m] = 0.0
            for n in range(nm):
                va = VA[c, n] * Eb[n]
                vb = VB[c, n] * Eb[n]
                ar = va.real
                ai = va.imag
                br = vb.real
                bi = vb.imag
                rr = Rr[n]
                ri = Ri[n]
                for m in range(nb):
                    Hc[m] += ar * rr[m] - ai * ri[m]
                    dHc[m] += br * rr[m] - bi * ri[m]
            c0 = PC[c, 0].real
            c1 = PC[c, 1].real
            c2 = PC[c, 2].real
            c3 = PC[c, 3].real
            if has_sin:
                c4 = PC[c, 4]
                c5 = PC[c, 5].real
                c6 = PC[c, 6].real
                for m in range(nb):
                    tau = taub[m]
                    th = Om * tau + phi
                    zr = math.cos(th)
                    zi = math.sin(th)
                    czr = c4.real * zr - c4.imag * zi
                    czi = c4.real * zi + c4.imag * zr
                    pv = c0 + tau * (c1 + tau * (c2 + tau * c3)) + czi + c5 * zi + c6 * tau * zr
                    pd = c1 + tau * (2.0 * c2 + 3.0 * c3 * tau) + Om * czr + Om * c5 * zr + c6 * (zr - Om * tau * zi)
                    Hc[m] += pv
                    dHc[m] += pd
            else:
                for m in range(nb):
                    tau = taub[m]
                    Hc[m] += c0 + tau * (c1 + tau * (c2 + tau * c3))
                    dHc[m] += c1 + tau * (2.0 * c2 + 3.0 * c3 * tau)
        for m in range(nb):
            tau = taub[m]
            if tau - tprev > 0.0:
                best_t = np.inf
                best_c = -1
                for c in range(nc):
                    Hc = Hb[c, m]
                    dHc = dHb[c, m]
                    if Hc > 0.0 and not (dHp[c] < 0.0 and dHc > 0.0):
                        continue  # neither a crossing, a tension release nor a grazing dip
                    r = _check(c, Hc, dHc, Hp[c], dHp[c], tprev, tau, tol_h, xtol,
                               mu, VA, VB, base, PC, Om, phi, has_sin)
                    if not np.isnan(r) and r < best_t:
                        best_t = r
                        best_c = c
                if best_c >= 0:
                    return best_t, best_c
            for c in range(nc):
                Hp[c] = Hb[c, m]
                dHp[c] = dHb[c, m]
            tprev = tau
        j += nb
    last_tau = (k0 + n_grid - 1) * h - t0 if n_grid > 0 else 0.0
    if tau_end > last_tau + 1e-15:
        tau = tau_end
        if tau - tprev > 0.0:
            best_t = np.inf
            best_c = -1
            for c in range(nc):
                H, dH = _h(c, tau, mu, VA, VB, base, PC, Om, phi, has_sin)
                r = _check(c, H, dH, Hp[c], dHp[c], tprev, tau, tol_h, xtol,
                           mu, VA, VB, base, PC, Om, phi, has_sin)
                if not np.isnan(r) and r < best_t:
                    best_t = r
                    best_c = c
            if best_c >= 0:
                return best_t, best_c
    return np.nan, -1


# --------------------------------------------------------------------------- output
@njit(cache=True)
def _output(t0, dt, i0, i1, mu, A, B, C, Om, phi, has_sin, fa, fb, fd, omega, damp2, Wout, Wc, Rr, Ri,
            Vb, Db, taub, zrb, zib, Kb, Sb, Lb, Pb, Wb, w, w_t, wc, wtc, kin, strain, lpow, dpow, eta, eta_t):
    # pragma: no cover - compiled
    """``kernels.output`` with block tables: samples i0..i1-1 (``tau = i dt - t0``)."""
    nm = mu.size
    npt = Wout.shape[0]
    nc = Wc.shape[0]
    j = i0
    while j < i1:
        nb = min(Rr.shape[1], i1 - j)
        for m in range(nb):
            taub[m] = (j + m) * dt - t0
        if has_sin:
            for m in range(nb):
                th = Om * taub[m] + phi
                zrb[m] = math.cos(th)
                zib[m] = math.sin(th)
        else:
            for m in range(nb):
                zrb[m] = 0.0
                zib[m] = 0.0
        for m in range(nb):
            Kb[m] = 0.0
            Sb[m] = 0.0
            Lb[m] = 0.0
            Pb[m] = 0.0
        for n in range(nm):
            Eb = np.exp(mu[n] * taub[0])
            ab = A[n] * Eb
            bb = B[n] * Eb
            ar = ab.real
            ai = ab.imag
            br = bb.real
            bi = bb.imag
            rr = Rr[n]
            ri = Ri[n]
            V = Vb[n]
            D = Db[n]
            c0 = C[n, 0].real
            c1 = C[n, 1].real
            c2 = C[n, 2].real
            c3 = C[n, 3].real
            for m in range(nb):
                tau = taub[m]
                V[m] = ar * rr[m] - ai * ri[m] + (c0 + tau * (c1 + tau * (c2 + tau * c3)))
                D[m] = br * rr[m] - bi * ri[m] + (c1 + tau * (2.0 * c2 + 3.0 * c3 * tau))
            if has_sin:
                c4r = C[n, 4].real
                c4i = C[n, 4].imag
                c5 = C[n, 5].real
                c6 = C[n, 6].real
                for m in range(nb):
                    tau = taub[m]
                    zr = zrb[m]
                    zi = zib[m]
                    V[m] += c4r * zi + c4i * zr + c5 * zi + c6 * tau * zr
                    D[m] += Om * (c4r * zr - c4i * zi) + Om * c5 * zr + c6 * (zr - Om * tau * zi)
            o = omega[n]
            g2 = damp2[n]
            a_ = fa[n]
            b_ = fb[n]
            d_ = fd[n]
            for m in range(nb):
                d = D[m]
                v = o * V[m]
                Kb[m] += d * d
                Sb[m] += v * v
                Lb[m] += (a_ + b_ * taub[m] + d_ * zib[m]) * d
                Pb[m] += g2 * d * d
        for m in range(nb):
            i = j + m
            kin[i] = 0.5 * Kb[m]
            strain[i] = 0.5 * Sb[m]
            lpow[i] = Lb[m]
            dpow[i] = Pb[m]
            for n in range(nm):
                eta[i, n] = Vb[n, m]
                eta_t[i, n] = Db[n, m]
        for q in range(npt + nc):
            Wq = Wout[q] if q < npt else Wc[q - npt]
            W0 = Wb[0]
            W1 = Wb[1]
            for m in range(nb):
                W0[m] = 0.0
                W1[m] = 0.0
            for n in range(nm):
                wq = Wq[n]
                V = Vb[n]
                D = Db[n]
                for m in range(nb):
                    W0[m] += wq * V[m]
                    W1[m] += wq * D[m]
            if q < npt:
                for m in range(nb):
                    w[j + m, q] = W0[m]
                    w_t[j + m, q] = W1[m]
            else:
                for m in range(nb):
                    wc[j + m, q - npt] = W0[m]
                    wtc[j + m, q - npt] = W1[m]
        j += nb


# --------------------------------------------------------------------------- main loop
@njit(cache=True)
def run(
    om, xi, dec, wd, mu, Wc, Wo, pw, gf, Tm, gap, side, kst,
    pt0, pt1, pconst, pslope, pamp, pOm, pphase,
    T, dt, h, n_out, tol_h, xtol, max_events, eta_init, deta_init,
    Rs_r, Rs_i, Ro_r, Ro_i, built,
    w, w_t, wc, wtc, code, kin, strain, lpow, dpow, eta_out, eta_t_out,
):  # pragma: no cover - compiled
    """Event-driven exact integration (``engine._Integrator._run_from``), all states under-damped.

    State ``s`` is the bit mask of the engaged contactors. ``Tm[to, frm]`` is
    the transfer matrix of eq. (12) between states differing by one contactor.
    ``built[s]`` tells whether the grid tables ``Rs_*`` (scan step ``h``) and
    ``Ro_*`` (output step ``dt``) of state ``s`` are filled; they are filled
    on first use.
    """
    nm = om.shape[1]
    nc = gap.size
    S = om.shape[0]
    npieces = pt0.size
    # per-segment work arrays
    A = np.empty(nm, dtype=np.complex128)
    B = np.empty(nm, dtype=np.complex128)
    C = np.empty((nm, 7), dtype=np.complex128)
    fa = np.empty(nm)
    fb = np.empty(nm)
    fd = np.empty(nm)
    VA = np.empty((nc, nm), dtype=np.complex128)
    VB = np.empty((nc, nm), dtype=np.complex128)
    PC = np.empty((nc, 7), dtype=np.complex128)
    base = np.empty(nc)
    e0 = np.empty(nm)
    d0 = np.empty(nm)
    e1 = np.empty(nm)
    d1 = np.empty(nm)
    h0 = np.empty(nc)
    dh0 = np.empty(nc)
    h1 = np.empty(nc)
    dh1 = np.empty(nc)
    moved = np.empty(nc)
    scl = np.empty(nc)
    wb = np.empty(nc)
    damp2 = 2.0 * dec
    # block buffers
    BK = Rs_r.shape[2]
    Hb = np.empty((nc, BK))
    dHb = np.empty((nc, BK))
    taub = np.empty(BK)
    Hp = np.empty(nc)
    dHp = np.empty(nc)
    Eb = np.empty(nm, dtype=np.complex128)
    Vb = np.empty((nm, BK))
    Db = np.empty((nm, BK))
    zrb = np.empty(BK)
    zib = np.empty(BK)
    Kb = np.empty(BK)
    Sb = np.empty(BK)
    Lb = np.empty(BK)
    Pb = np.empty(BK)
    Wb = np.empty((2, BK))
    # growing records
    seg_t0 = np.empty(16)
    seg_t1 = np.empty(16)
    seg_s = np.empty(16, dtype=np.int64)
    seg_k = np.empty(16, dtype=np.int64)
    seg_eta = np.empty((16, nm))
    seg_deta = np.empty((16, nm))
    nseg = 0
    ev_t = np.empty(16)
    ev_kind = np.empty(16, dtype=np.int64)  # 1 impact, 0 rebound
    ev_c = np.empty(16, dtype=np.int64)
    ev_v = np.empty(16)
    nev = 0
    jumps = np.empty(16)
    njump = 0
    code_of = np.full(S, -1, dtype=np.int64)
    key_order = np.empty(S, dtype=np.int64)
    nkeys = 0
    warn = False
    warn_t = 0.0
    warn_c = -1
    warn_moved = 0.0
    warn_scale = 0.0
    toggles = np.zeros(max(nc, 1), dtype=np.int64)

    eta = eta_init.copy()
    deta = deta_init.copy()
    s = 0
    t = 0.0
    kp = 0
    status = 0
    last_t = -1.0
    just = -1
    while t < T and kp < npieces:
        # ---------------------------------------------------------- segment setup
        has_sin, Om, phi = _setup(
            om[s], xi[s], dec[s], wd[s], pw[s], gf[s], pconst[kp], pslope[kp], pamp[kp], pOm[kp], pphase[kp],
            t - pt0[kp], eta, deta, A, B, C, fa, fb, fd,
        )
        t_end = min(pt1[kp], T)
        mu_s = mu[s]
        Wc_s = Wc[s]
        # ---------------------------------------------------------- consistency at the start
        c_bad = -1
        if nc > 0:
            tau1 = min(h, t_end - t) if t_end > t else h
            _state_at(0.0, mu_s, A, B, C, has_sin, Om, phi, e0, d0)
            _opening(s, Wc_s, gap, side, e0, d0, h0, dh0)
            clear = just < 0
            if clear:
                for c in range(nc):
                    if not (h0[c] > tol_h):
                        clear = False
            if not clear:
                _state_at(tau1, mu_s, A, B, C, has_sin, Om, phi, e1, d1)
                _opening(s, Wc_s, gap, side, e1, d1, h1, dh1)
                for c in range(nc):
                    if c == just:
                        if dh0[c] * tau1 < -tol_h:
                            c_bad = c
                            break
                        continue
                    if h0[c] < -tol_h:
                        c_bad = c
                        break
                    if abs(h0[c]) <= tol_h:
                        if dh0[c] * tau1 < -tol_h:
                            c_bad = c
                            break
                        if abs(dh0[c]) * tau1 <= tol_h and h1[c] < -tol_h:
                            c_bad = c
                            break
        c_switch = -1
        if c_bad >= 0:
            if t != last_t:
                toggles[:] = 0
                last_t = t
            toggles[c_bad] += 1
            if toggles[c_bad] <= 2:
                c_switch = c_bad
        c_hit = -1
        if c_switch < 0:
            # ------------------------------------------------------ scan for the first event
            if not built[s]:
                _table(mu_s, h, Rs_r[s], Rs_i[s])
                _table(mu_s, dt, Ro_r[s], Ro_i[s])
                built[s] = True
            te = t_end
            if nc > 0:
                for c in range(nc):
                    o = -1.0 if (s >> c) & 1 else 1.0
                    base[c] = o * gap[c]
                    for n in range(nm):
                        v = (o * -side[c]) * Wc_s[c, n]
                        VA[c, n] = v * A[n]
                        VB[c, n] = v * B[n]
                    for q in range(7):
                        acc = 0j
                        for n in range(nm):
                            acc += ((o * -side[c]) * Wc_s[c, n]) * C[n, q]
                        PC[c, q] = acc
                k0 = int(math.ceil(t / h - 1e-9))  # noqa: RUF046
                k_last = int(math.floor(t_end / h + 1e-9))  # noqa: RUF046
                r, ch = _scan(t, h, k0, k_last, t_end, mu_s, VA, VB, base, PC, Om, phi, has_sin, s, tol_h, xtol,
                              Rs_r[s], Rs_i[s], Hb, dHb, taub, Hp, dHp, Eb)
                if ch >= 0:
                    te = t + r
                    c_hit = ch
            # ------------------------------------------------------ output on [t, te)
            i0 = max(0, int(math.ceil(t / dt - 1e-9)))  # noqa: RUF046
            i1 = n_out if te >= T else min(n_out, int(math.ceil(te / dt - 1e-9)))  # noqa: RUF046
            if code_of[s] < 0:
                code_of[s] = nkeys
                key_order[nkeys] = s
                nkeys += 1
            if i1 > i0:
                _output(t, dt, i0, i1, mu_s, A, B, C, Om, phi, has_sin, fa, fb, fd, om[s], damp2[s], Wo[s], Wc_s,
                        Ro_r[s], Ro_i[s], Vb, Db, taub, zrb, zib, Kb, Sb, Lb, Pb, Wb,
                        w, w_t, wc, wtc, kin, strain, lpow, dpow, eta_out, eta_t_out)
                for i in range(i0, i1):
                    code[i] = code_of[s]
            # ------------------------------------------------------ record the segment
            if nseg >= seg_t0.shape[0]:
                seg_t0 = _grow1(seg_t0, nseg + 1)
                seg_t1 = _grow1(seg_t1, nseg + 1)
                seg_s = _grow1(seg_s, nseg + 1)
                seg_k = _grow1(seg_k, nseg + 1)
                seg_eta = _grow2(seg_eta, nseg + 1)
                seg_deta = _grow2(seg_deta, nseg + 1)
            seg_t0[nseg] = t
            seg_t1[nseg] = te
            seg_s[nseg] = s
            seg_k[nseg] = kp
            seg_eta[nseg] = eta
            seg_deta[nseg] = deta
            nseg += 1
            _state_at(te - t, mu_s, A, B, C, has_sin, Om, phi, eta, deta)
            t = te
            just = c_hit
            if c_hit >= 0:
                c_switch = c_hit
            elif t >= pt1[kp]:
                kp += 1
        if c_switch < 0:
            continue
        # ---------------------------------------------------------- switch contactor c_switch at t
        c = c_switch
        new = s ^ (1 << c)
        E_before = _energy(s, eta, deta, om[s], Wc_s, gap, side, kst)
        vel = _dot(Wc_s[c], deta)
        if nev > 0 and ev_t[nev - 1] == t and ev_c[nev - 1] == c:
            nev -= 1  # an impact and a rebound at one instant cancel (grazing touch)
        else:
            if nev >= ev_t.shape[0]:
                ev_t = _grow1(ev_t, nev + 1)
                ev_kind = _grow1(ev_kind, nev + 1)
                ev_c = _grow1(ev_c, nev + 1)
                ev_v = _grow1(ev_v, nev + 1)
            ev_t[nev] = t
            ev_kind[nev] = 1 if (new >> c) & 1 else 0
            ev_c[nev] = c
            ev_v[nev] = vel
            nev += 1
        P = Tm[new, s]
        for i in range(nc):
            wb[i] = _dot(Wc_s[i], eta)
        for n in range(nm):
            e0[n] = _dot(P[n], eta)
            d0[n] = _dot(P[n], deta)
        eta[:] = e0
        deta[:] = d0
        worst = 0
        best = -1.0
        for i in range(nc):
            moved[i] = abs(_dot(Wc[new, i], eta) - wb[i])
            scl[i] = max(max(gap[i], abs(wb[i])), 1e6 * tol_h)  # floor 1e-6 L: zero gap at rest
            ratio = moved[i] / scl[i]
            if ratio > best:
                best = ratio
                worst = i
        if nc > 0 and moved[worst] > 0.05 * scl[worst] and not warn:
            warn = True
            warn_t = t
            warn_c = worst
            warn_moved = moved[worst]
            warn_scale = scl[worst]
        if njump >= jumps.shape[0]:
            jumps = _grow1(jumps, njump + 1)
        jumps[njump] = _energy(new, eta, deta, om[new], Wc[new], gap, side, kst) - E_before
        njump += 1
        s = new
        if c_bad >= 0 and c_switch == c_bad and c_hit < 0:
            just = c_bad
        if nev >= max_events:
            status = 1
            break
    return (
        status, t, nseg, seg_t0, seg_t1, seg_s, seg_k, seg_eta, seg_deta, nev, ev_t, ev_kind, ev_c, ev_v,
        njump, jumps, nkeys, key_order, warn, warn_t, warn_c, warn_moved, warn_scale,
    )
