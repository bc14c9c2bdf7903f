"""The Dask cluster of parallel studies: a local cluster tuned for the solver, or a running scheduler.

Used by parameter sweeps (:mod:`impactbeam.sweeps`) and by bifurcation maps
(:mod:`impactbeam.periodic.maps`).
"""

from __future__ import annotations

import contextlib
import logging
import os
from collections.abc import Iterator
from typing import Any

from .._optional import require
from ..exceptions import ParameterError

__all__ = ["WORKER_BYTES", "check_workers", "dask_client", "fork_context", "worker_config"]

#: Memory of one worker of the local cluster once it has run a case: its process (~190 MiB
#: resident after one Case-3 simulation, measured) and its nanny (~60 MiB).
WORKER_BYTES = 256 << 20
#: Most worker processes per core: the cases are CPU-bound, more only wait for a core.
WORKERS_PER_CORE = 4


def check_workers(workers: int | None, option: str = "--workers") -> None:
    """Refuse a local cluster larger than the machine: more than 4 per core or more than the memory holds.

    Parameters
    ----------
    workers : int or None
        Requested worker processes (None: one per core, always accepted).
    option : str
        The option named in the error.

    Raises
    ------
    ParameterError
        With the estimate and the largest count accepted.
    """
    if workers is None:
        return
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 0:
        raise ParameterError(f"{option}: must be an integer >= 0, got {workers!r}")
    from .._memory import memory_limit

    cores = os.cpu_count() or 1
    limit = memory_limit()
    most = max(1, min(WORKERS_PER_CORE * cores, limit // WORKER_BYTES))
    if workers > most:
        raise ParameterError(
            f"{option}: {workers} worker processes would need about {workers * WORKER_BYTES / 2**30:.3g} GiB "
            f"({WORKER_BYTES >> 20} MiB each; the limit is {limit / 2**30:.3g} GiB) on {cores} core"
            f"{'s' if cores != 1 else ''}; use at most {most} (0 runs in this process)"
        )


def worker_config() -> dict[str, Any]:
    """Dask settings for the local cluster's worker processes.

    * One BLAS thread per worker (the matrices are small; also makes results
      independent of the core count).
    * No ``MALLOC_TRIM_THRESHOLD_``: distributed sets it to 64 KiB by default,
      which pins glibc's mmap threshold, so every array of the solver
      (hundreds of kB) is mmap-ed and page-faulted afresh; measured here that
      makes a simulation ~40 % slower.
    * No statistical profiler (it samples the computing thread every 10 ms).
    """
    dask = require("dask", "sweep")

    env = dict(dask.config.get("distributed.nanny.pre-spawn-environ", {}) or {})
    env.pop("MALLOC_TRIM_THRESHOLD_", None)
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        env[var] = 1
    return {"distributed.nanny.pre-spawn-environ": env, "distributed.worker.profile.enabled": False}


@contextlib.contextmanager
def dask_client(workers: int | None, scheduler: str | None) -> Iterator[Any]:
    """A Dask client, closed (with its local cluster) on exit.

    Parameters
    ----------
    workers : int or None
        Processes of a local cluster (one thread each; default: one per core).
    scheduler : str or None
        Address of a running scheduler; excludes a local cluster.

    Yields
    ------
    distributed.Client

    Raises
    ------
    ParameterError
        The scheduler cannot be reached.
    """
    dask = require("dask", "sweep")
    distributed = require("distributed", "sweep")
    cluster = None
    if scheduler is not None:
        try:
            client = distributed.Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as exc:
            raise ParameterError(f'--scheduler: cannot connect to "{scheduler}": {exc}') from None
    else:
        check_workers(workers)
        with dask.config.set(worker_config()):
            cluster = distributed.LocalCluster(
                n_workers=workers or os.cpu_count() or 1,
                threads_per_worker=1,
                processes=True,
                dashboard_address=None,
                silence_logs=logging.ERROR,
            )
        client = distributed.Client(cluster)
    try:
        yield client
    finally:
        try:
            client.close()
        finally:
            if cluster is not None:
                cluster.close()


def fork_context() -> Any:
    """The multiprocessing context that forks this process where forking is safe to use (Linux), else None.

    A forked process starts at once with what this one has loaded (the
    solver's kernels, the problem's states); elsewhere (macOS, Windows)
    processes are spawned, or the work is done in this process.
    """
    import multiprocessing as mp
    import sys

    if sys.platform.startswith("linux") and "fork" in mp.get_all_start_methods():
        return mp.get_context("fork")
    return None
