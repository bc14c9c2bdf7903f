"""Excitations and initial conditions (paper section 2, eqs. 8-10).

An :class:`Excitation` is a load history ``f(x, t) = p(x) u(t)``: a spatial
distribution ``p`` (uniform over the beam, or a point at ``position``) times a
time history ``u(t)``. Base acceleration ``ug''(t)`` is the distributed load
``-rho A ug''(t)``. The time history is one of

* ``half_sine``: ``A sin(pi (t - start)/duration)`` for ``start <= t <= start + duration``;
* ``step``: ``A`` for ``t >= start``;
* ``harmonic``: ``A sin(2 pi f (t - start) + phase)`` for ``t >= start``;
* ``table``: samples ``(t_k, u_k)`` held constant (the paper's rectangular steps)
  or linear between samples (first-order hold), shifted by ``start``; zero outside.

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
from ..exceptions import ParameterError

__all__ = ["Excitation", "InitialCondition", "ExcitationKind", "ExcitationShape", "Hold"]

ExcitationKind = Literal["base_acceleration", "point_force", "distributed_force", "none"]
ExcitationShape = Literal["half_sine", "step", "table", "harmonic"]
Hold = Literal["constant", "linear"]

UNITS = {"base_acceleration": "m/s^2", "point_force": "N", "distributed_force": "N/m", "none": ""}


@dataclass(frozen=True, eq=False)
class Excitation:
    """A load history acting on the beam.

    Parameters
    ----------
    kind : {"base_acceleration", "point_force", "distributed_force", "none"}
    shape : {"half_sine", "step", "table", "harmonic"}
    amplitude : float
        Peak value: [m/s^2] for base acceleration, [N] point force, [N/m]
        distributed force. Positive along +w. For ``table`` the tabulated
        values are used as given and ``amplitude`` is ignored.
    duration : float or None, [s]
        Pulse length (half_sine only).
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

    def __post_init__(self) -> None:
        choice("excitation.kind", self.kind, tuple(UNITS))
        choice("excitation.shape", self.shape, ("half_sine", "step", "table", "harmonic"))
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
        if self.kind == "point_force":
            if self.position is None:
                raise ParameterError("excitation.position: required for a point_force")
            object.__setattr__(self, "position", nonnegative_finite("excitation.position", self.position))
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
        assert self.times is not None
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


@dataclass(frozen=True, eq=False)
class InitialCondition:
    """Initial state of the beam (at rest unless given).

    Parameters
    ----------
    tip_displacement : float or None, [m]
        Release from the static shape of a point load at ``position`` (default
        the right end) that gives this deflection there (paper Case 0/13).
    position : float or None, [m]
        Where ``tip_displacement`` is imposed; default: the beam's right end.
    modal_displacement, modal_velocity : sequence of float or None
        Free-state modal coordinates ``eta_n(0)`` [m kg^0.5] and their rates.
    """

    tip_displacement: float | None = None
    position: float | None = None
    modal_displacement: tuple[float, ...] | None = None
    modal_velocity: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        if self.tip_displacement is not None:
            object.__setattr__(
                self, "tip_displacement", finite("initial.tip_displacement", self.tip_displacement)
            )
        if self.position is not None:
            object.__setattr__(self, "position", nonnegative_finite("initial.position", self.position))
        for name in ("modal_displacement", "modal_velocity"):
            val = getattr(self, name)
            if val is not None:
                object.__setattr__(
                    self, name, tuple(finite(f"initial.{name}[{i}]", v) for i, v in enumerate(val))
                )

    @property
    def at_rest(self) -> bool:
        """True when the beam starts undeformed and still."""
        return (
            self.tip_displacement in (None, 0.0)
            and not any(self.modal_displacement or ())
            and not any(self.modal_velocity or ())
        )


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


def time_pieces(excitation: Excitation, end_time: float) -> list[TimePiece]:
    """Cut the history of ``excitation`` on [0, end_time] into pieces of one closed form each.

    The solver integrates each piece exactly: the half-sine and the harmonic
    load as a sinusoid, a table held constant (paper, rectangular steps before eq. 10) or linear
    (first-order hold) between samples.
    """
    T = float(end_time)
    s = excitation.scale
    if not excitation.active:
        return [TimePiece(0.0, T)]
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
    else:
        assert excitation.times is not None and excitation.values is not None
        tk = excitation.times + start
        vk = s * excitation.values
        raw.append(TimePiece(0.0, float(tk[0])))
        for i in range(tk.size - 1):
            t0, t1 = float(tk[i]), float(tk[i + 1])
            if excitation.hold == "linear":
                slope = (vk[i + 1] - vk[i]) / (t1 - t0)
                raw.append(TimePiece(t0, t1, const=float(vk[i]), slope=float(slope)))
            else:
                raw.append(TimePiece(t0, t1, const=float(vk[i])))
        raw.append(TimePiece(float(tk[-1]), math.inf))
    out = []
    for p in raw:
        t0, t1 = max(p.t0, 0.0), min(p.t1, T)
        if t1 <= t0:
            continue
        if t0 > p.t0:  # shift the piece's origin to t0
            tau = t0 - p.t0
            p = TimePiece(p.t0, p.t1, p.const + p.slope * tau, p.slope, p.amp, p.Omega, p.phase + p.Omega * tau)
        out.append(TimePiece(t0, t1, p.const, p.slope, p.amp, p.Omega, p.phase))
    return out


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
