"""The physical system: a uniform Euler-Bernoulli beam, its end supports and contactors.

All quantities are SI. The sign convention (see the model page) is that the
deflection ``w`` is measured from the undeformed rest position. A contactor
``below`` has its surface at ``w(a) = -gap`` and pushes with
``F = k (-gap - w(a))`` while ``w(a) < -gap``; one ``above`` is the mirror image.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

from ._validation import choice, nonnegative_finite, positive_finite, stiffness
from .exceptions import ParameterError

__all__ = ["Support", "Beam", "Contactor", "SUPPORT_PRESETS", "Side"]

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
class Beam:
    """Uniform Euler-Bernoulli beam with elastic end supports (paper eq. 1).

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

    def __post_init__(self) -> None:
        for name in ("length", "youngs_modulus", "density", "area", "second_moment"):
            object.__setattr__(self, name, positive_finite(f"beam.{name}", getattr(self, name)))
        for name in ("left", "right"):
            if not isinstance(getattr(self, name), Support):
                raise ParameterError(f"beam.{name}: expected a Support, got {getattr(self, name)!r}")

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
        """rho A [kg/m]."""
        return self.density * self.area


@dataclass(frozen=True)
class Contactor:
    """One-sided linear contact spring with clearance (paper Fig. 1).

    Parameters
    ----------
    position : float, [m]
        Distance ``a`` from the left end, in [0, L].
    stiffness : float, [N/m]
        Contact stiffness ``k`` (positive, finite).
    gap : float, [m]
        Clearance ``c`` >= 0 between the beam at rest and the contactor surface.
    side : {"below", "above"}
        ``below`` resists ``w(a) < -gap``; ``above`` resists ``w(a) > gap``.
    """

    position: float
    stiffness: float
    gap: float = 0.0
    side: Side = "below"

    def __post_init__(self) -> None:
        object.__setattr__(self, "position", nonnegative_finite("contactor.position", self.position))
        object.__setattr__(self, "stiffness", positive_finite("contactor.stiffness", self.stiffness))
        object.__setattr__(self, "gap", nonnegative_finite("contactor.gap", self.gap))
        choice("contactor.side", self.side, ("below", "above"))

    @property
    def direction(self) -> float:
        """+1 for a contactor above, -1 below: the sign ``s`` in ``F = -k w(a) + s k gap``."""
        return 1.0 if self.side == "above" else -1.0

    def gap_function(self, w_at_contact: float) -> float:
        """Opening ``g = gap - s w(a)``: positive while free, negative while engaged."""
        return self.gap - self.direction * w_at_contact

    def check_on(self, beam: Beam, name: str = "contactor") -> None:
        """Raise ParameterError unless the contactor lies on ``beam``."""
        if self.position > beam.length * (1.0 + 1e-12):
            raise ParameterError(
                f"{name}.position: {self.position:g} m is off the beam (length {beam.length:g} m)"
            )
