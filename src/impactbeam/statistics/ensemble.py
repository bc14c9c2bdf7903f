"""Ensemble statistics: estimates and confidence intervals from independent runs (batch means).

Each seed of an ensemble is one independent record of the same stationary
process, so its time averages are independent, identically distributed
estimates (batch means, each batch a whole record). The ensemble estimate
is their mean ``m`` and its two-sided interval of confidence ``1 - a`` is
``m +- t_{n-1}(1 - a/2) s / sqrt(n)`` with the sample standard deviation
``s`` of the ``n`` per-seed values and Student's ``t`` with ``n - 1``
degrees of freedom: exact for normal batch means, and close for long
records by the central limit theorem. With one seed there is no interval
(NaN).

An RMS is estimated through its mean square: the interval of the mean
square is carried through the square root (a monotone map keeps the
probability). A ratio of totals (mean peak force = total of the peaks over
the number of impacts) is pooled over the seeds.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["batch_mean", "rms_from_mean_squares"]


def batch_mean(values: np.ndarray, confidence: float = 0.95) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean over the first axis and its Student-t interval (module docstring).

    Parameters
    ----------
    values : array_like, (n_seeds, ...)
        One estimate per seed.
    confidence : float
        ``1 - a``.

    Returns
    -------
    mean, lower, upper : ndarray
        Over the remaining axes; the bounds are NaN with fewer than two seeds.
    """
    from scipy import stats

    v = np.asarray(values, dtype=float)
    n = v.shape[0]
    mean = np.mean(v, axis=0)
    if n < 2:
        nan = np.full(mean.shape, math.nan)
        return mean, nan, nan.copy()
    half = stats.t.ppf(0.5 + confidence / 2, n - 1) * np.std(v, axis=0, ddof=1) / math.sqrt(n)
    return mean, mean - half, mean + half


def rms_from_mean_squares(mean_squares: np.ndarray, confidence: float = 0.95) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """RMS and its interval from per-seed mean squares (module docstring).

    Parameters
    ----------
    mean_squares : array_like, (n_seeds, ...)
    confidence : float

    Returns
    -------
    rms, lower, upper : ndarray
    """
    m, lo, hi = batch_mean(mean_squares, confidence)
    return np.sqrt(m), np.sqrt(np.maximum(lo, 0.0)), np.sqrt(hi)
