"""Convergence in the number of modes: ``solver.modes = "auto"`` and the unconverged warning.

Modal truncation is the one approximation of the exact solver that the user
controls (paper section 2 used 4 modes free and 8 in contact). A result is
called converged in the modes when the Table-2 metrics
(:data:`CONVERGENCE_METRICS`) change by less than ``solver.tolerance``
(relative) between the count used and a smaller one:

* ``modes = "auto"`` runs 4, 8, 12, 16, 24, 32, 48, 64, 96, 128, 200 modes and
  stops at the first count whose metrics differ from the previous count's by
  less than the tolerance;
* a fixed count ``n`` is compared, on request
  (:meth:`~impactbeam.result.SimulationResult.convergence`), with ``n - max(2, n // 4)``
  modes; a larger change is reported as a warning.

Relative changes: displacements against the largest displacement metric of
the run, times against the run's duration scale (``t_max`` and durations
against themselves), the impact count against itself; a metric defined at one
count and undefined at the other counts as a change of 1.
"""

from __future__ import annotations

import math
from typing import Any

__all__ = ["AUTO_COUNTS", "CONVERGENCE_METRICS", "relative_changes", "coarser_count"]

#: Mode counts tried by ``solver.modes = "auto"``.
AUTO_COUNTS = (4, 8, 12, 16, 24, 32, 48, 64, 96, 128, 200)
#: The metrics whose change decides convergence (the paper's Table 2 quantities).
CONVERGENCE_METRICS = (
    "max_response", "t_max", "first_impact_time", "free_duration", "contact_duration", "min_response",
    "max_penetration", "n_impacts",
)
_DISPLACEMENTS = ("max_response", "min_response", "max_penetration")


def coarser_count(n: int) -> int:
    """The smaller mode count a fixed count ``n`` is compared with."""
    return max(1, n - max(2, n // 4))


def relative_changes(new: dict[str, Any], old: dict[str, Any]) -> dict[str, float]:
    """Relative change of each convergence metric from ``old`` to ``new`` (see the module docstring)."""
    disp = max((abs(new[k]) for k in _DISPLACEMENTS if new.get(k) is not None), default=0.0)
    out: dict[str, float] = {}
    for key in CONVERGENCE_METRICS:
        a, b = new.get(key), old.get(key)
        if a is None and b is None:
            out[key] = 0.0
        elif a is None or b is None:
            out[key] = 1.0
        else:
            scale = disp if key in _DISPLACEMENTS else max(abs(a), abs(b))
            out[key] = abs(a - b) / scale if scale > 0 else (0.0 if a == b else math.inf)
    return out


def worst(changes: dict[str, float]) -> tuple[str, float]:
    """The metric with the largest change."""
    key = max(changes, key=lambda k: changes[k])
    return key, changes[key]
