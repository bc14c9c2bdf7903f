"""Running a sweep: in process or on Dask, batches written as they finish, signals handled between writes."""

from __future__ import annotations

import logging
import os
import shutil
import signal
import threading
from functools import partial
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal
import numpy as np

from .._io import WriteError, check_writable, write_error
from .._optional import check_installed, require
from .._warnings import Progress
from ..exceptions import ImpactBeamError, ParameterError, SimulationError
if TYPE_CHECKING:
    import xarray as xr
from .cluster import check_workers, dask_client, fork_context
from .batches import (
    _Batch,
    _chunk_shape,
    _error_message,
    _make_batch,
    _regions,
    run_batch,
)
from .parse import load_sweep, parse_sweep
from .spec import FAILED, NOT_RUN, SweepSpec
from .store import StoreMaker, _StoreLock, _open_existing, open_result, quiet_consolidation, statistic_names

log = logging.getLogger(__name__)

__all__ = ["SweepInterrupted", "SweepRun", "run_sweep", "sweep"]


class SweepInterrupted(KeyboardInterrupt):
    """The sweep was stopped by a signal (SIGINT or SIGTERM) between two writes.

    The store holds every batch finished so far; run the same sweep again to
    finish the rest. ``signum`` is the signal number.
    """

    def __init__(self, signum: int, done: int = 0, total: int = 0) -> None:
        super().__init__(f"interrupted by signal {signum}")
        self.signum = signum
        self.done = done
        self.total = total

    def summary(self, noun: str, where: str) -> str:
        """The line a command prints: how many ``noun`` are in ``where`` (none started: nothing was written).

        Parameters
        ----------
        noun : str
            What the runs are (``"cases"``, ``"seeds"``).
        where : str
            The store.
        """
        if not self.total:
            return f"interrupted before the first of the {noun} ran: nothing was written"
        return f"interrupted: {self.done} of {self.total} {noun} are in {where}; run the same command again to finish"


@dataclass
class SweepRun:
    """Outcome of :func:`run_sweep`.

    Parameters
    ----------
    opener : callable
        Returns the results as a Dataset (called once, on first use of
        :attr:`dataset`).

    Attributes
    ----------
    dataset : xarray.Dataset
        The results (lazily read from the store, opened on first use, or in
        memory without ``out``).
    n_cases, computed, skipped, failed : int
        All cases; cases run now; cases already done in the store (resume);
        cases that failed in this run.
    out : Path or None
    """

    opener: Any = field(repr=False)
    n_cases: int
    computed: int
    skipped: int
    failed: int
    out: Path | None

    @property
    def dataset(self) -> xr.Dataset:
        """The results (opened from the store on first use: the command line never needs them)."""
        if not hasattr(self, "_dataset"):
            self._dataset = self.opener()
        return self._dataset


class _SignalGuard:
    """Turn SIGINT/SIGTERM into SweepInterrupted, but never in the middle of a write."""

    def __init__(self) -> None:
        self.critical = False
        self.pending: int | None = None
        self.previous: dict[int, Any] = {}

    def _handler(self, signum: int, frame: Any) -> None:
        if self.critical:
            self.pending = signum
        else:
            raise SweepInterrupted(signum)

    def __enter__(self) -> _SignalGuard:
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self.previous[sig] = signal.signal(sig, self._handler)
        return self

    def __exit__(self, *exc: Any) -> None:
        for sig, handler in self.previous.items():
            signal.signal(sig, handler)

    def write(self) -> _Critical:
        return _Critical(self)


class _Critical:
    def __init__(self, guard: _SignalGuard) -> None:
        self.guard = guard

    def __enter__(self) -> None:
        self.guard.critical = True

    def __exit__(self, exc_type: Any, *rest: Any) -> None:
        self.guard.critical = False
        if exc_type is None and self.guard.pending is not None:
            raise SweepInterrupted(self.guard.pending)


