"""impactbeam: transient response of impacting beams by exact piecewise modal analysis.

Implements and extends W. Xu and E. K. Ervin, "Parameters affecting the
transient response of an impacting beam", Shock and Vibration 20 (2013).
"""

from importlib.metadata import PackageNotFoundError, version

from .beam import Beam, Contactor, InteriorSpring, PointMass, Section, Support
from .exceptions import (
    ImpactBeamError,
    ModeSolveError,
    ParameterError,
    ScenarioError,
    SimulationError,
)
from .loading import Excitation, InitialCondition
from .modes import ModeSet, ScenarioModes, mode_set, modes, scenario_modes
from .result import SimulationResult, write_result
from .solver import Damping, Event, SolverOptions, simulate, simulate_system

try:
    __version__ = version("impactbeam")
except PackageNotFoundError:  # pragma: no cover
    __version__ = "0+unknown"

__all__ = [
    "Beam",
    "Contactor",
    "Support",
    "Section",
    "PointMass",
    "InteriorSpring",
    "Excitation",
    "InitialCondition",
    "Damping",
    "SolverOptions",
    "ModeSet",
    "ScenarioModes",
    "mode_set",
    "modes",
    "scenario_modes",
    "simulate",
    "simulate_system",
    "SimulationResult",
    "Event",
    "write_result",
    "ImpactBeamError",
    "ParameterError",
    "ScenarioError",
    "ModeSolveError",
    "SimulationError",
    "__version__",
]

from .scenario import Scenario, load_scenario, parse_scenario
from .sweep import sweep

__all__ += ["Scenario", "load_scenario", "parse_scenario", "sweep"]
