"""Two-parameter maps of the steady state (e.g. frequency x amplitude -> period), on Dask, resumable.

Each row of the map (one value of the ``y`` parameter) is one continuation
sweep along ``x`` (:func:`~impactbeam.periodic.bifurcation.bifurcation`,
``sweep = "up"`` or ``"down"``), run as one task on a local Dask cluster (or a
running scheduler, or in this process with ``workers = 0``). The results go
to a Zarr store as each row finishes, with a ``done`` flag per row written
after the row's data: stop the run at any time and call it again with the same
arguments to compute only the missing rows. A store made with other
arguments is refused (its ``map_hash`` attribute differs).

Variables over ``(y, x)``: ``period`` (0: none found), ``impacts_per_period``,
``max``, ``min`` [m]; over ``(y, x, sample)``: ``strobe`` [m].
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._optional import require
from ..exceptions import ParameterError
from .bifurcation import _dimension, _unit, _with, bifurcation, parameter_values
from .forcing import harmonic_period
from .strobe import PERIOD_TOLERANCE, count

if TYPE_CHECKING:
    from ..scenario import Scenario

__all__ = ["bifurcation_map", "map_row"]


def map_row(data: dict[str, Any], base_dir: str | None, x_key: str, x_values: list[float], y_key: str,
            y_value: float, sweep: str, settle: int, record: int, tolerance: float) -> dict[str, np.ndarray]:
    """One row of the map (runs on a worker): the sweep along ``x`` at one ``y``."""
    import warnings

    from ..exceptions import ImpactBeamWarning
    from ..scenario import parse_scenario

    sc = parse_scenario(data, base_dir=base_dir)
    sc = _with(sc, y_key, y_value)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ImpactBeamWarning)  # recorded as period 0 in the map
        d = bifurcation(sc, x_key, x_values, sweep=sweep, settle_periods=settle,  # type: ignore[arg-type]
                        record_periods=record, tolerance=tolerance)
    pts = sorted(d.points, key=lambda p: p.value)
    return {
        "period": np.array([p.state.period for p in pts], dtype=np.int64),
        "impacts_per_period": np.array([p.state.impacts_per_period for p in pts]),
        "max": np.array([p.state.max for p in pts]),
        "min": np.array([p.state.min for p in pts]),
        "strobe": np.stack([p.state.strobe[:record] for p in pts]),
    }


def _hash(sc: Scenario, x: tuple[str, list[float]], y: tuple[str, list[float]], sweep: str, settle: int,
          record: int, tolerance: float) -> str:
    text = json.dumps([sc.data, x, y, sweep, settle, record, tolerance], sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _template(x: tuple[str, list[float]], y: tuple[str, list[float]], record: int, units: tuple[str, str],
              attrs: dict[str, Any]) -> Any:
    import xarray as xr

    ny, nx = len(y[1]), len(x[1])
    return xr.Dataset(
        {
            "period": (("y", "x"), np.zeros((ny, nx), dtype=np.int64), {"units": "1"}),
            "impacts_per_period": (("y", "x"), np.full((ny, nx), np.nan), {"units": "1"}),
            "max": (("y", "x"), np.full((ny, nx), np.nan), {"units": "m"}),
            "min": (("y", "x"), np.full((ny, nx), np.nan), {"units": "m"}),
            "strobe": (("y", "x", "sample"), np.full((ny, nx, record), np.nan), {"units": "m"}),
            "done": ("y", np.zeros(ny, dtype=bool)),
        },
        coords={"x": ("x", np.asarray(x[1]), {"long_name": x[0], "units": units[0]}),
                "y": ("y", np.asarray(y[1]), {"long_name": y[0], "units": units[1]}),
                "sample": ("sample", np.arange(record))},
        attrs=attrs,
    )


def _open_or_create(out: Path, template: Any) -> Any:
    """The store's ``done`` flags; a new store from ``template``; ParameterError for another map's store."""
    import xarray as xr

    if out.exists():
        try:
            old = xr.open_zarr(str(out), consolidated=False)
        except Exception as exc:
            raise ParameterError(f'out: "{out}" exists and is not a map store ({type(exc).__name__})') from None
        if old.attrs.get("map_hash") != template.attrs["map_hash"]:
            raise ParameterError(f'out: "{out}" holds another map (other scenario, parameters or periods); '
                                 "give a new path or delete it")
        return np.asarray(old["done"].values, dtype=bool)
    template.to_zarr(str(out), mode="w-", consolidated=False)
    return np.zeros(template.sizes["y"], dtype=bool)


def _write_row(out: Path, i: int, row: dict[str, np.ndarray]) -> None:
    import xarray as xr

    ds = xr.Dataset({
        "period": (("y", "x"), row["period"][None]),
        "impacts_per_period": (("y", "x"), row["impacts_per_period"][None]),
        "max": (("y", "x"), row["max"][None]), "min": (("y", "x"), row["min"][None]),
        "strobe": (("y", "x", "sample"), row["strobe"][None]),
    })
    ds.to_zarr(str(out), region={"y": slice(i, i + 1), "x": slice(None), "sample": slice(None)}, consolidated=False)
    xr.Dataset({"done": ("y", np.array([True]))}).to_zarr(str(out), region={"y": slice(i, i + 1)}, consolidated=False)


def bifurcation_map(
    scenario: Scenario,
    x: tuple[str, Sequence[Any]],
    y: tuple[str, Sequence[Any]],
    out: str | os.PathLike[str],
    *,
    sweep: str = "up",
    settle_periods: int = 100,
    record_periods: int = 20,
    tolerance: float = PERIOD_TOLERANCE,
    workers: int | None = None,
    scheduler: str | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> Any:
    """Period, impacts per period and extremes of the steady state over two parameters.

    Parameters
    ----------
    scenario : Scenario
        With a harmonic load.
    x, y : (key, values)
        Scenario keys and their values (SI numbers or strings with units).
        Each row (one ``y`` value) is a continuation sweep along ``x``.
    out : path
        Zarr store; an existing store of the same map is resumed.
    sweep : {"up", "down"}
        Direction of the sweep along ``x`` in each row.
    settle_periods, record_periods, tolerance
        As for :func:`~impactbeam.periodic.bifurcation.bifurcation`.
    workers : int, optional
        Worker processes of a local Dask cluster (default: all cores); 0
        runs in this process.
    scheduler : str, optional
        Address of a running Dask scheduler.
    progress : callable, optional
        ``progress(done_rows, total_rows)``.

    Returns
    -------
    xarray.Dataset
        The store, opened (dims y, x, sample).
    """
    xr = require("xarray", "sweep")
    require("zarr", "sweep")
    if sweep not in ("up", "down"):
        raise ParameterError(f"sweep: expected 'up' or 'down' along x, got {sweep!r}")
    if workers is not None and scheduler is not None:
        raise ParameterError("workers and scheduler exclude each other")
    from ..sweeps.cluster import check_workers

    check_workers(workers, "workers")
    settle = count("settle_periods", settle_periods, 0)
    record = count("record_periods", record_periods, 2)
    harmonic_period(scenario)
    xs = (x[0], parameter_values(x[0], scenario, list(x[1])))
    ys = (y[0], parameter_values(y[0], scenario, list(y[1])))
    for key, vals in (xs, ys):
        for v in dict.fromkeys(vals):
            harmonic_period(_with(scenario, key, v))  # every value checked before anything runs
    path = Path(out)
    if not path.parent.is_dir():
        raise ParameterError(f'out: directory "{path.parent}" does not exist')
    from ..result.dataset import provenance

    attrs = {**provenance(f"impactbeam bifurcation map over {xs[0]} and {ys[0]}", "bifurcation-map",
                          "strobe samples of exact piecewise modal runs, each row a continuation sweep along x"),
             "map_hash": _hash(scenario, xs, ys, sweep, settle, record, tolerance), "x_parameter": xs[0],
             "y_parameter": ys[0], "sweep": sweep, "settle_periods": settle, "record_periods": record,
             "tolerance": tolerance, "scenario": scenario.to_toml()}
    units = (_unit(_dimension(xs[0], scenario)), _unit(_dimension(ys[0], scenario)))
    done = _open_or_create(path, _template(xs, ys, record, units, attrs))
    todo = [i for i in range(len(ys[1])) if not done[i]]
    base = None if scenario.base_dir is None else str(scenario.base_dir)
    args = [(scenario.data, base, xs[0], xs[1], ys[0], ys[1][i], sweep, settle, record, tolerance) for i in todo]
    finished = len(ys[1]) - len(todo)

    def store(i: int, row: dict[str, np.ndarray]) -> None:
        nonlocal finished
        _write_row(path, i, row)
        finished += 1
        if progress is not None:
            progress(finished, len(ys[1]))

    if workers == 0 or not todo:
        for i, a in zip(todo, args):
            store(i, map_row(*a))
    else:
        _run_on_dask(todo, args, store, workers, scheduler)
    return xr.open_zarr(str(path), consolidated=False)


def _run_on_dask(todo: list[int], args: list[tuple], store: Callable[[int, dict], None], workers: int | None,
                 scheduler: str | None) -> None:
    """Submit one task per row; store each as it finishes; cancel the rest on an interrupt."""
    from ..sweeps.cluster import dask_client

    distributed = require("distributed", "sweep")
    futures: list[Any] = []
    with dask_client(workers, scheduler) as client:
        try:
            row_of = {}
            for i, a in zip(todo, args):
                fut = client.submit(map_row, *a, pure=False)
                row_of[fut.key] = i
                futures.append(fut)
            for fut, row in distributed.as_completed(futures, with_results=True):
                store(row_of[fut.key], row)
        finally:
            client.cancel(futures)
