"""impactbeam: transient response of impacting beams by exact piecewise modal analysis.

Implements and extends W. Xu and E. K. Ervin, "Parameters affecting the
transient response of an impacting beam", Shock and Vibration 20 (2013).

The public names below are imported on first use (PEP 562), so that
``import impactbeam`` and the command line start quickly; ``dir(impactbeam)``
and ``from impactbeam import X`` work as usual.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

#: public name -> module that defines it
_EXPORTS: dict[str, str] = {
    "Beam": "beam",
    "Contactor": "beam",
    "Support": "beam",
    "Section": "beam",
    "PointMass": "beam",
    "InteriorSpring": "beam",
    "Excitation": "loading",
    "InitialCondition": "loading",
    "Damping": "solver",
    "SolverOptions": "solver",
    "ModeSet": "modes",
    "ScenarioModes": "modes",
    "mode_set": "modes",
    "scenario_modes": "modes",
    "simulate": "solver",
    "simulate_system": "solver",
    "SimulationResult": "result",
    "Event": "solver",
    "write_result": "result",
    "ImpactBeamError": "exceptions",
    "ParameterError": "exceptions",
    "ScenarioError": "exceptions",
    "ModeSolveError": "exceptions",
    "SimulationError": "exceptions",
    "ResourceError": "exceptions",
    "ImpactBeamWarning": "exceptions",
    "Scenario": "scenario",
    "load_scenario": "scenario",
    "parse_scenario": "scenario",
    "identify": "identification",
    "Identification": "identification",
}

__all__ = [*_EXPORTS, "modes", "sweep", "__version__"]

if TYPE_CHECKING:  # pragma: no cover - for type checkers and IDEs
    from .beam import Beam, Contactor, InteriorSpring, PointMass, Section, Support
    from .exceptions import (
        ImpactBeamError,
        ImpactBeamWarning,
        ModeSolveError,
        ParameterError,
        ResourceError,
        ScenarioError,
        SimulationError,
    )
    from .loading import Excitation, InitialCondition
    from .modes import ModeSet, ScenarioModes, mode_set, modes, scenario_modes
    from .result import SimulationResult, write_result
    from .scenario import Scenario, load_scenario, parse_scenario
    from .solver import Damping, Event, SolverOptions, simulate, simulate_system
    from .identification import Identification, identify
    from .sweep import sweep


# ``modes`` and ``sweep`` are both API functions and submodules: import the
# submodules now (both are light at import) and bind the functions over them.
from . import modes as _modes_module  # noqa: E402
from . import sweep as _sweep_module  # noqa: E402

modes = _modes_module.modes
sweep = _sweep_module.sweep


def __getattr__(name: str) -> Any:
    if name == "__version__":
        from importlib.metadata import PackageNotFoundError, version

        try:
            value = version("impactbeam")
        except PackageNotFoundError:  # pragma: no cover
            value = "0+unknown"
    elif name in _EXPORTS:
        value = getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    else:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
