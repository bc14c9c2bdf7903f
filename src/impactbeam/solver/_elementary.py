"""Compiled elementary functions of the closed form: its kernels, their sines, cosines and exponentials.

A coordinate's homogeneous solution is built from two kernels (paper eq. 10,
:mod:`~impactbeam.solver._closed`): ``e_C, e_S = e^{-a tau}`` times ``cos,
sin(w tau)/w`` when under-damped. The event scans and the extremes evaluate
them for every mode at every step, so they are written here in plain IEEE
arithmetic, no library call:

* :func:`sincos`: a polynomial (Cephes) after a three-part reduction by
  pi/4, within two units in the last place of the C library;
* :func:`exponential`: ``2^k e^r`` with ``|r| <= ln 2 / 2`` (a two-part
  ``ln 2``) and the degree-13 Taylor polynomial of ``e^r`` (its truncation
  error 4e-18), within one unit in the last place of the C library;
* :func:`kernels_at`: every coordinate's kernels at one ``tau`` in loops
  without branches or calls, which the compiler turns into SIMD
  instructions (four modes at a time with AVX2, eight with AVX-512; the
  rows are padded to whole vectors); ``2^k`` is assembled from
  its bits in a scratch row. The same numbers as :func:`kernel`, mode by mode.

The library is used beyond the reduced ranges (``|w tau| > 2**28``,
``e^x`` outside ``[-708, 709]``), and for the other damping regimes.
"""

from __future__ import annotations

import math

import numpy as np

from ._jit import COMPILED, njit

__all__ = ["REG_UNDER", "REG_CRITICAL", "REG_OVER", "sincos", "exponential", "kernel", "kernels_at", "kernel_work"]

REG_UNDER = 0
REG_CRITICAL = 1
REG_OVER = 2

# sin and cos on [-pi/4, pi/4] (Cephes, S. L. Moshier: relative error about 1e-16) and the three-part pi/4 of
# its argument reduction
_S = (1.58962301576546568060e-10, -2.50507477628578072866e-8, 2.75573136213857245213e-6,
      -1.98412698295895385996e-4, 8.33333333332211858878e-3, -1.66666666666666307295e-1)
_C = (-1.13585365213876817300e-11, 2.08757008419747316778e-9, -2.75573141792967388112e-7,
      2.48015872888517045348e-5, -1.38888888888730564116e-3, 4.16666666666665929218e-2)
_DP1, _DP2, _DP3 = 7.85398125648498535156e-1, 3.77489470793079817668e-8, 2.69515142907905952645e-15
_FOUR_OVER_PI = 1.27323954473516268615
_REDUCED_MAX = 2.0**28  # 2.7e8: within two units in the last place up to here (tests/test_closed_form.py)

# e^x = 2^k e^r: log2(e), ln 2 in two parts (the first with 32 significant bits, so that k ln2_hi is exact)
_LOG2E = 1.4426950408889634074
_LN2_HI, _LN2_LO = 6.93145751953125e-1, 1.42860682030941723212e-6
_EXP_MIN, _EXP_MAX = -708.0, 709.0  # 2^k stays a normal number
_T = (1.0 / 6.0, 1.0 / 24.0, 1.0 / 120.0, 1.0 / 720.0, 1.0 / 5040.0, 1.0 / 40320.0, 1.0 / 362880.0,
      1.0 / 3628800.0, 1.0 / 39916800.0, 1.0 / 479001600.0, 1.0 / 6227020800.0)  # 1/k!, k = 3 .. 13

ROW_A, ROW_W, ROW_C, ROW_S, ROW_K, ROW_SCALE = 0, 1, 2, 3, 4, 5  # the rows of kernel_work


@njit(cache=True, nogil=True, _nrt=False)
def _sincos_reduced(x):  # pragma: no cover - compiled
    """``(sin x, cos x)`` for ``|x| <= 2**28``, without branches (every choice a select)."""
    ax = abs(x)
    t = np.floor(ax * _FOUR_OVER_PI)
    j = t + (t - 2.0 * np.floor(0.5 * t))  # an odd octant rounds up to even
    y = ((ax - j * _DP1) - j * _DP2) - j * _DP3
    q = j - 8.0 * np.floor(0.125 * j)  # 0, 2, 4 or 6
    z = y * y
    ps = y + y * z * (((((_S[0] * z + _S[1]) * z + _S[2]) * z + _S[3]) * z + _S[4]) * z + _S[5])
    pc = 1.0 - 0.5 * z + z * z * (((((_C[0] * z + _C[1]) * z + _C[2]) * z + _C[3]) * z + _C[4]) * z + _C[5])
    swap = q == 2.0 or q == 6.0
    sn = pc if swap else ps
    cs = ps if swap else pc
    sn = -sn if (q >= 4.0) != (x < 0.0) else sn
    cs = -cs if (q == 2.0 or q == 4.0) else cs
    return sn, cs


@njit(cache=True, nogil=True, _nrt=False)
def sincos(x):  # pragma: no cover - compiled
    """``(sin x, cos x)`` to within two units in the last place of the C library's values.

    Plain IEEE arithmetic (a polynomial after a three-part reduction by
    pi/4), no library call: cheaper in the event loop's scans than the C
    library's ``sincos``, which took about a third of that loop's time
    (docs/performance.md). Beyond ``|x| = 2**28`` it defers to the library.
    """
    if not abs(x) <= _REDUCED_MAX:
        return math.sin(x), math.cos(x)
    return _sincos_reduced(x)


