"""The state at t = 0 and the constant preload (``[initial]``, ``[preload]``).

An :class:`InitialCondition` says where the beam starts: a static tip
deflection (paper Case 0), fields of displacement and velocity along the beam
(:class:`Profile` tables, a uniform translation, a rigid rotation about a
pivot), modal coordinates, or the static equilibrium under the
:class:`Preload`, a constant load acting during the whole run. The solver
projects every field on the run's modes
(:func:`impactbeam.solver.initial.initial_coordinates`).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Literal

import numpy as np

from .._validation import choice, finite, nonnegative_finite
from ..exceptions import ParameterError
from .loading import Excitation

__all__ = ["InitialCondition", "Preload", "Profile"]


@dataclass(frozen=True, eq=False)
class Profile:
    """A field along the beam given at rows ``(x_k, v_k)``, linear between rows.

    Parameters
    ----------
    positions : ndarray, (n,), [m]
        Strictly increasing positions, ``n >= 2``; they must span the beam
        (:meth:`check_on`).
    values : ndarray, (n,)
        The field at ``positions`` (SI: [m] for a displacement, [m/s] for a velocity).
    name : str
        The scenario key the profile came from, for messages.
    """

    positions: np.ndarray
    values: np.ndarray
    name: str = "initial.displacement"

    def __post_init__(self) -> None:
        x = np.array(self.positions, dtype=float)
        v = np.array(self.values, dtype=float)
        if x.ndim != 1 or x.shape != v.shape or x.size < 2:
            raise ParameterError(f"{self.name}: need at least two [x, value] rows")
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(v))):
            raise ParameterError(f"{self.name}: the table holds NaN or infinite values")
        if np.any(np.diff(x) <= 0.0):
            raise ParameterError(f"{self.name}: the positions must be strictly increasing")
        x.setflags(write=False)
        v.setflags(write=False)
        object.__setattr__(self, "positions", x)
        object.__setattr__(self, "values", v)

    def check_on(self, length: float) -> None:
        """Raise ParameterError unless the rows span the beam ``[0, length]`` (to 1e-9 of its length).

        Parameters
        ----------
        length : float, [m]
            The beam's length.
        """
        x0, x1, tol = float(self.positions[0]), float(self.positions[-1]), 1e-9 * length
        if x0 < -tol or x1 > length + tol:
            raise ParameterError(
                f"{self.name}: rows at {x0:g} .. {x1:g} m, off the beam [0, {length:g}] m"
            )
        if x0 > tol or x1 < length - tol:
            raise ParameterError(
                f"{self.name}: the rows cover {x0:g} .. {x1:g} m; they must span the beam from 0 to "
                f"{length:g} m (the field is linear between rows and is not extrapolated)"
            )

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """The field at ``x`` (linear between rows).

        Parameters
        ----------
        x : array_like, [m]
            Positions on the beam.
        """
        return np.interp(np.asarray(x, dtype=float), self.positions, self.values)

    def slope(self, x: np.ndarray) -> np.ndarray:
        """``d/dx`` of the field at ``x``; at a row, the mean of the slopes on either side.

        Parameters
        ----------
        x : array_like, [m]
            Positions on the beam.
        """
        x = np.atleast_1d(np.asarray(x, dtype=float))
        xs, s = self.positions, np.diff(self.values) / np.diff(self.positions)
        right = s[np.clip(np.searchsorted(xs, x, side="right") - 1, 0, s.size - 1)]
        left = s[np.clip(np.searchsorted(xs, x, side="left") - 1, 0, s.size - 1)]
        return 0.5 * (left + right)


@dataclass(frozen=True, eq=False)
class InitialCondition:
    """Initial state of the beam (at rest unless given).

    Displacements and velocities from several entries add up. Fields are
    projected onto the run's free-state basis in the kinetic inner product
    (:func:`impactbeam.solver.initial.initial_coordinates`).

    Parameters
    ----------
    tip_displacement : float or None, [m]
        Release from the static shape of a point load at ``position`` (default
        the right end) that gives this deflection there (paper Case 0/13).
    position : float or None, [m]
        Where ``tip_displacement`` is imposed; default: the beam's right end.
    modal_displacement, modal_velocity : sequence of float or None
        Free-state modal coordinates ``eta_n(0)`` [m kg^0.5] and their rates.
    velocity : float or None, [m/s]
        Uniform translation ``w_t(x, 0) = velocity``.
    angular_velocity : float or None, [rad/s]
        Rigid rotation about ``pivot``: ``w_t(x, 0) = angular_velocity (x - pivot)``
        (positive turns +x toward +w), cross-sections turning at that rate.
    pivot : float or None, [m]
        The axis of ``angular_velocity`` (on the beam).
    displacement_profile, velocity_profile : Profile or None
        ``w(x, 0)`` [m] and ``w_t(x, 0)`` [m/s] along the beam, linear between rows.
    equilibrium : bool
        Start from the static equilibrium under the scenario's preload, with
        the contactors it engages (needs a :class:`Preload`).
    """

    tip_displacement: float | None = None
    position: float | None = None
    modal_displacement: tuple[float, ...] | None = None
    modal_velocity: tuple[float, ...] | None = None
    velocity: float | None = None
    angular_velocity: float | None = None
    pivot: float | None = None
    displacement_profile: Profile | None = None
    velocity_profile: Profile | None = None
    equilibrium: bool = False

    def __post_init__(self) -> None:
        for name in ("tip_displacement", "velocity", "angular_velocity", "pivot"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, finite(f"initial.{name}", getattr(self, name)))
        if self.position is not None:
            object.__setattr__(self, "position", nonnegative_finite("initial.position", self.position))
        for name in ("modal_displacement", "modal_velocity"):
            val = getattr(self, name)
            if val is not None:
                object.__setattr__(
                    self, name, tuple(finite(f"initial.{name}[{i}]", v) for i, v in enumerate(val))
                )
        for name in ("displacement_profile", "velocity_profile"):
            val = getattr(self, name)
            if val is not None and not isinstance(val, Profile):
                raise ParameterError(f"initial.{name}: expected a Profile, got {type(val).__name__}")
        if (self.angular_velocity is None) != (self.pivot is None):
            raise ParameterError("initial.pivot: give angular_velocity and pivot together (the rigid rotation and its axis)")
        if self.velocity is not None and self.velocity_profile is not None:
            raise ParameterError("initial.velocity: give a uniform velocity or a velocity profile, not both")
        if self.tip_displacement is not None and self.displacement_profile is not None:
            raise ParameterError("initial.displacement: give tip_displacement or a displacement profile, not both")
        if not isinstance(self.equilibrium, bool):
            raise ParameterError(f"initial.equilibrium: must be true or false, got {self.equilibrium!r}")
        if self.equilibrium:
            for name in ("tip_displacement", "displacement_profile", "modal_displacement"):
                if getattr(self, name) is not None:
                    raise ParameterError(
                        f"initial.{name.replace('_profile', '')}: cannot be combined with initial.equilibrium = "
                        "true (the equilibrium sets the displacement)"
                    )

    @property
    def at_rest(self) -> bool:
        """True when the beam starts undeformed and still."""
        return (
            self.tip_displacement in (None, 0.0)
            and not any(self.modal_displacement or ())
            and not any(self.modal_velocity or ())
            and self.velocity in (None, 0.0)
            and self.angular_velocity in (None, 0.0)
            and (self.displacement_profile is None or not np.any(self.displacement_profile.values))
            and (self.velocity_profile is None or not np.any(self.velocity_profile.values))
            and not self.equilibrium
        )

    def key(self) -> tuple:
        """A hashable value of the whole state (profiles by their tables): equal keys, equal starts.

        Instances compare by identity (their profiles hold arrays); runs that
        may share a start state (the batches of a sweep) compare keys.
        """
        out: list = []
        for f in dataclasses.fields(self):
            v = getattr(self, f.name)
            out.append((v.positions.tobytes(), v.values.tobytes()) if isinstance(v, Profile) else v)
        return tuple(out)


PreloadKind = Literal["gravity", "base_acceleration", "point_force"]


@dataclass(frozen=True)
class Preload:
    """A constant load acting during the whole run (``[preload]``), and the one of the static equilibrium.

    Parameters
    ----------
    kind : {"gravity", "base_acceleration", "point_force"}
        ``"gravity"``: the acceleration of gravity along +w (``"-1 g"`` when
        w points up), the load ``rho A(x) amplitude`` (and ``m amplitude`` on
        point masses); ``"base_acceleration"``: a constant acceleration of the
        base, the load ``-rho A(x) amplitude``, as for ``[excitation]`` (gravity
        toward -w is a base acceleration of ``+1 g``); ``"point_force"``: a
        constant force at ``position``.
    amplitude : float
        [m/s^2] for gravity and base acceleration, [N] for a point force; along +w.
    position : float or None, [m]
        Point of application (point_force only).
    """

    kind: PreloadKind
    amplitude: float
    position: float | None = None

    def __post_init__(self) -> None:
        choice("preload.kind", self.kind, ("gravity", "base_acceleration", "point_force"))
        object.__setattr__(self, "amplitude", finite("preload.amplitude", self.amplitude))
        if self.kind == "point_force":
            if self.position is None:
                raise ParameterError("preload.position: required for a point_force")
            object.__setattr__(self, "position", nonnegative_finite("preload.position", self.position))
        elif self.position is not None:
            raise ParameterError(f'preload.position: has no effect with kind = "{self.kind}" (only with "point_force")')

    def excitation(self) -> Excitation:
        """The preload as a load history: a step from t = 0 (gravity as the equivalent base acceleration)."""
        if self.kind == "point_force":
            return Excitation("point_force", "step", self.amplitude, position=self.position)
        amplitude = -self.amplitude if self.kind == "gravity" else self.amplitude
        return Excitation("base_acceleration", "step", amplitude)
