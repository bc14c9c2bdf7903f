"""Files: JSON text, accepted suffixes, atomic writes and the one reader of delimited text.

Everything the package writes or reads as a file goes through here:

* **JSON** (:func:`to_jsonable`, :func:`json_text`): numpy scalars and arrays
  become Python numbers and lists, NaN and infinity become ``null``; the one
  rule for ``--json`` output and the metrics stored in result files.
* **Suffixes** (:data:`RESULT_SUFFIXES`, :data:`PLOT_SUFFIXES`,
  :func:`check_output`): an output path is checked before any computing.
* **Atomic writes** (:func:`atomic_path`, :func:`write_text`,
  :func:`write_bytes`, :func:`write_netcdf`): a temporary file beside the
  target, then :func:`os.replace`. A reader never sees half a file, and a
  failed or interrupted write leaves nothing behind. The temporary name holds
  the writer's pid, so a file left by a writer killed outright (SIGKILL) is
  removed by the next write to the same target. Every operating-system error
  of a write (read-only or full file system, permissions) becomes one
  :class:`WriteError` naming the target and the reason, after the temporary
  file is removed; success is reported only once the file is closed and in
  place. :func:`check_writable` tries the directory before any computing.
* **Reading** (:func:`read_text_file`): a regular file only (a device or a
  pipe is refused at once, without reading), text only (a binary file is
  refused from its first bytes), and its size checked against the memory
  limit before it is read.
* **Delimited text** (:func:`read_delimited`, :func:`numeric_columns`): the
  one reader of scenario traces (``[excitation] shape = "table"``) and of
  measured records (:func:`impactbeam.experiment.load_record`), so they accept
  the same layout: cells separated by commas, or semicolons, or tabs (the
  first of these that occurs), else by blanks; blank lines and lines starting
  with ``#`` skipped; an optional header line naming the columns, each with an
  optional unit in brackets or parentheses at its end (``time [ms]``, ``acc
  (mm/(s^2))``); a column without a unit is SI. The caller
  decides what a unit means for each column and passes the SI factors to
  :func:`numeric_columns`, which scales each written number in decimal
  arithmetic (:func:`impactbeam.units.scale_decimal`), so ``1.5`` in a
  ``time (ms)`` column gives exactly the float ``0.0015``.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import re
import tempfile
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from glob import escape as glob_escape
from pathlib import Path
from typing import Any

import numpy as np

from .exceptions import ImpactBeamError, ParameterError
from .units import scale_decimal

__all__ = [
    "to_jsonable", "json_text", "RESULT_SUFFIXES", "PLOT_SUFFIXES", "check_output", "check_writable",
    "WriteError", "write_error", "atomic_path", "write_text", "write_bytes", "write_netcdf", "pid_alive",
    "read_text_file", "TEXT_MEMORY_FACTOR",
    "HEADER_CELL", "DelimitedText", "numeric_columns", "read_data_lines", "read_delimited",
]

# --------------------------------------------------------------------------- JSON


def to_jsonable(value: Any) -> Any:
    """Convert ``value`` for :func:`json.dumps`: numpy scalars and arrays to Python
    numbers and lists, tuples to lists, NaN, infinity and None to ``null``,
    paths and other objects to their text."""
    if isinstance(value, Mapping):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return [to_jsonable(v) for v in value.tolist()]
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return str(value)


def json_text(value: Any, indent: int | None = None) -> str:
    """Strict JSON text of ``value`` after :func:`to_jsonable` (never ``NaN``)."""
    return json.dumps(to_jsonable(value), indent=indent, allow_nan=False)


# --------------------------------------------------------------------------- suffixes

#: File types of a full result (written by :func:`impactbeam.result.write_result`).
RESULT_SUFFIXES = (".nc", ".csv", ".parquet")
#: File types of a figure (matplotlib formats).
PLOT_SUFFIXES = (".png", ".pdf", ".svg", ".jpg", ".jpeg", ".eps", ".ps", ".tif", ".tiff", ".webp")


def check_output(option: str, path: str | None, suffixes: tuple[str, ...]) -> None:
    """Reject an unsupported suffix or a missing directory before any computing.

    Parameters
    ----------
    option : str
        The option or field named in the error (e.g. ``"--out"``).
    path : str or None
        The requested file; None is accepted (no output asked for).
    suffixes : tuple of str
        The accepted suffixes, lower case with the dot.

    Raises
    ------
    ParameterError
        Naming ``option`` and the problem.
    """
    if path is None:
        return
    p = Path(path)
    if not path.strip():
        raise ParameterError(f"{option}: the file name is empty (use {', '.join(suffixes)})")
    if p.is_dir() or path.endswith(("/", "\\")):
        raise ParameterError(
            f'{option}: "{path}" is a directory; give a file name in it, e.g. "{p / ("result" + suffixes[0])}"'
        )
    if p.suffix.lower() not in suffixes:
        raise ParameterError(
            f'{option}: unsupported file type "{p.suffix or p.name}" (use {", ".join(suffixes)})'
        )
    if not p.parent.is_dir():
        raise ParameterError(f'{option}: directory "{p.parent}" does not exist')
    check_writable(option, p)


def check_writable(option: str, path: str | os.PathLike[str]) -> None:
    """Refuse, before any computing, an output whose directory cannot take a new file (:class:`WriteError`).

    A file is created beside ``path`` (a file or a Zarr store) and removed:
    the answer is the operating system's (a read-only file system, missing
    permissions, no free inode). A full disk that still takes an empty file
    is found when the data is written. ``option`` is named in the error.
    """
    target = Path(path)
    try:
        fd, probe = tempfile.mkstemp(prefix=f".{target.name}.{os.getpid()}.", suffix=".probe",
                                     dir=target.parent if str(target.parent) else ".")
    except OSError as exc:
        raise write_error(target, exc, option) from None
    os.close(fd)
    with contextlib.suppress(OSError):
        os.unlink(probe)


# --------------------------------------------------------------------------- atomic writes


class WriteError(ImpactBeamError, OSError):
    """A file could not be written (read-only or full file system, permissions): one line naming it.

    Also an :class:`OSError`. Attributes: ``path``, ``reason`` (the operating
    system's words, also as ``strerror``) and ``option`` (``--out``, when known).
    """

    def __init__(self, path: str | os.PathLike[str], reason: str, option: str | None = None,
                 errno_: int | None = None) -> None:
        prefix = f"{option}: " if option else ""
        self.message = f'{prefix}cannot write "{os.fspath(path)}": {reason}'
        super().__init__(self.message)
        self.path = os.fspath(path)
        self.reason = reason
        self.option = option
        self.errno = errno_
        self.strerror = reason  # what callers that format OSErrors themselves show

    def __str__(self) -> str:
        return self.message


_ERRNO_IN_TEXT = re.compile(r"errno\s*[=:]?\s*(\d+)", re.IGNORECASE)


def write_error(path: str | os.PathLike[str], exc: BaseException, option: str | None = None) -> WriteError:
    """The :class:`WriteError` of ``exc`` raised while writing ``path``: the reason is the operating
    system's message for the error number, also when a library (HDF5, Arrow) wrapped it in its own text."""
    if isinstance(exc, WriteError):
        return exc
    code = getattr(exc, "errno", None)
    if not isinstance(code, int):
        m = _ERRNO_IN_TEXT.search(str(exc))
        code = int(m.group(1)) if m else None
    if isinstance(code, int) and code > 0:
        reason = os.strerror(code)
    else:
        reason = getattr(exc, "strerror", None) or " ".join(str(exc).split()) or type(exc).__name__
    return WriteError(path, reason, option, code)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str], suffix: str | None = None) -> Iterator[str]:
    """Yield a temporary path to write; on success it replaces ``path``.

    The temporary file lives in the target's directory (so the replace is
    atomic) and ends with ``suffix`` (default: the target's suffix, which lets
    writers choose a format from it). It gets the usual ``0666 & ~umask`` mode.
    """
    target = Path(path)
    directory = target.parent if str(target.parent) else Path(".")
    _remove_stale(directory, target.name)
    try:
        fd, tmp = tempfile.mkstemp(
            prefix=f".{target.name}.{os.getpid()}.", suffix=target.suffix if suffix is None else suffix, dir=directory
        )
        os.close(fd)
    except OSError as exc:
        raise write_error(target, exc) from None
    try:
        yield tmp
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, target)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise write_error(target, exc) from None
        raise