@njit(cache=True, nogil=True, _nrt=False)
def _exp_k(x):  # pragma: no cover - compiled
    """The ``k`` of ``e^x = 2^k e^r`` (a whole number, as a float)."""
    return np.floor(x * _LOG2E + 0.5)


@njit(cache=True, nogil=True, _nrt=False)
def _exp_reduced(x, k):  # pragma: no cover - compiled
    """``e^r``, ``r = x - k ln 2`` (``|r| <= ln 2 / 2``): its Taylor polynomial of degree 13 (Horner)."""
    r = (x - k * _LN2_HI) - k * _LN2_LO
    p = _T[9] + r * _T[10]
    p = _T[8] + r * p
    p = _T[7] + r * p
    p = _T[6] + r * p
    p = _T[5] + r * p
    p = _T[4] + r * p
    p = _T[3] + r * p
    p = _T[2] + r * p
    p = _T[1] + r * p
    p = _T[0] + r * p
    return 1.0 + r * (1.0 + r * (0.5 + r * p))


@njit(cache=True, nogil=True, _nrt=False)
def exponential(x):  # pragma: no cover - compiled
    """``e^x`` to within one unit in the last place of the C library's value (module docstring)."""
    if not (_EXP_MIN <= x <= _EXP_MAX):
        return math.exp(x)
    k = _exp_k(x)
    return math.ldexp(_exp_reduced(x, k), int(k))  # exact: 2^k is a normal number


@njit(cache=True, nogil=True, _nrt=False)
def kernel(reg, a, w, tau):  # pragma: no cover - compiled
    """``(e_C, e_S)`` of one coordinate at ``tau >= 0`` (see :mod:`~impactbeam.solver._closed`)."""
    if reg == REG_UNDER:
        e = exponential(-a * tau)
        sn, cs = sincos(w * tau)
        return e * cs, e * sn / w
    if reg == REG_CRITICAL:
        e = exponential(-a * tau)
        return e, e * tau
    ep = math.exp((w - a) * tau)
    x = -2.0 * w * tau
    return 0.5 * ep * (1.0 + math.exp(x)), -0.5 * ep * math.expm1(x) / w


@njit(cache=True, nogil=True)
def kernel_work(nm):  # pragma: no cover - compiled
    """Scratch of :func:`kernels_at` for ``nm`` coordinates: six rows, padded to a multiple of eight.

    Eight: whole vectors with AVX-512 (eight lanes) and AVX2 (two of four),
    so that no coordinate falls to the scalar remainder of a vectorised loop
    (9 coordinates padded to 12 took 151 ns on an AVX-512 machine, to 16
    108 ns).
    """
    return np.zeros((6, (nm + 7) // 8 * 8))


@njit(cache=True, nogil=True, _nrt=False, error_model="numpy")
def kernels_at(tau, reg, a, w, kw):  # pragma: no cover - compiled
    """Every coordinate's kernels at ``tau`` into ``kw[ROW_C], kw[ROW_S]`` (the numbers of :func:`kernel`).

    ``kw`` from :func:`kernel_work`. The decays and frequencies are copied
    into its rows (padded with harmless values, so that the loops run over
    whole vectors), the under-damped kernels are evaluated for all at once
    in two loops without branches, and the coordinates they do not cover
    (other regimes, arguments beyond the reduced ranges) are redone by
    :func:`kernel`, which gives the same numbers where both apply.
    Compiled with NumPy's error model: Python's checks every divisor (to
    raise ZeroDivisionError), which keeps the compiler from vectorising;
    the divisors here are under-damped frequencies and the pads' 1.0. The
    interpreted twin calls :func:`kernel` mode by mode: the same numbers,
    in a fraction of the Python operations.
    """
    nm = a.size
    if not COMPILED:
        for i in range(nm):
            kw[ROW_C, i], kw[ROW_S, i] = kernel(reg[i], a[i], w[i], tau)
        return
    ka = kw[ROW_A]
    kf = kw[ROW_W]
    kcos = kw[ROW_C]
    ksin = kw[ROW_S]
    kr = kw[ROW_K]
    ks = kw[ROW_SCALE]
    bits = ks.view(np.int64)
    npad = ka.size
    for i in range(nm):
        ka[i] = a[i]
        kf[i] = w[i] if reg[i] == REG_UNDER else 1.0  # no division by a zero frequency (redone below anyway)
    for i in range(nm, npad):
        ka[i] = 0.0
        kf[i] = 1.0
    for i in range(npad):  # e^x = 2^k e^r: k, and 2^k from its bits
        k = _exp_k(min(max(-ka[i] * tau, _EXP_MIN), _EXP_MAX))
        kr[i] = k
        bits[i] = (np.int64(k) + 1023) << 52
    for i in range(npad):
        e = _exp_reduced(min(max(-ka[i] * tau, _EXP_MIN), _EXP_MAX), kr[i]) * ks[i]
        sn, cs = _sincos_reduced(kf[i] * tau)
        kcos[i] = e * cs
        ksin[i] = e * sn / kf[i]
    for i in range(nm):
        x = -a[i] * tau
        if reg[i] != REG_UNDER or not (abs(w[i] * tau) <= _REDUCED_MAX and _EXP_MIN <= x <= _EXP_MAX):
            kcos[i], ksin[i] = kernel(reg[i], a[i], w[i], tau)
