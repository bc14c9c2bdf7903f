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

import contextlib
import hashlib
import json
import logging
import math
import os
import re
import shutil
import signal
import sys
import threading
import time
import tomllib
import warnings
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from itertools import product
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from ._atomic import pid_alive
from ._optional import require
from .exceptions import ImpactBeamError, ParameterError, ScenarioError, SimulationError
from .metrics import METRIC_UNITS
from .scenario import EXCITATION_DIMENSIONS, Scenario, load_scenario, parse_scenario
from .units import DIMENSIONS, to_si

if TYPE_CHECKING:
    import xarray as xr

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
    "DESIGNS",
    "DISTRIBUTIONS",
    "STATUS_CODES",
    "NOT_RUN",
    "FAILED",
]

log = logging.getLogger(__name__)

#: Experimental designs: a full factorial grid, or sampled designs.
DESIGNS = ("grid", "lhs", "sobol", "random")
#: Distributions of sampled parameters and the names of their two numbers.
DISTRIBUTIONS: dict[str, tuple[str, str]] = {
    "uniform": ("low", "high"),
    "normal": ("mean", "std"),
    "lognormal": ("mean", "std"),
}
#: ``status`` of a case that failed (error recorded in ``message``).
FAILED = -1
#: ``status`` of a case not yet run.
NOT_RUN = -2
#: Meaning of the ``status`` variable.
STATUS_CODES = {0: "reached end_time", 1: "stopped by the chattering guard", FAILED: "failed", NOT_RUN: "not yet run"}

_FORMAT_VERSION = 1
_DEFAULT_MAX_BATCH = 100

_TOP_KEYS = ("base", "design", "samples", "seed", "parameters", "outputs", "name", "description")
_PARAM_KEYS = ("values", "range", "scale", "distribution", "low", "high", "mean", "std")
_OUTPUT_KEYS = ("metrics", "histories")
_HISTORY_KEYS = ("points", "time_step")

# Parameters that determine the mode sets (beam and its sections, supports, point masses,
# permanent springs, contact spring positions and stiffnesses, number of modes): cases
# sharing them reuse impactbeam.mode_set's cache.
_GEOMETRY = re.compile(
    r"^(beam(\..*)?|supports(\..*)?|masses(\..*)?|springs(\..*)?"
    r"|contactors(\.\d+(\.(position|position_ratio|stiffness))?)?|solver\.modes)$"
)

# Physical dimension of each scenario path (used to read "0.2 mm" and to label coordinates).
_PATH_DIMENSIONS: tuple[tuple[str, str], ...] = (
    (r"beam\.(length|width|height)", "length"),
    (r"beam\.area", "area"),
    (r"beam\.second_moment", "second_moment"),
    (r"beam\.youngs_modulus", "modulus"),
    (r"beam\.density", "density"),
    (r"beam\.sections\.\d+\.(length|width|height)", "length"),
    (r"beam\.sections\.\d+\.area", "area"),
    (r"beam\.sections\.\d+\.second_moment", "second_moment"),
    (r"beam\.sections\.\d+\.youngs_modulus", "modulus"),
    (r"beam\.sections\.\d+\.density", "density"),
    (r"(masses|springs)\.\d+\.position", "length"),
    (r"(masses|springs)\.\d+\.position_ratio", "dimensionless"),
    (r"masses\.\d+\.mass", "mass"),
    (r"masses\.\d+\.rotary_inertia", "rotary_inertia"),
    (r"springs\.\d+\.translational", "stiffness"),
    (r"springs\.\d+\.rotational", "rotational_stiffness"),
    (r"supports\.(left|right)\.translational", "stiffness"),
    (r"supports\.(left|right)\.rotational", "rotational_stiffness"),
    (r"contactors\.\d+\.(position|gap)", "length"),
    (r"contactors\.\d+\.position_ratio", "dimensionless"),
    (r"contactors\.\d+\.stiffness", "stiffness"),
    (r"damping\.(free|contact)(\.\d+)?", "dimensionless"),
    (r"excitation\.(duration|start)", "time"),
    (r"excitation\.position", "length"),
    (r"excitation\.(position_ratio|scale)", "dimensionless"),
    (r"initial\.(tip_displacement|position)", "length"),
    (r"solver\.(time_step|end_time|event_tolerance)", "time"),
    (r"solver\.(modes|max_events)", "integer"),
    (r"output\.points\.\d+", "length"),
    (r"output\.point_ratios\.\d+", "dimensionless"),
)


class SweepInterrupted(KeyboardInterrupt):
    """The sweep was stopped by a signal (SIGINT or SIGTERM) between two writes.

    The store holds every batch finished so far; run the same sweep again to
    finish the rest. ``signum`` is the signal number.
    """

    def __init__(self, signum: int, done: int = 0, total: int = 0) -> None:
        super().__init__(f"interrupted by signal {signum}")
        self.signum = signum
        self.done = done
        self.total = total


# --------------------------------------------------------------------------- spec


@dataclass(frozen=True)
class SweepParameter:
    """One varied scenario field.

    Attributes
    ----------
    path : str
        Dotted scenario path, exactly as written in the sweep file.
    values : tuple or None
        Grid values (SI floats, ints for integer fields, strings for choices).
    distribution : str or None
        ``uniform``, ``normal`` or ``lognormal`` (sampled designs).
    args : tuple of float
        The distribution's two numbers (SI): (low, high) or (mean, std); for
        ``lognormal`` the mean and standard deviation of the value itself.
    dimension : str or None
        Physical dimension of the field (``"length"``, ``"time"``, ...).
    """

    path: str
    values: tuple[Any, ...] | None = None
    distribution: str | None = None
    args: tuple[float, float] = ()  # type: ignore[assignment]
    dimension: str | None = None

    @property
    def units(self) -> str | None:
        """SI unit of the values (None for choices and unknown fields)."""
        if self.dimension in DIMENSIONS:
            return DIMENSIONS[self.dimension].si_unit or "1"
        if self.dimension == "integer":
            return "1"
        return None

    @property
    def geometry(self) -> bool:
        """True when the parameter changes the mode sets."""
        return bool(_GEOMETRY.match(self.path))

    def ppf(self, u: np.ndarray) -> np.ndarray:
        """Map unit-interval samples ``u`` through the distribution's inverse CDF."""
        from scipy import stats

        a, b = self.args
        if self.distribution == "uniform":
            return a + u * (b - a)
        if self.distribution == "normal":
            return stats.norm.ppf(u, loc=a, scale=b)
        # lognormal with mean a and standard deviation b of the value itself
        s2 = math.log1p((b / a) ** 2)
        return stats.lognorm.ppf(u, s=math.sqrt(s2), scale=a / math.sqrt(1.0 + (b / a) ** 2))

    def bounds(self) -> tuple[float, float]:
        """Support of the distribution (``-inf``/``inf`` where unbounded)."""
        if self.distribution == "uniform":
            return self.args
        if self.distribution == "lognormal":
            return (0.0, math.inf)
        return (-math.inf, math.inf)


