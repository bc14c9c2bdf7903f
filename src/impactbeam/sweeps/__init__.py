"""Parameter studies: sweep files, execution on Dask, labelled results in Zarr that resume.

A *sweep* varies a base scenario (see the scenario reference) through dotted paths
(``contactors.0.gap``, ``excitation.duration``, ``beam.height``, ...) and
records, for every case, the scalar response metrics of
:meth:`impactbeam.SimulationResult.metrics` (the quantities of the paper's
Table 2, section 4) and optionally the deflection history at chosen points on
a coarse time grid.

Sweep file (TOML)::

    base = "case03.toml"                # scenario path, relative to this file; or an inline [base] table
    design = "grid"                     # grid | lhs | sobol | random
    # samples = 1024                    # sampled designs only (lhs, sobol, random)
    # seed = 1                          # sampled designs; default 0
    [parameters."contactors.0.gap"]
    values = [0.0, 0.102e-3, 0.229e-3]  # numbers (SI) or strings with units ("0.229 mm")
    [parameters."excitation.duration"]
    range = [5e-3, 20e-3, 16]           # start, stop, num (inclusive); scale = "log" optional
    # [parameters."excitation.amplitude"]   # sampled designs:
    # distribution = "uniform"          # uniform: low, high | normal: mean, std | lognormal: mean, std
    # low = "10 g"
    # high = "20 g"
    [outputs]
    metrics = "all"                     # or a list of metric names
    # histories = { points = [0.052853], time_step = 1e-4 }

Results (:func:`sweep`) are an :class:`xarray.Dataset`: for a grid one
dimension per parameter, named by its path exactly as written and holding its
values (SI) as coordinate; for a sampled design a ``case`` dimension with the
sampled values as coordinates named by the paths. Variables: the metrics (the
names of ``impactbeam simulate --json``, float64 with ``units``; NaN where a
metric is undefined or the case failed), ``status`` (int8: 0 reached
end_time, 1 stopped by the chattering guard, -1 failed, -2 not yet run),
``message`` (the error or solver message; empty when status is 0) and, with
``histories``, ``w`` over (..., ``time``, ``point``).

Storage and resume: the Zarr store is created (atomically) with every case
not yet run; each batch of cases is one Zarr chunk, written when the batch
finishes (metrics first, ``status`` last, each chunk file written atomically
by zarr), so a store killed at any moment holds complete batches only.
Running the same sweep into the same store computes only the batches that
still have status -2; the attribute ``sweep_hash`` (SHA-256 of the resolved
sweep: base scenario content, design, parameter values, outputs) guards
against resuming into a store made by another sweep. Nothing
nondeterministic (times, host names, worker counts) is stored, so an
interrupted and resumed sweep gives the same contents as an uninterrupted one.
"""

from __future__ import annotations

from .batches import run_batch
from .parse import load_sweep, parse_sweep
from ..plot.sweep import plot_sweep, select_cases
from .run import SweepInterrupted, SweepRun, run_sweep, sweep
from .spec import DESIGNS, DISTRIBUTIONS, FAILED, NOT_RUN, STATUS_CODES, SweepParameter, SweepSpec

__all__ = [
    "SweepSpec",
    "SweepParameter",
    "SweepRun",
    "SweepInterrupted",
    "load_sweep",
    "parse_sweep",
    "sweep",
    "run_sweep",
    "run_batch",
    "plot_sweep",
    "select_cases",
    "DESIGNS",
    "DISTRIBUTIONS",
    "STATUS_CODES",
    "NOT_RUN",
    "FAILED",
]
