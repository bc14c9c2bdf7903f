"""Batches of cases: the chunks of the store, and running one batch in a worker.

A batch's cases run through :func:`impactbeam.sweeps.cases.run_cases`: those
that share their packed problem (the usual case: a batch holds one geometry)
run in one compiled call, metrics included. Building a case is cheap too:
the paths in :data:`_DIRECT` (gaps, sides, the load's amplitude, duration,
start, frequency, phase and scale, the run's end time, output step, event
tolerance and event limit) change no packed problem and are set on the model
objects of a scenario parsed once per value of the other paths; each of
their values is read by the scenario parser itself (one parse of that value
alone, so units, checks and messages are the parser's), which gives the
same model objects as re-parsing every case (a test compares them). A case
the direct route cannot build (an invalid value, or a value the model
objects refuse in combination) is parsed whole, as before, so its error
message is the same. So is a case whose direct value the parser derives
more from (a random load's record is drawn for ``solver.end_time``). Sampled
designs, whose values are all distinct, parse every case whole.
"""

from __future__ import annotations

import dataclasses
import math
import os
import re
import sys
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from itertools import product
from typing import Any
import numpy as np

from .._warnings import WarningLog
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


#: Paths set directly on the model objects (module docstring): section, index, field.
_DIRECT = re.compile(
    r"^(?:(contactors)\.(\d+)\.(gap|side)|(excitation)\.(amplitude|duration|start|frequency|phase|scale)"
    r"|(solver)\.(end_time|time_step|event_tolerance|max_events))$"
)


class _CaseBuilder:
    """The cases of a sweep as :class:`~impactbeam.sweeps.cases.Case` objects (module docstring).

    One per worker process and sweep (:func:`_builder`): the scenarios of
    the other paths' values, the direct values as the parser reads them and
    the model objects made from them are kept, so a grid's batches reuse
    them (and the load pieces cached on an excitation object).
    """

    def __init__(self, base: Any, paths: Sequence[str]) -> None:
        self.base = base
        self.paths = tuple(paths)
        self.direct = [i for i, p in enumerate(paths) if _DIRECT.match(p)]
        self.other = [i for i in range(len(paths)) if i not in self.direct]
        self._groups: dict[str, Any] = {}
        self._fields: dict[tuple[str, int, str], Any] = {}
        self._objects: dict[tuple, Any] = {}
        self._known: set[tuple[int, str]] = set()  # direct values read already (for some group)

    def cases(self, values: Sequence[Sequence[Any]]) -> list[Any]:
        """The cases of a batch (a Case each, or the exception its scenario raises)."""
        fresh = {(i, repr(v[i])) for v in values for i in self.direct} - self._known
        # a parse per new value against one per case: a grid's values recur (and are kept for the next
        # batches), a sampled design's are all new, several per case
        whole = len(fresh) > 1.5 * len(values)
        return [self._whole(vals) if whole else self._direct(vals) or self._whole(vals) for vals in values]

    def _whole(self, vals: Sequence[Any]) -> Any:
        """The case from the scenario re-parsed with all its values (or the exception)."""
        from .cases import Case

        try:
            sc = self.base.with_values(dict(zip(self.paths, vals)))
        except Exception as exc:  # recorded for this case
            return exc
        return Case(sc.beam, sc.contactors, sc.damping, sc.excitation, sc.initial, sc.solver, sc.output_points,
                    sc.preload)

    def _direct(self, vals: Sequence[Any]) -> Any:
        """The case built from the group's scenario and the direct values, or None (parse it whole)."""
        from .cases import Case

        gkey = repr([vals[i] for i in self.other])
        group = self._groups.get(gkey)
        if group is None:
            try:
                group = self.base.with_values({self.paths[i]: vals[i] for i in self.other})
            except Exception as exc:
                group = exc
            self._groups[gkey] = group
        if isinstance(group, Exception) or self._record_depends(group):
            return None
        changes: dict[str, list[tuple[Any, ...]]] = {"contactors": [], "excitation": [], "solver": []}
        for i in self.direct:
            value = self._field(gkey, group, i, vals[i])
            if isinstance(value, Exception):
                return None
            section, *rest = self.paths[i].split(".")
            changes[section].append((*rest, value) if section == "contactors" else (rest[-1], value))
        try:
            contactors = self._made("contactors", gkey, changes["contactors"], group)
            ex = self._made("excitation", gkey, changes["excitation"], group)
            solver = self._made("solver", gkey, changes["solver"], group)
        except Exception:
            return None
        return Case(group.beam, contactors, group.damping, ex, group.initial, solver, group.output_points,
                    group.preload)

    def _record_depends(self, group: Any) -> bool:
        """Whether a direct value also changes what the parser derives from it: a random load's record lasts
        ``solver.end_time - excitation.start`` and is drawn when the scenario is read, so those cases are read
        whole (a swept start had moved the start-0 record instead)."""
        derived = ("solver.end_time", "excitation.start")
        return group.excitation.shape == "random" and any(self.paths[i] in derived for i in self.direct)

    def _made(self, section: str, gkey: str, changes: list[tuple[Any, ...]], group: Any) -> Any:
        """The group's contactors, excitation or solver options with ``changes`` made (one object per change set)."""
        if not changes:
            return getattr(group, section)
        key = (section, gkey, repr(changes))
        if key not in self._objects:
            if section == "contactors":
                con = list(group.contactors)
                for index, name, value in changes:
                    con[int(index)] = dataclasses.replace(con[int(index)], **{name: value})
                self._objects[key] = tuple(con)
            else:
                self._objects[key] = dataclasses.replace(getattr(group, section), **dict(changes))
        return self._objects[key]

    def _field(self, gkey: str, group: Any, i: int, value: Any) -> Any:
        """The model value of direct path ``i`` set to ``value``, as the parser reads it (or its exception)."""
        key = (gkey, i, repr(value))
        if key not in self._fields:
            path = self.paths[i]
            try:
                sc = group.with_values({path: value})
                section, *rest = path.split(".")
                obj = sc.contactors[int(rest[0])] if section == "contactors" else getattr(sc, section)
                self._fields[key] = getattr(obj, rest[-1])
            except Exception as exc:
                self._fields[key] = exc
            self._known.add((i, key[2]))
        return self._fields[key]