@dataclass(frozen=True)
class Histories:
    """Deflection histories to keep: positions [m] and the coarse time step [s]."""

    points: tuple[float, ...]
    time_step: float


@dataclass(frozen=True, eq=False)
class SweepSpec:
    """A validated sweep (see the module docstring for the file format).

    Attributes
    ----------
    base : Scenario
        The scenario every case starts from.
    design : str
        ``grid``, ``lhs``, ``sobol`` or ``random``.
    parameters : tuple of SweepParameter
        In the order written.
    samples, seed : int or None
        Sampled designs only.
    metrics : tuple of str
        Names of the scalar metrics kept.
    histories : Histories or None
    source : Path or None
        The sweep file.
    name : str
    """

    base: Scenario
    design: str
    parameters: tuple[SweepParameter, ...]
    samples: int | None
    seed: int | None
    metrics: tuple[str, ...]
    histories: Histories | None
    source: Path | None = None
    name: str = "sweep"
    _samples_cache: dict[str, np.ndarray] = field(default_factory=dict, repr=False)

    # ------------------------------------------------------------ shape
    @property
    def paths(self) -> tuple[str, ...]:
        return tuple(p.path for p in self.parameters)

    @property
    def is_grid(self) -> bool:
        return self.design == "grid"

    @property
    def dims(self) -> tuple[str, ...]:
        """Dimensions of the result: the parameter paths (grid) or ``("case",)``."""
        return self.paths if self.is_grid else ("case",)

    @property
    def shape(self) -> tuple[int, ...]:
        if self.is_grid:
            return tuple(len(p.values or ()) for p in self.parameters)
        return (int(self.samples or 0),)

    @property
    def n_cases(self) -> int:
        return int(np.prod(self.shape, dtype=np.int64))

    # ------------------------------------------------------------ cases
    def sample_values(self) -> np.ndarray:
        """The sampled values, shape (samples, n_parameters) (sampled designs)."""
        if self.is_grid:
            raise ParameterError("sample_values: a grid design has no samples")
        if "x" not in self._samples_cache:
            self._samples_cache["x"] = _draw(self)
        return self._samples_cache["x"]

    def case_values(self, index: int | Sequence[int]) -> dict[str, Any]:
        """The parameter values of one case: a flat index (C order) or a grid index tuple."""
        if isinstance(index, (int, np.integer)):
            flat = int(index)
            if not 0 <= flat < self.n_cases:
                raise ParameterError(f"case index {flat} out of range (0..{self.n_cases - 1})")
            idx = np.unravel_index(flat, self.shape)
        else:
            idx = tuple(int(i) for i in index)
        if self.is_grid:
            return {p.path: _plain(p.values[i]) for p, i in zip(self.parameters, idx)}  # type: ignore[index]
        row = self.sample_values()[idx[0]]
        return {p.path: float(v) for p, v in zip(self.parameters, row)}

    def cases(self) -> Iterator[dict[str, Any]]:
        """Every case's parameter values, in C order of :attr:`shape`."""
        for i in range(self.n_cases):
            yield self.case_values(i)

    def scenario(self, index: int | Sequence[int]) -> Scenario:
        """The validated scenario of one case."""
        return self.base.with_values(self.case_values(index))

    # ------------------------------------------------------------ identity
    def canonical(self) -> dict[str, Any]:
        """Resolved description (base content, values, outputs) used for the hash."""
        params = []
        for p in self.parameters:
            d: dict[str, Any] = {"path": p.path}
            if p.values is not None:
                d["values"] = [_plain(v) for v in p.values]
            else:
                d["distribution"] = p.distribution
                d["args"] = list(p.args)
            params.append(d)
        out: dict[str, Any] = {
            "format": _FORMAT_VERSION,
            "base": self.base.data,
            "design": self.design,
            "parameters": params,
            "metrics": list(self.metrics),
        }
        if not self.is_grid:
            out["samples"] = self.samples
            out["seed"] = self.seed
        if self.histories is not None:
            out["histories"] = {"points": list(self.histories.points), "time_step": self.histories.time_step}
        return out

    @property
    def canonical_json(self) -> str:
        return json.dumps(self.canonical(), sort_keys=True, separators=(",", ":"), allow_nan=False)

    @property
    def hash(self) -> str:
        """SHA-256 of :meth:`canonical`: equal for sweeps that compute the same cases."""
        return hashlib.sha256(self.canonical_json.encode()).hexdigest()

    def history_times(self) -> np.ndarray:
        """The coarse time grid of the histories: 0, dt, ... up to the longest end_time."""
        if self.histories is None:
            return np.zeros(0)
        end = self.base.solver.end_time
        for p in self.parameters:
            if p.path == "solver.end_time":
                vals = p.values if p.values is not None else [p.bounds()[1]]
                end = max(end, *[float(v) for v in vals])
        if not math.isfinite(end):
            raise ScenarioError("outputs.histories: solver.end_time is sampled without bound", key="outputs.histories")
        dt = self.histories.time_step
        n = int(math.floor(end / dt * (1 + 1e-12))) + 1
        return np.arange(n) * dt


def _plain(v: Any) -> Any:
    return v.item() if isinstance(v, np.generic) else v


