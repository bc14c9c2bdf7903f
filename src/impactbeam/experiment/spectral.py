"""Natural frequencies of a free decay from its spectrum (paper section 4.1): Hann window, zero padding, interpolated peaks."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
import numpy as np

from ..exceptions import ParameterError
from .records import Record, _require_uniform

__all__ = ["FrequencyEstimate", "identify_frequencies"]


@dataclass(frozen=True, eq=False)
class FrequencyEstimate:
    """Natural frequencies identified from a record's spectrum.

    Attributes
    ----------
    frequencies_hz : ndarray, (n,), [Hz]
        Interpolated spectral peaks, ascending (damped frequencies
        ``f_d = f_n sqrt(1 - xi^2)``; for xi = 1.1 % they differ from the
        natural ones by 6e-5 relative).
    amplitudes : ndarray, (n,)
        Peak magnitudes of the windowed spectrum (relative units).
    resolution_hz : float
        Frequency resolution of the record, ``fs / N`` [Hz].
    bin_hz : float
        Bin width of the zero-padded spectrum [Hz].
    frequency, spectrum : ndarray
        The one-sided Hann-windowed, zero-padded magnitude spectrum (for plots).
    """

    frequencies_hz: np.ndarray
    amplitudes: np.ndarray
    resolution_hz: float
    bin_hz: float
    frequency: np.ndarray = field(repr=False)
    spectrum: np.ndarray = field(repr=False)


def _spectrum(x: np.ndarray, dt: float, pad: int) -> tuple[np.ndarray, np.ndarray]:
    from scipy.signal import detrend
    from scipy.signal.windows import hann

    n = x.size
    y = detrend(x, type="linear") * hann(n, sym=False)
    nfft = 1 << int(math.ceil(math.log2(max(pad, 1) * n)))
    mag = np.abs(np.fft.rfft(y, nfft))
    return np.fft.rfftfreq(nfft, dt), mag


def _interpolate_peak(freq: np.ndarray, mag: np.ndarray, k: int) -> tuple[float, float]:
    """Quadratic interpolation of the log magnitude through bins k-1, k, k+1."""
    a, b, c = np.log(mag[k - 1 : k + 2] + 1e-300)
    den = a - 2 * b + c
    delta = 0.5 * (a - c) / den if den < 0 else 0.0
    delta = float(np.clip(delta, -0.5, 0.5))
    df = freq[1] - freq[0]
    return float(freq[k] + delta * df), float(np.exp(b - 0.25 * (a - c) * delta))


def identify_frequencies(
    record: Record,
    n: int = 2,
    *,
    fmin: float | None = None,
    fmax: float | None = None,
    pad: int = 16,
    min_snr_db: float = 12.0,
) -> FrequencyEstimate:
    """Natural frequencies from the spectrum of a free-decay record (paper sections 3, 4.1).

    Parameters
    ----------
    record : Record
        Uniformly sampled (see :func:`load_record`), e.g. a release test.
    n : int
        Number of modes: the ``n`` most significant spectral peaks, sorted by frequency.
    fmin, fmax : float, optional, [Hz]
        Search band; default: above the Hann main lobe of DC (``2 fs/N``) and
        below 0.98 x Nyquist.
    pad : int
        Zero-padding factor (the FFT length is the next power of two of ``pad * N``).
    min_snr_db : float
        A peak must stand this far above the local noise floor (running
        median of the spectrum over 16 resolution bins).

    Returns
    -------
    FrequencyEstimate
        ``spectrum`` is that of the whole record.

    Notes
    -----
    Each spectrum is taken after removing a linear trend, with a Hann
    window and zero padding; every local maximum with at least 6 dB of
    prominence and ``min_snr_db`` above the local floor is a candidate, and
    is refined by a parabola through the log magnitude of its bin and the two
    neighbours (for the Hann lobe of zero-padded data the bias is far below
    a padded bin, so the error is set by the noise, not by the resolution
    ``fs/N``). In a free decay the higher modes die out early, where the
    Hann window of the whole record is small, so the spectra of the first
    1/2, 1/4 and 1/8 of the record (down to 64 samples) are searched too; a
    mode is reported from the longest of them in which it is significant
    (the best resolution). Peaks closer than 5 resolution bins to a more
    significant one (window side lobes, noise on a mode's skirt) are dropped;
    the ``n`` most significant remaining peaks are returned.

    Raises
    ------
    ParameterError
        For a non-uniform record, ``n < 1``, or when fewer than ``n`` peaks are
        found (the message says how many were).
    """
    from scipy.ndimage import median_filter
    from scipy.signal import find_peaks

    _require_uniform(record, "frequency identification")
    if isinstance(n, bool) or int(n) != n or n < 1:
        raise ParameterError(f"n: the number of frequencies must be a positive integer, got {n!r}")
    dt = record.step
    N = record.time.size
    hi = min(fmax if fmax is not None else math.inf, 0.98 * 0.5 / dt)
    candidates: list[tuple[float, float, float, float]] = []  # (snr, f, amplitude, resolution)
    full: tuple[np.ndarray, np.ndarray] | None = None
    length = N
    while True:
        freq, mag = _spectrum(record.values[:length], dt, pad)
        if full is None:
            full = (freq, mag)
        res = 1.0 / (length * dt)
        lo = max(fmin if fmin is not None else 0.0, 2.0 * res)
        band = (freq >= lo) & (freq <= hi)
        if band.sum() > 3:
            db = 20 * np.log10(mag + 1e-300)
            bin_ratio = res / (freq[1] - freq[0])
            floor = median_filter(db, size=max(3, int(16 * bin_ratio)) | 1, mode="nearest")
            peaks, _ = find_peaks(db, prominence=6.0)
            for k in peaks:
                if band[k] and 0 < k < db.size - 1 and db[k] - floor[k] >= min_snr_db:
                    f, amp = _interpolate_peak(freq, mag, int(k))
                    candidates.append((float(db[k] - floor[k]), f, amp, res))
        length //= 2
        if length < 64:
            break
    # longest record first (candidates are in that order), then by significance
    accepted: list[tuple[float, float, float, float]] = []
    for cand in sorted(candidates, key=lambda c: (c[3], -c[0])):
        snr, f, amp, res = cand
        if any(abs(f - g[1]) < 5.0 * max(res, g[3]) for g in accepted):
            continue
        accepted.append(cand)
    # drop what sits near a more significant peak of another resolution
    final: list[tuple[float, float, float, float]] = []
    for cand in sorted(accepted, key=lambda c: -c[0]):
        if any(abs(cand[1] - g[1]) < 5.0 * max(cand[3], g[3]) for g in final):
            continue
        final.append(cand)
    if len(final) < n:
        raise ParameterError(
            f"{record.label}: found {len(final)} significant spectral peak{'s' if len(final) != 1 else ''}, "
            f"{n} requested (record too short or too noisy, or the mode not excited?)"
        )
    top = sorted(final[:n], key=lambda c: c[1])
    assert full is not None
    return FrequencyEstimate(
        frequencies_hz=np.array([c[1] for c in top]),
        amplitudes=np.array([c[2] for c in top]),
        resolution_hz=1.0 / (N * dt),
        bin_hz=float(full[0][1] - full[0][0]),
        frequency=full[0],
        spectrum=full[1],
    )
