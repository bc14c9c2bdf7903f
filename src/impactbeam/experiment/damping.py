"""Damping ratios from free-decay records: three estimators (paper section 4.1).

The paper's logarithmic decrement (:func:`damping_log_decrement`, section
4.1 reports 1.1 +/- 0.1 %) band-passes the record and drops the filter's
start-up transients at both ends; on a record of ~10 cycles (the paper's
0.2 s camera records of a 57 Hz beam) nothing is left. Two estimators that
use every sample and need no filter:

* :func:`damping_sine_fit`: least squares of a sum of exponentially decaying
  sinusoids plus an offset and a linear trend to the raw record, by variable
  projection (Golub & Pereyra 1973): the amplitudes and phases are eliminated
  by linear least squares, only the decay rates ``sigma_k`` and damped
  frequencies ``omega_k`` are iterated (from the spectral peaks). For white
  Gaussian noise it is the maximum-likelihood estimator; its standard errors
  come from the Jacobian.
* :func:`damping_matrix_pencil`: the matrix-pencil method (Hua & Sarkar 1990),
  a subspace method with no iteration and no starting values: the poles
  ``z = exp((-sigma + i omega) dt)`` are the eigenvalues of the pencil of two
  shifted Hankel matrices of the samples, truncated to the signal subspace
  by an SVD.

Both give, per mode, ``xi = sigma / sqrt(sigma^2 + omega_d^2)`` (the modal
equation of the paper's eq. 9 with damping ratio ``xi`` decays as
``exp(-xi omega_n t)`` and oscillates at ``omega_d = omega_n sqrt(1 - xi^2)``).
Their difference is reported as the spread of the estimate.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..exceptions import ParameterError
from .records import Record, _require_uniform
from .spectral import identify_frequencies

__all__ = [
    "ratio_from_decrement",
    "DampingEstimate",
    "damping_log_decrement",
    "PENCIL_MAX_COLUMNS",
    "SineFit",
    "damping_matrix_pencil",
    "damping_sine_fit",
]


def ratio_from_decrement(delta: float) -> float:
    """Damping ratio from the logarithmic decrement per cycle: ``xi = delta / sqrt(4 pi^2 + delta^2)``.

    Parameters
    ----------
    delta : float
        ``ln(a_k / a_{k+1})`` of successive peaks one damped period apart.

    Returns
    -------
    float
    """
    return delta / math.sqrt(4 * math.pi**2 + delta**2)


@dataclass(frozen=True, eq=False)
class DampingEstimate:
    """Damping ratio of one mode by logarithmic decrement.

    Attributes
    ----------
    damping_ratio : float
        From the decay rate of the cycle peaks: least-squares slope of
        ``ln |peak|`` against time (positive and negative peaks, one intercept
        each), ``sigma``, and ``delta = sigma T_d``,
        ``xi = delta / sqrt(4 pi^2 + delta^2)``. This is the average
        logarithmic decrement over all the cycles used.
    spread : float
        Standard deviation of the per-cycle ratios (the paper's "+/-").
    per_cycle : ndarray
        ``xi_i`` from ``delta_i = ln(a_i / a_{i+1})`` of consecutive peaks of one sign.
    mean : float
        Mean of ``per_cycle``.
    standard_error : float
        Standard error of ``damping_ratio`` from the regression.
    frequency_hz : float
        Frequency of the mode [Hz] (the band-pass centre).
    band_hz : tuple of float
        Pass band used [Hz].
    n_cycles : int
        Number of per-cycle decrements.
    peak_times, peak_values : ndarray
        The refined peaks of the filtered record used.
    """

    damping_ratio: float
    spread: float
    per_cycle: np.ndarray = field(repr=False)
    mean: float
    standard_error: float
    frequency_hz: float
    band_hz: tuple[float, float]
    n_cycles: int
    peak_times: np.ndarray = field(repr=False)
    peak_values: np.ndarray = field(repr=False)


def _bandpass(record: Record, f: float, bandwidth: float, neighbours: Sequence[float] = ()) -> tuple[np.ndarray, tuple[float, float]]:
    from scipy.signal import butter, sosfiltfilt

    fs = record.sample_rate
    lo, hi = f * (1 - bandwidth), f * (1 + bandwidth)
    for g in neighbours:  # stay clear of neighbouring modes
        if g < f:
            lo = max(lo, 0.5 * (f + g))
        elif g > f:
            hi = min(hi, 0.5 * (f + g))
    hi = min(hi, 0.45 * fs)
    if not (0 < lo < f < hi):
        raise ParameterError(f"frequency: {f:g} Hz cannot be band-passed at a sample rate of {fs:g} Hz")
    sos = butter(4, [lo, hi], btype="bandpass", fs=fs, output="sos")
    x = record.values - np.mean(record.values)
    return sosfiltfilt(sos, x), (lo, hi)


def _vertices(t: np.ndarray, y: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Parabola vertices through samples k-1, k, k+1 (uniform step)."""
    idx = idx[(idx > 0) & (idx < y.size - 1)]
    a, b, c = y[idx - 1], y[idx], y[idx + 1]
    den = a - 2 * b + c
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.where(den != 0, 0.5 * (a - c) / den, 0.0)
    d = np.clip(d, -0.5, 0.5)
    h = t[1] - t[0]
    return t[idx] + d * h, b - 0.25 * (a - c) * d


def damping_log_decrement(
    record: Record,
    frequency: float | None = None,
    *,
    bandwidth: float = 0.3,
    min_amplitude: float = 0.05,
    neighbours: Sequence[float] = (),
) -> DampingEstimate:
    """Damping ratio of one mode by the logarithmic decrement (paper section 4.1).

    Parameters
    ----------
    record : Record
        A uniformly sampled free decay.
    frequency : float, optional, [Hz]
        The mode; default the dominant spectral peak (:func:`identify_frequencies` with n = 1).
    bandwidth : float
        Half-width of the pass band relative to ``frequency`` (0.3: 0.7 f .. 1.3 f),
        narrowed to halfway towards any of ``neighbours``.
    min_amplitude : float
        Peaks smaller than this fraction of the largest are not used (they
        are dominated by noise); none when the largest left after the
        filter's start-up is below this fraction of the record's largest (a
        decay over before it: heavy damping).
    neighbours : sequence of float, [Hz]
        Other identified frequencies the band must stay clear of.

    Returns
    -------
    DampingEstimate

    Notes
    -----
    The record is band-passed (4th-order Butterworth, forward and backward,
    so without phase shift) around the mode, which isolates it from the
    other modes. A linear filter does not change the decay rate of
    ``exp(-sigma t) sin(omega_d t)`` (an exponential is its eigenfunction);
    only its start-up transients do, so the peaks within seven filter time
    constants ``1 / (0.38 * 2 pi B)`` (``B`` the half bandwidth) of either
    end are dropped. Each peak is refined by a parabola through three
    samples. For ``a_i`` and ``a_{i+1}`` one period apart,
    ``delta_i = ln(a_i / a_{i+1})`` and ``xi_i = delta_i / sqrt(4 pi^2 + delta_i^2)``.

    Raises
    ------
    ParameterError
        For a non-uniform record or fewer than two usable cycles.
    """
    _require_uniform(record, "the logarithmic decrement")
    if frequency is None:
        frequency = float(identify_frequencies(record, 1).frequencies_hz[0])
    f = float(frequency)
    if not (math.isfinite(f) and f > 0):
        raise ParameterError(f"frequency: must be positive and finite, got {frequency!r}")
    if not 0 < bandwidth < 1:
        raise ParameterError(f"bandwidth: must lie in (0, 1), got {bandwidth!r}")
    y, band = _bandpass(record, f, bandwidth, neighbours)
    t = record.time
    from scipy.signal import find_peaks

    period = 1.0 / f
    dist = max(1, int(0.6 * period / record.step))
    half_band = 0.5 * (band[1] - band[0])
    edge = max(1.5 * period, 7.0 / (0.38 * 2 * math.pi * half_band))
    groups = []
    whole = 0.0  # the largest peak of the whole filtered record
    for sign in (1.0, -1.0):
        idx, _ = find_peaks(sign * y, distance=dist)
        pt, pv = _vertices(t, sign * y, idx)
        whole = max(whole, float(np.max(pv, initial=0.0)))
        ok = (pt > t[0] + edge) & (pt < t[-1] - edge) & (pv > 0)
        groups.append((pt[ok], pv[ok]))
    amax = max((g[1].max() for g in groups if g[1].size), default=0.0)
    if amax < min_amplitude * whole:  # the decay was over within the trimmed start: the peaks left are noise
        amax = math.inf  # (zeta 0.2 was read as 1.85 % from them)
    per_cycle: list[float] = []
    rows_t, rows_l, rows_g = [], [], []
    all_t, all_v = [], []
    for gi, (pt, pv) in enumerate(groups):
        use = pv >= min_amplitude * amax
        # stop at the first peak below the threshold (later ones are noise)
        if not use.all():
            stop = int(np.argmin(use))
            use[stop:] = False
        pt, pv = pt[use], pv[use]
        all_t.append(pt)
        all_v.append(pv if gi == 0 else -pv)
        for i in range(pt.size - 1):
            gap = pt[i + 1] - pt[i]
            if 0.7 * period < gap < 1.3 * period:
                d = math.log(pv[i] / pv[i + 1])
                per_cycle.append(ratio_from_decrement(d))
        rows_t.append(pt)
        rows_l.append(np.log(pv))
        rows_g.append(np.full(pt.size, gi))
    tt = np.concatenate(rows_t)
    ll = np.concatenate(rows_l)
    gg = np.concatenate(rows_g)
    if len(per_cycle) < 2 or tt.size < 4:
        raise ParameterError(
            f"{record.label}: fewer than two usable cycles at {f:.4g} Hz for the logarithmic decrement "
            "(record too short, too noisy, or the mode too weak)"
        )
    # ln a = c_g - sigma t: least squares with one intercept per sign
    A = np.column_stack([-tt, (gg == 0).astype(float), (gg == 1).astype(float)])
    A = A[:, np.any(A != 0, axis=0)]
    coef, res, rank, _ = np.linalg.lstsq(A, ll, rcond=None)
    sigma = float(coef[0])
    dof = max(tt.size - A.shape[1], 1)
    resid = ll - A @ coef
    cov = np.linalg.pinv(A.T @ A) * float(resid @ resid) / dof
    delta = sigma * period
    xi = ratio_from_decrement(delta)
    dxi_dsigma = period * 4 * math.pi**2 / (4 * math.pi**2 + delta**2) ** 1.5
    pc = np.asarray(per_cycle)
    order = np.argsort(np.concatenate(all_t))
    return DampingEstimate(
        damping_ratio=float(xi),
        spread=float(np.std(pc, ddof=1)),
        per_cycle=pc,
        mean=float(np.mean(pc)),
        standard_error=float(math.sqrt(max(cov[0, 0], 0.0)) * dxi_dsigma),
        frequency_hz=f,
        band_hz=(float(band[0]), float(band[1])),
        n_cycles=int(pc.size),
        peak_times=np.concatenate(all_t)[order],
        peak_values=np.concatenate(all_v)[order],
    )


#: Largest pencil parameter L (columns of the Hankel matrix); bounds the SVD cost on long records.
PENCIL_MAX_COLUMNS = 400


@dataclass(frozen=True, eq=False)
class SineFit:
    """Result of :func:`damping_sine_fit`.

    Attributes
    ----------
    frequencies_hz : ndarray, [Hz]
        Damped frequencies ``omega_k / 2 pi``.
    damping_ratios : ndarray
        ``sigma_k / sqrt(sigma_k^2 + omega_k^2)``.
    standard_errors : ndarray
        Standard errors of the damping ratios (linearised, from the Jacobian
        and the residual variance).
    amplitudes : ndarray
        Amplitudes at the first sample, in the record's unit.
    rms_residual : float
        Root-mean-square residual, in the record's unit.
    """

    frequencies_hz: np.ndarray
    damping_ratios: np.ndarray
    standard_errors: np.ndarray
    amplitudes: np.ndarray
    rms_residual: float


def _xi(sigma: np.ndarray, omega: np.ndarray) -> np.ndarray:
    return sigma / np.sqrt(sigma**2 + omega**2)


def _basis(tau: np.ndarray, sigma: np.ndarray, omega: np.ndarray) -> np.ndarray:
    cols = [np.ones_like(tau), tau / max(tau[-1], 1e-300)]
    for s, w in zip(sigma, omega):
        e = np.exp(-s * tau)
        cols += [e * np.cos(w * tau), e * np.sin(w * tau)]
    return np.column_stack(cols)


def damping_sine_fit(
    time: np.ndarray, values: np.ndarray, frequencies_hz: Sequence[float], *, damping_guess: float = 0.01
) -> SineFit:
    """Fit decaying sinusoids at the given frequencies to a free decay (variable projection).

    Parameters
    ----------
    time, values : ndarray, shape (n,)
        The record (uniform or not; SI or any consistent unit).
    frequencies_hz : sequence of float, [Hz]
        Starting damped frequencies, e.g. from
        :func:`impactbeam.experiment.identify_frequencies`; every mode with
        significant energy in the record should be listed (an unlisted one
        biases the others).
    damping_guess : float
        Starting damping ratio of every mode.

    Returns
    -------
    SineFit

    Raises
    ------
    ParameterError
        For fewer samples than ``4 n_modes + 4``, or when the fit does not converge.
    """
    from scipy.optimize import least_squares

    t = np.asarray(time, dtype=float)
    y = np.asarray(values, dtype=float)
    f0 = np.asarray(frequencies_hz, dtype=float)
    n = f0.size
    if n < 1 or t.size < 4 * n + 4:
        raise ParameterError(f"damping fit: {t.size} samples are too few for {n} mode(s)")
    tau = t - t[0]
    scale = float(np.std(y)) or 1.0
    yn = (y - np.mean(y)) / scale
    w0 = 2 * math.pi * f0

    def unpack(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        # p = (ln-free) sigma / omega0 and omega / omega0: well scaled near 1e-2 and 1
        return p[:n] * w0, p[n:] * w0

    def residual(p: np.ndarray) -> np.ndarray:
        sigma, omega = unpack(p)
        phi = _basis(tau, sigma, omega)
        c, *_ = np.linalg.lstsq(phi, yn, rcond=None)
        return yn - phi @ c

    p0 = np.concatenate([np.full(n, damping_guess), np.ones(n)])
    lower = np.concatenate([np.full(n, -0.2), np.full(n, 0.9)])
    upper = np.concatenate([np.full(n, 1.0), np.full(n, 1.1)])
    sol = least_squares(residual, p0, bounds=(lower, upper), x_scale=np.concatenate([np.full(n, 0.01), np.full(n, 0.01)]),
                        xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=200 * (2 * n + 1))
    if not sol.success:
        raise ParameterError(f"damping fit: did not converge ({sol.message})")
    sigma, omega = unpack(sol.x)
    r = sol.fun
    dof = max(t.size - (2 * n + 2) - 2 * n, 1)
    s2 = float(r @ r) / dof
    J = sol.jac
    cov = np.linalg.pinv(J.T @ J) * s2
    # xi(sigma, omega) with p = sigma / w0, q = omega / w0: d xi = (omega^2 dsigma - sigma omega domega) / wn^3
    wn = np.sqrt(sigma**2 + omega**2)
    g_sig = omega**2 / wn**3 * w0
    g_om = -sigma * omega / wn**3 * w0
    var = g_sig**2 * np.diag(cov)[:n] + g_om**2 * np.diag(cov)[n:] + 2 * g_sig * g_om * np.diag(cov[:n, n:])
    phi = _basis(tau, sigma, omega)
    c, *_ = np.linalg.lstsq(phi, yn, rcond=None)
    amps = np.hypot(c[2::2], c[3::2]) * scale
    return SineFit(
        frequencies_hz=omega / (2 * math.pi),
        damping_ratios=_xi(sigma, omega),
        standard_errors=np.sqrt(np.maximum(var, 0.0)),
        amplitudes=amps,
        rms_residual=float(math.sqrt(float(r @ r) / t.size)) * scale,
    )


def damping_matrix_pencil(
    values: np.ndarray, step: float, frequencies_hz: Sequence[float], *, extra_pairs: int = 2
) -> tuple[np.ndarray, np.ndarray]:
    """Damping ratios and damped frequencies of the given modes by the matrix-pencil method.

    Parameters
    ----------
    values : ndarray, shape (n,)
        A uniformly sampled free decay.
    step : float, [s]
        The sample step.
    frequencies_hz : sequence of float, [Hz]
        The modes to report: for each, the pole nearest in frequency.
    extra_pairs : int
        Pole pairs beyond one per requested mode (plus two real poles for an
        offset and a trend) kept in the signal subspace; they absorb weak
        unlisted modes and noise.

    Returns
    -------
    damping_ratios, frequencies_hz : ndarray
        Per requested mode (NaN where no pole lies within 20 % of the frequency).

    Notes
    -----
    Hua & Sarkar (1990): with the Hankel matrix ``Y[i, j] = y[i + j]`` of
    ``L + 1`` columns (``L = N/3``, at most :data:`PENCIL_MAX_COLUMNS`), the
    right singular vectors ``V`` of the ``M`` largest singular values
    (``M = 2 (n_modes + extra_pairs) + 2``) span the signal; the poles are the
    eigenvalues of ``pinv(V1) V2``, ``V1`` and ``V2`` being ``V`` without its
    last and first row. ``s = ln(z) / step``, ``sigma = -Re s``,
    ``omega = |Im s|``.
    """
    y = np.asarray(values, dtype=float)
    y = y - np.mean(y)
    f0 = np.asarray(frequencies_hz, dtype=float)
    N = y.size
    M = 2 * (f0.size + extra_pairs) + 2
    L = min(N // 3, PENCIL_MAX_COLUMNS)
    if L < M + 1:
        raise ParameterError(f"matrix pencil: {N} samples are too few for {f0.size} mode(s)")
    rows = N - L
    Y = np.lib.stride_tricks.sliding_window_view(y, L + 1)[:rows]
    _, _, vh = np.linalg.svd(Y, full_matrices=False)
    V = vh[:M].conj().T  # (L + 1, M)
    z = np.linalg.eigvals(np.linalg.pinv(V[:-1]) @ V[1:])
    s = np.log(z.astype(complex)) / step
    sigma, omega = -s.real, np.abs(s.imag)
    xi_out = np.full(f0.size, np.nan)
    f_out = np.full(f0.size, np.nan)
    for k, f in enumerate(f0):
        d = np.abs(omega / (2 * math.pi) - f)
        d[omega == 0] = np.inf
        j = int(np.argmin(d))
        if d[j] <= 0.2 * f:
            xi_out[k] = sigma[j] / math.hypot(sigma[j], omega[j])
            f_out[k] = omega[j] / (2 * math.pi)
    return xi_out, f_out
