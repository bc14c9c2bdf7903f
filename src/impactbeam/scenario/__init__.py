"""Scenario files: TOML <-> validated objects (see the scenario reference).

A scenario describes one simulation: the beam and its supports, the
contactors, damping, the excitation, the initial state, solver options and
the output points. :func:`load_scenario` reads a TOML file,
:func:`parse_scenario` a mapping; both return a validated, immutable
:class:`Scenario`. Numbers are SI; strings with units are accepted
(``"0.229 mm"``, ``"15 g"``, ``"15 ms"``, ``"1834 MPa"``; see :mod:`impactbeam.units`).

Every problem is reported as a :class:`~impactbeam.exceptions.ScenarioError`
whose message starts with the dotted key of the offending field and whose
``key`` attribute holds that key, for example::

    contactors.0.position: 0.2 m is off the beam (length 0.1092 m)
    unknown key "beam.lenght" (did you mean "beam.length"?)

Parameter studies vary a scenario through dotted paths
(:func:`set_path`, :meth:`Scenario.with_values`), so a sweep of
``contactors.0.gap`` re-validates every case exactly as a file would be.
The file format is described in ``examples/README.md``.
"""

from __future__ import annotations

from .core import Scenario, load_scenario, parse_scenario
from .edit import dump_scenario, scenario_toml, set_path
from .schema import EXCITATION_DIMENSIONS, SUPPORT_DEFAULTS, path_dimension, scenario_paths
from .traces import read_table

__all__ = [
    "Scenario",
    "load_scenario",
    "parse_scenario",
    "set_path",
    "scenario_paths",
    "dump_scenario",
    "read_table",
    "EXCITATION_DIMENSIONS",
    "path_dimension",
    "scenario_toml",
    "SUPPORT_DEFAULTS",
]
