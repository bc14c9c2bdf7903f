"""One-sided power spectral densities and the stationary Gaussian histories synthesised from them.

Convention (one-sided, in hertz): a stationary, zero-mean load ``u(t)`` has
the power spectral density ``G(f)`` defined for ``f >= 0`` with

.. math:: \\sigma_u^2 = \\int_0^\\infty G(f)\\,df ,

so a flat ``G = 0.01 g^2/Hz`` from 10 to 1000 Hz has ``sigma = sqrt(9.9) g``.
A table ``[[f_1, G_1], ..., [f_n, G_n]]`` is interpolated linearly in
``log f - log G`` (straight lines on a log-log plot, i.e. constant dB per
octave), and ``G = 0`` outside ``[f_1, f_n]``. A segment with a zero level at
one end is zero inside (the limit of the log-log line as that level tends to
zero).

Synthesis (spectral representation, random phases; Shinozuka & Deodatis
1991): a history of length ``T`` is the sum over the lines ``f_k = k / T``
(``k >= 1``: zero mean) of ``a_k cos(2 pi f_k t + phi_k)`` with
``a_k = sqrt(2 G(f_k) / T)`` and independent phases ``phi_k`` uniform on
``[0, 2 pi)``, evaluated by one inverse FFT. Its mean square is
``sum_k G(f_k) / T``, the Riemann sum of ``int G df``, exactly, in every
record; it is stationary and its distribution tends to the Gaussian as the
number of lines in the band grows (central limit theorem; the kurtosis of
``K`` equal lines is ``3 - 3 / (2 K)``). The phases come from
:class:`numpy.random.Generator` (PCG64) seeded by
``numpy.random.SeedSequence(seed)``, or by its child ``stream`` (the
``stream``-th of ``SeedSequence(seed).spawn(n)``) for the members of an
ensemble, so every record can be repeated bit for bit.

The solver holds the samples linearly between sample times (first-order
hold, integrated exactly). Linear interpolation of samples taken every
``h = 1 / f_s`` multiplies the spectrum by ``sinc^2(f h)`` and adds images
near ``f_s, 2 f_s, ...``; the line amplitudes are divided by ``sinc^2(f_k h)``
so that the held history has the target density in the band exactly, and the
images carry ``(x / (1 - x))^4`` of the density at ``x = f / f_s`` (at the
default ``f_s = RATE_FACTOR f_max`` at most ``(1/7)^4 = 4e-4`` of it, above
``7 f_max``). See :data:`RATE_FACTOR` for the evidence behind the default rate.

References
----------
M. Shinozuka and G. Deodatis, "Simulation of stochastic processes by spectral
representation", Applied Mechanics Reviews 44(4), 191-204 (1991).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._validation import positive_finite
from ..exceptions import ParameterError

__all__ = ["PowerSpectralDensity", "synthesize", "sample_rate", "RATE_FACTOR", "MIN_LINES"]

#: Default load sample rate over the highest frequency of the density (``f_s = RATE_FACTOR f_max``).
#: Chosen on evidence (benchmarks/bench_random.py --rates, docs/random-vibration.md): one 10 s record on
#: Case 3's beam with its stop under 10-1000 Hz, the same lines and phases sampled at 4, 8, 16 and 32 f_max
#: (a deterministic comparison). Against 32 f_max, at 8 f_max the RMS deflection, velocity and root stress,
#: the impact rate and the force RMS change by less than 0.01 %; at 4 f_max by up to 0.04 % (RMS values)
#: and under 1 % (impact rate: 2-3 of ~450 impacts; force RMS), while the hold's images grow from 4e-4 to
#: 1.2 % of the density. 8 keeps the sampling's share far below a record's statistical error on beams whose
#: modes sit near the images; ``excitation.sample_rate`` can halve the cost where that is shown not to matter.
RATE_FACTOR = 8.0
#: Fewer lines than this in the band of the density: the record is too short to be Gaussian (warning).
MIN_LINES = 32


@dataclass(frozen=True, eq=False)
class PowerSpectralDensity:
    """A one-sided power spectral density given by points, log-log between them (module docstring).

    Parameters
    ----------
    frequencies : array_like, (n,), [Hz]
        Strictly increasing, positive.
    levels : array_like, (n,), [unit^2/Hz]
        Non-negative (the unit is that of the load: (m/s^2)^2/Hz for a base
        acceleration, N^2/Hz for a point force, (N/m)^2/Hz for a distributed force).
    name : str
        The dotted key named in errors (``"excitation.psd"``).

    Raises
    ------
    ParameterError
        Fewer than two points, a non-positive or non-increasing frequency, a
        negative or non-finite level, or no positive level; the message names
        the entry (``excitation.psd.2.0``).
    """

    frequencies: np.ndarray
    levels: np.ndarray
    name: str = field(default="excitation.psd", repr=False)

    def __post_init__(self) -> None:
        f = np.array(self.frequencies, dtype=float).reshape(-1)
        g = np.array(self.levels, dtype=float).reshape(-1)
        key = self.name
        if f.size != g.size or f.size < 2:
            raise ParameterError(f"{key}: need at least two [frequency, level] points, got {min(f.size, g.size)}")
        for i, (fi, gi) in enumerate(zip(f, g)):
            positive_finite(f"{key}.{i}.0", fi)
            if not (math.isfinite(gi) and gi >= 0.0):
                raise ParameterError(f"{key}.{i}.1: the level must be zero or positive and finite, got {float(gi):g}")
            if i and fi <= f[i - 1]:
                raise ParameterError(
                    f"{key}.{i}.0: frequencies must increase strictly, got {fi:g} Hz after {f[i - 1]:g} Hz"
                )
        if not np.any((g[:-1] > 0.0) & (g[1:] > 0.0)):
            raise ParameterError(f"{key}: no two neighbouring points with positive levels (the density is zero)")
        f.setflags(write=False)
        g.setflags(write=False)
        object.__setattr__(self, "frequencies", f)
        object.__setattr__(self, "levels", g)

    @property
    def band(self) -> tuple[float, float]:
        """Lowest and highest frequency [Hz] where the density is not zero."""
        f, g = self.frequencies, self.levels
        live = np.flatnonzero((g[:-1] > 0.0) & (g[1:] > 0.0))  # segments with a positive density
        return float(f[live[0]]), float(f[live[-1] + 1])

    def __call__(self, frequency: np.ndarray | float) -> np.ndarray:
        """``G(f)`` by log-log interpolation, zero outside the table.

        Parameters
        ----------
        frequency : float or array_like, [Hz]

        Returns
        -------
        ndarray
            The density at each frequency [unit^2/Hz].
        """
        x = np.atleast_1d(np.asarray(frequency, dtype=float))
        f, g = self.frequencies, self.levels
        out = np.zeros_like(x)
        inside = (x >= f[0]) & (x <= f[-1])
        xi = x[inside]
        j = np.clip(np.searchsorted(f, xi, side="right") - 1, 0, f.size - 2)
        g0, g1 = g[j], g[j + 1]
        live = (g0 > 0.0) & (g1 > 0.0)
        val = np.zeros_like(xi)
        with np.errstate(divide="ignore", invalid="ignore"):
            slope = np.log(g1[live] / g0[live]) / np.log(f[j + 1][live] / f[j][live])
            val[live] = g0[live] * (xi[live] / f[j][live]) ** slope
        # a table point itself keeps its level, also next to a zero
        exact = np.searchsorted(f, xi)
        hit = (exact < f.size) & (f[np.minimum(exact, f.size - 1)] == xi)
        val[hit] = g[exact[hit]]
        out[inside] = val
        return out

    def variance(self) -> float:
        """``int G df`` over the table, exact for the log-log segments [unit^2].

        On a segment ``G = G_0 (f / f_0)^b`` the integral is
        ``G_0 f_0 ((f_1/f_0)^(b+1) - 1) / (b + 1)`` (``G_0 f_0 ln(f_1/f_0)`` for ``b = -1``).

        Returns
        -------
        float
        """
        f, g = self.frequencies, self.levels
        total = 0.0
        for f0, f1, g0, g1 in zip(f[:-1], f[1:], g[:-1], g[1:]):
            if g0 <= 0.0 or g1 <= 0.0:
                continue
            r = f1 / f0
            b = math.log(g1 / g0) / math.log(r)
            if abs(b + 1.0) < 1e-12:
                total += g0 * f0 * math.log(r)
            else:
                total += g0 * f0 * (r ** (b + 1.0) - 1.0) / (b + 1.0)
        return total

    def rms(self) -> float:
        """``sqrt(int G df)`` [unit]."""
        return math.sqrt(self.variance())


def sample_rate(psd: PowerSpectralDensity, requested: float | None = None) -> float:
    """The load sample rate [Hz]: ``requested``, else ``RATE_FACTOR`` times the density's upper frequency.

    Parameters
    ----------
    psd : PowerSpectralDensity
    requested : float, optional, [Hz]
        A rate given by the user (``excitation.sample_rate``); it must exceed
        twice the upper frequency (Nyquist).

    Returns
    -------
    float

    Raises
    ------
    ParameterError
        A requested rate at or below twice the upper frequency.
    """
    f_max = psd.band[1]
    if requested is None:
        return RATE_FACTOR * f_max
    rate = positive_finite("excitation.sample_rate", requested)
    if rate <= 2.0 * f_max:
        raise ParameterError(
            f"excitation.sample_rate: {rate:g} Hz must exceed twice the highest frequency of the density "
            f"({2 * f_max:g} Hz); the default is {RATE_FACTOR:g} times it ({RATE_FACTOR * f_max:g} Hz)"
        )
    return rate


#: Peak bytes per load sample of :func:`synthesize` and the run that holds it: the half spectrum and
#: its transform, the samples, their times, the load pieces made of them.
SAMPLE_BYTES = 64


def synthesize(
    psd: PowerSpectralDensity,
    duration: float,
    seed: int,
    stream: int | None = None,
    rate: float | None = None,
) -> tuple[np.ndarray, np.ndarray, int]:
    """Samples of a stationary Gaussian history with density ``psd`` (module docstring).

    Parameters
    ----------
    psd : PowerSpectralDensity
    duration : float, [s]
        Length ``T`` of the record; the lines are ``k / T``.
    seed : int
        Root of the random stream (``numpy.random.SeedSequence(seed)``).
    stream : int, optional
        Member of an ensemble: the child ``SeedSequence(seed, spawn_key=(stream,))``,
        which is ``SeedSequence(seed).spawn(n)[stream]``.
    rate : float, optional, [Hz]
        Sample rate; default :func:`sample_rate`.

    Returns
    -------
    times : ndarray, (N + 1,), [s]
        ``0, T/N, ..., T``.
    values : ndarray, (N + 1,)
        The samples, pre-compensated for the linear hold; ``values[N] = values[0]``
        (the record is periodic).
    lines : int
        Spectral lines with a positive level.
    """
    T = positive_finite("excitation.duration", duration)
    fs = sample_rate(psd, rate)
    from .._memory import check_memory

    check_memory(T * fs * SAMPLE_BYTES, f"excitation.sample_rate: {fs:g} Hz over a history of {T:g} s (from "
                 f"excitation.start to solver.end_time; {T * fs:.3g} load samples)",
                 "ask for a lower sample rate or a shorter history (solver.end_time)")
    n = max(int(math.ceil(T * fs)), 4)
    n += n % 2
    f_lo, f_hi = psd.band
    k_max = int(math.floor(f_hi * T))
    if k_max >= n // 2:  # pragma: no cover - sample_rate guarantees fs > 2 f_max
        raise ParameterError("excitation.sample_rate: too low for the density")
    seq = np.random.SeedSequence(int(seed), spawn_key=() if stream is None else (int(stream),))
    phases = 2.0 * np.pi * np.random.Generator(np.random.PCG64(seq)).random(k_max)
    fk = np.arange(1, k_max + 1) / T
    amp = np.sqrt(2.0 * psd(fk) / T)
    h = T / n
    amp /= np.sinc(fk * h) ** 2  # np.sinc(x) = sin(pi x) / (pi x): the hold's response
    spectrum = np.zeros(n // 2 + 1, dtype=complex)
    spectrum[1 : k_max + 1] = 0.5 * n * amp * np.exp(1j * phases)
    x = np.fft.irfft(spectrum, n)
    values = np.concatenate([x, x[:1]])
    times = np.arange(n + 1) * h
    return times, values, int(np.count_nonzero(amp))
