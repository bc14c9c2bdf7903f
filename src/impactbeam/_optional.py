"""Optional dependencies: one helper that names the extra to install.

The core of impactbeam (``impactbeam modes``, ``impactbeam simulate`` and the
Python API behind them) needs numpy, scipy, numba, xarray, pandas, pint,
click, tomli-w and tqdm. Everything else is an *extra*::

    pip install "impactbeam[sweep]"    # Dask and Zarr: parameter studies
    pip install "impactbeam[fit]"      # lmfit: identification from records
    pip install "impactbeam[io]"       # h5netcdf, h5py, pyarrow: .nc / .parquet files
    pip install "impactbeam[plot]"     # matplotlib: figures and reports
    pip install "impactbeam[explore]"  # Panel: the live explorer
    pip install "impactbeam[all]"      # all of the above

Modules import optional packages inside the functions that need them,
through :func:`require`, so a missing package is reported as one sentence
naming the extra instead of a bare ``ModuleNotFoundError``.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from .exceptions import ImpactBeamError

__all__ = ["EXTRAS", "MissingDependencyError", "require", "check_installed"]

#: The extra that provides each optional top-level package.
EXTRAS: dict[str, str] = {
    "dask": "sweep",
    "distributed": "sweep",
    "zarr": "sweep",
    "lmfit": "fit",
    "h5netcdf": "io",
    "h5py": "io",
    "pyarrow": "io",
    "matplotlib": "plot",
    "panel": "explore",
    "bokeh": "explore",
}

#: What each extra enables, for the message.
_PURPOSE: dict[str, str] = {
    "sweep": "parameter studies",
    "fit": "identification from measured records",
    "io": "netCDF and Parquet files",
    "plot": "figures",
    "explore": "the live explorer",
}


class MissingDependencyError(ImpactBeamError, ImportError):
    """An optional package needed by the requested feature is not installed."""


def require(module: str, extra: str | None = None, *, feature: str | None = None) -> ModuleType:
    """Import ``module`` or raise one clear error naming the extra that provides it.

    Parameters
    ----------
    module : str
        Dotted module name, e.g. ``"zarr"`` or ``"matplotlib.pyplot"``.
    extra : str, optional
        The ``impactbeam[...]`` extra that installs it; looked up in
        :data:`EXTRAS` from the top-level package when omitted.
    feature : str, optional
        What the user asked for (e.g. ``"impactbeam sweep"``), for the message.

    Returns
    -------
    module
        The imported module.

    Raises
    ------
    MissingDependencyError
        The package (or one it needs) cannot be imported. It is an
        :class:`ImportError` and an :class:`~impactbeam.exceptions.ImpactBeamError`,
        so the command line prints it as one ``error:`` line (exit status 1).
    """
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise _missing(module, extra, feature, f"{type(exc).__name__}: {exc}") from exc


def check_installed(module: str, extra: str | None = None, *, feature: str | None = None) -> None:
    """Raise :func:`require`'s error if ``module`` is not installed, without importing it.

    For a check before any work of a package a run may not import at all
    (Dask's scheduler when the sweep runs on local processes): finding the
    module costs a file lookup, importing it tenths of a second.

    Parameters
    ----------
    module, extra, feature
        As for :func:`require`.

    Raises
    ------
    MissingDependencyError
        No installed package provides ``module``.
    """
    import importlib.util

    try:
        found = importlib.util.find_spec(module) is not None
    except (ImportError, ValueError) as exc:  # a parent package missing, or blocked in sys.modules
        found = False
        reason = f"{type(exc).__name__}: {exc}"
    else:
        reason = f"no module named {module!r}"
    if not found:
        raise _missing(module, extra, feature, reason)


def _missing(module: str, extra: str | None, feature: str | None, reason: str) -> MissingDependencyError:
    top = module.split(".")[0]
    extra = extra or EXTRAS.get(top)
    what = feature or _PURPOSE.get(extra or "", "this feature")
    hint = f'pip install "impactbeam[{extra}]"' if extra else f"pip install {top}"
    return MissingDependencyError(
        f"{what} needs the optional package {top!r}, which is not installed ({reason}); install it with: {hint}")
