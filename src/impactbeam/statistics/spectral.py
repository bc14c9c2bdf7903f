"""Spectral tools for random responses: Welch estimates with chi-squared bands, moments, Rice, Dirlik.

* :func:`welch_psd`: the one-sided density of a sampled history by Welch's
  method (Hann window, half overlap, scipy), with its equivalent degrees of
  freedom ``nu`` and the chi-squared band that holds the estimate of a
  Gaussian process of density ``G`` with probability ``confidence``:
  ``[G chi2_nu(a/2) / nu, G chi2_nu(1 - a/2) / nu]`` (Bendat & Piersol,
  *Random Data*, 4th ed., section 8.5.4). ``nu = 2 K / (1 + 2 sum_j (1 - j/K) rho_j^2)``
  for ``K`` segments whose windows overlap with correlation ``rho_j``
  (Welch 1967), about ``1.9 K`` for Hann with half overlap.
* :func:`spectral_moments`: ``m_k = int f^k G(f) df`` (f in Hz).
* :func:`rice_rate`: Rice's rate of up-crossings of a level ``b`` by a
  stationary zero-mean Gaussian process, ``nu_0 exp(-b^2 / (2 sigma^2))``
  with ``nu_0 = sigma_v / (2 pi sigma)`` (Rice 1945).
* :func:`dirlik_damage_rate`: Dirlik's (1985) estimate of the rainflow
  range density from ``m_0, m_1, m_2, m_4`` of the stress density, and the
  Basquin-Miner damage rate it gives. Valid for a stationary Gaussian stress
  (the linear case); a cross-check of the counted damage, not a substitute.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["welch_psd", "chi2_band", "spectral_moments", "rice_rate", "dirlik_range_density", "dirlik_damage_rate"]


def welch_psd(values: np.ndarray, rate: float, *, segment: int | None = None,
              confidence: float = 0.95) -> dict[str, Any]:
    """One-sided density of a uniformly sampled history by Welch's method, with its chi-squared band.

    Parameters
    ----------
    values : array_like, (n,)
        Samples (the mean is removed per segment).
    rate : float, [Hz]
        Sample rate.
    segment : int, optional
        Samples per segment (default: n // 16, at least 256).
    confidence : float
        Probability of the band.

    Returns
    -------
    dict
        ``frequency`` [Hz], ``psd`` [unit^2/Hz], ``dof`` (equivalent degrees
        of freedom), ``band`` = (lower, upper) factors of the true density
        between which the estimate lies with probability ``confidence``.
    """
    from scipy import signal

    x = np.asarray(values, dtype=float)
    nper = int(segment or max(256, x.size // 16))
    nper = min(nper, x.size)
    step = nper // 2
    f, p = signal.welch(x, fs=rate, window="hann", nperseg=nper, noverlap=nper - step, detrend="constant")
    k = 1 + (x.size - nper) // step
    w = signal.get_window("hann", nper)
    denom = float(np.sum(w * w))
    corr = 0.0
    for j in range(1, k):
        lag = j * step
        if lag >= nper:
            break
        rho = float(np.sum(w[:-lag] * w[lag:])) / denom
        corr += (1.0 - j / k) * rho**2
    dof = 2.0 * k / (1.0 + 2.0 * corr)
    return {"frequency": f, "psd": p, "dof": dof, "band": chi2_band(dof, confidence)}


def chi2_band(dof: float, confidence: float = 0.95) -> tuple[float, float]:
    """``(chi2_nu(a/2) / nu, chi2_nu(1 - a/2) / nu)``: the band of an estimate with ``nu`` degrees of freedom.

    Parameters
    ----------
    dof : float
        Equivalent degrees of freedom ``nu``.
    confidence : float
        ``1 - a``.

    Returns
    -------
    (float, float)
    """
    from scipy import stats

    a = 1.0 - confidence
    return float(stats.chi2.ppf(a / 2, dof) / dof), float(stats.chi2.ppf(1 - a / 2, dof) / dof)


def spectral_moments(frequency: np.ndarray, psd: np.ndarray, orders: tuple[int, ...] = (0, 1, 2, 4)) -> dict[int, float]:
    """``m_k = int f^k G(f) df`` by the trapezoid rule (f in Hz, one-sided G).

    Parameters
    ----------
    frequency : array_like, [Hz]
    psd : array_like, [unit^2/Hz]
    orders : tuple of int

    Returns
    -------
    dict of int to float
    """
    f = np.asarray(frequency, dtype=float)
    g = np.asarray(psd, dtype=float)
    return {k: float(np.trapezoid(f**k * g, f)) for k in orders}


def rice_rate(level: float, sigma: float, sigma_velocity: float) -> float:
    """Up-crossings per second of ``level`` by a zero-mean stationary Gaussian process (Rice).

    Parameters
    ----------
    level : float
        The level ``b`` (same unit as ``sigma``).
    sigma : float
        Standard deviation of the process.
    sigma_velocity : float
        Standard deviation of its time derivative.

    Returns
    -------
    float, [1/s]
    """
    return sigma_velocity / (2.0 * math.pi * sigma) * math.exp(-(level**2) / (2.0 * sigma**2))


def _dirlik_parameters(m: dict[int, float]) -> tuple[float, ...]:
    m0, m1, m2, m4 = m[0], m[1], m[2], m[4]
    xm = m1 / m0 * math.sqrt(m2 / m4)
    gamma = m2 / math.sqrt(m0 * m4)
    d1 = 2.0 * (xm - gamma**2) / (1.0 + gamma**2)
    r = (gamma - xm - d1**2) / (1.0 - gamma - d1 + d1**2)
    d2 = (1.0 - gamma - d1 + d1**2) / (1.0 - r)
    d3 = 1.0 - d1 - d2
    q = 1.25 * (gamma - d3 - d2 * r) / d1
    return d1, d2, d3, q, r


def dirlik_range_density(ranges: np.ndarray, moments: dict[int, float]) -> np.ndarray:
    """Dirlik's density of rainflow ranges ``p(S)`` [1/unit] (ranges, not amplitudes).

    Parameters
    ----------
    ranges : array_like
        Stress ranges ``S``.
    moments : dict
        ``m_0, m_1, m_2, m_4`` (:func:`spectral_moments`).

    Returns
    -------
    ndarray
    """
    d1, d2, d3, q, r = _dirlik_parameters(moments)
    scale = 2.0 * math.sqrt(moments[0])
    z = np.asarray(ranges, dtype=float) / scale
    return (d1 / q * np.exp(-z / q) + d2 * z / r**2 * np.exp(-(z**2) / (2 * r**2)) + d3 * z * np.exp(-(z**2) / 2)) / scale


def dirlik_damage_rate(moments: dict[int, float], sn_stress: float, sn_cycles: float, sn_exponent: float) -> float:
    """Basquin-Miner damage per second from Dirlik's range density (closed form).

    With ``N(S_a) = N_ref (S_a / S_ref)^(-m)`` and ``S_a = S / 2``, the damage
    rate is ``nu_p E[S_a^m] / (N_ref S_ref^m)`` with the peak rate
    ``nu_p = sqrt(m_4 / m_2)`` and
    ``E[S^m] = (2 sqrt(m_0))^m [D_1 Q^m Gamma(1+m) + 2^(m/2) Gamma(1+m/2) (D_2 |R|^m + D_3)]``.

    Parameters
    ----------
    moments : dict
        ``m_0, m_1, m_2, m_4`` of the stress density.
    sn_stress, sn_cycles, sn_exponent : float
        ``S_ref`` [unit], ``N_ref``, ``m``.

    Returns
    -------
    float, [1/s]
    """
    d1, d2, d3, q, r = _dirlik_parameters(moments)
    m = sn_exponent
    es = (2.0 * math.sqrt(moments[0])) ** m * (
        d1 * q**m * math.gamma(1 + m) + 2 ** (m / 2) * math.gamma(1 + m / 2) * (d2 * abs(r) ** m + d3)
    )
    peaks = math.sqrt(moments[4] / moments[2])
    return peaks * es / 2.0**m / (sn_cycles * sn_stress**m)
