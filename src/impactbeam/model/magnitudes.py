"""Orders of magnitude of a model: its frequency scale, how far its loads can drive it, its run's work.

These are bounds, not results: cheap estimates from the inputs alone (no
modes), used to refuse before any work an input whose response would
overflow double precision or whose run would take out of proportion to what
it asks (:mod:`impactbeam.scenario.checks`).

Response bound. A mode ``eta'' + 2 a eta' + omega^2 eta = f(t)`` with
``|f| <= F`` and ``a >= 0`` has ``|eta(t)| <= F min(t / omega, t^2 / 2)``
(the impulse response is bounded by ``1 / omega`` and by ``t``). A load of
acceleration scale ``F`` (a base acceleration, or a force over the beam's
mass) over ``end_time`` ``T`` therefore moves the beam by about
``F min(T / omega_0, T^2 / 2)``, with ``omega_0 = sqrt(E I / rho A) / L^2``
the beam's frequency scale (its first natural frequency is 3.5 omega_0
cantilevered, 22 omega_0 clamped at both ends). Initial modal coordinates
``eta`` [m kg^0.5] give ``|w| ~ 2 eta / sqrt(m)`` (a mass-normalised shape
is of order ``1 / sqrt(m)``), modal velocities that times ``min(T, 1 / omega_0)``.
A half-sine pulse of duration ``D`` moves the beam at most as its impulse
does, ``F (2 D / pi) min(T, 1 / omega_0)``.

Why 1e100 m. The solver squares deflections and multiplies them by
stiffnesses and squared frequencies (energies ``k w^2``, bounds
``omega^2 eta``): measured on the paper's Case 3, a half-sine of 1e155 m/s^2
(response 7e149 m) still runs and scales exactly linearly, 1e160 m/s^2 never
ends (the event scan meets infinities). :data:`RESPONSE_LIMIT` keeps a
margin of 1e50 below that for stiffer contactors and higher modes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .beam import Beam
from .loading import Excitation
from .starting import InitialCondition

__all__ = ["RESPONSE_FLOOR", "RESPONSE_LIMIT", "frequency_scale", "response_estimates", "scan_work"]

#: Largest deflection [m] a model may be driven to (see the module notes).
RESPONSE_LIMIT = 1e100
#: Smallest deflection [m] a load may drive the beam to: below it the closed form's terms (a
#: response times squared frequency ratios) underflow and the response comes out as zero (measured:
#: a half-sine of 1e-300 s on Case 3, an impulse response of 1.5e-301 m, gave exactly 0).
RESPONSE_FLOOR = 1e-250


def frequency_scale(beam: Beam) -> float:
    """``omega_0 = sqrt(E I / rho A) / L^2`` [rad/s] of the ``[beam]`` section.

    Parameters
    ----------
    beam : Beam
    """
    return math.sqrt(beam.bending_stiffness / beam.mass_per_length) / beam.length**2


def _largest(values: Sequence[float] | np.ndarray | None) -> float:
    if values is None or len(values) == 0:
        return 0.0
    return float(np.max(np.abs(np.asarray(values, dtype=float))))


def response_estimates(beam: Beam, excitation: Excitation, initial: InitialCondition,
                       end_time: float) -> list[tuple[str, float]]:
    """The deflection [m] each input could drive the beam to within ``end_time``, by scenario key.

    Parameters
    ----------
    beam : Beam
    excitation : Excitation
    initial : InitialCondition
    end_time : float, [s]

    Returns
    -------
    list of (str, float)
        ``(key, metres)`` for the excitation (``excitation.amplitude``,
        ``excitation.file`` for a table, ``excitation.scale`` when the scale
        dominates) and each initial condition given; see the module notes.
    """
    omega0 = frequency_scale(beam)
    mass = beam.total_mass
    T = float(end_time)
    reach = min(T / omega0, 0.5 * T * T)  # metres per (m/s^2) of a load over T
    out: list[tuple[str, float]] = []
    if excitation.active:
        sampled = excitation.shape in ("table", "random")  # a random load's samples are drawn when it is made
        peak = _largest(excitation.values) if sampled else abs(excitation.amplitude)
        per_mass = {"base_acceleration": 1.0, "point_force": 1.0 / mass,
                    "distributed_force": beam.length / mass}[excitation.kind]
        key = {"table": "excitation.file", "random": "excitation.psd"}.get(excitation.shape, "excitation.amplitude")
        if abs(excitation.scale) > 1.0 and (peak == 0.0 or abs(excitation.scale) > peak):
            key = "excitation.scale"
        span = reach
        if excitation.shape == "half_sine" and excitation.duration is not None:  # at most its impulse's response
            span = min(reach, 2.0 * excitation.duration / math.pi * min(T, 1.0 / omega0))
        out.append((key, peak * abs(excitation.scale) * per_mass * span))
    if initial.tip_displacement is not None:
        out.append(("initial.tip_displacement", abs(initial.tip_displacement)))
    shape = 2.0 / math.sqrt(mass)  # order of a mass-normalised shape [kg^-0.5]
    if initial.modal_displacement is not None:
        out.append(("initial.modal_displacement", _largest(initial.modal_displacement) * shape))
    if initial.modal_velocity is not None:
        out.append(("initial.modal_velocity", _largest(initial.modal_velocity) * shape * min(T, 1.0 / omega0)))
    return out


def scan_work(beam: Beam, modes: int, end_time: float) -> float:
    """Mode-periods a run scans: ``modes x end_time x omega_0 / 2 pi`` (the work of its exact extrema).

    The metrics' extrema (branch and bound on the closed form) cost in
    proportion to the simulated time and the number of modes, also after the
    response has decayed: measured on Case 3 (4 to 32 modes, 2000 s, three
    beam heights) 0.9 to 2.9 us per unit of this product on one core, and
    4 us undamped with impacts.

    Parameters
    ----------
    beam : Beam
    modes : int
        Modes per state.
    end_time : float, [s]
    """
    return float(modes) * float(end_time) * frequency_scale(beam) / (2.0 * math.pi)
