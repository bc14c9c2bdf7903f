"""Writing a simulation result to a file: netCDF, CSV or Parquet, atomically."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._io import RESULT_SUFFIXES, atomic_path, write_netcdf
from .._memory import check_output_size
from ..exceptions import ParameterError

if TYPE_CHECKING:
    from .simulation_result import SimulationResult

__all__ = ["write_result"]


def write_result(result: SimulationResult, path: str | os.PathLike, *,
                 report: Mapping[str, Any] | None = None) -> Path:
    """Write the full result to ``.nc`` (netCDF4/HDF5), ``.csv`` or ``.parquet``, atomically.

    Parameters
    ----------
    result : SimulationResult
    path : str or path-like
        The file; its suffix chooses the format (:data:`RESULT_SUFFIXES`).
    report : mapping, optional
        What was reported of the run besides its metrics (``impactbeam
        simulate``: convergence, impact statistics, fatigue, seed, and
        ``"warnings"``, every warning of the command): stored as the files'
        ``metrics`` and ``warnings`` attributes in place of the run's own
        (:func:`~impactbeam.result.dataset.result_attrs`).

    Returns
    -------
    Path

    Raises
    ------
    ParameterError
        An unsupported suffix.
    ResourceError
        The sampled histories would exceed the memory limit.
    WriteError
        The file could not be written (a read-only or full file system): nothing is left behind.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in RESULT_SUFFIXES:
        raise ParameterError(f"--out: unsupported file type {suffix!r}; use one of {', '.join(RESULT_SUFFIXES)}")
    from .._optional import require

    require({".nc": "h5netcdf", ".csv": "pandas", ".parquet": "pyarrow"}[suffix], "io", feature=f"writing {suffix}")
    path.parent.mkdir(parents=True, exist_ok=True)
    check_output_size(result.time.size, result.points.size, len(result.contactors), result.solution.n_modes)
    from .dataset import result_attrs

    if suffix == ".nc":
        ds = result.to_xarray()  # with the run's own attributes (result_attrs)
        if report is not None:
            ds.attrs.update(result_attrs(result, report))
        write_netcdf(ds, path)
        return path
    table = result.to_dataframe()
    with atomic_path(path) as tmp:
        if suffix == ".csv":
            table.to_csv(tmp, index=False)
        else:  # Parquet keeps the attributes (pandas' attrs in its metadata); a CSV file has no place for them
            attrs = result_attrs(result, report)
            table.attrs = {k: v if isinstance(v, (str, int, float)) else str(v) for k, v in attrs.items()}
            table.to_parquet(tmp, index=False)
    return path
