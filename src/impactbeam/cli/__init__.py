"""The ``impactbeam`` command line: thin wrappers around the Python API.

Every command reports bad input (:class:`~impactbeam.exceptions.ParameterError`,
which includes :class:`~impactbeam.exceptions.ScenarioError`) as exactly one
line ``error: <message>`` on stderr and exits with status 2; a failed
computation (:class:`~impactbeam.exceptions.SimulationError` and other
:class:`~impactbeam.exceptions.ImpactBeamError`) exits with status 1. Never a
traceback for those. Ctrl-C exits 130, SIGTERM 143.

One module per command (or family of commands); each calls the public API
and formats its answer. The commands are registered here, explicitly. Heavy
modules (the solver, matplotlib, Dask) are imported inside the commands, so
``impactbeam --help`` stays fast.
"""

from __future__ import annotations

from . import (
    cmd_bifurcation,
    cmd_convergence,
    cmd_explore,
    cmd_info,
    cmd_measure,
    cmd_modes,
    cmd_periodic,
    cmd_random,
    cmd_reproduce,
    cmd_simulate,
    cmd_sweep,
    cmd_validate,
)
from ._group import (Interrupted, console_main, fail, handle_errors, load_with_overrides, main, take_warnings,
                     warning_lines)

__all__ = ["main", "console_main", "handle_errors", "take_warnings", "warning_lines", "load_with_overrides", "Interrupted", "fail"]

for _command in (
    cmd_modes.modes,
    cmd_simulate.simulate,
    cmd_convergence.convergence,
    cmd_reproduce.reproduce,
    cmd_sweep.sweep_command,
    cmd_sweep.plot_command,
    cmd_measure.identify,
    cmd_measure.compare,
    cmd_measure.fit,
    cmd_bifurcation.bifurcation_command,
    cmd_bifurcation.bifurcation_map_command,
    cmd_periodic.periodic,
    cmd_random.random_command,
    cmd_explore.explore,
    cmd_info.info,
    cmd_validate.validate,
):
    main.add_command(_command)