def _draw(spec: SweepSpec) -> np.ndarray:
    """Unit-hypercube samples mapped through each parameter's distribution."""
    from scipy.stats import qmc

    n, d = int(spec.samples or 0), len(spec.parameters)
    rng = np.random.default_rng(spec.seed)
    if spec.design == "lhs":
        u = qmc.LatinHypercube(d, rng=rng).random(n)
    elif spec.design == "sobol":
        if n & (n - 1):
            warnings.warn(
                f"samples = {n} is not a power of 2: Sobol points keep their balance "
                "properties only for 2^m samples",
                UserWarning,
                stacklevel=3,
            )
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)  # scipy's own version of the warning above
            u = qmc.Sobol(d, scramble=True, rng=rng).random(n)
    else:  # random
        u = rng.random((n, d))
    # keep the inverse CDFs finite (a scrambled Sobol point may be exactly 0)
    eps = np.finfo(float).eps
    u = np.clip(u, eps, 1.0 - eps)
    return np.column_stack([p.ppf(u[:, j]) for j, p in enumerate(spec.parameters)]) if d else np.zeros((n, 0))


# --------------------------------------------------------------------------- parsing


def _dimension_of(path: str, base: Scenario) -> str | None:
    if path == "excitation.amplitude":
        return EXCITATION_DIMENSIONS.get(base.excitation.kind)
    for pattern, dim in _PATH_DIMENSIONS:
        if re.fullmatch(pattern, path):
            return dim
    return None


class _Errors:
    """Builds one-line ScenarioErrors prefixed by the sweep file's name."""

    def __init__(self, source: Path | None) -> None:
        self.prefix = f"{source.name}: " if source is not None else ""

    def __call__(self, key: str, message: str) -> ScenarioError:
        return ScenarioError(f"{self.prefix}{key}: {message}", key=key)


def _describe(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, list):
        return "a list"
    if isinstance(value, str):
        return json.dumps(value)
    return repr(value)


