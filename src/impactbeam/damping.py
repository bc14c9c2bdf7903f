"""Damping ratios from short free-decay records: two independent estimators.

The logarithmic decrement of :func:`impactbeam.experiment.damping_log_decrement`
band-passes the record and drops the filter's start-up transients at both
ends; on a record of ~10 cycles (the paper's 0.2 s camera records of a 57 Hz
beam, Xu & Ervin 2013 section 4.1) nothing is left. Two estimators that use
every sample and need no filter:

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
from dataclasses import dataclass

import numpy as np

from .exceptions import ParameterError

__all__ = ["PENCIL_MAX_COLUMNS", "SineFit", "damping_matrix_pencil", "damping_sine_fit"]

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
