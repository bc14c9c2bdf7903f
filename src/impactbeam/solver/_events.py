"""Compiled event location on the closed form: no crossing can be missed.

The oriented opening of contactor ``c`` in the current state is
``h_c(tau) = o_c (gap_c - s_c w(a_c, tau))`` (``o = +1`` free, ``-1``
engaged), positive while the state is consistent. With a bound ``M_c`` on
``|h_c''|`` over the segment (:func:`~impactbeam.solver._closed.curvature_bound`),
Taylor's theorem gives, from any point with ``h > 0``,

.. math:: h(\\tau + s) \\ge h + h' s - M s^2 / 2 > 0 \\quad\\text{for } s < s^* = \\frac{h' + \\sqrt{h'^2 + 2Mh}}{M},

so the scan steps by ``s*`` (at least ``dmin``) and every step is either
proven root-free from both of its ends, or subdivided until it is, or until a
point with ``h <= 0`` is found; a sub-interval that starts positive, ends
non-positive and on which ``h' < 0`` is proven (the same bound applied to
``h'``) holds exactly one root, which Newton's method with the slope each
evaluation gives, kept inside the bracket (:func:`_crossing`), locates to
``xtol`` and beyond. Brent's method (SciPy's ``brentq`` algorithm) locates
the roots of ``h'``. Grazing dips of any depth above the touch
tolerance are found this way, two crossings inside one step cannot be
missed, and the scan does not depend on the output time step. A segment whose
rows are all proven positive up to its end
(:func:`~impactbeam.solver._closed.clear_to_end`, at its start and wherever
the curvature bounds are refreshed) is not stepped further: no event can
occur in it.

A contactor left on the wrong side of its state by the projection of eq. (12)
(``h < 0``, only for the contactor switched at the segment start, moving back
towards its side) switches where its opening turns back, i.e. at the root
of ``h'`` while ``h < 0``.

Tangency at a segment start (``|h| <= tol_h``: zero gap at rest, a contactor
just switched) is decided by the sign of the first derivative of ``h`` that
is not zero up to round-off (:func:`departure`), computed exactly from the
equation of motion, never by the sign of round-off in ``h`` itself.
"""

from __future__ import annotations

import math

import numpy as np
from ._jit import njit

from ._closed import EPS, clear_to_end, curvature_bound_at, derivatives, kernels_into, mode_state, particular
from ._elementary import ROW_C, ROW_S, kernels_at

__all__ = ["row_at", "row_from", "brent", "secant_start", "newton_step", "safe_step", "first_event", "scan",
           "departure"]

RTOL = 4.0 * EPS
_STACK = 96
# what brent() solves for (the roots of h_c' only since the crossings of h_c are refined by _crossing):
# an int64 value, not a literal constant, so that numba compiles one specialisation of brent, _f and row_at
SLOPE = np.int64(1)


@njit(cache=True, nogil=True, _nrt=False)
def row_at(c, tau, reg, a, w, om, VH, VD, base, PV, Om, phi, kw):  # pragma: no cover - compiled
    """``(h_c, h_c')`` of one row at ``tau`` (``kw``: the scratch of :func:`~impactbeam.solver._elementary.kernels_at`)."""
    kernels_at(tau, reg, a, w, kw)
    return row_from(c, tau, kw[ROW_C], kw[ROW_S], a, om, VH, VD, base, PV, Om, phi)


@njit(cache=True, nogil=True, _nrt=False)
def row_from(c, tau, kc, ks, a, om, VH, VD, base, PV, Om, phi):  # pragma: no cover - compiled
    """:func:`row_at` with the kernels at ``tau`` given (:func:`~impactbeam.solver._closed.kernels_into`)."""
    pv, pd = particular(PV[c], tau, Om, phi)
    g = base[c] + pv
    dg = pd
    for n in range(om.size):
        zh, dzh = mode_state(kc[n], ks[n], a[n], om[n], VH[c, n], VD[c, n])
        g += zh
        dg += dzh
    return g, dg