class _Writer:
    """Writes finished batches into the store's chunks (status last).

    A batch's arrays are written by a few threads at once (each write is a
    round trip through Zarr's event loop, most of it waiting), then its
    status: an interrupted write leaves the batch "not yet run".
    """

    def __init__(self, store: Any, spec: SweepSpec) -> None:
        zarr = require("zarr", "sweep")

        self.group = zarr.open_group(store, mode="r+")
        names = (*spec.metrics, *statistic_names(spec), "message", "status")
        self.arrays = {name: self.group[name] for name in names}
        for name in ("modes", "warnings"):  # a store made before they were recorded has none
            if name in self.group:
                self.arrays[name] = self.group[name]
        if spec.histories is not None:
            self.arrays["w"] = self.group["w"]
        self._threads: Any = None

    def write(self, region: tuple[tuple[int, int], ...], res: Mapping[str, Any]) -> None:
        sl = tuple(slice(a, b) for a, b in region)
        shape = tuple(b - a for a, b in region)
        jobs = []
        for name, arr in self.arrays.items():
            if name == "status":
                continue
            value = res[name]
            if name in ("message", "warnings"):
                value = np.array(value, dtype=np.dtypes.StringDType())
            jobs.append((arr, np.asarray(value).reshape(shape + np.shape(value)[1:])))
        if self._threads is None:
            from concurrent.futures import ThreadPoolExecutor

            self._threads = ThreadPoolExecutor(4, thread_name_prefix="impactbeam-zarr")
        for f in [self._threads.submit(arr.__setitem__, sl, value) for arr, value in jobs]:
            f.result()
        self.arrays["status"][sl] = np.asarray(res["status"], dtype=np.int8).reshape(shape)

    def close(self) -> None:
        if self._threads is not None:
            self._threads.shutdown()

    def status(self) -> np.ndarray:
        return self.arrays["status"][...]


def run_sweep(
    spec_or_path: SweepSpec | str | os.PathLike[str] | Mapping[str, Any],
    out: str | os.PathLike[str] | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    batch_size: int | None = None,
    progress: bool = True,
    on_error: Literal["record", "raise"] = "record",
    label: str = "sweep",
) -> SweepRun:
    """Run (or resume) a sweep; like :func:`sweep` but returns a :class:`SweepRun` with counts.

    Parameters
    ----------
    spec_or_path : SweepSpec, path or mapping
        The sweep.
    out : str or path-like, optional
        Zarr store to create or resume (None: in memory).
    workers : int, optional
        Worker processes on this machine (0: in this process).
    scheduler : str, optional
        Address of a running Dask scheduler.
    batch_size : int, optional
        Cases per batch (one Zarr chunk).
    progress : bool
        Show progress on stderr (a bar on a terminal, lines into a file or a pipe).
    label : str
        What the progress calls the study ("ensemble" for a random ensemble).
    on_error : {"record", "raise"}
        Record a failed case (status -1) or raise.
    """
    for name in ("zarr", "dask", "distributed"):  # before any work: one clear message (found, not imported)
        check_installed(name, "sweep", feature="parameter sweeps")
    spec = _as_spec(spec_or_path)
    if on_error not in ("record", "raise"):
        raise ParameterError(f'on_error: must be "record" or "raise", got {on_error!r}')
    if workers is not None and scheduler is not None:
        raise ParameterError("give either workers (a local cluster) or scheduler (a running one), not both")
    check_workers(workers, "workers")
    if batch_size is not None and (isinstance(batch_size, bool) or not isinstance(batch_size, int) or batch_size < 1):
        raise ParameterError(f"batch_size: must be a positive integer, got {batch_size!r}")
    out_path = Path(out) if out is not None else None
    chunk = _chunk_shape(spec, batch_size or spec.default_batch())
    spec.check_memory(int(np.prod(chunk)))
    if out_path is None:
        _check_in_memory(spec)
    else:
        _check_store_path(out_path)
    try:
        with _StoreLock(out_path):
            return _run_locked(spec, out_path, chunk, workers, scheduler, label if progress else "", on_error)
    except OSError as exc:  # a read-only or full file system: one line; finished batches stay in the store
        err = write_error(out_path or "the sweep", exc)
        raise WriteError(err.path, f"{err.reason} (the batches finished before are kept in the store; "
                                   "free space and run the same sweep again)", errno_=err.errno) from None


