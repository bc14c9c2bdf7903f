"""The Zarr store of a sweep: created from metadata, reopened to resume, guarded by one writer's lock."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import time
from collections.abc import Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any
import numpy as np

from .._io import pid_alive
from .._optional import require
from ..exceptions import ParameterError
if TYPE_CHECKING:
    import xarray as xr
from .parse import metric_units
from .spec import NOT_RUN, STATUS_CODES, SweepSpec

__all__ = []


def _template(spec: SweepSpec, chunk: tuple[int, ...]) -> tuple[xr.Dataset, dict[str, Any]]:
    """The empty result (every case not run) as a lazy Dataset, and its Zarr encoding.

    Each variable is one lazy dask chunk (never computed: only the metadata
    is written), so a sweep of millions of cases starts at once; the Zarr
    encoding sets the on-disk chunks, one per batch.
    """
    da = require("dask.array", "sweep")
    import xarray as xr

    from .. import __version__

    S = np.dtypes.StringDType()
    shape, dims = spec.shape, spec.dims
    coords: dict[str, Any] = {}
    if spec.is_grid:
        for p in spec.parameters:
            vals = list(p.values or ())
            arr = np.array(vals, dtype=S) if isinstance(vals[0], str) else np.array(vals)
            attrs = {"long_name": p.path}
            if p.units is not None:
                attrs["units"] = p.units
            coords[p.path] = xr.Variable((p.path,), arr, attrs)
    else:
        coords["case"] = xr.Variable(("case",), np.arange(shape[0], dtype=np.int64), {"long_name": "case number"})
        x = spec.sample_values()
        for j, p in enumerate(spec.parameters):
            attrs = {"long_name": p.path, "distribution": p.distribution or "", "distribution_args": list(p.args)}
            if p.units is not None:
                attrs["units"] = p.units
            coords[p.path] = xr.Variable(("case",), x[:, j].copy(), attrs)
    data: dict[str, Any] = {}
    enc: dict[str, Any] = {}
    units = metric_units(spec.base)
    for m in spec.metrics:
        data[m] = xr.Variable(dims, da.full(shape, np.nan, chunks=-1), {"units": units[m], "long_name": m.replace("_", " ")})
        enc[m] = {"chunks": chunk, "fill_value": np.nan}
    data["status"] = xr.Variable(
        dims,
        da.full(shape, NOT_RUN, dtype=np.int8, chunks=-1),
        {
            "long_name": "case status",
            "flag_values": list(STATUS_CODES),
            "flag_meanings": " ".join(v.replace(" ", "_") for v in STATUS_CODES.values()),
        },
    )
    enc["status"] = {"chunks": chunk, "fill_value": NOT_RUN}
    data["message"] = xr.Variable(dims, da.full(shape, "", dtype=S, chunks=-1), {"long_name": "error or solver message"})
    enc["message"] = {"chunks": chunk}
    data["warnings"] = xr.Variable(dims, da.full(shape, "", dtype=S, chunks=-1),
                                   {"long_name": "the case's warnings, one per line (empty: none)"})
    enc["warnings"] = {"chunks": chunk}
    if spec.base.solver.modes == "auto":  # the count each case chose (0: not run or failed)
        data["modes"] = xr.Variable(dims, da.full(shape, 0, dtype=np.int16, chunks=-1),
                                    {"long_name": 'modes per state chosen by solver.modes = "auto"'})
        enc["modes"] = {"chunks": chunk, "fill_value": 0}
    if spec.statistics:
        _statistics_template(spec, chunk, coords, data, enc)
    if spec.histories is not None:
        t = spec.history_times()
        pts = np.array(spec.histories.points)
        coords["time"] = xr.Variable(("time",), t, {"units": "s", "long_name": "time"})
        coords["point"] = xr.Variable(("point",), pts, {"units": "m", "long_name": "x of the output point"})
        hchunk = (*chunk, t.size, pts.size)
        data["w"] = xr.Variable(
            (*dims, "time", "point"),
            da.full((*shape, t.size, pts.size), np.nan, chunks=-1),
            {"units": "m", "long_name": "deflection w(x, t)"},
        )
        enc["w"] = {"chunks": hchunk, "fill_value": np.nan}
    c0 = spec.base.contactors[0] if spec.base.contactors else None
    where = (
        "u at the first contactor, positive away from it (u = -w for a contactor above the beam)"
        if c0 is not None
        else "u = w at the first output point"
    )
    attrs = {
        "title": f"impactbeam sweep {spec.name!r} of scenario {spec.base.name!r}",
        "design": spec.design,
        "n_cases": spec.n_cases,
        "sweep_hash": spec.hash,
        "sweep": spec.canonical_json,
        "metrics_of": where,
        "status_codes": "; ".join(f"{k}: {v}" for k, v in STATUS_CODES.items()),
        "impactbeam_version": __version__,
    }
    if not spec.is_grid:
        attrs["seed"] = int(spec.seed or 0)
        attrs["samples"] = int(spec.samples or 0)
    return xr.Dataset(data, coords, attrs), enc


def _statistics_template(spec: SweepSpec, chunk: tuple[int, ...], coords: dict[str, Any], data: dict[str, Any],
                         enc: dict[str, Any]) -> None:
    """The per-case statistics (``outputs.statistics``): variables over the case dims and their own dim."""
    da = require("dask.array", "sweep")
    import xarray as xr

    from ..statistics.record import record_coordinates, record_variables

    dims, shape = spec.dims, spec.shape
    extra = record_coordinates(spec.base)
    units = {"output_point": "m", "contactor": "1", "fatigue_point": "m"}
    for dim, values in extra.items():
        if values.size:
            coords[dim] = xr.Variable((dim,), values, {"units": units[dim], "long_name": dim.replace("_", " ")})
    for name, (dim, unit, long_name) in record_variables(spec.base).items():
        tail = () if dim is None else (dim,)
        n = () if dim is None else (extra[dim].size,)
        data[name] = xr.Variable((*dims, *tail), da.full((*shape, *n), np.nan, chunks=-1),
                                 {"units": unit, "long_name": long_name})
        enc[name] = {"chunks": (*chunk, *n), "fill_value": np.nan}


def statistic_names(spec: SweepSpec) -> tuple[str, ...]:
    """Names of the statistics variables a sweep stores (none without ``outputs.statistics``)."""
    if not spec.statistics:
        return ()
    from ..statistics.record import record_variables

    return tuple(record_variables(spec.base))


def _create_store(spec: SweepSpec, out: Path | None, chunk: tuple[int, ...]) -> Any:
    """Write the empty store (metadata, consolidated, and coordinates); atomic for a directory.

    A store's metadata never changes after this (batches write chunks only),
    so it is consolidated here, once.
    """
    ds, enc = _template(spec, chunk)
    if out is None:
        zarr = require("zarr", "sweep")

        store = zarr.storage.MemoryStore()
        ds.to_zarr(store, compute=False, encoding=enc, consolidated=False)
        return store
    tmp = out.with_name(f".{out.name}.tmp-{os.getpid()}")
    if tmp.exists():
        shutil.rmtree(tmp)
    try:
        with quiet_consolidation():
            ds.to_zarr(str(tmp), compute=False, encoding=enc, consolidated=True)
        if out.exists():  # an empty directory
            out.rmdir()
        os.replace(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return str(out)


@contextlib.contextmanager
def quiet_consolidation() -> Iterator[None]:
    """Consolidated metadata lets ``xr.open_zarr(path)`` open a store without a warning; Zarr 3 notes
    (a UserWarning) that it is an extension of its format 3, which tells the user nothing."""
    import warnings

    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Consolidated metadata", category=UserWarning)
        yield


class StoreMaker:
    """Creates a new store (:func:`_create_store`) while the sweep's process runs its first batch.

    Making a store imports xarray, Dask's arrays and Zarr and writes the
    metadata: ~1.5 s of one core, as much as the first batch (which loads the
    solver). On Linux a forked process makes it meanwhile (forked first,
    before any thread of this process exists); elsewhere, and for a store in
    memory, :meth:`result` makes it here. :meth:`result` gives what
    :func:`_create_store` returns or raises what it raised; :meth:`close`
    stops an unfinished maker (an interrupt), which removes its partial
    directory as :func:`_create_store` does.

    Parameters
    ----------
    spec : SweepSpec
    out : Path or None
        The store's directory (None: in memory).
    chunk : tuple of int
    """

    def __init__(self, spec: SweepSpec, out: Path | None, chunk: tuple[int, ...]) -> None:
        from .cluster import fork_context

        self._args = (spec, out, chunk)
        self._proc: Any = None
        self._conn: Any = None
        ctx = fork_context() if out is not None else None
        if ctx is not None:
            self._conn, send = ctx.Pipe(duplex=False)
            self._proc = ctx.Process(target=_make_in_child, args=(*self._args, send), daemon=True,
                                     name="impactbeam-store")
            self._proc.start()
            send.close()

    def result(self) -> Any:
        """The store (its path, or the in-memory store), once made."""
        if self._proc is None:
            return _create_store(*self._args)
        try:
            kind, value = self._conn.recv()
        except EOFError:
            kind, value = "error", None
        finally:
            self._conn.close()
            self._proc.join()
            code, self._proc = self._proc.exitcode, None
        if kind == "ok":
            return value
        if isinstance(value, BaseException):
            raise value
        from ..exceptions import ImpactBeamError

        raise ImpactBeamError(f"--out: creating the store failed ({value or f'its process ended with status {code}'})")

    def close(self) -> None:
        """Stop a maker still running (it removes its partial directory) and wait for it."""
        if self._proc is None:
            return
        import signal

        if self._proc.is_alive():
            with contextlib.suppress(OSError):
                os.kill(self._proc.pid, signal.SIGTERM)
        self._proc.join(10.0)
        if self._proc.is_alive():
            self._proc.kill()
            self._proc.join()
        self._conn.close()
        self._proc = None


def _make_in_child(spec: SweepSpec, out: Path, chunk: tuple[int, ...], conn: Any) -> None:
    """The forked maker: send ("ok", path) or ("error", the exception, or its text if it does not pickle)."""
    import pickle
    import signal

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the sweep's process decides; SIGTERM (close) stops this one
    signal.signal(signal.SIGTERM, _raise_interrupt)
    try:
        msg: tuple[str, Any] = ("ok", _create_store(spec, out, chunk))
    except BaseException as exc:  # noqa: BLE001 - everything is reported to the sweep's process
        try:
            pickle.loads(pickle.dumps(exc))
            msg = ("error", exc)
        except Exception:
            msg = ("error", f"{type(exc).__name__}: {exc}")
    with contextlib.suppress(OSError):
        conn.send(msg)
    conn.close()


def _raise_interrupt(signum: int, frame: Any) -> None:
    raise KeyboardInterrupt(f"signal {signum}")


def open_result(spec: SweepSpec, store: Any, in_memory: bool) -> xr.Dataset:
    """The sweep's results as a Dataset: variables in the sweep's order; loaded for an in-memory store."""
    import xarray as xr

    ds = xr.open_zarr(store, consolidated=False, chunks=None)
    order = [*spec.metrics, *statistic_names(spec), "status", *(["modes"] if "modes" in ds else []), "message",
             *(["warnings"] if "warnings" in ds else []), *(["w"] if spec.histories is not None else [])]
    ds = ds[order]  # the store lists its arrays in no particular order
    return ds.load() if in_memory else ds


def _open_existing(spec: SweepSpec, out: Path) -> Any:
    """Open a store made by the same sweep, else raise ParameterError."""
    zarr = require("zarr", "sweep")

    try:
        group = zarr.open_group(str(out), mode="r")
        attrs = dict(group.attrs)
    except Exception:
        raise ParameterError(
            f'--out: "{out}" exists and is not a sweep result; choose another path or remove it'
        ) from None
    found = attrs.get("sweep_hash")
    if found is None or "status" not in group:
        raise ParameterError(f'--out: "{out}" exists and is not a sweep result; choose another path or remove it')
    if found != spec.hash:
        raise ParameterError(
            f'--out: "{out}" holds the results of a different sweep (hash {str(found)[:12]}, this sweep '
            f"{spec.hash[:12]}); choose another path or remove it"
        )
    return str(out)


class _StoreLock:
    """One writer per store: a lock file beside it with the holder's pid, host and start time.

    A second run on the same store is refused with the holder's identity; a lock
    left by a process of this host that no longer exists (killed) is stale and
    is taken over.
    """

    def __init__(self, out: Path | None) -> None:
        self.out = out
        self.path = None if out is None else out.with_name(out.name + ".lock")

    def __enter__(self) -> _StoreLock:
        if self.path is None:
            return self
        import socket

        me = {"pid": os.getpid(), "host": socket.gethostname(), "started": time.time()}
        for _ in range(3):
            try:
                fd = os.open(self.path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
            except FileExistsError:
                holder = self._holder()
                if holder is not None and holder.get("host") == me["host"] and not pid_alive(holder.get("pid")):
                    with contextlib.suppress(FileNotFoundError):
                        os.unlink(self.path)  # stale: its process is gone
                    continue
                if holder is None:  # being written this very instant
                    time.sleep(0.05)
                    continue
                when = time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(float(holder.get("started", 0))))
                raise ParameterError(
                    f'--out: "{self.out}" is being written by another sweep (pid {holder.get("pid")} on host '
                    f'{holder.get("host")}, since {when}); wait for it to finish, or remove "{self.path}" if '
                    "that process is gone"
                ) from None
            try:
                with os.fdopen(fd, "w") as fh:
                    json.dump(me, fh)
            except OSError:  # a full disk: the lock was created empty; do not leave it behind
                with contextlib.suppress(OSError):
                    os.unlink(self.path)
                raise
            return self
        raise ParameterError(f'--out: cannot take the lock "{self.path}"')

    def _holder(self) -> dict[str, Any] | None:
        try:
            return json.loads(Path(self.path).read_text())  # type: ignore[arg-type]
        except (OSError, ValueError):
            return None

    def __exit__(self, *exc: Any) -> None:
        if self.path is not None:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(self.path)
