"""What a simulation gives: the result object, its metrics, fields and files.

* :class:`SimulationResult` (:mod:`.simulation_result`) and :func:`write_result` (:mod:`.files`):
  the exact solution with lazy sampled grids, provenance and file writing;
* :mod:`.metrics`: the response metrics from the exact solution;
* :mod:`.stress`: bending moment and stress with the static correction;
* :mod:`.dataset`: the result as a labelled :class:`xarray.Dataset`.

This package reads the solver's exact solution; the figures are in
:mod:`impactbeam.plot`, imported only when a figure is drawn.
"""

from __future__ import annotations

from .files import write_result
from .simulation_result import SimulationResult

__all__ = ["SimulationResult", "write_result"]