def _count(err: _Errors, key: str, value: Any, *, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or (
        isinstance(value, float) and not (math.isfinite(value) and value.is_integer())
    ):
        raise err(key, f"expected an integer, got {_describe(value)}")
    if value < minimum:
        what = "a positive integer" if minimum == 1 else f"an integer >= {minimum}"
        raise err(key, f"must be {what}, got {int(value)}")
    return int(value)


def _number(err: _Errors, key: str, value: Any, dimension: str | None, what: str) -> float:
    """A number in SI: plain numbers, or strings with units when the dimension is known."""
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise err(key, f"{what}: expected a number, got {_describe(value)}")
    if isinstance(value, str):
        if dimension is None or dimension == "integer":
            raise err(key, f"{what}: expected a number, got {value!r}")
        try:
            return to_si(value, dimension, key)
        except ScenarioError as exc:
            raise ScenarioError(f"{err.prefix}{exc}", key=key) from None
    x = float(value)
    if not math.isfinite(x):
        raise err(key, f"{what}: expected a finite number, got {value!r}")
    return x


def _grid_values(err: _Errors, key: str, table: Mapping[str, Any], dimension: str | None) -> tuple[Any, ...]:
    if "values" in table:
        raw = table["values"]
        if "range" in table:
            raise err(key, 'give either "values" or "range", not both')
        if "scale" in table:
            raise err(key, '"scale" applies to "range" only')
        if not isinstance(raw, list):
            raise err(key, f"values: expected a list, got {_describe(raw)}")
        if not raw:
            raise err(key, "values: the list is empty")
        if dimension is None and all(isinstance(v, str) for v in raw):
            values: list[Any] = list(raw)  # choices ("clamped", "above", ...)
        elif dimension == "integer":
            values = [_count(err, f"{key}.values", v, minimum=-(2**62)) for v in raw]
        elif dimension is None and any(isinstance(v, str) for v in raw):
            raise err(key, "values: mix of numbers and strings")
        else:
            values = [_number(err, key, v, dimension, f"values[{i}]") for i, v in enumerate(raw)]
    elif "range" in table:
        raw = table["range"]
        if not isinstance(raw, list) or len(raw) != 3:
            raise err(key, f"range: expected [start, stop, num], got {_describe(raw)}")
        num_raw = raw[2]
        if isinstance(num_raw, (int, float)) and not isinstance(num_raw, bool) and num_raw < 1:
            raise err(key, f"range: num must be a positive integer, got {num_raw!r} (an empty range)")
        num = _count(err, f"{key}.range", num_raw)
        num_dim = "dimensionless" if dimension == "integer" else dimension
        start = _number(err, key, raw[0], num_dim, "range start")
        stop = _number(err, key, raw[1], num_dim, "range stop")
        scale = table.get("scale", "linear")
        if scale not in ("linear", "log"):
            raise err(key, f'scale: must be "linear" or "log", got {_describe(scale)}')
        if scale == "log":
            if start <= 0 or stop <= 0:
                raise err(key, f"range: a log scale needs start and stop > 0, got {start!r}, {stop!r}")
            arr = np.geomspace(start, stop, num)
        else:
            arr = np.linspace(start, stop, num)
        if dimension == "integer":
            if not np.all(arr == np.round(arr)):
                raise err(key, f"range: {arr.tolist()} are not all integers (the field is an integer)")
            values = [int(v) for v in np.round(arr)]
        else:
            values = [float(v) for v in arr]
    else:
        raise err(key, 'a grid parameter needs "values" or "range = [start, stop, num]"')
    if len(set(values)) != len(values):
        raise err(key, f"values: repeated value in {values}")
    return tuple(values)


def _distribution(err: _Errors, key: str, table: Mapping[str, Any], dimension: str | None) -> tuple[str, tuple[float, float]]:
    kind = table.get("distribution")
    if "values" in table or "range" in table:
        raise err(key, 'a sampled design takes "distribution", not "values" or "range" (those are for design = "grid")')
    if kind is None:
        raise err(key, f'a sampled design needs "distribution" ({", ".join(DISTRIBUTIONS)})')
    if kind not in DISTRIBUTIONS:
        raise err(key, f'distribution: unknown {_describe(kind)} (use {", ".join(DISTRIBUTIONS)})')
    if dimension == "integer":
        raise err(key, "an integer field cannot be sampled from a continuous distribution; use a grid")
    names = DISTRIBUTIONS[kind]
    for other in ("low", "high", "mean", "std"):
        if other in table and other not in names:
            raise err(key, f'{other}: not a parameter of the {kind} distribution (it takes {" and ".join(names)})')
    for name in names:
        if name not in table:
            raise err(key, f'the {kind} distribution needs "{names[0]}" and "{names[1]}" ("{name}" is missing)')
    a = _number(err, key, table[names[0]], dimension, names[0])
    b = _number(err, key, table[names[1]], dimension, names[1])
    if kind == "uniform" and not a < b:
        raise err(key, f"uniform: low must be < high, got low = {a!r}, high = {b!r}")
    if kind in ("normal", "lognormal") and not b > 0:
        raise err(key, f"{kind}: std must be > 0, got {b!r}")
    if kind == "lognormal" and not a > 0:
        raise err(key, f"lognormal: mean must be > 0, got {a!r}")
    return kind, (a, b)


def _check_value(err: _Errors, base: Scenario, path: str, value: Any, label: str) -> None:
    """Set one value on the base scenario and re-validate it (unknown path, bad value)."""
    try:
        base.with_values({path: value})
    except ScenarioError as exc:
        msg = str(exc)
        if msg.startswith(f'unknown key "{path}"') or msg.startswith(f'unknown table "{path}"') or msg.startswith("invalid path"):
            raise err(f'parameters."{path}"', msg) from None
        raise err(f'parameters."{path}"', f"{label}: {msg}") from None


def parse_sweep(
    data: Mapping[str, Any],
    *,
    base_dir: str | os.PathLike[str] | None = None,
    source: str | os.PathLike[str] | None = None,
) -> SweepSpec:
    """Validate a sweep mapping (the TOML format of the module docstring).

    Every parameter path is checked against the base scenario, and every
    value of every parameter (grid values; for distributions, the bounds or
    the mean) is set on the base scenario and re-validated, so an unknown
    path or an invalid value is reported before anything runs. A combination
    of values that is invalid only together (a contactor beyond a shortened
    beam) is recorded as a failed case when it runs.

    Parameters
    ----------
    data : mapping
    base_dir : path-like, optional
        Directory for a relative ``base`` path (default: the current one).
    source : path-like, optional
        The sweep file (named in error messages).

    Raises
    ------
    ScenarioError
        One line, naming the file and the key.
    """
    src = Path(source) if source is not None else None
    err = _Errors(src)
    if not isinstance(data, Mapping):
        raise err("sweep", f"expected a table, got {_describe(data)}")
    for key in data:
        if key not in _TOP_KEYS:
            import difflib

            match = difflib.get_close_matches(key, _TOP_KEYS, n=1)
            hint = f' (did you mean "{match[0]}"?)' if match else f" (valid keys: {', '.join(_TOP_KEYS)})"
            raise err(key, f"unknown key{hint}")
    bdir = Path(base_dir) if base_dir is not None else Path.cwd()

    # base scenario
    if "base" not in data:
        raise err("base", 'missing: give a scenario path (base = "case03.toml") or an inline [base] table')
    raw_base = data["base"]
    if isinstance(raw_base, str):
        path = Path(raw_base)
        if not path.is_absolute():
            path = bdir / path
        try:
            base = load_scenario(path)
        except ScenarioError as exc:
            raise err("base", f'"{raw_base}": {exc}') from None
    elif isinstance(raw_base, Mapping):
        try:
            base = parse_scenario(raw_base, base_dir=bdir, source=src, name=str(data.get("name", "base")))
        except ScenarioError as exc:
            raise err("base", str(exc)) from None
    else:
        raise err("base", f"expected a scenario path or a table, got {_describe(raw_base)}")

    # design
    design = data.get("design", "grid")
    if design not in DESIGNS:
        raise err("design", f'unknown design {_describe(design)} (use {", ".join(DESIGNS)})')
    samples = seed = None
    if design == "grid":
        for key in ("samples", "seed"):
            if key in data:
                raise err(key, 'only for sampled designs (design = "lhs", "sobol" or "random")')
    else:
        if "samples" not in data:
            raise err("samples", f'design = "{design}" needs the number of samples')
        samples = _count(err, "samples", data["samples"])
        seed = _count(err, "seed", data.get("seed", 0), minimum=0)

    # parameters
    raw_params = data.get("parameters")
    if not isinstance(raw_params, Mapping) or not raw_params:
        raise err("parameters", 'no parameters: add tables such as [parameters."contactors.0.gap"]')
    params: list[SweepParameter] = []
    for path, table in raw_params.items():
        key = f'parameters."{path}"'
        if not isinstance(table, Mapping):
            raise err(key, f"expected a table (values, range or distribution), got {_describe(table)}")
        for k in table:
            if k not in _PARAM_KEYS:
                raise err(key, f'unknown key "{k}" (use values, range [+ scale] or distribution)')
        dim = _dimension_of(path, base)
        if design == "grid":
            if "distribution" in table:
                raise err(key, 'a distribution needs a sampled design (design = "lhs", "sobol" or "random")')
            values = _grid_values(err, key, table, dim)
            for v in values:
                _check_value(err, base, path, v, f"value {v!r}")
            params.append(SweepParameter(path, values=values, dimension=dim))
        else:
            kind, args = _distribution(err, key, table, dim)
            probes = list(args) if kind == "uniform" else [args[0]]
            for v in probes:
                _check_value(err, base, path, v, f"{kind} value {v!r}")
            params.append(SweepParameter(path, distribution=kind, args=args, dimension=dim))
    _check_alternatives(err, [p.path for p in params])

    # outputs
    outputs = data.get("outputs", {})
    if not isinstance(outputs, Mapping):
        raise err("outputs", f"expected a table, got {_describe(outputs)}")
    for k in outputs:
        if k not in _OUTPUT_KEYS:
            raise err(f"outputs.{k}", f"unknown key (use {', '.join(_OUTPUT_KEYS)})")
    metrics = _metric_names(err, outputs.get("metrics", "all"))
    histories = None
    if "histories" in outputs:
        histories = _histories(err, outputs["histories"], base)

    name = data.get("name", src.stem if src is not None else "sweep")
    if not isinstance(name, str):
        raise err("name", f"expected a string, got {_describe(name)}")
    spec = SweepSpec(base, design, tuple(params), samples, seed, metrics, histories, src, name)
    if histories is not None:
        spec.history_times()  # checks a bounded end time
    return spec


def _check_alternatives(err: _Errors, paths: list[str]) -> None:
    seen = set(paths)
    for p in paths:
        for a, b in (("position", "position_ratio"), ("points", "point_ratios")):
            if p.endswith("." + a) and p[: -len(a)] + b in seen:
                raise err(f'parameters."{p}"', f'and "{p[: -len(a)] + b}" set the same field; vary one of them')


def _metric_names(err: _Errors, value: Any) -> tuple[str, ...]:
    if value == "all":
        return tuple(METRIC_UNITS)
    if not isinstance(value, list) or not value or not all(isinstance(v, str) for v in value):
        raise err("outputs.metrics", f'expected "all" or a list of metric names, got {_describe(value)}')
    for v in value:
        if v not in METRIC_UNITS:
            raise err("outputs.metrics", f'unknown metric "{v}" (use {", ".join(METRIC_UNITS)})')
    if len(set(value)) != len(value):
        raise err("outputs.metrics", "a metric is listed twice")
    return tuple(v for v in METRIC_UNITS if v in value)  # canonical order


def _histories(err: _Errors, value: Any, base: Scenario) -> Histories:
    key = "outputs.histories"
    if not isinstance(value, Mapping):
        raise err(key, f"expected a table {{ points = [...], time_step = ... }}, got {_describe(value)}")
    for k in value:
        if k not in _HISTORY_KEYS:
            raise err(f"{key}.{k}", f"unknown key (use {', '.join(_HISTORY_KEYS)})")
    for k in _HISTORY_KEYS:
        if k not in value:
            raise err(key, f'"{k}" is missing')
    pts = value["points"]
    if not isinstance(pts, list) or not pts:
        raise err(f"{key}.points", f"expected a non-empty list of positions, got {_describe(pts)}")
    points = tuple(_number(err, f"{key}.points", p, "length", f"points[{i}]") for i, p in enumerate(pts))
    for x in points:
        if not 0.0 <= x <= base.beam.length * (1 + 1e-12):
            raise err(f"{key}.points", f"{x!r} m is off the beam (length {base.beam.length:g} m)")
    dt = _number(err, f"{key}.time_step", value["time_step"], "time", "time_step")
    if not dt > 0:
        raise err(f"{key}.time_step", f"must be > 0, got {dt!r}")
    return Histories(points, dt)


def load_sweep(path: str | os.PathLike[str]) -> SweepSpec:
    """Read and validate a sweep file; a relative ``base`` is resolved against its directory."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ScenarioError(f"{p}: no such sweep file", key="sweep") from None
    except OSError as exc:
        raise ScenarioError(f"{p}: cannot read the sweep file: {exc.strerror or exc}", key="sweep") from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{p.name}: invalid TOML: {exc}", key="sweep") from None
    return parse_sweep(data, base_dir=p.resolve().parent, source=p)


# --------------------------------------------------------------------------- batches


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


def default_batch_size(n_cases: int) -> int:
    """Cases per batch when not given: about 32 batches, at most 100 cases each.

    It does not depend on the number of workers, so the same sweep gives the
    same store layout on a laptop and on a cluster.
    """
    return max(1, min(_DEFAULT_MAX_BATCH, math.ceil(n_cases / 32)))


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


def run_batch(batch: _Batch) -> dict[str, Any]:
    """Run the cases of one batch (on a worker); per-case errors are recorded.

    Returns a dict of arrays over the batch's cases (C order of its region):
    one per metric, ``status``, ``message`` and, with histories, ``w``
    (n_cases, n_times, n_points).
    """
    from .solver import simulate

    _tune_malloc()
    n = len(batch.values)
    out: dict[str, Any] = {m: np.full(n, np.nan) for m in batch.metrics}
    status = np.full(n, FAILED, dtype=np.int8)
    message = [""] * n
    ht = batch.history_times
    w = None if ht is None else np.full((n, ht.size, len(batch.history_points)), np.nan)
    base = parse_scenario(batch.base_data, base_dir=batch.base_dir, source=batch.source, name=batch.name)
    for k, vals in enumerate(batch.values):
        try:
            sc = base.with_values(dict(zip(batch.paths, vals)))
            res = simulate(sc)
            metrics = res.metrics(impacts=False)
            if w is not None:  # NaN after this case's end_time
                inside = ht <= sc.solver.end_time * (1.0 + 1e-12)
                w[k][inside] = res.displacement(list(batch.history_points), ht[inside]).T
        except Exception as exc:  # recorded: the sweep goes on
            if batch.on_error == "raise":
                raise
            message[k] = _error_message(exc)
            continue
        for m in batch.metrics:
            v = metrics.get(m)
            out[m][k] = np.nan if v is None else float(v)
        status[k] = res.status
        message[k] = "" if res.status == 0 else " ".join(str(res.message).split())
    out["status"] = status
    out["message"] = message
    if w is not None:
        out["w"] = w
    return out


# --------------------------------------------------------------------------- store


def _template(spec: SweepSpec, chunk: tuple[int, ...]) -> tuple[xr.Dataset, dict[str, Any]]:
    """The empty result (every case not run) as a lazy Dataset, and its Zarr encoding.

    Each variable is one lazy dask chunk (never computed: only the metadata
    is written), so a sweep of millions of cases starts at once; the Zarr
    encoding sets the on-disk chunks, one per batch.
    """
    da = require("dask.array", "sweep")
    import xarray as xr

    from . import __version__

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
    for m in spec.metrics:
        data[m] = xr.Variable(dims, da.full(shape, np.nan, chunks=-1), {"units": METRIC_UNITS[m], "long_name": m.replace("_", " ")})
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


def _create_store(spec: SweepSpec, out: Path | None, chunk: tuple[int, ...]) -> Any:
    """Write the empty store (metadata and coordinates); atomic for a directory."""
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
        ds.to_zarr(str(tmp), compute=False, encoding=enc, consolidated=False)
        if out.exists():  # an empty directory
            out.rmdir()
        os.replace(tmp, out)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return str(out)


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


# --------------------------------------------------------------------------- execution


@dataclass
class SweepRun:
    """Outcome of :func:`run_sweep`.

    Attributes
    ----------
    dataset : xarray.Dataset
        The results (lazily read from the store, or in memory without ``out``).
    n_cases, computed, skipped, failed : int
        All cases; cases run now; cases already done in the store (resume);
        cases that failed in this run.
    out : Path or None
    """

    dataset: Any
    n_cases: int
    computed: int
    skipped: int
    failed: int
    out: Path | None


class _SignalGuard:
    """Turn SIGINT/SIGTERM into SweepInterrupted, but never in the middle of a write."""

    def __init__(self) -> None:
        self.critical = False
        self.pending: int | None = None
        self.previous: dict[int, Any] = {}

    def _handler(self, signum: int, frame: Any) -> None:
        if self.critical:
            self.pending = signum
        else:
            raise SweepInterrupted(signum)

    def __enter__(self) -> _SignalGuard:
        if threading.current_thread() is threading.main_thread():
            for sig in (signal.SIGINT, signal.SIGTERM):
                self.previous[sig] = signal.signal(sig, self._handler)
        return self

    def __exit__(self, *exc: Any) -> None:
        for sig, handler in self.previous.items():
            signal.signal(sig, handler)

    def write(self) -> _Critical:
        return _Critical(self)


class _Critical:
    def __init__(self, guard: _SignalGuard) -> None:
        self.guard = guard

    def __enter__(self) -> None:
        self.guard.critical = True

    def __exit__(self, exc_type: Any, *rest: Any) -> None:
        self.guard.critical = False
        if exc_type is None and self.guard.pending is not None:
            raise SweepInterrupted(self.guard.pending)


class _Writer:
    """Writes finished batches into the store's chunks (status last)."""

    def __init__(self, store: Any, spec: SweepSpec) -> None:
        zarr = require("zarr", "sweep")

        self.group = zarr.open_group(store, mode="r+")
        self.arrays = {name: self.group[name] for name in (*spec.metrics, "message", "status")}
        if spec.histories is not None:
            self.arrays["w"] = self.group["w"]

    def write(self, region: tuple[tuple[int, int], ...], res: Mapping[str, Any]) -> None:
        sl = tuple(slice(a, b) for a, b in region)
        shape = tuple(b - a for a, b in region)
        for name, arr in self.arrays.items():
            if name == "status":
                continue
            value = res[name]
            if name == "message":
                value = np.array(value, dtype=np.dtypes.StringDType())
            value = np.asarray(value).reshape(shape + np.shape(value)[1:])
            arr[sl] = value
        self.arrays["status"][sl] = np.asarray(res["status"], dtype=np.int8).reshape(shape)

    def status(self) -> np.ndarray:
        return self.arrays["status"][...]


def run_sweep(
    spec_or_path: SweepSpec | str | os.PathLike[str] | Mapping[str, Any],
    out: str | os.PathLike[str] | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    batch_size: int | None = None,
    progress: bool = True,
    on_error: Literal["record", "raise"] = "record",
) -> SweepRun:
    """Run (or resume) a sweep; like :func:`sweep` but returns a :class:`SweepRun` with counts."""
    for name in ("zarr", "dask", "distributed"):  # before any work: one clear message
        require(name, "sweep", feature="parameter sweeps")
    spec = _as_spec(spec_or_path)
    if on_error not in ("record", "raise"):
        raise ParameterError(f'on_error: must be "record" or "raise", got {on_error!r}')
    if workers is not None and scheduler is not None:
        raise ParameterError("give either workers (a local cluster) or scheduler (a running one), not both")
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 0):
        raise ParameterError(f"workers: must be an integer >= 0, got {workers!r}")
    if batch_size is not None and (isinstance(batch_size, bool) or not isinstance(batch_size, int) or batch_size < 1):
        raise ParameterError(f"batch_size: must be a positive integer, got {batch_size!r}")
    out_path = Path(out) if out is not None else None
    chunk = _chunk_shape(spec, batch_size or default_batch_size(spec.n_cases))
    if out_path is None:
        _check_in_memory(spec)
    if out_path is not None and not out_path.parent.is_dir():
        raise ParameterError(f'--out: directory "{out_path.parent}" does not exist')
    with _StoreLock(out_path):
        return _run_locked(spec, out_path, chunk, workers, scheduler, progress, on_error)


