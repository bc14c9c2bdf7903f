"""Excitations: the load histories and their spatial distributions (paper section 2, eqs. 8-10).

An :class:`Excitation` is a load history ``f(x, t) = p(x) u(t)``: a spatial
distribution ``p`` (uniform over the beam, or a point at ``position``) times a
time history ``u(t)``. Base acceleration ``ug''(t)`` is the distributed load
``-rho A ug''(t)``. The time history is one of

* ``half_sine``: ``A sin(pi (t - start)/duration)`` for ``start <= t <= start + duration``;
* ``step``: ``A`` for ``t >= start``;
* ``harmonic``: ``A sin(2 pi f (t - start) + phase)`` for ``t >= start``;
* ``table``: samples ``(t_k, u_k)`` held constant (the paper's rectangular steps)
  or linear between samples (first-order hold), shifted by ``start``; zero outside;
* ``random``: a stationary Gaussian history of one-sided power spectral
  density ``psd`` (:mod:`impactbeam.model.psd`), synthesised from ``seed``
  over ``duration`` and held linearly between its samples, from ``start``.

Every shape is integrated in closed form by the solver: the half-sine and the
harmonic load exactly (also at an undamped resonance), the table exactly for
the hold chosen. A half-sine shorter than 3e-70 s is integrated as one of
that length with the same impulse (:data:`PULSE_OMEGA_LIMIT`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .._validation import choice, finite, nonnegative_finite, positive_finite
from .._warnings import emit_user_level_warning
from ..exceptions import ParameterError
from .psd import MIN_LINES, PowerSpectralDensity, synthesize

__all__ = ["Excitation", "ExcitationKind", "ExcitationShape", "Hold"]

ExcitationKind = Literal["base_acceleration", "point_force", "distributed_force", "none"]
ExcitationShape = Literal["half_sine", "step", "table", "harmonic", "random"]
Hold = Literal["constant", "linear"]

UNITS = {"base_acceleration": "m/s^2", "point_force": "N", "distributed_force": "N/m", "none": ""}


@dataclass(frozen=True, eq=False)
class Excitation:
    """A load history acting on the beam.

    Parameters
    ----------
    kind : {"base_acceleration", "point_force", "distributed_force", "none"}
    shape : {"half_sine", "step", "table", "harmonic", "random"}
    amplitude : float
        Peak value: [m/s^2] for base acceleration, [N] point force, [N/m]
        distributed force. Positive along +w. For ``table`` the tabulated
        values are used as given and ``amplitude`` is ignored (also for ``random``).
    duration : float or None, [s]
        Pulse length (half_sine); length of the random history (random).
    start : float, [s]
        When the pulse, step, table or harmonic load begins.
    position : float or None, [m]
        Point of application (point_force only).
    times, values : ndarray or None
        The table (shape ``table``): strictly increasing times [s] (relative to
        ``start``) and values in the unit of ``kind``.
    hold : {"constant", "linear"}
        How a table is held between samples.
    scale : float
        Factor applied to the whole history (for fits and sweeps of "pulse scale").
    frequency : float or None, [Hz]
        Forcing frequency ``f`` (harmonic only).
    phase : float, [rad]
        Phase of the harmonic load at ``start`` (harmonic only); a phase
        outside [-2 pi, 2 pi] is reduced to (-pi, pi] (the same sinusoid).
    psd : PowerSpectralDensity or None
        One-sided density of the random load (random only).
    seed : int or None
        Root of the random stream (random only; ``numpy.random.SeedSequence(seed)``).
    stream : int or None
        Member of an ensemble: the stream ``SeedSequence(seed).spawn(n)[stream]`` (random only).
    sample_rate : float or None, [Hz]
        Load samples per second (random only); default
        :data:`~impactbeam.model.psd.RATE_FACTOR` times the density's highest frequency.
    seed_drawn : bool
        The seed was drawn because the scenario gave none (reported, so the run can be repeated).

    Notes
    -----
    A random load is synthesised when the object is made: ``times`` and
    ``values`` then hold its samples (relative to ``start``), held linearly.
    """

    kind: ExcitationKind = "none"
    shape: ExcitationShape = "half_sine"
    amplitude: float = 0.0
    duration: float | None = None
    start: float = 0.0
    position: float | None = None
    times: np.ndarray | None = field(default=None, repr=False)
    values: np.ndarray | None = field(default=None, repr=False)
    hold: Hold = "constant"
    scale: float = 1.0
    frequency: float | None = None
    phase: float = 0.0
    psd: PowerSpectralDensity | None = field(default=None, repr=False)
    seed: int | None = None
    stream: int | None = None
    sample_rate: float | None = None
    seed_drawn: bool = False

    def __post_init__(self) -> None:
        choice("excitation.kind", self.kind, tuple(UNITS))
        choice("excitation.shape", self.shape, ("half_sine", "step", "table", "harmonic", "random"))
        choice("excitation.hold", self.hold, ("constant", "linear"))
        object.__setattr__(self, "amplitude", finite("excitation.amplitude", self.amplitude))
        object.__setattr__(self, "start", nonnegative_finite("excitation.start", self.start))
        object.__setattr__(self, "scale", finite("excitation.scale", self.scale))
        object.__setattr__(self, "phase", _reduced_angle(finite("excitation.phase", self.phase)))
        if self.kind == "none":
            return
        if self.shape == "half_sine":
            if self.duration is None:
                raise ParameterError("excitation.duration: required for a half_sine pulse")
            object.__setattr__(self, "duration", positive_finite("excitation.duration", self.duration))
            spacing = math.ulp(max(self.start, 1e-300))  # the pulse ends at start + duration, a double
            if spacing > 1e-4 * self.duration:
                raise ParameterError(
                    f"excitation.duration: {self.duration:g} s is too short to be told apart from the spacing "
                    f"of times near excitation.start = {self.start:g} s ({spacing:.2g} s); "
                    + ("start the pulse at 0 s or give a longer one" if self.start > 0 else "give a longer one")
                )
        if self.shape == "harmonic":
            if self.frequency is None:
                raise ParameterError("excitation.frequency: required for a harmonic load")
            object.__setattr__(self, "frequency", positive_finite("excitation.frequency", self.frequency))
            if 2.0 * math.pi * self.frequency > PULSE_OMEGA_LIMIT:  # its closed form forms Omega^4
                raise ParameterError(
                    f"excitation.frequency: {self.frequency:g} Hz is above the {PULSE_OMEGA_LIMIT:.0e} rad/s at "
                    "which the closed form of a sinusoidal load overflows (Omega^4); check the value and its unit"
                )
        if self.kind == "point_force":
            if self.position is None:
                raise ParameterError("excitation.position: required for a point_force")
            object.__setattr__(self, "position", nonnegative_finite("excitation.position", self.position))
        if self.shape == "random":
            self._synthesize()
        if self.shape == "table":
            if self.times is None or self.values is None:
                raise ParameterError("excitation.file: a table excitation needs times and values")
            t = np.asarray(self.times, dtype=float)
            v = np.asarray(self.values, dtype=float)
            if t.ndim != 1 or t.shape != v.shape or t.size < 2:
                raise ParameterError("excitation.file: need at least two (time, value) rows")
            if not (np.all(np.isfinite(t)) and np.all(np.isfinite(v))):
                raise ParameterError("excitation.file: the table holds NaN or infinite values")
            if np.any(np.diff(t) <= 0.0):
                raise ParameterError("excitation.file: times must be strictly increasing")
            t.setflags(write=False)
            v.setflags(write=False)
            object.__setattr__(self, "times", t)
            object.__setattr__(self, "values", v)

    def _synthesize(self) -> None:
        """Draw the samples of a random load (:func:`impactbeam.model.psd.synthesize`)."""
        if not isinstance(self.psd, PowerSpectralDensity):
            raise ParameterError("excitation.psd: required for a random load (a PowerSpectralDensity)")
        for name in ("seed", "stream"):
            value = getattr(self, name)
            if value is None and name == "stream":
                continue
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
                raise ParameterError(f"excitation.{name}: expected an integer >= 0, got {value!r}")
        if self.duration is None:
            raise ParameterError("excitation.duration: required for a random load (the length of the history)")
        duration = positive_finite("excitation.duration", self.duration)
        times, values, lines = synthesize(self.psd, duration, int(self.seed), self.stream,  # type: ignore[arg-type]
                                          self.sample_rate)
        if lines < MIN_LINES:
            lo, hi = self.psd.band
            emit_user_level_warning(
                f"excitation.psd: a history of {duration:g} s has only {lines} spectral lines (spacing "
                f"{1 / duration:g} Hz) in the band {lo:g}-{hi:g} Hz; the load is far from Gaussian and its "
                f"spectrum coarse: simulate at least {MIN_LINES / (hi - lo):.3g} s"
            )
        object.__setattr__(self, "duration", duration)
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "values", values)
        object.__setattr__(self, "hold", "linear")

    @property
    def unit(self) -> str:
        """Unit of the time history values."""
        return UNITS[self.kind]

    @property
    def active(self) -> bool:
        """False when there is no load at all."""
        return self.kind != "none" and self.scale != 0.0

    def end_time(self) -> float:
        """Time after which the load is zero (inf for a step)."""
        if not self.active:
            return 0.0
        if self.shape == "half_sine":
            assert self.duration is not None
            return self.start + self.duration
        if self.shape in ("step", "harmonic"):
            return math.inf
        assert self.times is not None  # table and random
        return self.start + float(self.times[-1])

    def history(self, t: np.ndarray) -> np.ndarray:
        """The time history ``u(t)`` (including ``scale``) at times ``t``, vectorised.

        Parameters
        ----------
        t : ndarray, [s]
            Times (absolute, ``start`` included).
        """
        t = np.asarray(t, dtype=float)
        out = np.zeros_like(t)
        if not self.active:
            return out
        tau = t - self.start
        if self.shape == "half_sine":
            assert self.duration is not None
            inside = (tau >= 0.0) & (tau <= self.duration)
            out[inside] = self.amplitude * np.sin(np.pi * tau[inside] / self.duration)
        elif self.shape == "step":
            out[tau >= 0.0] = self.amplitude
        elif self.shape == "harmonic":
            assert self.frequency is not None
            on = tau >= 0.0
            out[on] = self.amplitude * np.sin(2.0 * np.pi * self.frequency * tau[on] + self.phase)
        else:
            assert self.times is not None and self.values is not None
            tk, vk = self.times, self.values
            inside = (tau >= tk[0]) & (tau <= tk[-1])
            if self.hold == "linear":
                out[inside] = np.interp(tau[inside], tk, vk)
            else:
                idx = np.clip(np.searchsorted(tk, tau[inside], side="right") - 1, 0, tk.size - 1)
                out[inside] = vk[idx]
        return self.scale * out


def _reduced_angle(phase: float) -> float:
    """``phase`` [rad] reduced to (-pi, pi] when it lies outside [-2 pi, 2 pi].

    ``sin(Omega tau + phase)`` with a phase of 1e20 rad would lose ``Omega tau``
    entirely in the sum (the spacing of doubles near 1e20 is 16384); the
    reduction goes through :func:`math.sin` and :func:`math.cos`, whose
    argument reduction is exact, so the load is the same sinusoid.
    """
    if abs(phase) <= 2.0 * math.pi:
        return phase
    return math.atan2(math.sin(phase), math.cos(phase))


#: Highest circular frequency [rad/s] at which a half-sine pulse is integrated. The closed form of a
#: sinusoidal load forms Omega^4 (its resonance denominator), finite up to ~1e77; a pulse shorter
#: than pi / PULSE_OMEGA_LIMIT (3e-70 s) is integrated as the half-sine of that duration with the
#: same impulse 2 A D / pi and start. Retained modes are at most ~1e57 rad/s (the scenario checks
#: the frequency scale), so they see the same impulse to 1e-13: the response is the impulse
#: response, which a half-sine of any D << 1 / omega tends to. Measured on Case 3: the exact
#: closed form matches the impulse response down to D = 1e-30 s; at 1e-300 s, before this rule,
#: Omega^2 overflowed and the run gave a 0.57 mm response.
PULSE_OMEGA_LIMIT = 1e70


@dataclass(frozen=True)
class TimePiece:
    """One piece of a time history: ``u(t) = const + slope (t - t0) + amp sin(Omega (t - t0) + phase)``."""

    t0: float
    t1: float
    const: float = 0.0
    slope: float = 0.0
    amp: float = 0.0
    Omega: float = 0.0
    phase: float = 0.0

    def value(self, t: float) -> float:
        tau = t - self.t0
        return self.const + self.slope * tau + self.amp * math.sin(self.Omega * tau + self.phase)


#: The fields of a time piece, in the order of the arrays of :func:`piece_arrays`.
PIECE_FIELDS = ("t0", "t1", "const", "slope", "amp", "Omega", "phase")


def piece_arrays(excitation: Excitation, end_time: float) -> tuple[np.ndarray, ...]:
    """The pieces of :func:`time_pieces` as seven arrays (``PIECE_FIELDS``), built without a Python loop.

    Parameters
    ----------
    excitation : Excitation
    end_time : float, [s]
        End of the run.

    Returns
    -------
    tuple of ndarray
        ``t0, t1, const, slope, amp, Omega, phase``, one entry per piece.
    """
    T = float(end_time)
    s = excitation.scale
    if not excitation.active:
        return tuple(np.array([v]) for v in (0.0, T, 0.0, 0.0, 0.0, 0.0, 0.0))
    start = excitation.start
    raw: list[TimePiece] = []
    if excitation.shape == "half_sine":
        assert excitation.duration is not None
        duration, amp = excitation.duration, s * excitation.amplitude
        if math.pi / duration > PULSE_OMEGA_LIMIT:  # the same impulse and start, at a frequency the closed form can square
            duration, amp = math.pi / PULSE_OMEGA_LIMIT, amp * duration * PULSE_OMEGA_LIMIT / math.pi
        raw.append(TimePiece(0.0, start))
        raw.append(TimePiece(start, start + duration, amp=amp, Omega=math.pi / duration))
        raw.append(TimePiece(start + duration, math.inf))
    elif excitation.shape == "step":
        raw.append(TimePiece(0.0, start))
        raw.append(TimePiece(start, math.inf, const=s * excitation.amplitude))
    elif excitation.shape == "harmonic":
        assert excitation.frequency is not None
        Om = 2.0 * math.pi * excitation.frequency
        raw.append(TimePiece(0.0, start))
        raw.append(
            TimePiece(start, math.inf, amp=s * excitation.amplitude, Omega=Om, phase=excitation.phase)
        )
    if raw:
        cols = [np.array([getattr(p, f) for p in raw], dtype=float) for f in PIECE_FIELDS]
    else:  # a table or a random load: samples held constant or linear
        assert excitation.times is not None and excitation.values is not None
        tk = excitation.times + start
        vk = s * excitation.values
        m = tk.size - 1
        slope = (vk[1:] - vk[:-1]) / (tk[1:] - tk[:-1]) if excitation.hold == "linear" else np.zeros(m)
        zero = np.zeros(m + 2)
        cols = [
            np.concatenate([[0.0], tk[:-1], [tk[-1]]]), np.concatenate([[tk[0]], tk[1:], [math.inf]]),
            np.concatenate([[0.0], vk[:-1], [0.0]]), np.concatenate([[0.0], slope, [0.0]]),
            zero, zero.copy(), zero.copy(),
        ]
    p_t0, p_t1, const, slope_, amp, Omega, phase = cols
    t0, t1 = np.maximum(p_t0, 0.0), np.minimum(p_t1, T)
    keep = t1 > t0
    shifted = t0 > p_t0  # shift the piece's origin to t0
    tau = np.where(shifted, t0 - p_t0, 0.0)
    const = np.where(shifted, const + slope_ * tau, const)
    phase = np.where(shifted, phase + Omega * tau, phase)
    return tuple(np.ascontiguousarray(a[keep]) for a in (t0, t1, const, slope_, amp, Omega, phase))


def time_pieces(excitation: Excitation, end_time: float) -> list[TimePiece]:
    """Cut the history of ``excitation`` on [0, end_time] into pieces of one closed form each.

    The solver integrates each piece exactly: the half-sine and the harmonic
    load as a sinusoid, a table held constant (paper, rectangular steps before eq. 10) or linear
    (first-order hold) between samples, a random load linear between its samples.
    The same pieces as arrays: :func:`piece_arrays`.
    """
    cols = piece_arrays(excitation, end_time)
    return [TimePiece(*row) for row in zip(*(c.tolist() for c in cols))]


def spatial_projection(
    excitation: Excitation,
    shapes_at,
    integral: np.ndarray,
    rho_a: float,
    inertia: np.ndarray | None = None,
) -> np.ndarray:
    """Modal weights ``p_n`` with ``<f(., t), W_n> = p_n u(t)`` (paper eq. 8).

    Parameters
    ----------
    shapes_at : callable
        ``shapes_at(x) -> (n, p)`` mode shapes of the state.
    integral : ndarray, (n,)
        ``int W_n dx`` of the state.
    rho_a : float
        Mass per length; base acceleration is the load ``-rho A ug''(t)``.
    inertia : ndarray, (n,), optional
        ``int rho A(x) W_n dx + sum_j m_j W_n(x_j)``
        (:meth:`~impactbeam.modal.ModeSet.inertia_integral`): the base
        acceleration weight of a stepped beam or one carrying point masses.
        When given it replaces ``rho_a * integral``; without it a beam with
        masses or sections would get a wrong load, so pass it always.
    """
    if excitation.kind == "base_acceleration":
        if inertia is not None:
            return -np.asarray(inertia, dtype=float)
        return -rho_a * integral
    if excitation.kind == "distributed_force":
        return integral.copy()
    if excitation.kind == "point_force":
        return shapes_at([excitation.position])[:, 0]
    return np.zeros_like(integral)