def _remove_stale(directory: Path, name: str) -> None:
    """Remove temporary files of ``name`` left by writers that were killed (their pid is gone)."""
    for p in directory.glob(f".{glob_escape(name)}.*"):
        parts = p.name[len(name) + 2 :].split(".", 1)
        if parts[0].isdigit() and not pid_alive(int(parts[0])):
            with contextlib.suppress(OSError):
                p.unlink()


def pid_alive(pid: object) -> bool:
    """Whether a process with this pid exists on this host (True when it cannot be told)."""
    try:
        os.kill(int(pid), 0)  # type: ignore[call-overload]
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, TypeError, ValueError):
        return True
    return True


def write_text(path: str | os.PathLike[str], text: str) -> None:
    """Write UTF-8 text (LF line ends) to ``path`` atomically.

    Parameters
    ----------
    path : path-like
        The file.
    text : str
        Its content.

    Raises
    ------
    WriteError
        The file could not be written (nothing is left behind).
    """
    write_bytes(path, text.encode("utf-8"), ".tmp")


def write_bytes(path: str | os.PathLike[str], data: bytes | memoryview, suffix: str | None = None) -> None:
    """Write ``data`` to ``path`` atomically; it is in place only once written, flushed and closed.

    Parameters
    ----------
    path : path-like
        The file.
    data : bytes or memoryview
        Its content.
    suffix : str, optional
        Suffix of the temporary file (default the target's).

    Raises
    ------
    WriteError
        The file could not be written (nothing is left behind).
    """
    with atomic_path(path, suffix) as tmp:
        with open(tmp, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())