def _check_in_memory(spec: SweepSpec) -> None:
    """Refuse, before any work, an in-memory result larger than the memory limit."""
    from .result import check_memory

    per_case = 8 * len(spec.metrics) + 40
    if spec.histories is not None:
        per_case += 8 * spec.history_times().size * len(spec.histories.points)
    check_memory(per_case * spec.n_cases, f"an in-memory sweep of {spec.n_cases} cases",
                 "write it to a store (out=...), or sweep fewer cases or histories")


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
            with os.fdopen(fd, "w") as fh:
                json.dump(me, fh)
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


def _run_locked(spec: SweepSpec, out_path: Path | None, chunk: tuple[int, ...], workers: int | None,
                scheduler: str | None, progress: bool, on_error: str) -> SweepRun:
    """:func:`run_sweep` once the store is ours."""
    fresh = not (out_path is not None and out_path.exists()
                 and not (out_path.is_dir() and not any(out_path.iterdir())))
    store = _create_store(spec, out_path, chunk) if fresh else _open_existing(spec, out_path)  # type: ignore[arg-type]
    writer = _Writer(store, spec)
    chunk = tuple(writer.arrays["status"].chunks)  # the store's layout wins on resume
    # a new store has run nothing: no need to read its (possibly millions of) status chunks
    status = np.full(spec.shape, NOT_RUN, dtype=np.int8) if fresh else writer.status()
    regions = (r for r in _regions(spec.shape, chunk) if (status[r] == NOT_RUN).any())  # lazily
    skipped = int((status != NOT_RUN).sum())
    n_todo = spec.n_cases - skipped
    counts = {"computed": 0, "failed": 0}

    from tqdm.auto import tqdm

    bar = tqdm(total=spec.n_cases, initial=spec.n_cases - n_todo, desc="sweep", unit="case",
               file=sys.stderr, disable=not progress, dynamic_ncols=True)

    def done(region: tuple[tuple[int, int], ...], res: Mapping[str, Any]) -> None:
        with guard.write():
            writer.write(region, res)
        n = len(res["status"])
        counts["computed"] += n
        counts["failed"] += int((np.asarray(res["status"]) == FAILED).sum())
        bar.update(n)

    try:
        with _SignalGuard() as guard:
            if n_todo:
                batches = (_make_batch(spec, r, on_error) for r in regions)
                try:
                    if workers == 0:
                        for b in batches:
                            done(b.region, run_batch(b))
                    else:
                        _run_dask(batches, done, workers=workers, scheduler=scheduler, on_error=on_error)
                except SweepInterrupted as exc:
                    exc.done = spec.n_cases - n_todo + counts["computed"]
                    exc.total = spec.n_cases
                    raise
    finally:
        bar.close()
    log.info("sweep %s: %d cases, %d computed, %d already done, %d failed",
             spec.name, spec.n_cases, counts["computed"], skipped, counts["failed"])
    import xarray as xr

    if out_path is not None:
        import warnings

        zarr = require("zarr", "sweep")

        # consolidated metadata lets xr.open_zarr(path) open the finished store without a
        # warning; zarr 3 notes (ZarrUserWarning) that it is an extension of its format 3
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message="Consolidated metadata", category=UserWarning)
            zarr.consolidate_metadata(store)
    ds = xr.open_zarr(store, consolidated=False, chunks=None)
    order = [*spec.metrics, "status", "message", *(["w"] if spec.histories is not None else [])]
    ds = ds[order]  # the store lists its arrays in no particular order
    if out_path is None:
        ds = ds.load()
    return SweepRun(ds, spec.n_cases, counts["computed"], skipped, counts["failed"], out_path)


