"""Measured records and identification: the workflow of the paper's section 4.

An experimenter (Xu & Ervin 2013, sections 3 and 4) measures

* a free-decay record (the beam released from a tip deflection, Case 0/13)
  -> natural frequencies (:func:`identify_frequencies`), damping ratio by
  logarithmic decrement (:func:`damping_log_decrement`, section 4.1 reports
  1.1 +/- 0.1 %) and the Young's modulus that makes the model's first
  frequency match (:func:`modulus_from_frequency`, section 4.1);
* a contact test (Case 3) -> the frequency of the contact portions
  (:func:`contact_frequency_from_record`) and the contact stiffness that gives
  the model the same contact-state fundamental
  (:func:`contact_stiffness_from_frequency`, section 4.2: 4030 N/m);
* the shaker's base acceleration (paper Fig. 3) -> the model driven by that
  trace (:func:`drive_with_trace`), compared with the measured deflection
  (:func:`compare`, the section-4 quantities side by side).

A :class:`Record` is one channel against time, in SI units: a deflection
[m] or a base acceleration [m/s^2]. :func:`load_record` reads CSV and netCDF.

Sign convention: a deflection record holds ``w`` at one point of the beam in
the model's convention (see the model page: measured from the rest position,
positive along +w). The comparison quantities are computed, as the metrics
of :mod:`impactbeam.metrics`, on ``u`` positive away from the first
contactor (``u = -w`` for a contactor "above"), so a contact shows as ``u``
below ``-gap``.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from ._optional import require
from ._textdata import numeric_columns, read_delimited
from .exceptions import ParameterError, ScenarioError, SimulationError

if TYPE_CHECKING:
    from .loading import Excitation
    from .result import SimulationResult
    from .scenario import Scenario

__all__ = [
    "Record",
    "load_record",
    "MIN_SAMPLES",
    "GAP_FACTOR",
    "FrequencyEstimate",
    "identify_frequencies",
    "DampingEstimate",
    "damping_log_decrement",
    "modulus_from_frequency",
    "contact_stiffness_from_frequency",
    "contact_state_frequency",
    "ContactFrequency",
    "contact_frequency_from_record",
    "drive_with_trace",
    "response_features",
    "FEATURES",
    "Comparison",
    "compare",
    "record_point",
]

Quantity = Literal["deflection", "acceleration"]

#: Fewest samples a record may have.
MIN_SAMPLES = 8
#: A step longer than this many median steps is a gap (an error, not resampled).
GAP_FACTOR = 5.0
#: Relative spread of the steps above which a record counts as unevenly sampled.
UNEVEN_TOLERANCE = 1e-6

_SI_UNIT = {"deflection": "m", "acceleration": "m/s^2"}
_NETCDF_SUFFIXES = (".nc", ".nc4", ".cdf", ".netcdf", ".h5", ".hdf5")


# =========================================================================== records


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
        """The samples with ``start <= time <= stop`` (either may be None)."""
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
        """Plot the record against time; returns the line. ``scale`` defaults to mm for deflections."""
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
    from .units import unit_scale

    problems = []
    for dimension, quantity in (("length", "deflection"), ("acceleration", "acceleration")):
        try:
            return unit_scale(unit, dimension, "record"), quantity  # type: ignore[return-value]
        except ScenarioError as exc:
            problems.append(str(exc).partition(": ")[2])
    raise ScenarioError(
        f'{label}: {where}: unit "{unit}" is neither a length (deflection) nor an acceleration '
        f"({problems[0]})",
        key="record",
    )


def _time_scale(unit: str, label: str, where: str) -> float:
    from .units import unit_scale

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
                f"but a {quantity} record was expected",
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
        raise ParameterError(f"{record.label}: {what} needs a {quantity} record, got a {record.quantity} record")


# =========================================================================== frequencies


@dataclass(frozen=True, eq=False)
class FrequencyEstimate:
    """Natural frequencies identified from a record's spectrum.

    Attributes
    ----------
    frequencies_hz : ndarray, (n,), [Hz]
        Interpolated spectral peaks, ascending (damped frequencies
        ``f_d = f_n sqrt(1 - xi^2)``; for xi = 1.1 % they differ from the
        natural ones by 6e-5 relative).
    amplitudes : ndarray, (n,)
        Peak magnitudes of the windowed spectrum (relative units).
    resolution_hz : float
        Frequency resolution of the record, ``fs / N`` [Hz].
    bin_hz : float
        Bin width of the zero-padded spectrum [Hz].
    frequency, spectrum : ndarray
        The one-sided Hann-windowed, zero-padded magnitude spectrum (for plots).
    """

    frequencies_hz: np.ndarray
    amplitudes: np.ndarray
    resolution_hz: float
    bin_hz: float
    frequency: np.ndarray = field(repr=False)
    spectrum: np.ndarray = field(repr=False)


def _spectrum(x: np.ndarray, dt: float, pad: int) -> tuple[np.ndarray, np.ndarray]:
    from scipy.signal import detrend
    from scipy.signal.windows import hann

    n = x.size
    y = detrend(x, type="linear") * hann(n, sym=False)
    nfft = 1 << int(math.ceil(math.log2(max(pad, 1) * n)))
    mag = np.abs(np.fft.rfft(y, nfft))
    return np.fft.rfftfreq(nfft, dt), mag


def _interpolate_peak(freq: np.ndarray, mag: np.ndarray, k: int) -> tuple[float, float]:
    """Quadratic interpolation of the log magnitude through bins k-1, k, k+1."""
    a, b, c = np.log(mag[k - 1 : k + 2] + 1e-300)
    den = a - 2 * b + c
    delta = 0.5 * (a - c) / den if den < 0 else 0.0
    delta = float(np.clip(delta, -0.5, 0.5))
    df = freq[1] - freq[0]
    return float(freq[k] + delta * df), float(np.exp(b - 0.25 * (a - c) * delta))


def identify_frequencies(
    record: Record,
    n: int = 2,
    *,
    fmin: float | None = None,
    fmax: float | None = None,
    pad: int = 16,
    min_snr_db: float = 12.0,
) -> FrequencyEstimate:
    """Natural frequencies from the spectrum of a free-decay record (paper sections 3, 4.1).

    Parameters
    ----------
    record : Record
        Uniformly sampled (see :func:`load_record`), e.g. a release test.
    n : int
        Number of modes: the ``n`` most significant spectral peaks, sorted by frequency.
    fmin, fmax : float, optional, [Hz]
        Search band; default: above the Hann main lobe of DC (``2 fs/N``) and
        below 0.98 x Nyquist.
    pad : int
        Zero-padding factor (the FFT length is the next power of two of ``pad * N``).
    min_snr_db : float
        A peak must stand this far above the local noise floor (running
        median of the spectrum over 16 resolution bins).

    Returns
    -------
    FrequencyEstimate
        ``spectrum`` is that of the whole record.

    Notes
    -----
    Each spectrum is taken after removing a linear trend, with a Hann
    window and zero padding; every local maximum with at least 6 dB of
    prominence and ``min_snr_db`` above the local floor is a candidate, and
    is refined by a parabola through the log magnitude of its bin and the two
    neighbours (for the Hann lobe of zero-padded data the bias is far below
    a padded bin, so the error is set by the noise, not by the resolution
    ``fs/N``). In a free decay the higher modes die out early, where the
    Hann window of the whole record is small, so the spectra of the first
    1/2, 1/4 and 1/8 of the record (down to 64 samples) are searched too; a
    mode is reported from the longest of them in which it is significant
    (the best resolution). Peaks closer than 5 resolution bins to a more
    significant one (window side lobes, noise on a mode's skirt) are dropped;
    the ``n`` most significant remaining peaks are returned.

    Raises
    ------
    ParameterError
        For a non-uniform record, ``n < 1``, or when fewer than ``n`` peaks are
        found (the message says how many were).
    """
    from scipy.ndimage import median_filter
    from scipy.signal import find_peaks

    _require_uniform(record, "frequency identification")
    if isinstance(n, bool) or int(n) != n or n < 1:
        raise ParameterError(f"n: the number of frequencies must be a positive integer, got {n!r}")
    dt = record.step
    N = record.time.size
    hi = min(fmax if fmax is not None else math.inf, 0.98 * 0.5 / dt)
    candidates: list[tuple[float, float, float, float]] = []  # (snr, f, amplitude, resolution)
    full: tuple[np.ndarray, np.ndarray] | None = None
    length = N
    while True:
        freq, mag = _spectrum(record.values[:length], dt, pad)
        if full is None:
            full = (freq, mag)
        res = 1.0 / (length * dt)
        lo = max(fmin if fmin is not None else 0.0, 2.0 * res)
        band = (freq >= lo) & (freq <= hi)
        if band.sum() > 3:
            db = 20 * np.log10(mag + 1e-300)
            bin_ratio = res / (freq[1] - freq[0])
            floor = median_filter(db, size=max(3, int(16 * bin_ratio)) | 1, mode="nearest")
            peaks, _ = find_peaks(db, prominence=6.0)
            for k in peaks:
                if band[k] and 0 < k < db.size - 1 and db[k] - floor[k] >= min_snr_db:
                    f, amp = _interpolate_peak(freq, mag, int(k))
                    candidates.append((float(db[k] - floor[k]), f, amp, res))
        length //= 2
        if length < 64:
            break
    # longest record first (candidates are in that order), then by significance
    accepted: list[tuple[float, float, float, float]] = []
    for cand in sorted(candidates, key=lambda c: (c[3], -c[0])):
        snr, f, amp, res = cand
        if any(abs(f - g[1]) < 5.0 * max(res, g[3]) for g in accepted):
            continue
        accepted.append(cand)
    # drop what sits near a more significant peak of another resolution
    final: list[tuple[float, float, float, float]] = []
    for cand in sorted(accepted, key=lambda c: -c[0]):
        if any(abs(cand[1] - g[1]) < 5.0 * max(cand[3], g[3]) for g in final):
            continue
        final.append(cand)
    if len(final) < n:
        raise ParameterError(
            f"{record.label}: found {len(final)} significant spectral peak{'s' if len(final) != 1 else ''}, "
            f"{n} requested (record too short or too noisy, or the mode not excited?)"
        )
    top = sorted(final[:n], key=lambda c: c[1])
    assert full is not None
    return FrequencyEstimate(
        frequencies_hz=np.array([c[1] for c in top]),
        amplitudes=np.array([c[2] for c in top]),
        resolution_hz=1.0 / (N * dt),
        bin_hz=float(full[0][1] - full[0][0]),
        frequency=full[0],
        spectrum=full[1],
    )


# =========================================================================== damping


@dataclass(frozen=True, eq=False)
class DampingEstimate:
    """Damping ratio of one mode by logarithmic decrement.

    Attributes
    ----------
    damping_ratio : float
        From the decay rate of the cycle peaks: least-squares slope of
        ``ln |peak|`` against time (positive and negative peaks, one intercept
        each), ``sigma``, and ``delta = sigma T_d``,
        ``xi = delta / sqrt(4 pi^2 + delta^2)``. This is the average
        logarithmic decrement over all the cycles used.
    spread : float
        Standard deviation of the per-cycle ratios (the paper's "+/-").
    per_cycle : ndarray
        ``xi_i`` from ``delta_i = ln(a_i / a_{i+1})`` of consecutive peaks of one sign.
    mean : float
        Mean of ``per_cycle``.
    standard_error : float
        Standard error of ``damping_ratio`` from the regression.
    frequency_hz : float
        Frequency of the mode [Hz] (the band-pass centre).
    band_hz : tuple of float
        Pass band used [Hz].
    n_cycles : int
        Number of per-cycle decrements.
    peak_times, peak_values : ndarray
        The refined peaks of the filtered record used.
    """

    damping_ratio: float
    spread: float
    per_cycle: np.ndarray = field(repr=False)
    mean: float
    standard_error: float
    frequency_hz: float
    band_hz: tuple[float, float]
    n_cycles: int
    peak_times: np.ndarray = field(repr=False)
    peak_values: np.ndarray = field(repr=False)


def _bandpass(record: Record, f: float, bandwidth: float, neighbours: Sequence[float] = ()) -> tuple[np.ndarray, tuple[float, float]]:
    from scipy.signal import butter, sosfiltfilt

    fs = record.sample_rate
    lo, hi = f * (1 - bandwidth), f * (1 + bandwidth)
    for g in neighbours:  # stay clear of neighbouring modes
        if g < f:
            lo = max(lo, 0.5 * (f + g))
        elif g > f:
            hi = min(hi, 0.5 * (f + g))
    hi = min(hi, 0.45 * fs)
    if not (0 < lo < f < hi):
        raise ParameterError(f"frequency: {f:g} Hz cannot be band-passed at a sample rate of {fs:g} Hz")
    sos = butter(4, [lo, hi], btype="bandpass", fs=fs, output="sos")
    x = record.values - np.mean(record.values)
    return sosfiltfilt(sos, x), (lo, hi)


def _vertices(t: np.ndarray, y: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Parabola vertices through samples k-1, k, k+1 (uniform step)."""
    idx = idx[(idx > 0) & (idx < y.size - 1)]
    a, b, c = y[idx - 1], y[idx], y[idx + 1]
    den = a - 2 * b + c
    with np.errstate(divide="ignore", invalid="ignore"):
        d = np.where(den != 0, 0.5 * (a - c) / den, 0.0)
    d = np.clip(d, -0.5, 0.5)
    h = t[1] - t[0]
    return t[idx] + d * h, b - 0.25 * (a - c) * d


def damping_log_decrement(
    record: Record,
    frequency: float | None = None,
    *,
    bandwidth: float = 0.3,
    min_amplitude: float = 0.05,
    neighbours: Sequence[float] = (),
) -> DampingEstimate:
    """Damping ratio of one mode by the logarithmic decrement (paper section 4.1).

    Parameters
    ----------
    record : Record
        A uniformly sampled free decay.
    frequency : float, optional, [Hz]
        The mode; default the dominant spectral peak (:func:`identify_frequencies` with n = 1).
    bandwidth : float
        Half-width of the pass band relative to ``frequency`` (0.3: 0.7 f .. 1.3 f),
        narrowed to halfway towards any of ``neighbours``.
    min_amplitude : float
        Peaks smaller than this fraction of the largest are not used (they
        are dominated by noise).
    neighbours : sequence of float, [Hz]
        Other identified frequencies the band must stay clear of.

    Returns
    -------
    DampingEstimate

    Notes
    -----
    The record is band-passed (4th-order Butterworth, forward and backward,
    so without phase shift) around the mode, which isolates it from the
    other modes. A linear filter does not change the decay rate of
    ``exp(-sigma t) sin(omega_d t)`` (an exponential is its eigenfunction);
    only its start-up transients do, so the peaks within seven filter time
    constants ``1 / (0.38 * 2 pi B)`` (``B`` the half bandwidth) of either
    end are dropped. Each peak is refined by a parabola through three
    samples. For ``a_i`` and ``a_{i+1}`` one period apart,
    ``delta_i = ln(a_i / a_{i+1})`` and ``xi_i = delta_i / sqrt(4 pi^2 + delta_i^2)``.

    Raises
    ------
    ParameterError
        For a non-uniform record or fewer than two usable cycles.
    """
    _require_uniform(record, "the logarithmic decrement")
    if frequency is None:
        frequency = float(identify_frequencies(record, 1).frequencies_hz[0])
    f = float(frequency)
    if not (math.isfinite(f) and f > 0):
        raise ParameterError(f"frequency: must be positive and finite, got {frequency!r}")
    if not 0 < bandwidth < 1:
        raise ParameterError(f"bandwidth: must lie in (0, 1), got {bandwidth!r}")
    y, band = _bandpass(record, f, bandwidth, neighbours)
    t = record.time
    from scipy.signal import find_peaks

    period = 1.0 / f
    dist = max(1, int(0.6 * period / record.step))
    half_band = 0.5 * (band[1] - band[0])
    edge = max(1.5 * period, 7.0 / (0.38 * 2 * math.pi * half_band))
    groups = []
    for sign in (1.0, -1.0):
        idx, _ = find_peaks(sign * y, distance=dist)
        pt, pv = _vertices(t, sign * y, idx)
        ok = (pt > t[0] + edge) & (pt < t[-1] - edge) & (pv > 0)
        groups.append((pt[ok], pv[ok]))
    amax = max((g[1].max() for g in groups if g[1].size), default=0.0)
    per_cycle: list[float] = []
    rows_t, rows_l, rows_g = [], [], []
    all_t, all_v = [], []
    for gi, (pt, pv) in enumerate(groups):
        use = pv >= min_amplitude * amax
        # stop at the first peak below the threshold (later ones are noise)
        if not use.all():
            stop = int(np.argmin(use))
            use[stop:] = False
        pt, pv = pt[use], pv[use]
        all_t.append(pt)
        all_v.append(pv if gi == 0 else -pv)
        for i in range(pt.size - 1):
            gap = pt[i + 1] - pt[i]
            if 0.7 * period < gap < 1.3 * period:
                d = math.log(pv[i] / pv[i + 1])
                per_cycle.append(d / math.sqrt(4 * math.pi**2 + d * d))
        rows_t.append(pt)
        rows_l.append(np.log(pv))
        rows_g.append(np.full(pt.size, gi))
    tt = np.concatenate(rows_t)
    ll = np.concatenate(rows_l)
    gg = np.concatenate(rows_g)
    if len(per_cycle) < 2 or tt.size < 4:
        raise ParameterError(
            f"{record.label}: fewer than two usable cycles at {f:.4g} Hz for the logarithmic decrement "
            "(record too short, too noisy, or the mode too weak)"
        )
    # ln a = c_g - sigma t: least squares with one intercept per sign
    A = np.column_stack([-tt, (gg == 0).astype(float), (gg == 1).astype(float)])
    A = A[:, np.any(A != 0, axis=0)]
    coef, res, rank, _ = np.linalg.lstsq(A, ll, rcond=None)
    sigma = float(coef[0])
    dof = max(tt.size - A.shape[1], 1)
    resid = ll - A @ coef
    cov = np.linalg.pinv(A.T @ A) * float(resid @ resid) / dof
    delta = sigma * period
    xi = delta / math.sqrt(4 * math.pi**2 + delta**2)
    dxi_dsigma = period * 4 * math.pi**2 / (4 * math.pi**2 + delta**2) ** 1.5
    pc = np.asarray(per_cycle)
    order = np.argsort(np.concatenate(all_t))
    return DampingEstimate(
        damping_ratio=float(xi),
        spread=float(np.std(pc, ddof=1)),
        per_cycle=pc,
        mean=float(np.mean(pc)),
        standard_error=float(math.sqrt(max(cov[0, 0], 0.0)) * dxi_dsigma),
        frequency_hz=f,
        band_hz=(float(band[0]), float(band[1])),
        n_cycles=int(pc.size),
        peak_times=np.concatenate(all_t)[order],
        peak_values=np.concatenate(all_v)[order],
    )


# =========================================================================== modulus and contact stiffness


def _elastic_frequency(beam: Any, springs: Sequence[tuple[float, float]], mode: int) -> float:
    from .modes import mode_set

    count = mode
    while True:
        ms = mode_set(beam, springs, count)
        if ms.count - ms.n_rigid >= mode:
            return float(ms.frequencies_hz[ms.n_rigid + mode - 1])
        count += ms.n_rigid


def modulus_from_frequency(scenario: Scenario, f1_measured: float, *, mode: int = 1) -> float:
    """Young's modulus that gives the scenario's free state the measured frequency (paper 4.1).

    Parameters
    ----------
    scenario : Scenario
    f1_measured : float, [Hz]
        Measured natural frequency of elastic mode ``mode`` (rigid-body modes
        are not counted).
    mode : int
        Which elastic mode (1 = the fundamental).

    Returns
    -------
    float, [Pa]

    Notes
    -----
    With rigid or free ends, ``omega_n = beta_n^2 sqrt(EI / rho A)`` with
    ``beta_n`` independent of E (paper, after eq. 5), so
    ``E_new = E (f_measured / f_model)^2``. The modes are then recomputed with
    ``E_new``; when they do not match to 1e-10 relative (elastic end springs
    make ``beta_n`` depend on E), E is refined by Brent's method.

    Raises
    ------
    ParameterError
        For a frequency that is not positive and finite.
    SimulationError
        If the recomputed frequency cannot be matched.
    """
    from scipy.optimize import brentq

    f_meas = float(f1_measured)
    if not (math.isfinite(f_meas) and f_meas > 0):
        raise ParameterError(f"f1_measured: must be a positive frequency in Hz, got {f1_measured!r}")
    beam = scenario.beam
    f_model = _elastic_frequency(beam, (), mode)
    e_new = beam.youngs_modulus * (f_meas / f_model) ** 2

    def mismatch(e: float) -> float:
        return _elastic_frequency(dataclasses.replace(beam, youngs_modulus=e), (), mode) / f_meas - 1.0

    err = mismatch(e_new)
    if abs(err) > 1e-10:
        lo, hi = e_new, e_new
        for _ in range(60):
            lo, hi = lo / 1.5, hi * 1.5
            if mismatch(lo) < 0 < mismatch(hi):
                break
        else:
            raise SimulationError(f"modulus_from_frequency: no modulus gives {f_meas:g} Hz")
        e_new = brentq(mismatch, lo, hi, xtol=1e-14 * e_new, rtol=1e-14)
        if abs(mismatch(e_new)) > 1e-9:
            raise SimulationError(f"modulus_from_frequency: could not match {f_meas:g} Hz")
    return float(e_new)


def contact_state_frequency(scenario: Scenario, stiffness: float, contactor: int = 0, *, mode: int = 1) -> float:
    """Elastic frequency ``mode`` [Hz] of the state with contactor ``contactor`` engaged at ``stiffness``."""
    c = _contactor(scenario, contactor)
    return _elastic_frequency(scenario.beam, ((c.position, float(stiffness)),), mode)


def _contactor(scenario: Scenario, contactor: int) -> Any:
    if not scenario.contactors:
        raise ParameterError("contactors: the scenario has no contactor")
    if not 0 <= contactor < len(scenario.contactors):
        raise ParameterError(
            f"contactor: index {contactor} out of range (the scenario has {len(scenario.contactors)})"
        )
    return scenario.contactors[contactor]


def contact_stiffness_from_frequency(scenario: Scenario, f_contact: float, contactor: int = 0) -> float:
    """Contact stiffness whose contact-state fundamental equals ``f_contact`` (paper 4.2).

    Parameters
    ----------
    scenario : Scenario
        Beam and contactor position (the gap does not change the contact
        state's frequencies: it only adds a constant force).
    f_contact : float, [Hz]
        Measured fundamental of the contact state.
    contactor : int
        Which contactor is engaged (the others stay free).

    Returns
    -------
    float, [N/m]

    Notes
    -----
    The fundamental of the beam with the spring ``k`` at ``a`` rises
    monotonically from the free-state fundamental (``k -> 0``) to that of the
    beam pinned at ``a`` (``k -> inf``); ``k`` is found by Brent's method on
    ``log k``, each step an exact modal analysis (:func:`impactbeam.mode_set`).
    The paper matched the frequency of the contact portion of Case 3 and
    found 4030 N/m.

    Raises
    ------
    ParameterError
        When ``f_contact`` lies outside the attainable range (the message
        gives it), or the scenario has no such contactor.
    """
    from scipy.optimize import brentq

    f = float(f_contact)
    if not (math.isfinite(f) and f > 0):
        raise ParameterError(f"f_contact: must be a positive frequency in Hz, got {f_contact!r}")
    c = _contactor(scenario, contactor)
    beam = scenario.beam
    k_ref = 3.0 * beam.bending_stiffness / beam.length**3
    lo, hi = math.log(k_ref * 1e-8), math.log(k_ref * 1e10)

    def g(logk: float) -> float:
        return _elastic_frequency(beam, ((c.position, math.exp(logk)),), 1) - f

    g_lo, g_hi = g(lo) + f, g(hi) + f
    if not g_lo < f < g_hi:
        raise ParameterError(
            f"f_contact: {f:.6g} Hz is outside the range of contact-state fundamentals "
            f"({g_lo:.6g} Hz for a soft contact to {g_hi:.6g} Hz for a rigid one at x = {c.position:.6g} m)"
        )
    logk = brentq(g, lo, hi, xtol=1e-13, rtol=1e-14)
    return float(math.exp(logk))


@dataclass(frozen=True, eq=False)
class ContactFrequency:
    """Frequency of the contact portions of a deflection record (paper 4.2).

    Attributes
    ----------
    frequency_hz : float
        From a least-squares fit of ``c_i + a_i sin(omega t) + b_i cos(omega t)``
        to the samples of every contact interval ``i``, with one ``omega``
        shared by all intervals.
    half_period_hz : float
        ``1 / (2 mean duration)``: each contact taken as half a cycle (biased high, see Notes).
    intervals : list of (float, float)
        Contact intervals [s] (threshold crossings, linearly interpolated).
    n_samples : int
        Samples used by the fit.
    rms_residual : float, [m]
        RMS of the fit residual.
    """

    frequency_hz: float
    half_period_hz: float
    intervals: list[tuple[float, float]]
    n_samples: int
    rms_residual: float


def _crossings(t: np.ndarray, s: np.ndarray) -> list[tuple[float, float, int, int]]:
    """Intervals where ``s > 0``: (start, end, first index, last index), ends linearly interpolated."""
    pos = s > 0
    out = []
    i = 0
    n = s.size
    while i < n:
        if not pos[i]:
            i += 1
            continue
        j = i
        while j + 1 < n and pos[j + 1]:
            j += 1
        if i > 0:
            t0 = t[i - 1] + (t[i] - t[i - 1]) * (0 - s[i - 1]) / (s[i] - s[i - 1])
        else:
            t0 = t[0]
        if j < n - 1:
            t1 = t[j] + (t[j + 1] - t[j]) * (0 - s[j]) / (s[j + 1] - s[j])
        else:
            t1 = t[-1]
        out.append((float(t0), float(t1), i, j))
        i = j + 1
    return out


def contact_frequency_from_record(
    record: Record, scenario: Scenario, *, contactor: int = 0, min_samples: int = 5
) -> ContactFrequency:
    """Frequency of the contact portions of a deflection record at the contactor (paper 4.2).

    Parameters
    ----------
    record : Record
        Deflection ``w`` at the contactor's position (model sign convention).
    scenario : Scenario
        Gives the contactor's side and gap: a sample is in contact when the
        beam is beyond the contactor surface (``w > gap`` above, ``w < -gap`` below).
    contactor : int
    min_samples : int
        Contact intervals with fewer samples are not used by the fit.

    Returns
    -------
    ContactFrequency

    Notes
    -----
    The paper took an FFT of "the contact portion of a captured response".
    The portions are short (about 4 ms, 8 samples at 2 kHz), so neither
    concatenating them for an FFT (the joins add spurious content) nor timing
    them as half cycles is accurate: while engaged the beam oscillates about
    the contact state's equilibrium, which the gap preload puts on the free
    side of the surface (``w_eq(a) = k c / (k + K_a)``, ``K_a`` the beam's
    stiffness at ``a``), so each contact lasts *less* than half a period and
    ``half_period_hz`` is biased high (by 10-30 % in Case 3, more as the
    contacts weaken). Instead, the samples of all contact intervals are
    fitted together by ``w_eq + a_i sin(omega t) + b_i cos(omega t)``: one
    amplitude and phase per interval, one equilibrium ``w_eq`` and one
    frequency shared by all (variable projection: grid search over omega
    refined by Brent's method); intervals of different amplitudes make
    ``w_eq`` and omega separable.

    This is an *approximate* frequency: a contact lasts less than half a
    cycle of the fundamental while the projection of the free motion onto
    the contact modes (paper eq. 12) also excites the second contact mode,
    so a single sinusoid describes the arcs only roughly. On noise-free
    simulated Case 3 records at 2 kHz it lands within about 10 % of the
    model's contact fundamental (often within 1-2 %), and noise of 5 um adds
    a few percent; the contact stiffness it gives (about 5 times more
    sensitive) is a starting value for :func:`impactbeam.fit.fit`, which
    recovers k from the whole history within 2 %.

    Raises
    ------
    ParameterError
        A record that is not a deflection, or no contact interval with
        ``min_samples`` samples.
    """
    from scipy.optimize import minimize_scalar

    _require(record, "deflection", "the contact frequency")
    c = _contactor(scenario, contactor)
    t, w = record.time, record.values
    beyond = c.direction * w - c.gap
    ivs = _crossings(t, beyond)
    used = [(i0, i1) for _, _, i0, i1 in ivs if i1 - i0 + 1 >= min_samples]
    if not used:
        raise ParameterError(
            f"{record.label}: no contact interval with {min_samples} samples or more "
            f"(beyond the contactor surface at w = {c.direction * c.gap:+.4g} m)"
        )
    durations = [b - a for a, b, i0, i1 in ivs if i1 - i0 + 1 >= min_samples]
    half = 1.0 / (2.0 * float(np.mean(durations)))
    segs = [(t[i0 : i1 + 1], w[i0 : i1 + 1]) for i0, i1 in used]

    n_used = sum(ts.size for ts, _ in segs)
    rows = np.concatenate([np.full(ts.size, i) for i, (ts, _) in enumerate(segs)])
    tau = np.concatenate([ts - ts.mean() for ts, _ in segs])
    ws = np.concatenate([w_ for _, w_ in segs])

    def design(omega: float) -> np.ndarray:
        A = np.zeros((n_used, 1 + 2 * len(segs)))
        A[:, 0] = 1.0  # the contact-state equilibrium, shared by every interval
        A[np.arange(n_used), 1 + 2 * rows] = np.sin(omega * tau)
        A[np.arange(n_used), 2 + 2 * rows] = np.cos(omega * tau)
        return A

    def cost(omega: float) -> float:
        A = design(omega)
        coef, *_ = np.linalg.lstsq(A, ws, rcond=None)
        r = ws - A @ coef
        return float(r @ r)

    w0 = 2 * math.pi * half
    grid = np.linspace(0.4 * w0, 1.6 * w0, 241)
    costs = np.array([cost(o) for o in grid])
    k = int(np.argmin(costs))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    res = minimize_scalar(cost, bounds=(lo, hi), method="bounded", options={"xatol": 1e-10 * w0})
    omega = float(res.x)
    return ContactFrequency(
        frequency_hz=omega / (2 * math.pi),
        half_period_hz=half,
        intervals=[(a, b) for a, b, _, _ in ivs],
        n_samples=int(n_used),
        rms_residual=math.sqrt(cost(omega) / n_used),
    )


# =========================================================================== driving and comparing


def drive_with_trace(scenario: Scenario, trace: Record, *, hold: Literal["constant", "linear"] = "linear") -> Scenario:
    """The scenario driven by a measured base-acceleration trace (paper Fig. 3).

    Parameters
    ----------
    scenario : Scenario
    trace : Record
        Base acceleration [m/s^2] against time [s] on the clock of the
        deflection record (the model starts at t = 0; samples before 0 are
        ignored by the solver).
    hold : {"constant", "linear"}
        Between samples: constant steps (the paper's discretisation) or
        linear (first-order hold). The solver integrates either exactly.

    Returns
    -------
    Scenario
        A copy whose ``excitation`` is
        ``Excitation(kind="base_acceleration", shape="table", times=trace.time,
        values=trace.values, hold=hold, start=0, scale=s)``, ``s`` being the
        scenario's ``excitation.scale`` (1 by default). Its ``data`` still
        describes the original excitation: :func:`impactbeam.fit.fit` keeps
        the trace separately and writes it next to a fitted scenario.
    """
    from .loading import Excitation

    _require(trace, "acceleration", "a base-acceleration excitation")
    if hold not in ("constant", "linear"):
        raise ParameterError(f"hold: must be 'constant' or 'linear', got {hold!r}")
    scale = scenario.excitation.scale if scenario.excitation.kind != "none" else 1.0
    exc = Excitation(
        kind="base_acceleration", shape="table", times=trace.time, values=trace.values, hold=hold,
        start=0.0, scale=scale,
    )
    return dataclasses.replace(scenario, excitation=exc)


def record_point(scenario: Scenario, point: float | None = None) -> float:
    """Where a deflection record is taken [m]: ``point``, else the first contactor, else the first output point."""
    if point is not None:
        x = float(point)
        if not 0 <= x <= scenario.beam.length * (1 + 1e-12):
            raise ParameterError(f"point: {x:g} m is off the beam (length {scenario.beam.length:g} m)")
        return x
    if scenario.contactors:
        return float(scenario.contactors[0].position)
    return float(scenario.output_points[0])


#: The section-4 comparison quantities: key -> (label, unit scale, unit).
FEATURES: dict[str, tuple[str, float, str]] = {
    "first_peak": ("first major peak", 1e3, "mm"),
    "first_peak_time": ("  at time", 1e3, "ms"),
    "first_negative_peak": ("first negative peak", 1e3, "mm"),
    "first_negative_peak_time": ("  at time", 1e3, "ms"),
    "first_contact_duration": ("first contact duration", 1e3, "ms"),
    "negative_period": ("period around first negative peak", 1e3, "ms"),
}


def _vertex(t: np.ndarray, u: np.ndarray, k: int, *, drop: float = 0.05, max_side: int = 25) -> tuple[float, float]:
    """Maximum of ``u`` near sample ``k``: least-squares parabola through the samples around ``k``
    that lie within ``drop * |u[k]|`` of it (at most ``max_side`` on each side), which averages
    the noise of a measured peak; the sample itself when no parabola fits."""
    peak = u[k]
    thr = peak - drop * abs(peak)
    i = k
    while i > 0 and k - i < max_side and u[i - 1] >= thr:
        i -= 1
    j = k
    while j < u.size - 1 and j - k < max_side and u[j + 1] >= thr:
        j += 1
    if k - i < 1 or j - k < 1:
        i, j = max(k - 1, 0), min(k + 1, u.size - 1)
    if j - i < 2:
        return float(t[k]), float(peak)
    x = t[i : j + 1] - t[k]
    a, b, c = np.polyfit(x, u[i : j + 1], 2)
    if not a < 0:
        return float(t[k]), float(peak)
    xv = -b / (2 * a)
    if not x[0] <= xv <= x[-1]:
        return float(t[k]), float(peak)
    return float(t[k] + xv), float(c - b * b / (4 * a))


def response_features(
    time: np.ndarray, u: np.ndarray, *, gap: float | None = None, major: float = 0.8
) -> dict[str, float | None]:
    """The section-4 quantities of a response ``u`` (positive away from the contactor).

    Parameters
    ----------
    time : ndarray, [s]
        Uniform sample times.
    u : ndarray, [m]
        ``u = -w`` for a contactor above, ``w`` otherwise.
    gap : float or None, [m]
        Contactor clearance; contact is ``u < -gap``. None without contactor.
    major : float
        A peak is "major" when it reaches this fraction of ``max u``.

    Returns
    -------
    dict
        ``first_peak`` [m] and ``first_peak_time`` [s]: the first local
        maximum reaching ``major * max(u)`` (paper 4.1/4.2 "first major
        peak"); ``first_negative_peak`` and its time: the minimum of the first
        excursion below zero after it ("first negative peak", "minimum
        deflection for the first contact state"); ``negative_period`` [s]: the
        time between the zero crossings bounding that excursion (the paper's
        "time period in the first negative peak", 4.1);
        ``first_contact_duration`` [s]: the first interval after the major
        peak with ``u < -gap`` (4.2). Extremes are refined by a parabola
        through three samples, crossings by linear interpolation. ``None``
        where undefined.
    """
    t = np.asarray(time, dtype=float)
    u = np.asarray(u, dtype=float)
    out: dict[str, float | None] = {k: None for k in FEATURES}
    umax = float(np.max(u))
    if not umax > 0:
        return out
    i0 = int(np.argmax(u >= major * umax))
    after = np.nonzero(u[i0:] < 0)[0]
    i_end = i0 + int(after[0]) if after.size else u.size
    kp = i0 + int(np.argmax(u[i0:i_end]))
    out["first_peak_time"], out["first_peak"] = _vertex(t, u, kp)
    if not after.size:
        return out
    n0 = i_end
    back = np.nonzero(u[n0:] >= 0)[0]
    n1 = n0 + int(back[0]) if back.size else u.size
    kn = n0 + int(np.argmin(u[n0:n1]))
    tv, mv = _vertex(t, -u, kn)
    out["first_negative_peak_time"], out["first_negative_peak"] = tv, -mv
    if back.size and n0 > 0:
        down = t[n0 - 1] + (t[n0] - t[n0 - 1]) * u[n0 - 1] / (u[n0 - 1] - u[n0])
        up = t[n1 - 1] + (t[n1] - t[n1 - 1]) * u[n1 - 1] / (u[n1 - 1] - u[n1])
        out["negative_period"] = float(up - down)
    if gap is not None:
        s = -u - gap
        for a, b, i, j in _crossings(t, s):
            if t[i] >= out["first_peak_time"]:  # type: ignore[operator]
                if j < u.size - 1 and i > 0:
                    out["first_contact_duration"] = b - a
                break
    return out


@dataclass(frozen=True, eq=False)
class Comparison:
    """Simulated and measured deflection histories side by side (paper section 4).

    Attributes
    ----------
    scenario : Scenario
        The scenario simulated (with the measured excitation, if given).
    result : SimulationResult
    measured : Record
        The measured deflection (restricted to t >= 0).
    simulated : Record
        The simulation at the measured times (exact, :meth:`SimulationResult.displacement`).
    point : float, [m]
        Where the deflection is compared.
    sign : float
        ``u = sign * w`` (-1 for a contactor above).
    features : dict
        ``{key: {"simulated", "measured", "difference_percent"}}`` for the keys of
        :data:`FEATURES`; the difference is ``(sim - meas) / |meas|`` in percent.
    rms_difference : float, [m]
        RMS of ``w_sim - w_meas`` at the measured times.
    nrmse : float or None
        ``rms_difference / rms(w_meas)``; None when the measured rms is 0.
    """

    scenario: Scenario
    result: SimulationResult = field(repr=False)
    measured: Record = field(repr=False)
    simulated: Record = field(repr=False)
    point: float
    sign: float
    features: dict[str, dict[str, float | None]]
    rms_difference: float
    nrmse: float | None

    def to_dict(self) -> dict[str, Any]:
        """Plain-Python summary (for JSON)."""
        return {
            "point": self.point,
            "sign": self.sign,
            "features": self.features,
            "units": {k: "s" if k.endswith(("_time", "duration", "period")) else "m" for k in FEATURES},
            "rms_difference": self.rms_difference,
            "nrmse": self.nrmse,
            "n_samples": int(self.measured.time.size),
        }

    def table(self) -> str:
        """The quantities side by side, as text."""
        rows = [("quantity", "simulated", "measured", "difference")]
        for key, (label, scale, unit) in FEATURES.items():
            f = self.features[key]
            fmt = lambda v: "n/a" if v is None else f"{v * scale:.4f}"  # noqa: E731
            d = f["difference_percent"]
            rows.append((f"{label} [{unit}]", fmt(f["simulated"]), fmt(f["measured"]),
                         "n/a" if d is None else f"{d:+.2f} %"))
        rel = "n/a (measured rms is 0)" if self.nrmse is None else f"{self.nrmse * 100:.1f} % of rms"
        rows.append(("rms difference [mm]", f"{self.rms_difference * 1e3:.4f}", "", rel))
        widths = [max(len(r[j]) for r in rows) for j in range(4)]
        lines = [
            f"Comparison at x = {self.point * 1e3:.4g} mm (u = {'-w' if self.sign < 0 else 'w'}, "
            f"positive away from the contactor), {self.measured.time.size} samples"
        ]
        for r in rows:
            lines.append("  ".join([r[0].ljust(widths[0])] + [c.rjust(w) for c, w in zip(r[1:], widths[1:])]))
        return "\n".join(lines)

    def plot(self, path: str | Path | None = None, *, ax: Any = None) -> Any:
        """Overlay of the measured and simulated deflection (mm) against time.

        Returns the ``(figure, axes, lines)`` of matplotlib; with ``path`` the
        figure is also saved (atomically) there.
        """
        if ax is None:
            plt = require("matplotlib.pyplot", "plot")

            fig, ax = plt.subplots(figsize=(8, 4.5))
        else:
            fig = ax.figure
        tm = self.measured.time
        lines = [
            ax.plot(tm, self.measured.values * 1e3, ".", ms=2.5, color="0.35", label="measured")[0],
        ]
        res = self.result
        t = res.time[res.time <= tm[-1]]
        ws = res.displacement([self.point], t)[0]
        lines.append(ax.plot(t, ws * 1e3, "-", lw=1.2, color="C3", label="simulated")[0])
        for c in self.scenario.contactors[:1]:
            lines.append(ax.axhline(c.direction * c.gap * 1e3, ls="--", lw=0.8, color="C0", label="contactor surface"))
        ax.set_xlabel("time [s]")
        ax.set_ylabel(f"deflection w at x = {self.point * 1e3:.4g} mm [mm]")
        ax.legend(loc="best", fontsize="small")
        ax.grid(True, lw=0.3)
        if path is not None:
            _save_figure(fig, path)
        return fig, ax, lines


def _save_figure(fig: Any, path: str | Path) -> None:
    from ._atomic import atomic_path

    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=130, bbox_inches="tight")


def _prepare(
    scenario: Scenario,
    measured: Record,
    excitation: Record | Excitation | None,
    hold: Literal["constant", "linear"],
    window: tuple[float | None, float | None] | None,
) -> tuple[Scenario, Record]:
    from .loading import Excitation

    _require(measured, "deflection", "a comparison")
    meas = measured
    if window is not None:
        meas = meas.window(*window)
    if meas.time[0] < 0:
        meas = meas.window(0.0, None)
    sc = scenario
    if isinstance(excitation, Record):
        sc = drive_with_trace(sc, excitation, hold=hold)
    elif isinstance(excitation, Excitation):
        sc = dataclasses.replace(sc, excitation=excitation)
    elif excitation is not None:
        raise ParameterError(f"excitation: expected a Record or an Excitation, got {type(excitation).__name__}")
    t_end = float(meas.time[-1])
    if t_end <= 0:
        raise ParameterError(f"{measured.label}: no samples after t = 0")
    sc = dataclasses.replace(sc, solver=dataclasses.replace(sc.solver, end_time=t_end))
    return sc, meas


def _sign(scenario: Scenario) -> float:
    return -1.0 if scenario.contactors and scenario.contactors[0].side == "above" else 1.0


def compare(
    scenario: Scenario,
    measured: Record,
    *,
    excitation: Record | Excitation | None = None,
    hold: Literal["constant", "linear"] = "linear",
    point: float | None = None,
    window: tuple[float | None, float | None] | None = None,
) -> Comparison:
    """Simulate ``scenario`` and compare it with a measured deflection (paper section 4).

    Parameters
    ----------
    scenario : Scenario
    measured : Record
        Deflection ``w`` [m] at ``point`` against time [s] (the model's clock:
        t = 0 when the simulation starts).
    excitation : Record or Excitation, optional
        A measured base-acceleration trace (:func:`drive_with_trace`, with
        ``hold``) or any excitation, replacing the scenario's.
    hold : {"constant", "linear"}
        How a trace is held between samples.
    point : float, optional, [m]
        Default: the first contactor's position, else the first output point.
    window : (start, stop), optional, [s]
        Compare only this part of the record.

    Returns
    -------
    Comparison

    Notes
    -----
    The simulation runs to the last measured time and is evaluated exactly
    at the measured times. The quantities (:func:`response_features`) are
    computed the same way on both: on the measured samples and on the
    simulation's output grid (``solver.time_step``).
    """
    from .solver import simulate

    sc, meas = _prepare(scenario, measured, excitation, hold, window)
    x = record_point(sc, point)
    result = simulate(sc)
    if not result.success:
        raise SimulationError(f"compare: the simulation stopped early: {result.message}")
    w_sim = result.displacement([x], meas.time)[0]
    sim_rec = Record(meas.time, w_sim, name="simulated deflection", quantity="deflection")
    sign = _sign(sc)
    gap = sc.contactors[0].gap if sc.contactors else None
    fm = response_features(meas.time, sign * meas.values, gap=gap)
    tg = result.time
    fs = response_features(tg, sign * result.displacement([x], tg)[0], gap=gap)
    feats: dict[str, dict[str, float | None]] = {}
    for k in FEATURES:
        s, m = fs[k], fm[k]
        d = None if (s is None or m is None or m == 0) else 100.0 * (s - m) / abs(m)
        feats[k] = {"simulated": s, "measured": m, "difference_percent": d}
    diff = w_sim - meas.values
    rms = float(np.sqrt(np.mean(diff**2)))
    rms_m = float(np.sqrt(np.mean(meas.values**2)))
    if float(np.ptp(meas.values)) <= 1e-12 * max(float(np.max(np.abs(meas.values))), 1e-300):
        from ._warnings import emit_user_level_warning

        emit_user_level_warning(
            f"{meas.label}: the measured deflection is constant ({float(meas.values[0]):.6g} m) over the "
            "compared window; the measured features are undefined and the comparison says little"
        )
    return Comparison(
        scenario=sc, result=result, measured=meas, simulated=sim_rec, point=x, sign=sign,
        features=feats, rms_difference=rms, nrmse=rms / rms_m if rms_m > 0 else None,
    )