def write_netcdf(dataset: Any, path: str | os.PathLike[str]) -> None:
    """Write an :class:`xarray.Dataset` to a netCDF4 (HDF5) file, atomically and safely on a full disk.

    The file is serialised in memory first (``h5netcdf``) and its bytes are
    then written by :func:`write_bytes`: the HDF5 library never writes to the
    disk itself, because on a full file system its close crashed the process
    (a segmentation fault inside the library) instead of raising an error.

    Parameters
    ----------
    dataset : xarray.Dataset
    path : path-like
        The ``.nc`` file.

    Raises
    ------
    WriteError
        The file could not be written (nothing is left behind).
    """
    write_bytes(path, dataset.to_netcdf(engine="h5netcdf"))


# --------------------------------------------------------------------------- delimited text

_UNIT_GROUP = r"(?:\[[^\[\]]*\]|\((?:[^()]|\([^()]*\))*\))"  # [mm/(s^2)] or (mm/(s^2)): one level inside
#: A header cell: a name and an optional unit in brackets or parentheses, at its end.
HEADER_CELL = re.compile(r"^\s*(?P<name>.*?)\s*(?P<group>" + _UNIT_GROUP + r")?\s*$")
_BLANK_HEADER = re.compile(r"[^\s\[\]()]+(?:\s*" + _UNIT_GROUP + r")?|" + _UNIT_GROUP)


def _header_cell(cell: str) -> tuple[str, str | None]:
    """Name and unit (None: none given) of a header cell; ValueError when its unit cannot be told (``time/ms``,
    a bracket left open), which would otherwise pass for a name and its column be read as SI."""
    m = HEADER_CELL.match(cell)
    name = (m.group("name") if m else cell).strip()
    group = m.group("group") if m else None
    if group is None and any(ch in cell for ch in "[]()/"):
        raise ValueError(f"cannot tell the unit of the column {cell.strip()!r}: write it after the name in "
                         "brackets, e.g. 'time [ms]'")
    return name or cell.strip(), None if group is None else group[1:-1].strip()


#: Peak memory of reading a text table, per byte of the file (the text, its lines, their cells
#: and the numbers): measured 16.5 (peak RSS) for a 29 MiB two-column record of full-precision
#: numbers, and ~24 by the trial of a 200 MB record (4.8 GB); a file is refused, before it is read,
#: when this many times its size exceeds the memory limit.
TEXT_MEMORY_FACTOR = 25

_SNIFF = 8192  # bytes read to tell text from binary


