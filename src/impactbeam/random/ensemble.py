"""``random_response``: an ensemble of independent random records and its estimates with confidence.

Each member ``i`` of an ensemble of ``n`` seeds is the scenario with
``excitation.stream = i``: its load is drawn from the child
``SeedSequence(seed).spawn(n)[i]`` of the scenario's seed, independent of the
others and repeatable alone (``impactbeam simulate`` of the scenario with
that stream gives the same bits). The members are the cases of a sweep over
``excitation.stream`` (:mod:`impactbeam.sweeps`), so they run in this
process or on a Dask cluster, are written to a Zarr store as they finish,
and an interrupted ensemble resumes where it stopped. Results depend on
neither the number of workers nor the order in which members finish.

Estimates (:mod:`impactbeam.statistics.ensemble`): every per-seed value is a
time average over that record's analysis window, so the seeds are batches;
the estimate is the mean over seeds and its interval the Student-t interval
of the batch means (RMS values through their mean squares); means per impact
(peak force, duration, impulse) are pooled over all the impacts of all seeds.
"""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._warnings import emit_user_level_warning
from ..exceptions import ParameterError
from ..statistics.ensemble import batch_mean, rms_from_mean_squares
from ..statistics.record import pooled_mean

if TYPE_CHECKING:
    import xarray as xr

    from ..scenario import Scenario

__all__ = ["RandomResponse", "random_response", "STORE_NAME", "SUMMARY_NAME"]

#: The per-seed store and the summary inside an ensemble's output directory.
STORE_NAME = "seeds.zarr"
SUMMARY_NAME = "summary.json"
_STREAM = "excitation.stream"


@dataclass(frozen=True)
class RandomResponse:
    """Estimates from an ensemble of random records (module docstring).

    Attributes
    ----------
    seed : int
        The root seed (``excitation.seed``).
    seeds : int
        Members that finished (status 0) and enter the estimates.
    duration : float, [s]
        Length of each record's analysis window (after the settling time).
    warmup : float, [s]
        Start of the analysis window (the excitation's start plus the settling time).
    points : list of float, [m]
        Output points.
    rms, rms_velocity : list of float
        Deflection [m] and velocity [m/s] RMS per point.
    rms_ci, rms_velocity_ci : list of [float, float]
        Their intervals of confidence ``confidence``.
    impacts : list of dict
        Per contactor: ``rate`` [1/s], ``rate_ci``, ``force_rms`` [N],
        ``force_rms_ci``, ``peak_force_mean``, ``peak_force_max`` [N],
        ``contact_fraction``, ``contact_fraction_ci``, ``duration_mean`` [s],
        ``impulse_mean`` [N s], ``n_impacts``.
    fatigue : list of dict
        Per ``[fatigue]`` point: ``point`` [m], ``damage_rate`` [1/s],
        ``damage_rate_ci``, ``life`` [s] (1 / damage rate), ``life_ci``.
    confidence : float
    failed : int
        Members that did not finish (see ``dataset.message``).
    warnings : list of str
    dataset : xarray.Dataset
        The per-seed statistics over the dimension ``excitation.stream``.
    out : Path or None
        The output directory.
    """

    seed: int
    seeds: int
    duration: float
    warmup: float
    points: list[float]
    rms: list[float]
    rms_ci: list[list[float]]
    rms_velocity: list[float]
    rms_velocity_ci: list[list[float]]
    impacts: list[dict[str, Any]]
    fatigue: list[dict[str, Any]]
    confidence: float = 0.95
    failed: int = 0
    warnings: list[str] = field(default_factory=list)
    dataset: Any = field(default=None, repr=False)
    out: Path | None = None

    def to_dict(self) -> dict[str, Any]:
        """The JSON of ``impactbeam random --json`` (SI units; NaN intervals with one seed become null)."""
        keys = ("seed", "seeds", "duration", "warmup", "points", "rms", "rms_ci", "rms_velocity", "rms_velocity_ci",
                "impacts", "fatigue", "confidence", "failed", "warnings")
        return {k: getattr(self, k) for k in keys}


