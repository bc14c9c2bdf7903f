"""The paper's specimen, its Table 1 cases, its published values, and the reproduction report.

W. Xu and E. K. Ervin, "Parameters affecting the transient response of an
impacting beam", Shock and Vibration 20 (2013) [1]_.

* :func:`specimen`, :func:`case`, :func:`cases`: the ABS cantilever of
  section 3 and the test cases of Table 1, as :class:`~impactbeam.scenario.Scenario`
  objects, read from ``examples/`` when the source tree is present, else
  built from the parameters below (the two agree; the tests check it).
* ``PAPER_*`` / ``TABLE2_MEASURED`` / ``SECTION4``: the published numbers,
  clearly labelled as reference data (never used as inputs).
* :func:`reproduce`: runs every study of issue 3 and writes ``report.md``,
  ``report.html`` and PNG figures.

How the paper's numbers are read (stated in the report as well):

1. The base pulse drives the beam *away* from the contactor first; it
   strikes the contactor on the way back ("when the specimen first contacts
   after the peak deflection", section 3.1).
2. The paper plots, and Table 2 lists, the deflection at the contact point
   measured from the contactor surface, positive away from it, so that a
   negative value means contact (section 3.1: "A deflection less than zero
   indicate that the structure enters into a contact state"). With the
   project's convention (see the model page: ``w`` from rest; a contactor
   "above" has its surface at ``w(a) = +c``) that quantity is the gap
   function ``d = c - s w(a)`` (``s = +1`` above, ``-1`` below), i.e.
   ``d = u + c`` with ``u`` the metrics' deflection (positive away from the
   contactor, from rest). Runs without contactor use ``d = -w`` at ``a`` (the
   same orientation, no gap).

References
----------
.. [1] W. Xu and E. K. Ervin, Parameters affecting the transient response of
   an impacting beam, Shock and Vibration 20 (2013).
"""

from __future__ import annotations

from .cases import specimen, specimen_data, case, case_data, cases
from .conventions import PaperMetrics, paper_metrics
from .data import (
    EXAMPLES_DIR,
    SPECIMEN,
    TableOneCase,
    TABLE1,
    PAPER_FREQUENCIES,
    Table2Row,
    TABLE2_MEASURED,
    SECTION4,
    PAPER_CONVERGENCE,
    PAPER_REFIT,
    PAPER_TRENDS,
)
from .document import write_readme_section
from .findings import Finding, ReproductionReport
from .plan import N_FIGURES, OPEN_ENGAGED_LIMIT
from .study import planned_simulations, reproduce

__all__ = [
    "EXAMPLES_DIR",
    "SPECIMEN",
    "TableOneCase",
    "TABLE1",
    "PAPER_FREQUENCIES",
    "Table2Row",
    "TABLE2_MEASURED",
    "SECTION4",
    "PAPER_CONVERGENCE",
    "PAPER_REFIT",
    "PAPER_TRENDS",
    "specimen",
    "specimen_data",
    "case",
    "case_data",
    "cases",
    "PaperMetrics",
    "paper_metrics",
    "Finding",
    "ReproductionReport",
    "reproduce",
    "planned_simulations",
    "N_FIGURES",
    "OPEN_ENGAGED_LIMIT",
    "write_readme_section",
]
