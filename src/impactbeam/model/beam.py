"""The physical system: an Euler-Bernoulli beam, its supports, attachments and contactors.

The beam of the paper is uniform with springs at its ends; a :class:`Beam` may
also be piecewise uniform (:class:`Section`), carry point masses
(:class:`PointMass`) and rest on permanent interior springs
(:class:`InteriorSpring`). These change only the segments and joint
conditions of the exact modal analysis (:mod:`impactbeam.modal`).

All quantities are SI. The sign convention (see the model page) is that the
deflection ``w`` is measured from the undeformed rest position. A contactor
``below`` has its surface at ``w(a) = -gap`` and pushes with
``F = k (-gap - w(a))`` while ``w(a) < -gap``; one ``above`` is the mirror image.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from .._validation import choice, nonnegative_finite, positive_finite, stiffness
from ..exceptions import ParameterError

__all__ = ["Support", "Beam", "Contactor", "Section", "PointMass", "InteriorSpring", "SUPPORT_PRESETS", "Side",
           "MERGE_DISTANCE"]

#: Attachments (springs, masses, contact springs) closer than this fraction of the length to a node
#: (an end, a section step, an earlier attachment) sit at that node in the modal analysis: a
#: shorter segment makes the exact dynamic stiffness too ill-conditioned to count roots.
MERGE_DISTANCE = 3e-5

Side = Literal["below", "above"]

#: End-condition presets as (translational, rotational) spring stiffness.
SUPPORT_PRESETS: dict[str, tuple[float, float]] = {
    "clamped": (math.inf, math.inf),
    "pinned": (math.inf, 0.0),
    "free": (0.0, 0.0),
    "sliding": (0.0, math.inf),
}


@dataclass(frozen=True)
class Support:
    """Elastic end support of the beam (paper Fig. 1, boundary conditions after eq. 5).

    Parameters
    ----------
    translational : float, [N/m]
        Translational spring ``k1`` (left) or ``k2`` (right); 0 = free, inf = rigid.
    rotational : float, [N m/rad]
        Rotational spring ``Kt1`` or ``Kt2``; 0 = free, inf = rigid.
    """

    translational: float = 0.0
    rotational: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "translational", stiffness("translational", self.translational))
        object.__setattr__(self, "rotational", stiffness("rotational", self.rotational))

    @classmethod
    def preset(cls, name: str) -> Support:
        """Return the support called ``clamped``, ``pinned``, ``free`` or ``sliding``."""
        choice("support", name, SUPPORT_PRESETS)
        k, kt = SUPPORT_PRESETS[name]
        return cls(k, kt)

    @property
    def name(self) -> str | None:
        """The preset name of this support, or None for general springs."""
        for key, (k, kt) in SUPPORT_PRESETS.items():
            if (k, kt) == (self.translational, self.rotational):
                return key
        return None

    def describe(self) -> str:
        """A short human-readable description."""
        if self.name is not None:
            return self.name
        return f"springs k={self.translational:g} N/m, Kt={self.rotational:g} N m/rad"


@dataclass(frozen=True)
class Section:
    """One uniform piece of a stepped beam (``[[beam.sections]]``).

    Parameters
    ----------
    length : float, [m]
    youngs_modulus : float, [Pa]
    density : float, [kg/m^3]
    area : float, [m^2]
    second_moment : float, [m^4]
    width, height : float or None, [m]
        Rectangle dimensions when known; ``height / 2`` is the outer-fibre distance.
    """

    length: float
    youngs_modulus: float
    density: float
    area: float
    second_moment: float
    width: float | None = None
    height: float | None = None

    def __post_init__(self) -> None:
        for name in ("length", "youngs_modulus", "density", "area", "second_moment"):
            object.__setattr__(self, name, positive_finite(f"section.{name}", getattr(self, name)))

    @property
    def bending_stiffness(self) -> float:
        """EI [N m^2]."""
        return self.youngs_modulus * self.second_moment

    @property
    def mass_per_length(self) -> float:
        """rho A [kg/m]."""
        return self.density * self.area


@dataclass(frozen=True)
class PointMass:
    """A rigid body attached at one point (``[[masses]]``): shear jump ``-m w^2 W``, moment jump ``-J w^2 W'``.

    Parameters
    ----------
    position : float, [m]
    mass : float, [kg]
    rotary_inertia : float, [kg m^2]
        About the axis normal to the plane of bending, through the attachment point.
    """

    position: float
    mass: float
    rotary_inertia: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", nonnegative_finite("mass.position", self.position))
        object.__setattr__(self, "mass", nonnegative_finite("mass.mass", self.mass))
        object.__setattr__(self, "rotary_inertia", nonnegative_finite("mass.rotary_inertia", self.rotary_inertia))


@dataclass(frozen=True)
class InteriorSpring:
    """A permanent two-sided support at one point (``[[springs]]``), unlike a one-sided contactor.

    Parameters
    ----------
    position : float, [m]
    translational : float, [N/m]
        0 = none, inf = rigid (a pin).
    rotational : float, [N m/rad]
        0 = none, inf = rigid (no rotation at the point).
    """

    position: float
    translational: float = 0.0
    rotational: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", nonnegative_finite("spring.position", self.position))
        object.__setattr__(self, "translational", stiffness("spring.translational", self.translational))
        object.__setattr__(self, "rotational", stiffness("spring.rotational", self.rotational))


@dataclass(frozen=True)
class Beam:
    """Euler-Bernoulli beam with elastic end supports (paper eq. 1), optionally stepped.

    Parameters
    ----------
    length : float, [m]
    youngs_modulus : float, [Pa]
    density : float, [kg/m^3]
    area : float, [m^2]
    second_moment : float, [m^4]
    left, right : Support
        End supports at x = 0 and x = length.
    width, height : float or None, [m]
        Cross-section dimensions when the beam was built as a rectangle
        (kept for reporting and for parameter studies).
    sections : tuple of Section
        Piecewise-uniform properties from x = 0; empty: uniform with the
        values above. The lengths must sum to ``length``.
    masses : tuple of PointMass
    springs : tuple of InteriorSpring
        Permanent interior (or end) springs, added to the end supports at an end.
    theory : {"euler-bernoulli", "timoshenko"}
        Euler-Bernoulli (the paper's eq. 1, default) or Timoshenko (shear
        deformation and rotary inertia, :mod:`impactbeam.modal.timoshenko`).
    poisson_ratio : float or None
        Poisson's ratio, in (-1, 0.5); a Timoshenko beam needs it (the shear
        modulus of each section is ``G = E / (2 (1 + nu))``).
    shear_coefficient : float or None
        Timoshenko shear coefficient ``kappa``; default Cowper's value for a
        rectangle, ``10 (1 + nu) / (12 + 11 nu)`` (a section given as area and
        second moment needs it).
    """

    length: float
    youngs_modulus: float
    density: float
    area: float
    second_moment: float
    left: Support = field(default_factory=lambda: Support.preset("clamped"))
    right: Support = field(default_factory=lambda: Support.preset("free"))
    width: float | None = None
    height: float | None = None
    sections: tuple[Section, ...] = ()
    masses: tuple[PointMass, ...] = ()
    springs: tuple[InteriorSpring, ...] = ()
    theory: Literal["euler-bernoulli", "timoshenko"] = "euler-bernoulli"
    poisson_ratio: float | None = None
    shear_coefficient: float | None = None

    def __post_init__(self) -> None:
        for name in ("length", "youngs_modulus", "density", "area", "second_moment"):
            object.__setattr__(self, name, positive_finite(f"beam.{name}", getattr(self, name)))
        for name in ("left", "right"):
            if not isinstance(getattr(self, name), Support):
                raise ParameterError(f"beam.{name}: expected a Support, got {getattr(self, name)!r}")
        for name, kind in (("sections", Section), ("masses", PointMass), ("springs", InteriorSpring)):
            items = tuple(getattr(self, name))
            for i, item in enumerate(items):
                if not isinstance(item, kind):
                    raise ParameterError(f"beam.{name}[{i}]: expected a {kind.__name__}, got {item!r}")
            object.__setattr__(self, name, items)
        if self.sections:
            total = math.fsum(sec.length for sec in self.sections)
            if abs(total - self.length) > 1e-9 * self.length:
                raise ParameterError(
                    f"beam.sections: the section lengths sum to {total:.12g} m, not beam.length = {self.length:.12g} m"
                )
        for i, sec in enumerate(self.sections):
            # measured: a section of 1e-5 L is exact, one of 1e-7 L gives no modes at all (its exact
            # dynamic stiffness overflows); below MERGE_DISTANCE attachments are merged for the same reason
            if sec.length < MERGE_DISTANCE * self.length:
                raise ParameterError(
                    f"beam.sections[{i}].length: {sec.length:g} m is {sec.length / self.length:.2g} of the beam; a "
                    f"section shorter than {MERGE_DISTANCE:g} L ({MERGE_DISTANCE * self.length:.3g} m) cannot be "
                    "resolved by the modal analysis in double precision: merge it into a neighbour (a short "
                    "flexible joint is a rotational spring, [[springs]])"
                )
        self._check_theory()
        tol = 1e-12 * self.length
        for name in ("masses", "springs"):
            for i, item in enumerate(getattr(self, name)):
                if item.position > self.length + tol:
                    raise ParameterError(
                        f"{name}[{i}].position: {item.position:g} m is off the beam (length {self.length:g} m)"
                    )

    def _check_theory(self) -> None:
        choice("beam.theory", self.theory, ("euler-bernoulli", "timoshenko"))
        nu, kappa = self.poisson_ratio, self.shear_coefficient
        if nu is not None:
            nu = float(nu)
            if not -1.0 < nu < 0.5:
                raise ParameterError(f"beam.poisson_ratio: must lie in (-1, 0.5), got {nu!r}")
            object.__setattr__(self, "poisson_ratio", nu)
        if kappa is not None:
            object.__setattr__(self, "shear_coefficient", positive_finite("beam.shear_coefficient", kappa))
        if self.theory == "euler-bernoulli":
            return
        if nu is None:
            raise ParameterError("beam.poisson_ratio: a Timoshenko beam needs it (or beam.shear_modulus)")
        if kappa is None and any(p.height is None for p in self.pieces()):
            raise ParameterError(
                "beam.shear_coefficient: required for a section given as area and second_moment "
                "(Cowper's default needs a rectangle)"
            )

    @property
    def is_timoshenko(self) -> bool:
        """True for a Timoshenko beam (``theory = "timoshenko"``)."""
        return self.theory == "timoshenko"

    def _nu(self) -> float:
        if self.poisson_ratio is None:
            raise ParameterError("beam.poisson_ratio: not given (only a Timoshenko beam has a shear stiffness)")
        return float(self.poisson_ratio)

    @property
    def kappa(self) -> float:
        """Shear coefficient: the given one, else Cowper's for a rectangle ``10 (1 + nu) / (12 + 11 nu)``."""
        if self.shear_coefficient is not None:
            return float(self.shear_coefficient)
        nu = self._nu()
        return 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu)

    def shear_stiffness(self, piece: Section) -> float:
        """``kappa G A`` of one piece [N], ``G = E / (2 (1 + nu))`` (Timoshenko beams).

        Parameters
        ----------
        piece : Section
            One of :meth:`pieces`.
        """
        return self.kappa * piece.youngs_modulus / (2.0 * (1.0 + self._nu())) * piece.area

    @classmethod
    def rectangular(
        cls,
        length: float,
        width: float,
        height: float,
        youngs_modulus: float,
        density: float,
        left: Support | str = "clamped",
        right: Support | str = "free",
    ) -> Beam:
        """A beam of rectangular cross-section ``width`` x ``height`` (A = b h, I = b h^3/12)."""
        b = positive_finite("beam.width", width)
        h = positive_finite("beam.height", height)
        left = Support.preset(left) if isinstance(left, str) else left
        right = Support.preset(right) if isinstance(right, str) else right
        return cls(length, youngs_modulus, density, b * h, b * h**3 / 12.0, left, right, b, h)

    @property
    def bending_stiffness(self) -> float:
        """EI [N m^2]."""
        return self.youngs_modulus * self.second_moment

    @property
    def mass_per_length(self) -> float:
        """rho A [kg/m] of the ``[beam]`` values (the reference section of a stepped beam)."""
        return self.density * self.area

    @property
    def is_uniform(self) -> bool:
        """True for the paper's beam: Euler-Bernoulli, one section, no masses, no interior springs."""
        return not (self.sections or self.masses or self.springs or self.is_timoshenko)

    def pieces(self) -> tuple[Section, ...]:
        """The uniform pieces from x = 0 (one piece with the ``[beam]`` values if not stepped)."""
        if self.sections:
            return self.sections
        return (Section(self.length, self.youngs_modulus, self.density, self.area, self.second_moment,
                        self.width, self.height),)

    def _piece_values(self, x: float | Sequence[float] | np.ndarray, attr: str) -> np.ndarray:
        x = np.atleast_1d(np.asarray(x, dtype=float))
        pieces = self.pieces()
        ends = np.cumsum([p.length for p in pieces])[:-1]
        idx = np.searchsorted(ends, x, side="right")
        vals = np.array([np.nan if getattr(p, attr) is None else float(getattr(p, attr)) for p in pieces])
        return vals[idx]

    def bending_stiffness_at(self, x: float | Sequence[float] | np.ndarray) -> np.ndarray:
        """EI(x) [N m^2]; at a step, the value of the section to the right.

        Parameters
        ----------
        x : float or array_like, [m]
            Positions on the beam.
        """
        return self._piece_values(x, "youngs_modulus") * self._piece_values(x, "second_moment")

    def second_moment_at(self, x: float | Sequence[float] | np.ndarray) -> np.ndarray:
        """I(x) [m^4]; at a step, the value of the section to the right.

        Parameters
        ----------
        x : float or array_like, [m]
            Positions on the beam.
        """
        return self._piece_values(x, "second_moment")

    def mass_per_length_at(self, x: float | Sequence[float] | np.ndarray) -> np.ndarray:
        """rho A(x) [kg/m]; at a step, the value of the section to the right.

        Parameters
        ----------
        x : float or array_like, [m]
            Positions on the beam.
        """
        return self._piece_values(x, "density") * self._piece_values(x, "area")

    def rotary_inertia_at(self, x: float | Sequence[float] | np.ndarray) -> np.ndarray:
        """rho I(x) [kg m], the rotary inertia per length (used by a Timoshenko beam).

        Parameters
        ----------
        x : float or array_like, [m]
            Positions on the beam.
        """
        return self._piece_values(x, "density") * self._piece_values(x, "second_moment")

    def fibre_distance_at(self, x: float | Sequence[float] | np.ndarray) -> np.ndarray:
        """Outer-fibre distance c(x) = height / 2 [m] (NaN where the section was given as area and I).

        The bending stress is ``sigma = M c / I`` with ``M = EI W''``.

        Parameters
        ----------
        x : float or array_like, [m]
            Positions on the beam.
        """
        return 0.5 * self._piece_values(x, "height")

    def require_free(self, x: float, key: str, consequence: str) -> None:
        """ParameterError naming ``key`` when ``x`` is where a support holds ``w = 0`` (:meth:`fixed_at`).

        Parameters
        ----------
        x : float, [m]
        key : str
            The input given there (``contactors.0.position``).
        consequence : str
            Why that is refused (``the contactor can never act``).
        """
        held = self.fixed_at(x)
        if held is not None:
            raise ParameterError(
                f"{key}: {x:.10g} m is at {held}, where w = 0 (within {MERGE_DISTANCE:g} L), so {consequence}; "
                f"remove it, or place it at least {MERGE_DISTANCE * self.length:.3g} m from the support"
            )

    def fixed_at(self, x: float) -> str | None:
        """What holds the deflection at ``x`` at zero, or None.

        An end or a permanent spring with a rigid translational stiffness,
        within :data:`MERGE_DISTANCE` of the length of ``x`` (closer, the
        modal analysis puts an attachment at that support).

        Parameters
        ----------
        x : float, [m]
            A position on the beam.

        Returns
        -------
        str or None
            E.g. ``"the right end (pinned)"``.
        """
        tol = MERGE_DISTANCE * self.length
        for end, at, support in (("left", 0.0, self.left), ("right", self.length, self.right)):
            if abs(x - at) <= tol and math.isinf(support.translational):
                return f"the {end} end ({support.describe()})"
        for i, sp in enumerate(self.springs):
            if abs(x - sp.position) <= tol and math.isinf(sp.translational):
                return f"springs.{i} (a rigid support at {sp.position:g} m)"
        return None

    @property
    def total_mass(self) -> float:
        """Mass of the beam and its point masses [kg]."""
        return math.fsum(p.mass_per_length * p.length for p in self.pieces()) + math.fsum(
            m.mass for m in self.masses
        )