def _worker_config() -> dict[str, Any]:
    """Dask settings for the local cluster's worker processes.

    * One BLAS thread per worker (the matrices are small; also makes results
      independent of the core count).
    * No ``MALLOC_TRIM_THRESHOLD_``: distributed sets it to 64 KiB by default,
      which pins glibc's mmap threshold, so every array of the solver
      (hundreds of kB) is mmap-ed and page-faulted afresh; measured here that
      makes a simulation ~40 % slower.
    * No statistical profiler (it samples the computing thread every 10 ms).
    """
    dask = require("dask", "sweep")

    env = dict(dask.config.get("distributed.nanny.pre-spawn-environ", {}) or {})
    env.pop("MALLOC_TRIM_THRESHOLD_", None)
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        env[var] = 1
    return {"distributed.nanny.pre-spawn-environ": env, "distributed.worker.profile.enabled": False}


def _run_dask(
    batches: Iterator[_Batch], done: Any, *, workers: int | None, scheduler: str | None, on_error: str = "record"
) -> None:
    """Run the batches on a Dask cluster; ``done(region, result)`` as each finishes."""
    dask = require("dask", "sweep")
    distributed = require("distributed", "sweep")
    Client, LocalCluster, as_completed = distributed.Client, distributed.LocalCluster, distributed.as_completed

    cluster = None
    client = None
    futures: list[Any] = []
    try:
        if scheduler is not None:
            try:
                client = Client(scheduler, timeout="10s")
            except (OSError, TimeoutError) as exc:
                raise ParameterError(f'--scheduler: cannot connect to "{scheduler}": {exc}') from None
        else:
            n = workers or os.cpu_count() or 1
            with dask.config.set(_worker_config()):
                cluster = LocalCluster(
                    n_workers=n,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=None,
                    silence_logs=logging.ERROR,
                )
            client = Client(cluster)
        # a bounded window of batches in flight: a sweep of any size starts at once, and
        # an interrupt has only a few tasks to cancel
        window = 4 * max(1, len(client.scheduler_info().get("workers", {})) or (workers or 1))
        pending = iter(batches)
        region_of: dict[Any, Any] = {}

        def submit() -> Any:
            b = next(pending, None)
            if b is None:
                return None
            fut = client.submit(run_batch, b, pure=False)
            region_of[fut.key] = b.region
            futures.append(fut)
            return fut

        first = [f for f in (submit() for _ in range(window)) if f is not None]
        queue = as_completed(first, with_results=True)
        try:
            for fut, res in queue:
                done(region_of.pop(fut.key), res)
                fut.release()
                futures.remove(fut)
                nxt = submit()
                if nxt is not None:
                    queue.add(nxt)
        except (ImpactBeamError, SweepInterrupted):
            raise
        except Exception as exc:
            # run_batch records every case's own error, so this is the cluster's
            # (a worker died, impactbeam missing on a worker): nothing is stored for it
            if on_error == "raise":
                raise
            raise SimulationError(
                f"a batch failed on the Dask cluster ({_error_message(exc)}); the finished batches "
                "are stored: run the same sweep again to retry the rest"
            ) from exc
    finally:
        if client is not None:
            try:
                if futures:
                    client.cancel(futures)
                client.close()
            finally:
                if cluster is not None:
                    cluster.close()


