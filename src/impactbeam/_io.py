"""Files: JSON text, accepted suffixes, atomic writes and the one reader of delimited text.

Everything the package writes or reads as a file goes through here:

* **JSON** (:func:`to_jsonable`, :func:`json_text`): numpy scalars and arrays
  become Python numbers and lists, NaN and infinity become ``null``; the one
  rule for ``--json`` output and the metrics stored in result files.
* **Suffixes** (:data:`RESULT_SUFFIXES`, :data:`PLOT_SUFFIXES`,
  :func:`check_output`): an output path is checked before any computing.
* **Atomic writes** (:func:`atomic_path`, :func:`write_text`): a temporary
  file beside the target, then :func:`os.replace`. A reader never sees half a
  file, and a failed or interrupted write leaves nothing behind. The temporary
  name holds the writer's pid, so a file left by a writer killed outright
  (SIGKILL) is removed by the next write to the same target.
* **Delimited text** (:func:`read_delimited`, :func:`numeric_columns`): the
  one reader of scenario traces (``[excitation] shape = "table"``) and of
  measured records (:func:`impactbeam.experiment.load_record`), so they accept
  the same layout: cells separated by commas, or semicolons, or tabs (the
  first of these that occurs), else by blanks; blank lines and lines starting
  with ``#`` skipped; an optional header line naming the columns, each with an
  optional unit in brackets or parentheses (``time [ms],acceleration [g]`` or
  ``time (ms),acceleration (g)``); a column without a unit is SI. The caller
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

from .exceptions import ParameterError
from .units import scale_decimal

__all__ = [
    "to_jsonable", "json_text", "RESULT_SUFFIXES", "PLOT_SUFFIXES", "check_output",
    "atomic_path", "write_text", "pid_alive",
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


# --------------------------------------------------------------------------- atomic writes


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
    fd, tmp = tempfile.mkstemp(
        prefix=f".{target.name}.{os.getpid()}.", suffix=target.suffix if suffix is None else suffix, dir=directory
    )
    os.close(fd)
    try:
        yield tmp
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
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
    """Write UTF-8 text (LF line ends) to ``path`` atomically."""
    with atomic_path(path, ".tmp") as tmp:
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())


# --------------------------------------------------------------------------- delimited text

#: A header cell: a name and an optional unit in brackets or parentheses.
HEADER_CELL = re.compile(r"^\s*(?P<name>.*?)\s*(?:[\[(](?P<unit>[^\[\]()]*)[\])])?\s*$")

_BLANK_HEADER = re.compile(r"[^\s\[\]()]+(?:\s*[\[(][^\[\]()]*[\])])?|[\[(][^\[\]()]*[\])]")


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
    is reported like any other read error).
    """
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except FileNotFoundError as exc:
        if not_found is None:
            raise fail(f"cannot be read: {exc.strerror or exc}") from None
        raise fail(not_found) from None
    except IsADirectoryError:
        raise fail("is a directory, not a CSV file") from None
    except UnicodeDecodeError:
        raise fail(not_text) from None
    except OSError as exc:
        raise fail(f"cannot be read: {exc.strerror or exc}") from None
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
        names, units = [], []
        for cell in first:
            m = HEADER_CELL.match(cell)
            name = (m.group("name") if m else cell).strip() or cell.strip()
            unit = m.group("unit") if m else None
            names.append(name)
            units.append(unit.strip() if unit is not None else None)
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
