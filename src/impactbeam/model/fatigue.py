"""The fatigue input: where the damage is computed and the material's S-N curve (``[fatigue]``).

The rules that use it (Basquin's curve, the endurance limit, Goodman's mean-stress
correction, rainflow counting and Miner's sum) are in :mod:`impactbeam.statistics.fatigue`;
this module only holds and checks the numbers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from .._validation import choice, nonnegative_finite, positive_finite
from ..exceptions import ParameterError

__all__ = ["FatigueSpec", "MeanStress"]

MeanStress = Literal["none", "goodman"]


@dataclass(frozen=True)
class FatigueSpec:
    """Fatigue points and a Basquin S-N curve ``N(S) = sn_cycles (S / sn_stress)^(-sn_exponent)``.

    Parameters
    ----------
    points : tuple of float, [m]
        Positions on the beam where the outer-fibre bending stress is counted.
    sn_stress : float, [Pa]
        Stress amplitude ``S_ref`` of the reference point of the curve.
    sn_cycles : float
        Cycles to failure ``N_ref`` at ``S_ref``.
    sn_exponent : float
        Basquin exponent ``m`` (> 0).
    endurance_limit : float, [Pa]
        Amplitudes (after the mean-stress correction) at or below it do no damage; 0: none.
    mean_stress : {"none", "goodman"}
        Mean-stress correction of each cycle's amplitude.
    ultimate_strength : float or None, [Pa]
        ``S_u`` of Goodman's line (required with ``mean_stress = "goodman"``).
    """

    points: tuple[float, ...]
    sn_stress: float
    sn_cycles: float
    sn_exponent: float
    endurance_limit: float = 0.0
    mean_stress: MeanStress = "none"
    ultimate_strength: float | None = None

    def __post_init__(self) -> None:
        pts = tuple(float(nonnegative_finite(f"fatigue.points.{i}", x)) for i, x in enumerate(self.points))
        if not pts:
            raise ParameterError("fatigue.points: at least one point is needed")
        object.__setattr__(self, "points", pts)
        for name in ("sn_stress", "sn_cycles", "sn_exponent"):
            object.__setattr__(self, name, positive_finite(f"fatigue.{name}", getattr(self, name)))
        object.__setattr__(self, "endurance_limit", nonnegative_finite("fatigue.endurance_limit", self.endurance_limit))
        choice("fatigue.mean_stress", self.mean_stress, ("none", "goodman"))
        if self.mean_stress == "goodman":
            if self.ultimate_strength is None:
                raise ParameterError('fatigue.ultimate_strength: required with mean_stress = "goodman"')
            object.__setattr__(self, "ultimate_strength",
                               positive_finite("fatigue.ultimate_strength", self.ultimate_strength))
        elif self.ultimate_strength is not None:
            raise ParameterError('fatigue.ultimate_strength: has no effect without mean_stress = "goodman"')