def _as_spec(spec_or_path: Any) -> SweepSpec:
    if isinstance(spec_or_path, SweepSpec):
        return spec_or_path
    if isinstance(spec_or_path, Mapping):
        return parse_sweep(spec_or_path)
    return load_sweep(spec_or_path)


def sweep(
    spec_or_path: SweepSpec | str | os.PathLike[str] | Mapping[str, Any],
    out: str | os.PathLike[str] | None = None,
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    batch_size: int | None = None,
    progress: bool = True,
    on_error: Literal["record", "raise"] = "record",
) -> xr.Dataset:
    """Run a parameter study and return its labelled results.

    Parameters
    ----------
    spec_or_path : SweepSpec, path or mapping
        A sweep file (TOML, see the module docstring), its parsed mapping or a
        :class:`SweepSpec`.
    out : path, optional
        Zarr store (a directory). Created with every case "not yet run" and
        filled as batches finish; if it exists and was made by the same sweep,
        only the missing cases run (resume). Without ``out`` the results are
        kept in memory.
    workers : int, optional
        Worker processes of a local ``dask.distributed`` cluster (one thread
        each); default all cores. ``0`` runs the cases in this process,
        without Dask.
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``) whose
        workers run the cases (they need ``impactbeam`` installed and the
        scenario's files at the same paths).
    batch_size : int, optional
        Cases per task (= per Zarr chunk); default :func:`default_batch_size`.
        A resumed store keeps its own batches.
    progress : bool
        Progress bar on stderr (tqdm).
    on_error : {"record", "raise"}
        ``record``: a case that fails gets status -1, its error in ``message``
        and NaN metrics, and the sweep goes on; ``raise``: the first failure
        stops the sweep.

    Returns
    -------
    xarray.Dataset
        One dimension per grid parameter (named by its path) or ``case``;
        metric variables (``units`` in their attributes), ``status``,
        ``message`` and optional ``w`` histories.

    Raises
    ------
    ScenarioError
        For an invalid sweep file (one line naming the key).
    ParameterError
        For ``out`` made by a different sweep, or bad arguments.
    SweepInterrupted
        On SIGINT / SIGTERM; the store keeps every finished batch.
    """
    return run_sweep(
        spec_or_path, out, workers=workers, scheduler=scheduler, batch_size=batch_size,
        progress=progress, on_error=on_error,
    ).dataset