def _interval(lo: Any, hi: Any) -> list[float]:
    """An interval of a non-negative quantity: the Student-t bounds, the lower one at least 0."""
    return [max(float(lo), 0.0) if np.isfinite(lo) else float(lo), float(hi)]


def _aggregate(ds: xr.Dataset, confidence: float, has_fatigue: bool) -> dict[str, Any]:
    """Estimates and intervals from the per-seed records of the finished members."""
    done = np.asarray(ds["status"].values) == 0
    v = {name: np.asarray(ds[name].values)[done] for name in ds.data_vars if name not in ("status", "message")}
    out: dict[str, Any] = {"seeds": int(done.sum())}
    out["duration"] = float(np.mean(v["window_duration"])) if done.any() else math.nan
    out["warmup"] = float(np.mean(v["window_start"])) if done.any() else math.nan
    for name in ("rms", "rms_velocity"):
        m, lo, hi = rms_from_mean_squares(v[name] ** 2, confidence)
        out[name] = m.tolist()
        out[f"{name}_ci"] = [_interval(a, b) for a, b in zip(lo, hi)]
    impacts = []
    if "impact_rate" in v:
        rate, rlo, rhi = batch_mean(v["impact_rate"], confidence)
        frac, flo, fhi = batch_mean(v["contact_fraction"], confidence)
        frms, frlo, frhi = rms_from_mean_squares(v["force_rms"] ** 2, confidence)
        n_complete = v["n_complete"]
        for c in range(rate.size):
            impacts.append({
                "contactor": c, "rate": float(rate[c]), "rate_ci": _interval(rlo[c], rhi[c]),
                "force_rms": float(frms[c]), "force_rms_ci": _interval(frlo[c], frhi[c]),
                "peak_force_mean": float(pooled_mean(v["peak_force_mean"][:, c], n_complete[:, c])),
                "peak_force_max": float(np.nanmax(v["peak_force_max"][:, c], initial=0.0)),
                "contact_fraction": float(frac[c]), "contact_fraction_ci": _interval(flo[c], fhi[c]),
                "duration_mean": float(pooled_mean(v["duration_mean"][:, c], n_complete[:, c])),
                "impulse_mean": float(pooled_mean(v["impulse_mean"][:, c], n_complete[:, c])),
                "n_impacts": int(np.sum(v["window_impacts"][:, c])),
            })
    out["impacts"] = impacts
    fatigue = []
    if has_fatigue and "damage_rate" in v:
        d, dlo, dhi = batch_mean(v["damage_rate"], confidence)
        for j, x in enumerate(np.asarray(ds["fatigue_point"].values)):
            inv = [1.0 / b if b > 0 else math.inf for b in (dhi[j], dlo[j])]
            fatigue.append({
                "point": float(x), "damage_rate": float(d[j]), "damage_rate_ci": _interval(dlo[j], dhi[j]),
                "life": 1.0 / float(d[j]) if d[j] > 0 else math.inf,
                "life_ci": inv if math.isfinite(dlo[j]) else [math.nan, math.nan],
            })
    out["fatigue"] = fatigue
    return out


def _member_warnings(ds: xr.Dataset, seeds: int) -> list[str]:
    """The members' warnings, each once with how many members gave it (from the store: a resumed ensemble too)."""
    if "warnings" not in ds:  # a store made before they were recorded
        return []
    counts: dict[str, int] = {}
    for text in np.asarray(ds["warnings"].values).ravel():
        for line in dict.fromkeys(str(text).splitlines()):
            if line:
                counts[line] = counts.get(line, 0) + 1
    return [f"{k} of {seeds} members: {line}" for line, k in counts.items()]


def _stored_seed(store: Path) -> int | None:
    """The root seed of an existing ensemble store (to resume one whose scenario gave no seed)."""
    if not store.exists():
        return None
    try:
        import zarr

        attrs = dict(zarr.open_group(str(store), mode="r").attrs)
        return int(json.loads(attrs["sweep"])["base"]["excitation"]["seed"])
    except Exception:  # not an ensemble store: run_sweep refuses it with its own message
        return None


