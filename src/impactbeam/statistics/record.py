"""The statistics of one run as fixed arrays: what sweeps store per case and ensembles combine per seed.

:func:`case_record` turns a result into the variables of
:data:`RECORD_VARIABLES`, each a scalar or an array over one of the
dimensions ``output_point`` (the scenario's output points), ``contactor``
or ``fatigue_point`` (``[fatigue] points``); :func:`record_coordinates` gives
those dimensions' coordinates for a scenario. Every value is a time average
over the analysis window (:func:`~impactbeam.statistics.window.analysis_window`)
or a count in it, so the records of independent seeds are batch means.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from .fatigue import fatigue_statistics
from .impacts import impact_statistics
from .response import response_statistics

if TYPE_CHECKING:
    from ..result.protocol import ResultLike

__all__ = ["RECORD_VARIABLES", "case_record", "record_coordinates", "record_variables", "pooled_mean"]

#: name -> (dimension or None, units, long name)
RECORD_VARIABLES: dict[str, tuple[str | None, str, str]] = {
    "window_start": (None, "s", "start of the analysis window"),
    "window_duration": (None, "s", "length of the analysis window"),
    "rms": ("output_point", "m", "RMS deflection"),
    "rms_velocity": ("output_point", "m/s", "RMS velocity"),
    "impact_rate": ("contactor", "1/s", "impacts per second"),
    "window_impacts": ("contactor", "1", "impacts begun in the window"),
    "n_complete": ("contactor", "1", "impacts begun and ended in the window"),
    "contact_fraction": ("contactor", "1", "fraction of the time in contact"),
    "force_mean": ("contactor", "N", "mean contact force over the total time"),
    "force_rms": ("contactor", "N", "RMS contact force over the total time"),
    "peak_force_mean": ("contactor", "N", "mean peak force of the impacts"),
    "peak_force_max": ("contactor", "N", "largest peak force"),
    "duration_mean": ("contactor", "s", "mean contact duration"),
    "impulse_mean": ("contactor", "N s", "mean impulse of the impacts"),
    "damage": ("fatigue_point", "1", "Miner damage over the window"),
    "damage_rate": ("fatigue_point", "1/s", "Miner damage per second"),
    "life": ("fatigue_point", "s", "fatigue life (1 / damage rate)"),
}

# the record's names of the impact statistics' keys: the Table-2 metric n_impacts (every impact of the run, one
# number) keeps its name in a sweep's store beside these
_FROM_IMPACTS = {"impact_rate": "rate", "window_impacts": "n_impacts"}


def record_coordinates(scenario: Any) -> dict[str, np.ndarray]:
    """Coordinates of the record's dimensions for a scenario.

    Parameters
    ----------
    scenario : Scenario

    Returns
    -------
    dict
        ``output_point`` [m], ``contactor`` (indices), ``fatigue_point`` [m] (empty without ``[fatigue]``).
    """
    fatigue = getattr(scenario, "fatigue", None)
    return {
        "output_point": np.asarray(scenario.output_points, dtype=float),
        "contactor": np.arange(len(scenario.contactors), dtype=np.int64),
        "fatigue_point": np.asarray(fatigue.points if fatigue is not None else (), dtype=float),
    }


def record_variables(scenario: Any) -> dict[str, tuple[str | None, str, str]]:
    """:data:`RECORD_VARIABLES` without those over an empty dimension (no contactor, no ``[fatigue]``).

    Parameters
    ----------
    scenario : Scenario

    Returns
    -------
    dict
    """
    sizes = {dim: c.size for dim, c in record_coordinates(scenario).items()}
    return {k: v for k, v in RECORD_VARIABLES.items() if v[0] is None or sizes[v[0]] > 0}


def case_record(result: ResultLike) -> dict[str, Any]:
    """The variables of :data:`RECORD_VARIABLES` for one result (NaN where undefined).

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    dict
        Floats for the scalars, 1-D float arrays over each dimension.
    """
    imp = impact_statistics(result)
    resp = response_statistics(result, imp.window)
    out: dict[str, Any] = {"window_start": imp.window[0], "window_duration": imp.duration,
                           "rms": np.asarray(resp["rms"]), "rms_velocity": np.asarray(resp["rms_velocity"])}
    for name, (dim, _, _) in RECORD_VARIABLES.items():
        if dim == "contactor":
            key = _FROM_IMPACTS.get(name, name)
            out[name] = np.array([c[key] for c in imp.contactors], dtype=float)
    fat = fatigue_statistics(result, None, imp.window)
    for name in ("damage", "damage_rate", "life"):
        out[name] = np.array([f[name] for f in fat], dtype=float)
    return out


def pooled_mean(means: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """``sum(mean_i n_i) / sum(n_i)`` over the first axis, ignoring the NaN means of empty batches.

    Parameters
    ----------
    means, counts : ndarray, (n_seeds, ...)

    Returns
    -------
    ndarray
    """
    m = np.asarray(means, dtype=float)
    n = np.asarray(counts, dtype=float)
    total = np.sum(np.where(n > 0, m * n, 0.0), axis=0)
    count = np.sum(n, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.where(count > 0, count, 1.0), math.nan)