# --------------------------------------------------------------------------- plot


def _axis_label(ds: Any, name: str) -> str:
    return _axis(ds, name)[0]


def _axis(ds: Any, name: str) -> tuple[str, float]:
    """Display label ("gap [mm]") and the factor from the stored SI values."""
    from ._plotstyle import display_label

    return display_label(name, ds[name].attrs.get("units"))


def select_cases(ds: Any, keep: Sequence[str], sel: Mapping[str, Any] | None = None) -> tuple[Any, dict[str, Any]]:
    """Reduce a grid result to the dimensions ``keep``.

    Other grid dimensions take the value in ``sel`` (nearest coordinate,
    within 1e-6 of the coordinate spacing) or else their first value.
    Returns the selection and the values chosen per dimension.
    """
    sel = dict(sel or {})
    chosen: dict[str, Any] = {}
    for name in sel:
        if name not in ds.dims:
            raise ParameterError(f'--sel: "{name}" is not a dimension of the results ({", ".join(map(str, ds.dims))})')
        if name in keep:
            raise ParameterError(f'--sel: "{name}" is plotted, it cannot also be selected')
    for dim in ds.dims:
        if dim in keep or dim in ("time", "point"):
            continue
        coord = ds[dim].values
        if dim in sel:
            value = sel[dim]
            if coord.dtype.kind in "fiu":
                try:
                    v = float(value)
                except (TypeError, ValueError):
                    raise ParameterError(f"--sel {dim}: expected a number, got {value!r}") from None
                i = int(np.argmin(np.abs(coord - v)))
                spacing = float(np.min(np.diff(np.sort(coord)))) if coord.size > 1 else max(abs(v), 1.0)
                if abs(coord[i] - v) > 1e-6 * spacing:
                    raise ParameterError(f"--sel {dim}: {value} is not one of its values {coord.tolist()}")
            else:
                matches = np.nonzero(coord.astype(str) == str(value))[0]
                if not matches.size:
                    raise ParameterError(f"--sel {dim}: {value!r} is not one of its values {coord.tolist()}")
                i = int(matches[0])
        else:
            i = 0
        chosen[dim] = _plain(coord[i])
        ds = ds.isel({dim: i})
    return ds, chosen


def plot_sweep(
    ds: Any,
    x: str,
    metric: str,
    *,
    y: str | None = None,
    sel: Mapping[str, Any] | None = None,
    ax: Any = None,
) -> Any:
    """Plot one metric of a sweep: a line over ``x``, or a heat map over (``x``, ``y``).

    For a sampled design (``case`` dimension) a scatter plot of the metric
    over ``x`` (colour-coded over ``x`` and ``y`` when ``y`` is given).
    Failed and not-run cases (NaN) are left blank.

    Returns
    -------
    matplotlib artist
        The Line2D, QuadMesh or PathCollection drawn.
    """
    plt = require("matplotlib.pyplot", "plot")

    if metric not in ds.data_vars or metric in ("status", "message", "w"):
        names = [v for v in ds.data_vars if v not in ("status", "message", "w")]
        raise ParameterError(f'--metric: "{metric}" is not in the results (use {", ".join(names)})')
    for opt, name in (("--x", x), ("--y", y)):
        if name is not None and name not in ds.coords:
            params = [c for c in ds.coords if c not in ("case", "time", "point")]
            raise ParameterError(f'{opt}: "{name}" is not a parameter of the results (use {", ".join(params)})')
    if y is not None and y == x:
        raise ParameterError("--y: must differ from --x")
    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 4.4))
    label, fm = _axis(ds, metric)
    fx = _axis(ds, x)[1]
    fy = _axis(ds, y)[1] if y is not None else 1.0
    if "case" in ds.dims:
        xs = ds[x].values * fx
        vals = ds[metric].values * fm
        if y is None:
            handle = ax.scatter(xs, vals, s=10)
            ax.set_ylabel(label)
        else:
            handle = ax.scatter(xs, ds[y].values * fy, c=vals, s=14, cmap="viridis")
            ax.figure.colorbar(handle, ax=ax, label=label)
            ax.set_ylabel(_axis_label(ds, y))
        ax.set_xlabel(_axis_label(ds, x))
        ax.set_title(f"{metric} ({ds.sizes['case']} samples)")
        return handle
    sub, chosen = select_cases(ds, [d for d in (x, y) if d is not None], sel)
    da = sub[metric].load()
    numeric_x = da[x].dtype.kind in "fiu"
    if y is None:
        xs = da[x].values * fx if numeric_x else np.arange(da.sizes[x])
        (handle,) = ax.plot(xs, da.values * fm, marker="o", ms=3)
        if not numeric_x:
            ax.set_xticks(xs, [str(v) for v in da[x].values])
        ax.set_ylabel(label)
    else:
        da = da.transpose(y, x)
        handle = ax.pcolormesh(_edges(da[x].values * fx), _edges(da[y].values * fy), da.values * fm, shading="flat",
                               cmap="viridis")
        ax.figure.colorbar(handle, ax=ax, label=label)
        ax.set_ylabel(_axis_label(ds, y))
    ax.set_xlabel(_axis_label(ds, x))
    where = ", ".join(f"{k} = {v:.4g}" if isinstance(v, float) else f"{k} = {v}" for k, v in chosen.items())
    ax.set_title(metric + (f" at {where}" if where else ""), fontsize=9)
    return handle


def _edges(c: np.ndarray) -> np.ndarray:
    """Cell edges around coordinate values (midpoints; categorical: unit cells)."""
    if c.dtype.kind not in "fiu":
        return np.arange(c.size + 1) - 0.5
    c = c.astype(float)
    if c.size == 1:
        return np.array([c[0] - 0.5, c[0] + 0.5]) if c[0] == 0 else np.array([0.5, 1.5]) * c[0]
    mid = 0.5 * (c[1:] + c[:-1])
    return np.concatenate([[c[0] - (mid[0] - c[0])], mid, [c[-1] + (c[-1] - mid[-1])]])
