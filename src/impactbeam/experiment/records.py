"""Measured records: one channel against time in SI units, read from CSV or netCDF (paper section 3).

A :class:`Record` is a deflection [m] or a base acceleration [m/s^2];
:func:`load_record` reads it through the one delimited-text reader (unit
headers honoured) or from a netCDF variable, and regularises an unevenly
sampled record (a gap is an error, not resampled).
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal
import numpy as np

from .._optional import require
from .._io import numeric_columns, read_delimited
from ..exceptions import ParameterError, ScenarioError

__all__ = ["GAP_FACTOR", "MIN_SAMPLES", "Quantity", "Record", "UNEVEN_TOLERANCE", "load_record"]


Quantity = Literal["deflection", "acceleration"]

#: Fewest samples a record may have.
MIN_SAMPLES = 8
#: A step longer than this many median steps is a gap (an error, not resampled).
GAP_FACTOR = 5.0
#: Relative spread of the steps above which a record counts as unevenly sampled.
UNEVEN_TOLERANCE = 1e-6

_SI_UNIT = {"deflection": "m", "acceleration": "m/s^2"}
_NETCDF_SUFFIXES = (".nc", ".nc4", ".cdf", ".netcdf", ".h5", ".hdf5")


@dataclass(frozen=True, eq=False)
class Record:
    """One measured channel against time, in SI units.

    Parameters
    ----------
    time : array_like, shape (n,), [s]
        Strictly increasing sample times, n >= :data:`MIN_SAMPLES`.
    values : array_like, shape (n,)
        The channel in SI: deflection [m] or base acceleration [m/s^2].
    name : str
        Channel name (the column header without its unit).
    quantity : {"deflection", "acceleration"}
    source : Path or None
        File the record was read from.
    notes : tuple of str
        What was done on reading (e.g. resampling); printed by the CLI.

    Raises
    ------
    ParameterError
        For arrays of different shapes, NaN or infinite values, times that do
        not increase strictly, or fewer than :data:`MIN_SAMPLES` samples.
    """

    time: np.ndarray
    values: np.ndarray
    name: str = "deflection"
    quantity: Quantity = "deflection"
    source: Path | None = None
    notes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        t = np.array(self.time, dtype=float)
        v = np.array(self.values, dtype=float)
        label = self.label
        if self.quantity not in _SI_UNIT:
            raise ParameterError(f"{label}: quantity must be 'deflection' or 'acceleration', got {self.quantity!r}")
        if t.ndim != 1 or t.shape != v.shape:
            raise ParameterError(f"{label}: time and values must be 1-D arrays of one length, got {t.shape} and {v.shape}")
        if t.size < MIN_SAMPLES:
            raise ParameterError(f"{label}: has {t.size} samples; a record needs at least {MIN_SAMPLES}")
        for what, arr in (("time", t), (self.name, v)):
            bad = np.nonzero(~np.isfinite(arr))[0]
            if bad.size:
                raise ParameterError(f"{label}: {what} sample {bad[0]} is {arr[bad[0]]} (NaN or infinite)")
        steps = np.diff(t)
        bad = np.nonzero(steps <= 0.0)[0]
        if bad.size:
            i = int(bad[0])
            raise ParameterError(
                f"{label}: time sample {i + 1} ({t[i + 1]:g} s) does not come after sample {i} ({t[i]:g} s)"
            )
        t.setflags(write=False)
        v.setflags(write=False)
        object.__setattr__(self, "time", t)
        object.__setattr__(self, "values", v)
        object.__setattr__(self, "notes", tuple(self.notes))

    @property
    def label(self) -> str:
        """How the record is named in messages: ``record "file.csv"``."""
        return f'record "{self.source}"' if self.source is not None else f"record {self.name!r}"

    @property
    def unit(self) -> str:
        """SI unit of :attr:`values` (``m`` or ``m/s^2``)."""
        return _SI_UNIT[self.quantity]

    @property
    def step(self) -> float:
        """Median sample step [s]."""
        return float(np.median(np.diff(self.time)))

    @property
    def sample_rate(self) -> float:
        """1 / :attr:`step` [Hz]."""
        return 1.0 / self.step

    @property
    def uniform(self) -> bool:
        """True when every step equals the median step within 1e-6 relative."""
        steps = np.diff(self.time)
        h = np.median(steps)
        return bool(np.max(np.abs(steps - h)) <= UNEVEN_TOLERANCE * h)

    @property
    def duration(self) -> float:
        """Last minus first sample time [s]."""
        return float(self.time[-1] - self.time[0])

    def window(self, start: float | None = None, stop: float | None = None) -> Record:
        """The samples with ``start <= time <= stop`` (either may be None).

        Parameters
        ----------
        start : float or None, [s]
            First time kept (None: from the first sample).
        stop : float or None, [s]
            Last time kept (None: to the last sample).
        """
        keep = np.ones(self.time.size, dtype=bool)
        if start is not None:
            keep &= self.time >= start
        if stop is not None:
            keep &= self.time <= stop
        if keep.sum() < MIN_SAMPLES:
            raise ParameterError(
                f"{self.label}: the window [{start}, {stop}] s holds {int(keep.sum())} samples; "
                f"at least {MIN_SAMPLES} are needed"
            )
        note = f"restricted to [{self.time[keep][0]:g}, {self.time[keep][-1]:g}] s"
        return dataclasses.replace(
            self, time=self.time[keep], values=self.values[keep], notes=self.notes + (note,)
        )

    def plot(self, *, ax: Any = None, scale: float | None = None, **kwargs: Any) -> Any:
        """Plot the record against time; returns the line. ``scale`` defaults to mm for deflections.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Draw here (default: a new figure).
        scale : float, optional
            Factor on the values (default 1e3 for a deflection, mm).
        **kwargs
            Passed to :meth:`matplotlib.axes.Axes.plot`.
        """
        plt = require("matplotlib.pyplot", "plot")

        if ax is None:
            _, ax = plt.subplots()
        if scale is None:
            scale = 1e3 if self.quantity == "deflection" else 1.0
        unit = {1e3: "mm", 1.0: self.unit}.get(scale, f"{1 / scale:g} {self.unit}")
        (line,) = ax.plot(self.time, self.values * scale, label=kwargs.pop("label", self.name), **kwargs)
        ax.set_xlabel("time [s]")
        ax.set_ylabel(f"{self.name} [{unit}]")
        return line


_ACCEL_NAME = re.compile(r"acc|^a$|^ug|^a_?base|^base_?a", re.IGNORECASE)


def _value_scale(unit: str, label: str, where: str) -> tuple[float, Quantity]:
    """SI factor and quantity of a value unit: a length or an acceleration."""
    from ..units import unit_scale

    problems = []
    for dimension, quantity in (("length", "deflection"), ("acceleration", "acceleration")):
        try:
            return unit_scale(unit, dimension, "record"), quantity  # type: ignore[return-value]
        except ScenarioError as exc:
            problems.append(str(exc).partition(": ")[2])
    raise ScenarioError(
        f'{label}: {where}: unit "{unit}" is neither a length (deflection) nor an acceleration '
        f"({problems[0]}; as an acceleration: {problems[1]})",
        key="record",
    )


def _time_scale(unit: str, label: str, where: str) -> float:
    from ..units import unit_scale

    unit = unit.split(" since ")[0]  # CF "seconds since ..." (relative times only)
    try:
        return unit_scale(unit, "time", "record")
    except ScenarioError as exc:
        raise ScenarioError(f"{label}: {where}: {str(exc).partition(': ')[2]}", key="record") from None


def _merge_unit(given: str | None, in_file: str | None, option: str, label: str) -> str | None:
    if given is not None and in_file is not None and given.strip() != in_file.strip():
        raise ScenarioError(
            f'{label}: the file gives unit "{in_file}" but {option} says "{given}"; remove one', key="record"
        )
    return given if given is not None else in_file


def load_record(
    path: str | Path,
    *,
    time_unit: str | None = None,
    value_unit: str | None = None,
    channel: str | None = None,
    quantity: Quantity | None = None,
    resample: bool = True,
) -> Record:
    """Read a measured record (CSV or netCDF) into SI units.

    Parameters
    ----------
    path : str or Path
        A text file (``.csv``, ``.txt``, ...) or a netCDF file (``.nc``).
        *Text*: cells separated by commas (or semicolons, tabs, blanks); blank
        lines and lines starting with ``#`` are skipped (so a file may begin
        with comment lines). An optional header names the columns, with the
        unit in brackets or parentheses: ``time [s],deflection [mm]``;
        ``time,deflection`` (no units) is SI. The first column is time.
        *netCDF*: a 1-D variable (the only one, or ``channel``) along a time
        coordinate; units from their ``units`` attributes (SI when absent).
    time_unit, value_unit : str, optional
        Units of the columns when the file does not give them (``"ms"``,
        ``"mm"``, ``"g"``); giving a different unit than the file is an error.
    channel : str, optional
        Column (variable) to read when the file holds more than one.
    quantity : {"deflection", "acceleration"}, optional
        What the channel is. Default: from the unit (a length or an
        acceleration, ``g`` = 9.80665 m/s^2), else from the name (names with
        ``acc`` are accelerations), else a deflection.
    resample : bool
        Unevenly sampled records are resampled onto a uniform grid (the
        median step) by linear interpolation, and a note says so. With
        ``False`` they are kept as they are (e.g. for an excitation table).

    Returns
    -------
    Record

    Raises
    ------
    ScenarioError
        (a :class:`ParameterError`) naming the file and the line/column: a
        missing file, one column only, a non-numeric cell, NaN or infinity,
        times that do not increase strictly, fewer than :data:`MIN_SAMPLES`
        samples, a gap longer than :data:`GAP_FACTOR` median steps, an unknown
        unit or one of the wrong dimension.
    """
    p = Path(path)
    label = f'record "{path}"'
    if not p.exists():
        raise ScenarioError(f"{label}: file not found", key="record")
    if p.is_dir():
        raise ScenarioError(f"{label}: is a directory, not a record file", key="record")
    if not p.is_file():  # a device or a pipe: never read (the text reader says the same for CSV)
        raise ScenarioError(f"{label}: is not a regular file (a device, a pipe or a socket); give a record file",
                            key="record")
    if p.suffix.lower() in _NETCDF_SUFFIXES:
        t, v, name, q, rows = _read_netcdf(p, label, time_unit, value_unit, channel, quantity)
    else:
        t, v, name, q, rows = _read_text(p, label, time_unit, value_unit, channel, quantity)
    t, v, notes = _regularize(t, v, rows, label, resample)
    try:
        return Record(t, v, name=name, quantity=q, source=p, notes=notes)
    except ScenarioError:
        raise
    except ParameterError as exc:
        raise ScenarioError(str(exc), key="record") from None


def _read_text(
    p: Path, label: str, time_unit: str | None, value_unit: str | None, channel: str | None,
    quantity: Quantity | None,
) -> tuple[np.ndarray, np.ndarray, str, Quantity, list[str]]:
    def fail(detail: str) -> ScenarioError:
        return ScenarioError(f"{label}: {detail}", key="record")

    table = read_delimited(
        p, fail, what="a record", example="time [s],deflection [mm]",
        not_found=None, not_text="is not a text (UTF-8) file; use .csv or .nc",
    )
    n0, ncol, names = table.first_line, table.ncol, list(table.names)
    if channel is None:
        if ncol > 2:
            raise fail(
                f"line {n0}: {ncol} columns ({', '.join(names)}); choose the channel to read "
                "(channel=..., or --channel on the command line)"
            )
        col = 1
    else:
        if channel not in names[1:]:
            raise fail(f"no column {channel!r}; the columns are {', '.join(names)}")
        col = names.index(channel)
    name = names[col] if table.header else ("deflection" if quantity != "acceleration" else "acceleration")
    t_unit = _merge_unit(time_unit, table.units[0], "the time unit option", label)
    v_unit = _merge_unit(value_unit, table.units[col], "the value unit option", label)
    t_scale = _time_scale(t_unit, label, f'line {n0}, column 1 ({names[0]!r}), unit "{t_unit}"') if t_unit else 1.0
    v_scale, q = _value_quantity(
        v_unit, name, quantity, label, f'line {n0}, column {col + 1} ({names[col]!r}), unit "{v_unit}"'
    )
    (t, v), line_numbers = numeric_columns(table, (0, col), (t_scale, v_scale), fail)
    if t.size < MIN_SAMPLES:
        raise fail(f"has {t.size} data row{'s' if t.size != 1 else ''}; a record needs at least {MIN_SAMPLES}")
    return t, v, name, q, [f"line {n}" for n in line_numbers]


def _value_quantity(
    unit: str | None, name: str, quantity: Quantity | None, label: str, where: str
) -> tuple[float, Quantity]:
    if unit:
        scale, q = _value_scale(unit, label, where)
        if quantity is not None and quantity != q:
            raise ScenarioError(
                f'{label}: {where}: unit "{unit}" is {"a length" if q == "deflection" else "an acceleration"}, '
                f"but {_a(quantity)} record was expected",
                key="record",
            )
        return scale, q
    if quantity is not None:
        return 1.0, quantity
    return 1.0, ("acceleration" if _ACCEL_NAME.search(name) else "deflection")


def _read_netcdf(
    p: Path, label: str, time_unit: str | None, value_unit: str | None, channel: str | None,
    quantity: Quantity | None,
) -> tuple[np.ndarray, np.ndarray, str, Quantity, list[str]]:
    import xarray as xr

    def fail(detail: str) -> ScenarioError:
        return ScenarioError(f"{label}: {detail}", key="record")

    try:
        ds = xr.open_dataset(p, decode_times=False, decode_timedelta=False)
    except Exception as exc:  # backends raise many types
        raise fail(f"cannot be read as netCDF ({type(exc).__name__}: {exc})") from None
    with ds:
        candidates = [k for k, v in ds.data_vars.items() if v.ndim == 1]
        if channel is not None:
            if channel not in ds.data_vars:
                raise fail(f"no variable {channel!r}; the variables are {', '.join(map(str, ds.data_vars))}")
            var = ds[channel]
        elif len(candidates) == 1:
            var = ds[candidates[0]]
        elif not candidates:
            raise fail("holds no 1-D variable (a record needs time and one channel)")
        else:
            raise fail(f"holds {len(candidates)} variables ({', '.join(map(str, candidates))}); choose one (channel=...)")
        if var.ndim != 1:
            raise fail(f"variable {var.name!r} has {var.ndim} dimensions; a record is 1-D along time")
        dim = var.dims[0]
        if dim in ds.coords:
            tvar = ds[dim]
        elif "time" in ds.variables and ds["time"].dims == (dim,):
            tvar = ds["time"]
        else:
            raise fail(f"variable {var.name!r} has no time coordinate along {dim!r}")
        t_raw = np.asarray(tvar.values)
        v_raw = np.asarray(var.values)
        name = str(var.name)
        t_attr = tvar.attrs.get("units")
        v_attr = var.attrs.get("units")
    if not (np.issubdtype(t_raw.dtype, np.number) and np.issubdtype(v_raw.dtype, np.number)):
        raise fail(f"time or {name!r} is not numeric ({t_raw.dtype}, {v_raw.dtype})")
    t_unit = _merge_unit(time_unit, t_attr, "the time unit option", label)
    v_unit = _merge_unit(value_unit, v_attr, "the value unit option", label)
    t_scale = _time_scale(str(t_unit), label, "time units") if t_unit else 1.0
    v_scale, q = _value_quantity(str(v_unit) if v_unit else None, name, quantity, label, f"{name} units")
    t = t_raw.astype(float) * t_scale
    v = v_raw.astype(float) * v_scale
    for what, arr in (("time", t), (name, v)):
        bad = np.nonzero(~np.isfinite(arr))[0]
        if bad.size:
            raise fail(f"{what} index {bad[0]}: NaN or infinite value")
    steps = np.diff(t)
    bad = np.nonzero(steps <= 0)[0]
    if bad.size:
        i = int(bad[0]) + 1
        raise fail(f"time index {i}: {t[i]:g} s does not come after the previous {t[i - 1]:g} s")
    if t.size < MIN_SAMPLES:
        raise fail(f"has {t.size} samples; a record needs at least {MIN_SAMPLES}")
    return t, v, name, q, [f"index {i}" for i in range(t.size)]


def _regularize(
    t: np.ndarray, v: np.ndarray, rows: Sequence[str], label: str, resample: bool
) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """Check for gaps; resample an uneven record onto the median step."""
    steps = np.diff(t)
    h = float(np.median(steps))
    big = np.nonzero(steps > GAP_FACTOR * h)[0]
    if big.size:
        i = int(big[0])
        raise ScenarioError(
            f"{label}: gap of {steps[i]:.4g} s between {rows[i]} and {rows[i + 1]} "
            f"(t = {t[i]:.6g} s to {t[i + 1]:.6g} s), more than {GAP_FACTOR:g} x the median step "
            f"{h:.4g} s; split the record or fill the gap",
            key="record",
        )
    if not resample or np.max(np.abs(steps - h)) <= UNEVEN_TOLERANCE * h:
        return t, v, ()
    n = int(math.floor((t[-1] - t[0]) / h * (1 + 1e-12))) + 1
    grid = t[0] + h * np.arange(n)
    grid = grid[grid <= t[-1] + 1e-12 * h]
    note = (
        f"unevenly sampled (steps {steps.min():.4g} s to {steps.max():.4g} s): resampled by linear "
        f"interpolation onto a uniform grid of step {h:.4g} s ({t.size} -> {grid.size} samples)"
    )
    return grid, np.interp(grid, t, v), (note,)


def _require_uniform(record: Record, what: str) -> None:
    if not record.uniform:
        raise ParameterError(
            f"{record.label}: {what} needs uniform sampling; load it with load_record(..., resample=True)"
        )


def _require(record: Record, quantity: Quantity, what: str) -> None:
    if record.quantity != quantity:
        raise ParameterError(f"{record.label}: {what} needs {_a(quantity)} record, got {_a(record.quantity)} record")


def _a(word: str) -> str:
    """``word`` with its indefinite article (an acceleration, a deflection)."""
    return f"{'an' if word[:1] in 'aeiou' else 'a'} {word}"
