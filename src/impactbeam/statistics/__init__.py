"""Statistics of any simulation result: impacts, response, fatigue, spectra and ensembles.

Beside :mod:`impactbeam.result`: everything here reads a result (its exact
solution and events) and never runs the solver.

* :mod:`.window`: the analysis window (the stationary part of a random run) and the scan grid;
* :mod:`.impacts`: impact rate, force RMS, contact fraction, peak forces,
  durations and impulses per contactor (code_aster's definitions), from the exact events;
* :mod:`.response`: mean and RMS of the deflection and velocity at the output points;
* :mod:`.fatigue`: exact turning points of the bending stress, rainflow counting
  (ASTM E1049), Basquin's S-N curve with endurance limit and Goodman's
  correction, Miner's damage, damage rate and life;
* :mod:`.spectral`: Welch densities with chi-squared bands, spectral moments,
  Rice's crossing rate and Dirlik's spectral fatigue estimate;
* :mod:`.ensemble`: batch means over seeds with Student-t intervals.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable

from .ensemble import batch_mean, rms_from_mean_squares
from .fatigue import cycles_to_failure, fatigue_statistics, miner_damage, rainflow_cycles, stress_turning_points
from .impacts import IMPACT_UNITS, ImpactStatistics, impact_statistics
from .response import response_statistics, time_average
from .spectral import chi2_band, dirlik_damage_rate, dirlik_range_density, rice_rate, spectral_moments, welch_psd
from .window import analysis_window, scan_times, settling_time

if TYPE_CHECKING:
    from ..result.protocol import ResultLike

__all__ = [
    "ImpactStatistics", "impact_statistics", "IMPACT_UNITS", "response_statistics", "time_average",
    "fatigue_statistics", "stress_turning_points", "rainflow_cycles", "cycles_to_failure", "miner_damage",
    "welch_psd", "chi2_band", "spectral_moments", "rice_rate", "dirlik_range_density", "dirlik_damage_rate",
    "batch_mean", "rms_from_mean_squares", "analysis_window", "scan_times", "settling_time", "run_statistics",
    "statistics_stages", "STATISTICS_DISPLAY",
]

#: How summaries show the impact statistics: (key, label, scale, unit).
STATISTICS_DISPLAY = (
    ("rate", "impacts per second", 1.0, "1/s"),
    ("contact_fraction", "contact fraction", 100.0, "%"),
    ("force_rms", "force RMS", 1.0, "N"),
    ("peak_force_mean", "mean peak force", 1.0, "N"),
    ("peak_force_max", "max peak force", 1.0, "N"),
    ("duration_mean", "mean contact", 1e3, "ms"),
    ("impulse_mean", "mean impulse", 1e3, "mN s"),
)


def statistics_stages(result: ResultLike) -> int:
    """How many stages :func:`run_statistics` reports: the impacts, and each fatigue point."""
    fatigue = getattr(getattr(result, "scenario", None), "fatigue", None)
    return 1 + (len(fatigue.points) if fatigue is not None else 0)


def run_statistics(result: ResultLike, progress: Callable[[float], None] | None = None) -> dict[str, Any]:
    """The statistics ``impactbeam simulate --json`` adds: impacts per contactor and, with ``[fatigue]``, fatigue.

    Parameters
    ----------
    result : SimulationResult
    progress : callable, optional
        Called with the stages done (:func:`statistics_stages` at the end;
        fractions within a fatigue point).

    Returns
    -------
    dict
        ``statistics_window`` [s], ``impact_statistics`` (a list per contactor,
        :mod:`.impacts`) and ``fatigue`` (a list per point, :mod:`.fatigue`)
        when the scenario has ``[fatigue]``.
    """
    imp = impact_statistics(result)
    if progress is not None:
        progress(1.0)
    out: dict[str, Any] = {"statistics_window": list(imp.window), "impact_statistics": imp.contactors}
    fatigue = getattr(getattr(result, "scenario", None), "fatigue", None)
    if fatigue is not None:
        out["fatigue"] = fatigue_statistics(result, fatigue, imp.window,
                                            None if progress is None else (lambda done: progress(1.0 + done)))
    return out