def read_text_file(
    path: str | os.PathLike[str],
    fail: Callable[[str], Exception],
    *,
    not_found: str | None = "not found",
    not_text: str = "is not a text (UTF-8) file",
    memory_factor: float = TEXT_MEMORY_FACTOR,
) -> str:
    """The UTF-8 text of a regular file, or one error at once for anything else.

    A device, a pipe or a socket (``/dev/zero``, ``/dev/stdin``) is refused
    from its file type, without reading; a binary file from a NUL byte in its
    first 8 KiB; a file whose reading would need more than the memory limit
    (``memory_factor`` times its size, :func:`impactbeam._memory.memory_limit`)
    from its size, with the estimate. A byte-order mark is dropped.

    Parameters
    ----------
    path : path-like
        The file.
    fail : callable
        ``fail(detail)`` builds the exception to raise (it adds the file name
        and the key).
    not_found : str or None
        Detail for a missing file (None: reported as a read error).
    not_text : str
        Detail for a file that is not UTF-8 text.
    memory_factor : float
        Peak bytes of memory per byte of the file.

    Returns
    -------
    str
    """
    import stat

    from ._memory import memory_limit

    p = Path(path)
    try:
        info = p.stat()
    except FileNotFoundError as exc:
        if not_found is None:
            raise fail(f"cannot be read: {exc.strerror or exc}") from None
        raise fail(not_found) from None
    except OSError as exc:
        raise fail(f"cannot be read: {exc.strerror or exc}") from None
    if stat.S_ISDIR(info.st_mode):
        raise fail("is a directory, not a text file")
    if not stat.S_ISREG(info.st_mode):
        raise fail("is not a regular file (a device, a pipe or a socket); give a text file")
    need, limit = memory_factor * info.st_size, memory_limit()
    if need > limit:
        raise fail(
            f"is {info.st_size / 2**20:.4g} MiB; reading it would need about {need / 2**30:.3g} GiB, above the "
            f"limit of {limit / 2**30:.3g} GiB (split or decimate the file, or raise IMPACTBEAM_MEMORY_LIMIT)"
        )
    try:
        with open(p, "rb") as fh:
            head = fh.read(_SNIFF)
            if b"\0" in head:
                raise fail(f"{not_text} (it holds binary data)")
            data = head + fh.read()
    except IsADirectoryError:
        raise fail("is a directory, not a text file") from None
    except OSError as exc:
        raise fail(f"cannot be read: {exc.strerror or exc}") from None
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise fail(not_text) from None