@dataclass(frozen=True)
class Contactor:
    """One-sided linear contact spring with clearance (paper Fig. 1).

    Parameters
    ----------
    position : float, [m]
        Distance ``a`` from the left end, in [0, L].
    stiffness : float, [N/m]
        Contact stiffness ``k`` (positive); ``inf`` (or ``"inf"``) is a rigid
        stop. A rigid contactor pins its point in the contact state, so its
        contact-state modes are defined (:func:`impactbeam.mode_set`), but a
        transient simulation needs a finite stiffness (see
        :func:`impactbeam.simulate_system`).
    gap : float, [m]
        Clearance ``c`` >= 0 between the beam at rest and the contactor surface.
    side : {"below", "above"}
        ``below`` resists ``w(a) < -gap``; ``above`` resists ``w(a) > gap``.
    damping : float, [N s/m]
        Dashpot ``c`` in parallel with the spring (code_aster's ``AMOR_NOR``):
        with the penetration ``d``, the force is ``k d + c d'`` while ``d > 0``
        and that force is positive, else 0; it never pulls, so the contact ends
        when the force reaches 0 (before ``d`` returns to 0).
    restitution : float, optional
        A coefficient of restitution ``0 < e <= 1`` instead of ``damping``: the
        dashpot that gives the engaged state's contact mode the damping ratio
        of a spring-dashpot impact with restitution ``e``
        (:func:`impactbeam.solver.damping.restitution_ratio`); ``e = 1`` is no dashpot.
    """

    position: float
    stiffness: float
    gap: float = 0.0
    side: Side = "below"
    damping: float = 0.0
    restitution: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", nonnegative_finite("contactor.position", self.position))
        k = stiffness("contactor.stiffness", self.stiffness)
        if k == 0.0:
            raise ParameterError("contactor.stiffness: must be positive (inf = rigid), got 0.0")
        object.__setattr__(self, "stiffness", k)
        object.__setattr__(self, "gap", nonnegative_finite("contactor.gap", self.gap))
        choice("contactor.side", self.side, ("below", "above"))
        object.__setattr__(self, "damping", nonnegative_finite("contactor.damping", self.damping))
        if self.restitution is not None:
            e = float(self.restitution)
            if not (0.0 < e <= 1.0):
                raise ParameterError(f"contactor.restitution: must be in (0, 1] (1: no loss), got {self.restitution!r}")
            if self.damping:
                raise ParameterError("contactor.restitution: give damping or restitution, not both")
            object.__setattr__(self, "restitution", e)

    @property
    def dissipative(self) -> bool:
        """True when the contactor has a dashpot (``damping > 0`` or ``restitution < 1``)."""
        return self.damping > 0.0 or (self.restitution is not None and self.restitution < 1.0)

    @property
    def rigid(self) -> bool:
        """True for an infinitely stiff contactor (``stiffness = inf``)."""
        return math.isinf(self.stiffness)

    @property
    def direction(self) -> float:
        """+1 for a contactor above, -1 below: the sign ``s`` in ``F = -k w(a) + s k gap``."""
        return 1.0 if self.side == "above" else -1.0

    def gap_function(self, w_at_contact: float) -> float:
        """Opening ``g = gap - s w(a)``: positive while free, negative while engaged.

        Parameters
        ----------
        w_at_contact : float, [m]
            Deflection of the beam at the contactor.
        """
        return self.gap - self.direction * w_at_contact

    def force(self, w_at_contact: Any, w_t_at_contact: Any, dashpot: float | None = None) -> Any:
        """Force of the engaged contactor on the beam, ``max(k d + c d', 0)`` with ``d = s w(a) - gap``.

        Positive whatever the side (it pushes the beam away from the
        contactor); zero where it would pull. Only meaningful while engaged:
        the events say when (a dashpot can hold ``d > 0`` after a release).

        Parameters
        ----------
        w_at_contact, w_t_at_contact : float or ndarray, [m], [m/s]
            Deflection and velocity of the beam at the contactor.
        dashpot : float, optional, [N s/m]
            The dashpot (default ``damping``; give the one the solver derived
            from ``restitution``).
        """
        c = self.damping if dashpot is None else dashpot
        d = self.direction * np.asarray(w_at_contact) - self.gap
        f = self.stiffness * d
        if c:
            f = f + c * self.direction * np.asarray(w_t_at_contact)
        return np.maximum(f, 0.0)

    def check_on(self, beam: Beam, name: str = "contactor") -> None:
        """Raise ParameterError unless the contactor lies on ``beam``, away from a rigid support.

        At a support that holds ``w = 0`` (:meth:`Beam.fixed_at`) a contactor
        can never act; it is refused rather than simulated.

        Parameters
        ----------
        beam : Beam
        name : str
            How the contactor is named in the error (e.g. ``contactors.0``).
        """
        if self.position > beam.length * (1.0 + 1e-12):
            raise ParameterError(
                f"{name}.position: {self.position:g} m is off the beam (length {beam.length:g} m)"
            )
        beam.require_free(self.position, f"{name}.position", "the contactor can never act")
