"""impactbeam: transient response of impacting beams by exact piecewise modal analysis.

Implements and extends W. Xu and E. K. Ervin, "Parameters affecting the
transient response of an impacting beam", Shock and Vibration 20 (2013).

The public names below are imported on first use (PEP 562), so that
``import impactbeam`` and the command line start quickly; ``dir(impactbeam)``
and ``from impactbeam import X`` work as usual.

Example: the paper's specimen (Table 1) against a soft contactor at 0.484 L,
driven by a 15 g, 15 ms half-sine base pulse:

>>> import impactbeam as ib
>>> sc = ib.parse_scenario({
...     "beam": {"length": "109.2 mm", "width": "9.93 mm", "height": "3.03 mm",
...              "youngs_modulus": "1834 MPa", "density": "951.98 kg/m^3"},
...     "contactors": [{"position_ratio": 0.484, "stiffness": "4030 N/m", "gap": "0.229 mm", "side": "above"}],
...     "excitation": {"kind": "base_acceleration", "amplitude": "15 g", "duration": "15 ms"},
...     "solver": {"modes": 6, "end_time": "50 ms"},
... })
>>> m = ib.simulate(sc).metrics()
>>> print(f"first impact at {m['first_impact_time'] * 1e3:.2f} ms, {m['n_impacts']} impacts")
first impact at 16.98 ms, 3 impacts
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

#: public name -> module that defines it
_EXPORTS: dict[str, str] = {
    "Beam": "model",
    "Contactor": "model",
    "Support": "model",
    "Section": "model",
    "PointMass": "model",
    "InteriorSpring": "model",
    "Excitation": "model",
    "InitialCondition": "model",
    "Preload": "model",
    "Profile": "model",
    "Damping": "model",
    "SolverOptions": "model",
    "ModeSet": "modal",
    "ScenarioModes": "modal",
    "mode_set": "modal",
    "scenario_modes": "modal",
    "modes": "modal",
    "simulate": "simulation",
    "simulate_system": "simulation",
    "convergence_study": "simulation",
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
    "identify": "experiment",
    "sweep": "sweeps",
    "Identification": "experiment",
    "periodic_orbit": "periodic.shooting",
    "PeriodicOrbit": "periodic.shooting",
    "ModalState": "solver",
    "SteadyState": "periodic.strobe",
    "steady_state": "periodic.strobe",
    "BifurcationDiagram": "periodic.bifurcation",
    "bifurcation": "periodic.bifurcation",
    "bifurcation_map": "periodic.maps",
    "FrequencyResponse": "periodic.frf",
    "frequency_response": "periodic.frf",
    "linear_frf": "periodic.frf",
    "ImpactStatistics": "statistics",
    "impact_statistics": "statistics",
    "PowerSpectralDensity": "model.psd",
    "FatigueSpec": "model.fatigue",
    "random_response": "random",
    "RandomResponse": "random",
    "validate": "validation",
    "ValidationReport": "validation",
}

__all__ = [*_EXPORTS, "__version__"]

if TYPE_CHECKING:  # pragma: no cover - for type checkers and IDEs
    from .model import (
        Beam,
        Contactor,
        Damping,
        Excitation,
        InitialCondition,
        InteriorSpring,
        PointMass,
        Preload,
        Profile,
        Section,
        SolverOptions,
        Support,
    )
    from .exceptions import (
        ImpactBeamError,
        ImpactBeamWarning,
        ModeSolveError,
        ParameterError,
        ResourceError,
        ScenarioError,
        SimulationError,
    )
    from .modal import ModeSet, ScenarioModes, mode_set, modes, scenario_modes
    from .result import SimulationResult, write_result
    from .scenario import Scenario, load_scenario, parse_scenario
    from .simulation import convergence_study, simulate, simulate_system
    from .validation import ValidationReport, validate
    from .solver import Event
    from .experiment import Identification, identify
    from .periodic.shooting import PeriodicOrbit, periodic_orbit
    from .periodic.bifurcation import BifurcationDiagram, bifurcation
    from .periodic.frf import FrequencyResponse, frequency_response, linear_frf
    from .periodic.maps import bifurcation_map
    from .statistics import ImpactStatistics, impact_statistics
    from .model.psd import PowerSpectralDensity
    from .model.fatigue import FatigueSpec
    from .random import RandomResponse, random_response
    from .periodic.strobe import SteadyState, steady_state
    from .solver import ModalState
    from .sweeps import sweep


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