def random_response(
    scenario: Scenario,
    seeds: int,
    workers: int | None = None,
    *,
    scheduler: str | None = None,
    out: str | os.PathLike[str] | None = None,
    confidence: float = 0.95,
    progress: bool = False,
) -> RandomResponse:
    """Run ``seeds`` independent records of a random scenario and estimate its statistics (module docstring).

    Parameters
    ----------
    scenario : Scenario
        With ``[excitation] shape = "random"``; its ``seed`` is the root of
        the ensemble (a drawn one is reported in ``seed``).
    seeds : int
        Number of independent records.
    workers : int, optional
        Processes of a local Dask cluster (default: one per core); 0 runs in this process.
    scheduler : str, optional
        Address of a running Dask scheduler (excludes ``workers``).
    out : path, optional
        Directory for the per-seed store (``seeds.zarr``, resumed when it
        exists) and ``summary.json``; created if absent.
    confidence : float
        Probability of the intervals.
    progress : bool
        Progress bar on stderr.

    Returns
    -------
    RandomResponse

    Raises
    ------
    ParameterError
        No random excitation, a stream already set, a bad count or confidence,
        or an output directory holding another ensemble.
    SweepInterrupted
        On SIGINT / SIGTERM; the store keeps every finished member.
    """
    from ..scenario import Scenario
    from ..sweeps import SweepParameter, SweepSpec, run_sweep

    if not isinstance(scenario, Scenario):
        raise TypeError(f"random_response: expected a Scenario, got {type(scenario).__name__}")
    ex = scenario.excitation
    if ex.shape != "random" or ex.kind == "none":
        raise ParameterError('excitation.shape: an ensemble needs a random excitation (shape = "random")')
    if ex.stream is not None:
        raise ParameterError("excitation.stream: an ensemble sets the stream of each member; remove it")
    if isinstance(seeds, bool) or not isinstance(seeds, (int, np.integer)) or seeds < 1:
        raise ParameterError(f"seeds: expected a positive integer, got {seeds!r}")
    if not 0.0 < float(confidence) < 1.0:
        raise ParameterError(f"confidence: must be between 0 and 1, got {confidence!r}")
    store = None
    if out is not None:
        directory = Path(out)
        if directory.exists() and not directory.is_dir():
            raise ParameterError(f'--out: "{directory}" exists and is not a directory')
        if not directory.parent.is_dir():
            raise ParameterError(f'--out: directory "{directory.parent}" does not exist')
        directory.mkdir(exist_ok=True)
        store = directory / STORE_NAME
        stored = _stored_seed(store)
        if ex.seed_drawn and stored is not None:  # resume the stored ensemble, not a new draw
            scenario = scenario.with_values({"excitation.seed": stored})
    seed = int(scenario.excitation.seed)  # type: ignore[arg-type]
    spec = SweepSpec(
        base=scenario, design="grid",
        parameters=(SweepParameter(_STREAM, values=tuple(range(int(seeds))), dimension="integer"),),
        samples=None, seed=None, metrics=(), histories=None, source=scenario.source,
        name=f"random ensemble of {scenario.name}", statistics=True,
    )
    run = run_sweep(spec, store, workers=workers, scheduler=scheduler, progress=progress, label="ensemble")
    ds = run.dataset.load()
    est = _aggregate(ds, float(confidence), scenario.fatigue is not None)
    warnings: list[str] = []
    failed = int(np.sum(np.asarray(ds["status"].values) != 0))
    if failed:
        first = next(m for m, s in zip(ds["message"].values, ds["status"].values) if s != 0)
        warnings.append(f"{failed} of {seeds} members did not finish and are left out (first: {first})")
    if est["seeds"] < 2:
        warnings.append("fewer than two finished members: no confidence intervals")
    warnings += _member_warnings(ds, int(seeds))
    for text in warnings:
        emit_user_level_warning(text)
    return RandomResponse(
        seed=seed, points=[float(x) for x in scenario.output_points], confidence=float(confidence),
        failed=failed, warnings=warnings, dataset=ds, out=None if out is None else Path(out), **est,
    )