def _check_store_path(out_path: Path) -> None:
    """The store is a Zarr directory in an existing, writable directory (checked before any work)."""
    if out_path.suffix and out_path.suffix.lower() != ".zarr":
        raise ParameterError(
            f'--out: "{out_path}": a sweep is stored as a Zarr directory, not a {out_path.suffix} file; give a '
            f'name ending in .zarr (then xarray.open_zarr(...).to_netcdf(...) writes a netCDF copy)'
        )
    if not out_path.parent.is_dir():
        raise ParameterError(f'--out: directory "{out_path.parent}" does not exist')
    check_writable("--out", out_path)


def _check_in_memory(spec: SweepSpec) -> None:
    """Refuse, before any work, an in-memory result larger than the memory limit."""
    from .._memory import check_memory

    per_case = 8 * len(spec.metrics) + 40 + spec.history_bytes()
    check_memory(per_case * spec.n_cases, f"an in-memory sweep of {spec.n_cases} cases",
                 "write it to a store (out=...), or sweep fewer cases or histories")


def _run_locked(spec: SweepSpec, out_path: Path | None, chunk: tuple[int, ...], workers: int | None,
                scheduler: str | None, progress: str, on_error: str) -> SweepRun:
    """:func:`run_sweep` once the store is ours; ``progress`` the label of its progress ("" for none)."""
    fresh = not (out_path is not None and out_path.exists()
                 and not (out_path.is_dir() and not any(out_path.iterdir())))
    local = maker = None
    unused = False  # a new store that an error left without a case: removed
    counts = {"computed": 0, "failed": 0}
    bar = writer = None
    try:
        with _SignalGuard() as guard:
            if fresh:  # made by a forked process (Linux) while this one runs the first batch
                maker = StoreMaker(spec, out_path, chunk)
            if fresh and workers != 0 and scheduler is None:
                # a new store runs every batch of this layout: the workers start on them while it is made
                local = _LocalWorkers(workers or os.cpu_count() or 1)
                local.start(_make_batch(spec, r, on_error) for r in _regions(spec.shape, chunk))
            require("zarr", "sweep")  # for the writer: imported while the store's maker works
            store = maker.result() if maker is not None else _open_existing(spec, out_path)  # type: ignore[arg-type]
            writer = _Writer(store, spec)
            chunk = tuple(writer.arrays["status"].chunks)  # the store's layout wins on resume
            # a new store has run nothing: no need to read its (possibly millions of) status chunks
            status = np.full(spec.shape, NOT_RUN, dtype=np.int8) if fresh else writer.status()
            regions = (r for r in _regions(spec.shape, chunk) if (status[r] == NOT_RUN).any())  # lazily
            skipped = int((status != NOT_RUN).sum())
            n_todo = spec.n_cases - skipped

            bar = Progress(spec.n_cases, desc=progress or "sweep", unit="case", enabled=bool(progress),
                           done=spec.n_cases - n_todo, after=0.0, dynamic_ncols=True)

            def done(region: tuple[tuple[int, int], ...], res: Mapping[str, Any]) -> None:
                n, written = len(res["status"]), False
                try:
                    with guard.write():  # an interrupt held during the write is raised on leaving it
                        writer.write(region, res)  # type: ignore[union-attr]
                        written = True
                finally:  # a batch written is counted, also when the interrupt comes right after it
                    if written:
                        counts["computed"] += n
                        counts["failed"] += int((np.asarray(res["status"]) == FAILED).sum())
                bar.advance(n)  # type: ignore[union-attr]

            if n_todo:
                batches = (_make_batch(spec, r, on_error) for r in regions)
                try:
                    if workers == 0:
                        for b in batches:
                            done(b.region, run_batch(b))
                    elif scheduler is None:
                        if local is None:
                            local = _LocalWorkers(workers or os.cpu_count() or 1)
                            local.start(batches)
                        local.finish(done)
                    else:
                        _run_dask(batches, done, workers=workers, scheduler=scheduler, on_error=on_error)
                except SweepInterrupted as exc:
                    exc.done = spec.n_cases - n_todo + counts["computed"]
                    exc.total = spec.n_cases
                    raise
                except Exception:  # an error before any case was stored (a scheduler out of reach): no store left
                    unused = fresh and out_path is not None and not counts["computed"]
                    raise
    finally:
        if maker is not None:
            maker.close()
        if local is not None:
            local.close()
        if bar is not None:
            bar.close()
        if writer is not None:
            writer.close()
        if unused:
            shutil.rmtree(out_path, ignore_errors=True)  # type: ignore[arg-type]
    log.info("sweep %s: %d cases, %d computed, %d already done, %d failed",
             spec.name, spec.n_cases, counts["computed"], skipped, counts["failed"])
    if out_path is not None and not fresh:  # a store made before metadata was consolidated at creation
        zarr = require("zarr", "sweep")
        with quiet_consolidation():
            zarr.consolidate_metadata(store)
    run = SweepRun(partial(open_result, spec, store, out_path is None), spec.n_cases, counts["computed"], skipped,
                   counts["failed"], out_path)
    if out_path is None:
        run.dataset  # noqa: B018 - loaded now, from the in-memory store
    return run