_BUILDERS: dict[str, _CaseBuilder] = {}


def _builder(batch: _Batch) -> _CaseBuilder:
    """The case builder of this batch's sweep in this process (kept for its next batches)."""
    key = repr((batch.base_data, batch.base_dir, batch.source, batch.name, batch.paths))
    b = _BUILDERS.get(key)
    if b is None:
        base = parse_scenario(batch.base_data, base_dir=batch.base_dir, source=batch.source, name=batch.name)
        b = _BUILDERS[key] = _CaseBuilder(base, batch.paths)
        while len(_BUILDERS) > 4:
            _BUILDERS.pop(next(iter(_BUILDERS)))
    return b


def run_batch(batch: _Batch) -> dict[str, Any]:
    """Run the cases of one batch (on a worker); per-case errors are recorded.

    Returns a dict of arrays over the batch's cases (C order of its region):
    one per metric, ``status``, ``message``, ``warnings`` (each case's, one
    per line) and, with histories, ``w`` (n_cases, n_times, n_points).

    Parameters
    ----------
    batch : _Batch
        The cases of one chunk of the store.
    """
    from ..result.metrics import METRIC_UNITS
    from .cases import BATCH_BYTES, case_bytes, run_cases

    _tune_malloc()
    n = len(batch.values)
    out: dict[str, Any] = {m: np.full(n, np.nan) for m in batch.metrics}
    status = np.full(n, FAILED, dtype=np.int8)
    out["modes"] = np.zeros(n, dtype=np.int16)  # modes per state of each case (stored with solver.modes = "auto")
    message = [""] * n
    out["warnings"] = [""] * n
    builder = _builder(batch)
    whole = batch.history_times is not None or batch.statistics or not set(batch.metrics) <= set(METRIC_UNITS)
    if whole:  # histories, statistics and the stress metrics need each case's whole result
        return _run_one_by_one(batch, builder.base, out, status, message)
    columns = [list(METRIC_UNITS).index(m) for m in batch.metrics]
    lo, step = 0, 1  # the first case alone gives the memory of one (a long random load: megabytes)
    while lo < n:
        built = builder.cases(batch.values[lo: lo + step])
        ok = [k for k, c in enumerate(built) if not isinstance(c, Exception)]
        with WarningLog():  # each case's warnings are stored with it (res.warnings), not issued here
            res = run_cases([built[k] for k in ok])
        row = {k: j for j, k in enumerate(ok)}
        for k, c in enumerate(built):
            err = c if isinstance(c, Exception) else res.errors[row[k]]
            if err is not None:  # the first failing case, in case order, when errors stop the sweep
                if batch.on_error == "raise":
                    raise err
                message[lo + k] = _error_message(err)
                continue
            j = row[k]
            for m, col in zip(batch.metrics, columns):
                out[m][lo + k] = res.scalars[j, col]
            status[lo + k] = res.status[j]
            out["modes"][lo + k] = res.modes[j]
            out["warnings"][lo + k] = "\n".join(res.warnings[j])
            message[lo + k] = "" if res.status[j] == 0 else " ".join(str(res.messages[j]).split())
        if step == 1 and ok:  # then as many at once as the batch memory allows
            step = max(1, BATCH_BYTES // max(case_bytes(built[ok[0]]), 1))
        lo += len(built)
    out["status"] = status
    out["message"] = message
    return out


def _run_one_by_one(batch: _Batch, base: Any, out: dict[str, Any], status: np.ndarray, message: list[str]
                    ) -> dict[str, Any]:
    """The cases with histories or statistics: each simulated alone (its deflection sampled at the history times)."""
    from ..simulation import simulate

    ht = batch.history_times
    n = len(batch.values)
    w = None if ht is None else np.full((n, ht.size, len(batch.history_points)), np.nan)
    stats = _statistics_arrays(base, n) if batch.statistics else {}
    for k, vals in enumerate(batch.values):
        try:
            with WarningLog() as log:  # the case's warnings (the run's, its statistics'): stored with it
                sc = base.with_values(dict(zip(batch.paths, vals)))
                res = simulate(sc)
                metrics = res.metrics(impacts=False) if batch.metrics else {}
                if stats:
                    from ..statistics.record import case_record

                    record = case_record(res)
                if w is not None:  # NaN after this case's end_time
                    inside = ht <= sc.solver.end_time * (1.0 + 1e-12)
                    w[k][inside] = res.displacement(list(batch.history_points), ht[inside]).T
            out["warnings"][k] = "\n".join(log.messages)
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
        out["modes"][k] = res.n_modes
        message[k] = "" if res.status == 0 else " ".join(str(res.message).split())
    out.update(stats)
    out["status"] = status
    out["message"] = message
    if w is not None:
        out["w"] = w
    return out
