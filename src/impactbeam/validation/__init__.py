"""The validation manual: published validation tests of impacting beams reproduced and compared.

:func:`validate` runs the cases and returns a :class:`ValidationReport`;
``impactbeam validate [--json]`` prints it and exits with status 1 when a case
falls outside its tolerance or cannot be run. The cases:

* ``SDLX400``: code_aster's pinned-free beam, frequencies without and with a
  tip spring (analytical reference);
* ``SDNL32``: code_aster's pinned beam swung onto a one-sided tip spring, both
  stiffnesses (the VPCS reference), free-mode damping and a rigid rotation;
* ``SDNL104``: code_aster's cantilever pushed onto a stiff stop, its 5-mode
  runs and the converged value;
* ``Table2``: the paper's measured frequencies (judged) and Table 2 (shown).

The references, with their sources, are in :mod:`.references`; the docs page
"Validation manual" shows the tables and figures. This package is a driver:
it uses the public flow (scenario, simulate, modes) and the paper's data.
"""

from __future__ import annotations

from .core import CASES, CaseResult, Check, ValidationReport
from .run import validate

__all__ = ["validate", "ValidationReport", "CaseResult", "Check", "CASES"]
