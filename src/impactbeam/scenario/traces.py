"""Excitation traces of a scenario (``[excitation] shape = "table"``), read through the one delimited-text reader."""

from __future__ import annotations

import os
import numpy as np

from .._io import numeric_columns, read_delimited
from ..exceptions import ScenarioError
from ..units import DIMENSIONS, unit_scale

__all__ = ["read_table"]


def read_table(
    path: str | os.PathLike[str],
    *,
    value_dimension: str,
    key: str,
    label: str | None = None,
    abscissa: str = "time",
) -> tuple[np.ndarray, np.ndarray]:
    """Read a two-column trace ``time, value`` (or ``position, value``) from a CSV file, in SI units.

    The file is read by the same reader as measured records
    (:func:`impactbeam.experiment.load_record`), so both honour the same
    unit headers.

    Parameters
    ----------
    path : path-like
        The file. Cells are separated by commas (or semicolons, or tabs, or
        blanks when the file has none of those). Blank lines and lines starting
        with ``#`` are skipped.
    value_dimension : str
        Dimension of the value column (see :mod:`impactbeam.units`), e.g.
        ``"acceleration"``.
    key : str
        Dotted key reported in errors (``"excitation.file"``).
    label : str, optional
        How the file is named in messages (default: ``path`` as given).
    abscissa : {"time", "length"}
        Dimension of the first column: times of a trace, or positions along
        the beam of a field (``[initial] displacement_file``).

    Returns
    -------
    times : ndarray, shape (n,), [s] (or [m])
        Strictly increasing, n >= 2.
    values : ndarray, shape (n,)
        In the SI unit of ``value_dimension``.

    Notes
    -----
    An optional first line names the columns, with units in brackets or
    parentheses: ``time [ms],acceleration [g]`` or ``time (ms),acceleration
    (g)`` (``g`` = 9.80665 m/s^2 for an acceleration). A column without a
    unit, or a file without a header, is SI. Each number is scaled in decimal
    arithmetic, so ``1.5`` ms gives exactly the float ``0.0015``.

    Raises
    ------
    ScenarioError
        With ``key``, the file name and the line number: missing or unreadable
        file, one column only, fewer than two rows, a wrong number of columns,
        a non-numeric cell, NaN or infinity, non-increasing times, an unknown
        unit or one of the wrong dimension (naming the column and the unit).
    """
    name = str(path) if label is None else label

    def fail(detail: str) -> ScenarioError:
        return ScenarioError(f'{key}: "{name}" {detail}', key=key)

    where = "" if str(path) == name else f" (looked for {path})"
    noun = "time" if abscissa == "time" else "position"
    si = DIMENSIONS[abscissa].si_unit
    table = read_delimited(
        path, fail, what="a trace" if abscissa == "time" else "a field along the beam",
        example=f"{noun} [{si}],value [{DIMENSIONS[value_dimension].si_unit}]",
        not_found=f"not found{where}",
    )
    if table.ncol != 2:
        raise fail(
            f"line {table.first_line}: {table.ncol} columns ({', '.join(table.names)}), expected 2 ({noun}, value)"
        )
    scales = [1.0, 1.0]
    for j, dimension in enumerate((abscissa, value_dimension)):
        unit = table.units[j]
        if unit is not None:
            try:
                scales[j] = unit_scale(unit, dimension, key)
            except ScenarioError as exc:
                detail = str(exc).partition(": ")[2]
                raise fail(
                    f'line {table.first_line}, column {j + 1} ({table.names[j]!r}), unit "{unit}": {detail}'
                ) from None
    (times, values), _ = numeric_columns(table, (0, 1), scales, fail, (noun, si))
    if times.size < 2:
        what = "a trace" if abscissa == "time" else "a field"
        raise fail(f"has {times.size} data row{'' if times.size == 1 else 's'}; {what} needs at least 2")
    return times, values