def _worker_start() -> None:
    """A local worker leaves SIGINT and SIGTERM to the sweep's process (which stops it) and uses one BLAS thread.

    It runs in a process group of its own: a signal sent to the sweep's group (a terminal's Ctrl-C, ``timeout``,
    a batch scheduler's SIGTERM) reaches the sweep's process alone, which stops the workers between writes. A
    worker killed by a group SIGTERM while it held the pool's task-queue lock left the sweep waiting for that
    lock for good.
    """
    os.setpgrp()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ[var] = "1"


class _LocalWorkers:
    """``workers`` processes on this machine running batches (:func:`run_batch`), a bounded window at a time.

    The processes are forked from this one where the platform allows it
    (Linux: they start at once, with the solver already loaded; the fork
    comes before Zarr starts its event-loop thread), elsewhere spawned. A
    window of batches is in flight (64, or 4 per worker if more: enough to
    keep the workers busy while a new store is being made), so a sweep of any
    size starts at once and an interrupt has only a few to drop; :meth:`close`
    terminates the processes (after an interrupt or an error too). A case's
    error reaches here only with ``on_error = "raise"``, and is raised again.
    """

    def __init__(self, workers: int) -> None:
        import queue

        self.workers = workers
        self.finished: queue.Queue[tuple[Any, Any, BaseException | None]] = queue.Queue()
        self.window = max(64, 4 * workers)
        self.pool: Any = None
        self.in_flight = 0
        self.pending: Iterator[_Batch] = iter(())

    def start(self, batches: Iterator[_Batch]) -> None:
        """Run the first batch here, then start the workers on the first window of the rest.

        The first batch loads (or compiles, on first use) the solver and
        builds the problem's states; forked workers inherit all of it instead
        of doing it once each.
        """
        import multiprocessing as mp

        self.pending = iter(batches)
        first = next(self.pending, None)
        if first is not None:
            try:
                self.finished.put((first.region, run_batch(first), None))
            except Exception as exc:
                self.finished.put((first.region, None, exc))
            self.in_flight += 1
        ctx = fork_context() or mp.get_context("spawn")
        self.pool = ctx.Pool(self.workers, initializer=_worker_start)
        while self.in_flight < self.window and self._submit():
            pass

    def _submit(self) -> bool:
        b = next(self.pending, None)
        if b is None:
            return False
        put = self.finished.put
        self.pool.apply_async(run_batch, (b,), callback=lambda r, region=b.region: put((region, r, None)),
                              error_callback=lambda e, region=b.region: put((region, None, e)))
        self.in_flight += 1
        return True

    def finish(self, done: Any) -> None:
        """``done(region, result)`` for every batch, in the order they finish."""
        while self.in_flight:
            region, res, err = self.finished.get()
            self.in_flight -= 1
            if err is not None:
                raise err
            done(region, res)
            self._submit()
        if self.pool is not None:
            self.pool.close()

    def close(self) -> None:
        if self.pool is not None:
            self.pool.terminate()
            self.pool.join()


