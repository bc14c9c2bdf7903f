"""Impact statistics of a steady state: :func:`impactbeam.statistics.impact_statistics` over its record.

Kept as the periodic package's name for them; the rules live in
:mod:`impactbeam.statistics.impacts` (one copy for every run: transient,
harmonic, random). For a steady state the window is the recorded periods and
``impacts_per_forcing_period`` is added per contactor.
"""

from __future__ import annotations

from ..statistics.impacts import ImpactStatistics, impact_statistics

__all__ = ["ImpactStatistics", "impact_statistics"]