@njit(cache=True, nogil=True, _nrt=False)
def _f(which, c, tau, reg, a, w, om, VH, VD, base, PV, Om, phi, kw):  # pragma: no cover - compiled
    g, dg = row_at(c, tau, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
    return g if which == 0 else dg


@njit(cache=True, nogil=True, _nrt=False)
def brent(which, c, xa, xb, fa, fb, xtol, reg, a, w, om, VH, VD, base, PV, Om, phi, kw):  # pragma: no cover
    """Root of ``h_c`` (which = 0) or ``h_c'`` (which = 1) in ``[xa, xb]`` bracketing a sign change.

    SciPy's ``brentq`` algorithm (``xtol`` absolute, ``4 eps`` relative).
    """
    xpre = xa
    xcur = xb
    fpre = fa
    fcur = fb
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
        delta = (xtol + RTOL * abs(xcur)) / 2.0
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
        fcur = _f(which, c, xcur, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
    return xcur


@njit(cache=True, nogil=True, _nrt=False)
def secant_start(t0, t1, f0, f1):  # pragma: no cover - compiled
    """Where the chord from ``(t0, f0)`` to ``(t1, f1)`` crosses zero (the midpoint if that is not inside)."""
    t = t0 + (t1 - t0) * (f0 / (f0 - f1))
    return t if t0 < t < t1 else 0.5 * (t0 + t1)


@njit(cache=True, nogil=True, _nrt=False)
def newton_step(t, f, df, lo, hi, xtol):  # pragma: no cover - compiled
    """One step of Newton's method for the root of a function that falls through zero in ``[lo, hi]``.

    ``f, df``: its value (nonzero) and slope at ``t``, which becomes the
    bracket's lower end if ``f > 0``, else its upper end. The step is kept
    inside the bracket (bisection when it would leave it). Returns ``(next,
    lo, hi, done)``: ``done`` when the step or the bracket is below
    :func:`brent`'s tolerance ``(xtol + 4 eps |t|) / 2``, ``next`` then
    being the last step (its error of the order of its square), or the
    bracket's midpoint.
    """
    if f > 0.0:
        lo = t
    else:
        hi = t
    delta = 0.5 * (xtol + RTOL * abs(t))
    tn = t - f / df if df < 0.0 else lo - 1.0
    if lo <= tn <= hi and (abs(tn - t) < delta or hi - lo < 2.0 * delta):
        return tn, lo, hi, True
    if not (lo < tn < hi):
        tn = 0.5 * (lo + hi)
        if hi - lo < 2.0 * delta:
            return tn, lo, hi, True
    return tn, lo, hi, False


@njit(cache=True, nogil=True, _nrt=False)
def _crossing(c, t0, t1, g0, g1, xtol, reg, a, w, om, VH, VD, base, PV, Om, phi, kw):  # pragma: no cover
    """The root of ``h_c`` in ``[t0, t1]``, where it goes from ``g0 > 0`` to ``g1 <= 0``.

    Newton's method (:func:`newton_step`) with the slope that each
    evaluation (:func:`row_at`) gives with the value, from the secant point;
    it returns the last step (the crossings of the random systems of the
    test suite are found to 3e-17 s, Brent's method stopped at up to 2e-14 s).
    """
    if g1 == 0.0:
        return t1
    lo = t0
    hi = t1
    t = secant_start(t0, t1, g0, g1)
    for _ in range(200):
        g, dg = row_at(c, t, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
        if g == 0.0:
            return t
        t, lo, hi, done = newton_step(t, g, dg, lo, hi, xtol)
        if done:
            return t
    return t


@njit(cache=True, nogil=True, _nrt=False)
def safe_step(h, dh, M):  # pragma: no cover - compiled
    """Largest ``s`` with ``h + dh s - M s^2/2 > 0`` (``h > 0``); inf if unbounded."""
    if M <= 0.0:
        return np.inf if dh >= 0.0 else h / (-dh)
    q = math.sqrt(dh * dh + 2.0 * M * h)
    if dh >= 0.0:
        return (dh + q) / M
    return 2.0 * h / (q - dh)


@njit(cache=True, nogil=True, _nrt=False)
def _monotone(d0, d1, M, L, sign):  # pragma: no cover - compiled
    """True when ``sign * h' > 0`` is proven on an interval of length L with end slopes d0, d1."""
    s0 = sign * d0
    s1 = sign * d1
    if s0 <= 0.0 or s1 <= 0.0:
        return False
    return M <= 0.0 or (s0 + s1) >= M * L


@njit(cache=True, nogil=True, _nrt=False)
def first_event(c, ta, ga, dga, tb, gb, dgb, M, xtol, tol_h, stack, reg, a, w, om, VH, VD, base, PV, Om, phi,
                kw):
    # pragma: no cover - compiled
    """First switching time of row ``c`` in ``(ta, tb]``, or NaN (see the module docstring).

    Values within ``tol_h`` of the surface count as touching: they are on the
    consistent side (their departure was judged at the segment start), and a
    dip that goes no deeper than ``tol_h`` is not an event.
    """
    top = 0
    stack[0, 0] = ta
    stack[0, 1] = ga
    stack[0, 2] = dga
    stack[0, 3] = tb
    stack[0, 4] = gb
    stack[0, 5] = dgb
    top = 1
    while top > 0:
        top -= 1
        t0 = stack[top, 0]
        g0 = stack[top, 1]
        d0 = stack[top, 2]
        t1 = stack[top, 3]
        g1 = stack[top, 4]
        d1 = stack[top, 5]
        L = t1 - t0
        if g0 >= -tol_h:
            touch0 = g0 <= tol_h
            if g1 > 0.0 or (touch0 and g1 >= -tol_h):
                # no event at the ends: prove that h stays above -tol_h inside
                if M <= 0.0 or safe_step(g0 + tol_h, d0, M) + safe_step(g1 + tol_h, -d1, M) >= L:
                    continue
            elif not touch0 and (_monotone(d0, d1, M, L, -1.0) or L <= xtol):
                return _crossing(c, t0, t1, g0, g1, xtol, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
            elif touch0 and L <= xtol:
                return t0  # from the surface straight into the stop
            if L <= xtol:
                continue  # a dip shallower than the touch tolerance
        else:
            # wrong side: switch where h' turns from + to - while h < 0 (moving further
            # in, it stays: switching back and forth at one instant cannot help)
            if _monotone(d0, d1, M, L, 1.0) or _monotone(d0, d1, M, L, -1.0):
                continue  # monotone: no turn-back inside, at most an upward crossing
            if d0 > 0.0 and d1 <= 0.0 and (L <= xtol or g1 <= 0.0):
                r = brent(SLOPE, c, t0, t1, d0, d1, xtol, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
                gr, dr = row_at(c, r, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
                if gr <= 0.0:
                    return r
                # it rose above zero and came back: look for the downward crossing after r
                stack[top, 0] = r
                stack[top, 1] = gr
                stack[top, 2] = dr
                stack[top, 3] = t1
                stack[top, 4] = g1
                stack[top, 5] = d1
                top += 1
                continue
            if L <= xtol:
                continue
        if top + 2 > stack.shape[0]:
            continue  # deeper than the stack: the interval is below any resolvable scale
        tm = 0.5 * (t0 + t1)
        gm, dm = row_at(c, tm, reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
        stack[top, 0] = tm  # right half, examined after the left one
        stack[top, 1] = gm
        stack[top, 2] = dm
        stack[top, 3] = t1
        stack[top, 4] = g1
        stack[top, 5] = d1
        stack[top + 1, 0] = t0
        stack[top + 1, 1] = g0
        stack[top + 1, 2] = d0
        stack[top + 1, 3] = tm
        stack[top + 1, 4] = gm
        stack[top + 1, 5] = dm
        top += 2
    return np.nan


@njit(cache=True, nogil=True, _nrt=False)
def scan(tau0, tau_end, g, dg, gb, dgb, M, dmin, xtol, tol_h, used0, budget, stack, reg, a, w, om, VH, VD, base, PV,
         Om, phi, work_h, work_d, kc, ks, ready, kw):
    # pragma: no cover - compiled
    """Advance from ``tau0`` to the first switching event before ``tau_end``.

    ``g, dg`` hold the openings at ``tau0`` on entry; ``M`` their curvature
    bounds, refreshed every 32 steps from the projected rows (``work_h``,
    ``work_d``: scratch arrays shaped like ``VH``). ``used0`` steps of this
    segment's scan were taken before ``tau0`` (0 from the segment start;
    more when a scan stopped by its budget resumes, with ``g, dg, M`` as it
    left them, so that a resumed scan takes exactly the steps of one that was
    never stopped). Returns ``(tau, c, n, ready)``: the event time and row,
    ``c = -1`` if none up to ``tau_end``, or ``c = -2`` when ``budget`` more
    steps were taken first (``tau`` is then the point reached, every row
    proven consistent up to it); ``n`` the steps of the segment so far;
    whether ``kc, ks`` now hold the kernels at ``tau_end``
    (:func:`~impactbeam.solver._closed.kernels_into`). They are computed here
    when a step reaches ``tau_end`` unless ``ready`` on entry (a segment
    ended by an event never needs them; equal lengths share them).
    """
    nc = g.size
    tau = tau0
    used = used0
    if clear_to_end(VH, VD, om, base, PV, tau_end):
        return tau_end, -1, used, ready
    while tau < tau_end:
        step = tau_end - tau
        for c in range(nc):
            if g[c] >= -tol_h:
                s = safe_step(g[c] + tol_h, dg[c], M[c])
            elif dg[c] > 0.0 and M[c] > 0.0:
                s = dg[c] / M[c]
            elif dg[c] > 0.0:
                s = np.inf
            else:
                s = 0.0
            if s < step:
                step = s
        step = min(max(step, dmin), tau_end - tau)
        tb = tau + step
        if tb <= tau:
            tb = tau_end
        if tb == tau_end:  # the kernels at the segment's end, once for every segment of this length
            if not ready:
                kernels_into(tau_end, reg, a, w, kc, ks, kw)
                ready = True
            for c in range(nc):
                gb[c], dgb[c] = row_from(c, tb, kc, ks, a, om, VH, VD, base, PV, Om, phi)
        else:  # the kernels once for every row
            kernels_at(tb, reg, a, w, kw)
            for c in range(nc):
                gb[c], dgb[c] = row_from(c, tb, kw[ROW_C], kw[ROW_S], a, om, VH, VD, base, PV, Om, phi)
        used += 1
        best = np.inf
        which = -1
        for c in range(nc):
            r = first_event(c, tau, g[c], dg[c], tb, gb[c], dgb[c], M[c], xtol, tol_h, stack,
                            reg, a, w, om, VH, VD, base, PV, Om, phi, kw)
            if not np.isnan(r) and r < best:
                best = r
                which = c
        if which >= 0:
            return best, which, used, ready
        tau = tb
        for c in range(nc):
            g[c] = gb[c]
            dg[c] = dgb[c]
        if used % 32 == 0:  # a decaying response earns longer steps
            curvature_bound_at(tau, VH, VD, reg, a, w, om, PV, Om, tau_end, M, work_h, work_d, kw)
            if clear_to_end(work_h, work_d, om, base, PV, tau_end):
                return tau_end, -1, used, ready
        if used - used0 >= budget and tau < tau_end:
            return tau, -2, used, ready
    return tau_end, -1, used, ready


@njit(cache=True, nogil=True, _nrt=False)
def departure(v, u, base, a, om, eta0, deta0, load_A, load_B, load_D, load_E, AL, Om, phi, dvec, mag, work):
    # pragma: no cover - compiled
    """Sign (-1, 0, +1) of the first derivative of the row ``(v, u, base)`` at 0 that is not round-off.

    A derivative counts as zero when it is below ``64 eps`` times the same sum
    taken with absolute values (:func:`~impactbeam.solver._closed.derivatives`).
    Orders 1 to ``dvec.size - 1`` are tried; 0 when all vanish (e.g. at rest). ``work``: scratch of
    shape ``(2, dvec.size + 1)``.
    """
    kmax = dvec.size - 1
    # the slope decides but at a tangency: the higher orders only then (the same sums either way)
    derivatives(v, u, base, a, om, eta0, deta0, load_A, load_B, load_D, load_E, AL, Om, phi, min(kmax, 1), dvec, mag,
                work)
    if kmax >= 1 and abs(dvec[1]) > 64.0 * EPS * mag[1]:
        return 1 if dvec[1] > 0.0 else -1
    if kmax <= 1:
        return 0
    derivatives(v, u, base, a, om, eta0, deta0, load_A, load_B, load_D, load_E, AL, Om, phi, kmax, dvec, mag, work)
    for k in range(2, kmax + 1):
        if abs(dvec[k]) > 64.0 * EPS * mag[k]:
            return 1 if dvec[k] > 0.0 else -1
    return 0
