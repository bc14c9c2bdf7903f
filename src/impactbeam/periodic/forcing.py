"""The harmonic load's period, and where a steady state is sampled.

Shared by the stroboscopic analysis (:mod:`~impactbeam.periodic.strobe`) and
the linear steady state (:mod:`~impactbeam.periodic.linear`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..exceptions import ScenarioError

if TYPE_CHECKING:
    from ..scenario import Scenario

__all__ = ["harmonic_period", "strobe_point"]


def harmonic_period(scenario: Scenario) -> float:
    """The forcing period ``1/f`` [s]; ScenarioError unless the load is harmonic."""
    ex = scenario.excitation
    if ex.kind == "none" or ex.shape != "harmonic" or ex.frequency is None:
        raise ScenarioError(
            'excitation.shape: steady-state analysis needs a harmonic load (shape = "harmonic" with a '
            f"frequency), got kind = {ex.kind!r}, shape = {ex.shape!r}",
            key="excitation.shape",
        )
    return 1.0 / float(ex.frequency)


def strobe_point(scenario: Scenario) -> float:
    """Where the strobe samples ``w``: the first contactor, else the first output point [m]."""
    if scenario.contactors:
        return float(scenario.contactors[0].position)
    return float(scenario.output_points[0])
