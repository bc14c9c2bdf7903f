"""The physical system and its run settings, as frozen, validated data classes (paper section 2).

* :mod:`.beam`: the beam (sections, point masses, interior springs), its end
  supports, and the contactors (one-sided springs with clearance);
* :mod:`.loading`: the excitation ``f(x, t) = p(x) u(t)`` and its time pieces,
  and the initial condition;
* :mod:`.damping`: modal damping of the free and contact states (eq. 9);
* :mod:`.options`: the run settings (modes, output step, end time, basis).

Built by the scenario parser (:mod:`impactbeam.scenario`) or directly; read by
the modal analysis and the solver. Nothing here computes a response.
"""

from __future__ import annotations

from .beam import SUPPORT_PRESETS, Beam, Contactor, InteriorSpring, PointMass, Section, Support
from .damping import Damping
from .loading import Excitation
from .starting import InitialCondition, Preload, Profile
from .options import BASES, MAX_MODES, SolverOptions

__all__ = [
    "Beam",
    "Contactor",
    "Support",
    "Section",
    "PointMass",
    "InteriorSpring",
    "SUPPORT_PRESETS",
    "Excitation",
    "InitialCondition",
    "Preload",
    "Profile",
    "Damping",
    "SolverOptions",
    "BASES",
    "MAX_MODES",
]