def _run_dask(
    batches: Iterator[_Batch], done: Any, *, workers: int | None, scheduler: str | None, on_error: str = "record"
) -> None:
    """Run the batches on a Dask cluster; ``done(region, result)`` as each finishes."""
    as_completed = require("distributed", "sweep").as_completed
    futures: list[Any] = []
    with dask_client(workers, scheduler) as client:
        try:
            # a bounded window of batches in flight: a sweep of any size starts at once, and
            # an interrupt has only a few tasks to cancel
            window = 4 * max(1, len(client.scheduler_info().get("workers", {})) or (workers or 1))
            pending = iter(batches)
            region_of: dict[Any, Any] = {}

            def submit() -> Any:
                b = next(pending, None)
                if b is None:
                    return None
                fut = client.submit(run_batch, b, pure=False)
                region_of[fut.key] = b.region
                futures.append(fut)
                return fut

            first = [f for f in (submit() for _ in range(window)) if f is not None]
            queue = as_completed(first, with_results=True)
            for fut, res in queue:
                done(region_of.pop(fut.key), res)
                fut.release()
                futures.remove(fut)
                nxt = submit()
                if nxt is not None:
                    queue.add(nxt)
        except (ImpactBeamError, SweepInterrupted):
            raise
        except Exception as exc:
            # run_batch records every case's own error, so this is the cluster's
            # (a worker died, impactbeam missing on a worker): nothing is stored for it
            if on_error == "raise":
                raise
            raise SimulationError(
                f"a batch failed on the Dask cluster ({_error_message(exc)}); the finished batches "
                "are stored: run the same sweep again to retry the rest"
            ) from exc
        finally:
            if futures:
                client.cancel(futures)


def _as_spec(spec_or_path: Any) -> SweepSpec:
    if isinstance(spec_or_path, SweepSpec):
        return spec_or_path
    if isinstance(spec_or_path, Mapping):
        return parse_sweep(spec_or_path)
    return load_sweep(spec_or_path)


def sweep(
    spec_or_path: SweepSpec | str | os.PathLike[str] | Mapping[str, Any],
    out: str | os.PathLike[str] | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    batch_size: int | None = None,
    progress: bool = True,
    on_error: Literal["record", "raise"] = "record",
) -> xr.Dataset:
    """Run a parameter study and return its labelled results.

    Parameters
    ----------
    spec_or_path : SweepSpec, path or mapping
        A sweep file (TOML, see the module docstring), its parsed mapping or a
        :class:`SweepSpec`.
    out : path, optional
        Zarr store (a directory). Created with every case "not yet run" and
        filled as batches finish; if it exists and was made by the same sweep,
        only the missing cases run (resume). Without ``out`` the results are
        kept in memory.
    workers : int, optional
        Worker processes on this machine (forked from this one on Linux,
        spawned elsewhere); default all cores. ``0`` runs the cases in this
        process.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``) whose
        workers run the cases (they need ``impactbeam`` installed and the
        scenario's files at the same paths).
    batch_size : int, optional
        Cases per task (= per Zarr chunk); default :func:`default_batch_size`.
        A resumed store keeps its own batches.
    progress : bool
        Progress on stderr (a bar on a terminal, lines into a file or a pipe).
    on_error : {"record", "raise"}
        ``record``: a case that fails gets status -1, its error in ``message``
        and NaN metrics, and the sweep goes on; ``raise``: the first failure
        stops the sweep.

    Returns
    -------
    xarray.Dataset
        One dimension per grid parameter (named by its path) or ``case``;
        metric variables (``units`` in their attributes), ``status``,
        ``message`` and optional ``w`` histories.

    Raises
    ------
    ScenarioError
        For an invalid sweep file (one line naming the key).
    ParameterError
        For ``out`` made by a different sweep, or bad arguments.
    SweepInterrupted
        On SIGINT / SIGTERM; the store keeps every finished batch.
    """
    return run_sweep(
        spec_or_path, out, workers=workers, scheduler=scheduler, batch_size=batch_size,
        progress=progress, on_error=on_error,
    ).dataset
