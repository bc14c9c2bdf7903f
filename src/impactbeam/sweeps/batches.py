"""Batches of cases: the chunks of the store, and running one batch in a worker."""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from itertools import product
from typing import Any
import numpy as np

from ..exceptions import ImpactBeamError
from ..scenario import parse_scenario
from .spec import FAILED, SweepSpec, _plain, default_batch_size

__all__ = ["default_batch_size", "run_batch"]


def _chunk_shape(spec: SweepSpec, batch_size: int) -> tuple[int, ...]:
    """Chunk (= batch) shape: fill the non-geometry dimensions first, innermost outward.

    A batch then holds as few geometries as possible, so its cases reuse the
    cached mode sets of :func:`impactbeam.mode_set`.
    """
    shape = spec.shape

    def balanced(n: int, fit: int) -> int:  # equal chunks rather than fit, fit, ..., remainder
        return math.ceil(n / math.ceil(n / fit)) if fit < n else n

    if not spec.is_grid:
        return (balanced(shape[0], max(1, batch_size)),)
    chunk = [1] * len(shape)
    order = [i for i in reversed(range(len(shape))) if not spec.parameters[i].geometry]
    order += [i for i in reversed(range(len(shape))) if spec.parameters[i].geometry]
    size = 1
    for i in order:
        chunk[i] = balanced(shape[i], max(1, batch_size // size))
        size *= chunk[i]
        if chunk[i] < shape[i]:
            break
    return tuple(chunk)


def _regions(shape: tuple[int, ...], chunk: tuple[int, ...]) -> Iterator[tuple[slice, ...]]:
    ranges = [range(0, n, c) for n, c in zip(shape, chunk)]
    for starts in product(*ranges):
        yield tuple(slice(s, min(s + c, n)) for s, c, n in zip(starts, chunk, shape))


@dataclass(frozen=True)
class _Batch:
    """What a worker needs to run one batch (small and picklable)."""

    region: tuple[tuple[int, int], ...]
    base_data: dict[str, Any]
    base_dir: str | None
    source: str | None
    name: str
    paths: tuple[str, ...]
    values: tuple[tuple[Any, ...], ...]
    metrics: tuple[str, ...]
    history_times: np.ndarray | None
    history_points: tuple[float, ...]
    on_error: str
    statistics: bool = False


def _make_batch(spec: SweepSpec, region: tuple[slice, ...], on_error: str) -> _Batch:
    if spec.is_grid:
        idx = product(*[range(s.start, s.stop) for s in region])
        values = tuple(tuple(_plain(p.values[i]) for p, i in zip(spec.parameters, ix)) for ix in idx)  # type: ignore[index]
    else:
        rows = spec.sample_values()[region[0]]
        values = tuple(tuple(float(v) for v in row) for row in rows)
    hist = spec.histories
    return _Batch(
        region=tuple((s.start, s.stop) for s in region),
        base_data=spec.base.data,
        base_dir=None if spec.base.base_dir is None else str(spec.base.base_dir),
        source=None if spec.base.source is None else str(spec.base.source),
        name=spec.base.name,
        paths=spec.paths,
        values=values,
        metrics=spec.metrics,
        history_times=spec.history_times() if hist is not None else None,
        history_points=hist.points if hist is not None else (),
        on_error=on_error,
        statistics=spec.statistics,
    )


def _error_message(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    if isinstance(exc, ImpactBeamError):
        return text
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


_MALLOC_TUNED = False


def _tune_malloc() -> None:
    """Undo the effect of ``MALLOC_TRIM_THRESHOLD_`` on glibc's mmap threshold (once per process).

    Dask's nannies set ``MALLOC_TRIM_THRESHOLD_`` in their workers, which
    freezes glibc's mmap threshold at 128 KiB: every solver array above that
    is then mmap-ed and page-faulted afresh, ~40 % slower per simulation
    (measured on Case 3). Raising the threshold to 32 MiB (glibc's maximum)
    restores the speed; memory returned by the sweep's arrays is still
    reused. Only on glibc and only when the variable is set; numerics are
    unaffected.
    """
    global _MALLOC_TUNED
    if _MALLOC_TUNED or "MALLOC_TRIM_THRESHOLD_" not in os.environ or not sys.platform.startswith("linux"):
        return
    _MALLOC_TUNED = True
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6")
        libc.mallopt(-3, 32 * 1024 * 1024)  # M_MMAP_THRESHOLD
    except (OSError, AttributeError):  # not glibc
        pass


def _statistics_arrays(base: Any, n: int) -> dict[str, np.ndarray]:
    """NaN arrays for the per-case statistics of ``n`` cases (:mod:`impactbeam.statistics.record`)."""
    from ..statistics.record import record_coordinates, record_variables

    sizes = {dim: c.size for dim, c in record_coordinates(base).items()}
    return {name: np.full((n,) if dim is None else (n, sizes[dim]), np.nan)
            for name, (dim, _, _) in record_variables(base).items()}


def run_batch(batch: _Batch) -> dict[str, Any]:
    """Run the cases of one batch (on a worker); per-case errors are recorded.

    Returns a dict of arrays over the batch's cases (C order of its region):
    one per metric, ``status``, ``message`` and, with histories, ``w``
    (n_cases, n_times, n_points).

    Parameters
    ----------
    batch : _Batch
        The cases of one chunk of the store.
    """
    from ..simulation import simulate

    _tune_malloc()
    n = len(batch.values)
    out: dict[str, Any] = {m: np.full(n, np.nan) for m in batch.metrics}
    status = np.full(n, FAILED, dtype=np.int8)
    message = [""] * n
    ht = batch.history_times
    w = None if ht is None else np.full((n, ht.size, len(batch.history_points)), np.nan)
    base = parse_scenario(batch.base_data, base_dir=batch.base_dir, source=batch.source, name=batch.name)
    stats = _statistics_arrays(base, n) if batch.statistics else {}
    for k, vals in enumerate(batch.values):
        try:
            sc = base.with_values(dict(zip(batch.paths, vals)))
            res = simulate(sc)
            metrics = res.metrics(impacts=False) if batch.metrics else {}
            if stats:
                from ..statistics.record import case_record

                record = case_record(res)
            if w is not None:  # NaN after this case's end_time
                inside = ht <= sc.solver.end_time * (1.0 + 1e-12)
                w[k][inside] = res.displacement(list(batch.history_points), ht[inside]).T
        except Exception as exc:  # recorded: the sweep goes on
            if batch.on_error == "raise":
                raise
            message[k] = _error_message(exc)
            continue
        for m in batch.metrics:
            v = metrics.get(m)
            out[m][k] = np.nan if v is None else float(v)
        for name, arr in stats.items():
            arr[k] = record[name]
        status[k] = res.status
        message[k] = "" if res.status == 0 else " ".join(str(res.message).split())
    out.update(stats)
    out["status"] = status
    out["message"] = message
    if w is not None:
        out["w"] = w
    return out