def read_data_lines(
    path: str | os.PathLike[str],
    fail: Callable[[str], Exception],
    *,
    not_found: str | None = "not found",
    not_text: str = "is not a text (UTF-8) file",
) -> tuple[list[tuple[int, str]], str | None]:
    """Numbered data lines of a UTF-8 text file and its delimiter.

    Blank lines and lines starting with ``#`` are skipped; the delimiter is the
    first of ``,``, ``;`` and tab that occurs, or None (white space). Read
    errors are raised as ``fail(detail)`` (``not_found=None``: a missing file
    is reported like any other read error); see :func:`read_text_file` for
    devices, binary files and files too large to read.
    """
    text = read_text_file(path, fail, not_found=not_found, not_text=not_text)
    lines = [
        (n, line) for n, line in enumerate(text.splitlines(), start=1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    delimiter = next((d for d in (",", ";", "\t") if any(d in line for _, line in lines)), None)
    return lines, delimiter


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


@dataclass(frozen=True)
class DelimitedText:
    """The cells of a delimited text table, not yet converted to numbers.

    Attributes
    ----------
    names : tuple of str
        Column names: from the header, else ``time, column 2, ...``.
    units : tuple of (str or None)
        Unit written in each header cell (None: none written, i.e. SI).
    header : bool
        Whether the file has a header line.
    first_line : int
        Line number of the header (or of the first data row).
    rows : list of (int, list of str)
        Line number and stripped cells of each data row.
    """

    names: tuple[str, ...]
    units: tuple[str | None, ...]
    header: bool
    first_line: int
    rows: list[tuple[int, list[str]]]

    @property
    def ncol(self) -> int:
        """Number of columns (from the first line)."""
        return len(self.names)


def read_delimited(
    path: str | os.PathLike[str],
    fail: Callable[[str], Exception],
    *,
    what: str,
    example: str,
    not_found: str | None = "not found",
    not_text: str = "is not a text (UTF-8) file",
) -> DelimitedText:
    """Read a delimited text table of at least two columns (time first).

    Parameters
    ----------
    path : path-like
        The text file.
    fail : callable
        ``fail(detail)`` builds the exception to raise (it adds the file name
        and the scenario key).
    what : str
        What the table is, for messages (``"a trace"``, ``"a record"``).
    example : str
        An example header for the message about a missing column.
    not_found, not_text : str
        Details for a missing file (None: reported as a read error) and for a
        file that is not UTF-8 text.

    Returns
    -------
    DelimitedText

    Raises
    ------
    Exception
        ``fail(...)``: unreadable or empty file, or one column only (this is
        checked before any unit, so the message is about the column).
    """
    lines, delimiter = read_data_lines(path, fail, not_found=not_found, not_text=not_text)
    if not lines:
        raise fail("holds no data")

    def cells(line: str, header: bool = False) -> list[str]:
        if delimiter is None:  # blanks separate cells; a header keeps "name (unit)" together
            return _BLANK_HEADER.findall(line) if header else line.split()
        return [c.strip() for c in next(csv.reader(io.StringIO(line), delimiter=delimiter))]

    n0, first_line = lines[0]
    first = cells(first_line, header=True)
    if any(_is_number(c) for c in first):
        first = cells(first_line)
    if len(first) < 2:
        raise fail(
            f"line {n0}: only one column ({first[0] if first else ''!r}); {what} needs two: time and "
            f"a value column (e.g. a header `{example}`)"
        )
    header = not any(_is_number(c) for c in first)
    if header:
        try:
            names, units = (list(col) for col in zip(*(_header_cell(cell) for cell in first)))
        except ValueError as exc:
            raise fail(f"line {n0}: {exc}") from None
        rows = lines[1:]
    else:
        names = ["time"] + [f"column {j}" for j in range(2, len(first) + 1)]
        units = [None] * len(first)
        rows = lines
    return DelimitedText(
        names=tuple(names), units=tuple(units), header=header, first_line=n0,
        rows=[(n, cells(line)) for n, line in rows],
    )


def numeric_columns(
    table: DelimitedText,
    columns: Sequence[int],
    scales: Sequence[float],
    fail: Callable[[str], Exception],
    abscissa: tuple[str, str] = ("time", "s"),
) -> tuple[list[np.ndarray], list[int]]:
    """Numbers of some columns in SI; the first of ``columns`` is time (or ``abscissa``).

    Each cell is checked (a number, finite) and multiplied by its column's
    factor in decimal arithmetic; times must increase strictly. ``abscissa``
    names the first column's quantity and SI unit in messages (``("position",
    "m")`` for a field along the beam).

    Returns
    -------
    arrays : list of ndarray
        One per entry of ``columns``, in SI.
    lines : list of int
        Line number of each row.
    """
    ncol = table.ncol
    names = table.names
    noun, si_unit = abscissa
    unit = table.units[columns[0]] or si_unit
    out: list[list[float]] = [[] for _ in columns]
    line_numbers: list[int] = []
    for n, row in table.rows:
        if len(row) != ncol:
            raise fail(
                f"line {n}: {len(row)} column{'s' if len(row) != 1 else ''}, expected {ncol} ({', '.join(names)})"
            )
        for k, (j, scale) in enumerate(zip(columns, scales)):
            cell = row[j]
            try:
                x = float(cell)
            except ValueError:
                raise fail(f"line {n}, column {j + 1} ({names[j]}): cannot read {cell!r} as a number") from None
            if math.isnan(x):
                raise fail(f"line {n}, column {j + 1} ({names[j]}): NaN value")
            if math.isinf(x):
                raise fail(f"line {n}, column {j + 1} ({names[j]}): infinite value")
            value = x if scale == 1.0 else scale_decimal(cell, scale)
            if k == 0 and out[0] and not value > out[0][-1]:
                raise fail(
                    f"line {n}, column {j + 1} ({names[j]}): {noun} {x:g} {unit} does not come after the "
                    f"previous {out[0][-1] / scale:g} {unit} ({noun}s must increase strictly)"
                )
            out[k].append(value)
        line_numbers.append(n)
    return [np.asarray(v, dtype=float) for v in out], line_numbers
