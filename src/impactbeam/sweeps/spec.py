"""A parameter study as data: its parameters, designs and outputs (:class:`SweepSpec`).

A grid is the product of the parameters' values; a sampled design (Latin
hypercube, Sobol, random) draws each parameter from its distribution. The
spec resolves every case's values and hashes itself for resumable stores.
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
import re
import warnings
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
import numpy as np

from .._memory import MAX_OUTPUT_SAMPLES
from ..exceptions import ParameterError, ScenarioError
from ..scenario import Scenario
from ..units import DIMENSIONS

__all__ = [
    "DESIGNS",
    "DISTRIBUTIONS",
    "FAILED",
    "Histories",
    "NOT_RUN",
    "STATUS_CODES",
    "SweepParameter",
    "SweepSpec",
    "default_batch_size",
]


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
#: Default batches: about this many, of at most :data:`_DEFAULT_MAX_BATCH` cases and, with histories, of
#: at most :data:`_DEFAULT_BATCH_BYTES` of them. Writing a batch costs ~1.7 ms per stored variable in the
#: sweep's process (Zarr 3, measured), ~20 ms for the ten metrics, whatever its size: as much as ~80
#: Case 3 cases of compute, so batches of 100 cases left the workers waiting on the writer.
_DEFAULT_BATCHES = 16
_DEFAULT_MAX_BATCH = 1000
_DEFAULT_BATCH_BYTES = 64e6
#: Peak bytes per sample and parameter of a sampled design: drawing (Latin hypercube, its
#: permutations, the inverse CDFs) and the store's coordinates; measured 67 with 2e6 samples of
#: 2 parameters (peak RSS).
SAMPLE_BYTES = 80

# Parameters that determine the mode sets (beam and its sections, supports, point masses,
# permanent springs, contact spring positions and stiffnesses, number of modes): cases
# sharing them reuse impactbeam.mode_set's cache.
_GEOMETRY = re.compile(
    r"^(beam(\..*)?|supports(\..*)?|masses(\..*)?|springs(\..*)?"
    r"|contactors(\.\d+(\.(position|position_ratio|stiffness))?)?|solver\.modes)$"
)


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
        """Map unit-interval samples ``u`` through the distribution's inverse CDF.

        Parameters
        ----------
        u : ndarray
            Samples in the unit interval.
        """
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
    statistics : bool
        Also store each case's statistics (:data:`impactbeam.statistics.record.RECORD_VARIABLES`).
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
    statistics: bool = False
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
        """The parameter values of one case: a flat index (C order) or a grid index tuple.

        Parameters
        ----------
        index : int or sequence of int
            A flat case index (C order) or a grid index tuple.
        """
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
        """The validated scenario of one case.

        Parameters
        ----------
        index : int or sequence of int
            As for :meth:`case_values`.
        """
        return self.base.with_values(self.case_values(index))

    # ------------------------------------------------------------ identity
    def canonical(self) -> dict[str, Any]:
        """Resolved description (base content, values, outputs) used for the hash."""
        params = []
        for p in self.parameters:
            d: dict[str, Any] = {"path": p.path}
            if p.values is not None:
                d["values"] = list(p.values)  # (made plain for JSON with the rest: _jsonable)
            else:
                d["distribution"] = p.distribution
                d["args"] = list(p.args)
            params.append(d)
        out: dict[str, Any] = {
            "format": _FORMAT_VERSION,
            "base": self.base.data,
            "samples_read": _read_samples_digest(self.base),
            "swept_files_read": self._swept_files_digest(),
            "design": self.design,
            "parameters": params,
            "metrics": list(self.metrics),
        }
        if not self.is_grid:
            out["samples"] = self.samples
            out["seed"] = self.seed
        if self.histories is not None:
            out["histories"] = {"points": list(self.histories.points), "time_step": self.histories.time_step}
        if self.statistics:
            out["statistics"] = True
        return out

    def _swept_files_digest(self) -> dict[str, list[str]]:
        """:func:`_read_samples_digest` of the base with each value of a parameter naming a file (a swept trace):
        a file changed after a store was made is another sweep, as a changed base file is."""
        out: dict[str, list[str]] = {}
        for p in self.parameters:
            if p.values is not None and p.path.rsplit(".", 1)[-1].endswith("file"):
                out[p.path] = [_read_samples_digest(self.base.with_values({p.path: v})) for v in p.values]
        return out

    @functools.cached_property
    def canonical_json(self) -> str:
        """:meth:`canonical` as JSON, computed once (it reads every file the sweep names)."""
        return json.dumps(_jsonable(self.canonical()), sort_keys=True, separators=(",", ":"), allow_nan=False)

    @property
    def hash(self) -> str:
        """SHA-256 of :meth:`canonical`: equal for sweeps that compute the same cases."""
        return hashlib.sha256(self.canonical_json.encode()).hexdigest()

    def history_bytes(self) -> float:
        """Bytes of one case's histories (``w`` at every history time and point; 0 without histories)."""
        if self.histories is None:
            return 0.0
        return 8.0 * self.history_times().size * len(self.histories.points)

    def default_batch(self) -> int:
        """:func:`default_batch_size` of this sweep (its cases, the bytes of one case's histories)."""
        return default_batch_size(self.n_cases, self.history_bytes())

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
        if end / dt > MAX_OUTPUT_SAMPLES:
            raise ScenarioError(
                f"outputs.histories.time_step: {dt:g} s gives {end / dt:.3g} samples of each history up to "
                f"solver.end_time = {end:g} s, too many (max {MAX_OUTPUT_SAMPLES:.0e}); use a larger time step",
                key="outputs.histories.time_step",
            )
        n = int(math.floor(end / dt * (1 + 1e-12))) + 1
        return np.arange(n) * dt

    def check_memory(self, batch_cases: int | None = None) -> None:
        """Refuse, before any work, a sweep whose samples or history batches exceed the memory limit.

        The sampled values (drawing them and the store's coordinates:
        :data:`SAMPLE_BYTES` per sample and parameter, measured) and, with
        histories, one batch of them in a worker (the batch's array, one
        case's evaluation and the compressed chunk: three copies).

        Parameters
        ----------
        batch_cases : int, optional
            Cases per batch (default: the default batch size).
        """
        from .._memory import check_memory

        if not self.is_grid:
            n, d = int(self.samples or 0), len(self.parameters)
            check_memory(n * (SAMPLE_BYTES * d + 16), f"samples: drawing {n} samples of {d} parameter"
                         f"{'s' if d != 1 else ''}", "draw fewer samples")
        if self.histories is not None:
            batch = batch_cases or self.default_batch()
            check_memory(3.0 * batch * self.history_bytes(), f"outputs.histories: a batch of {batch} cases of "
                         f"{self.history_times().size} samples at {len(self.histories.points)} points",
                         "use a larger outputs.histories.time_step, fewer points or a smaller --batch-size")


def default_batch_size(n_cases: int, case_bytes: float = 0.0) -> int:
    """Cases per batch when not given: about 16 batches, at most 1,000 cases and 64 MB of histories each.

    It does not depend on the number of workers, so the same sweep gives the
    same store layout on a laptop and on a cluster (give ``batch_size`` for
    more, smaller batches on a large cluster).

    Parameters
    ----------
    n_cases : int
    case_bytes : float
        Bytes of one case's histories (0 without histories).
    """
    size = min(_DEFAULT_MAX_BATCH, math.ceil(n_cases / _DEFAULT_BATCHES))
    if case_bytes > 0:
        size = min(size, int(_DEFAULT_BATCH_BYTES // case_bytes))
    return max(1, size)


def _jsonable(obj: Any) -> Any:
    """``obj`` with every value :func:`_plain` (tables and lists walked)."""
    if isinstance(obj, dict):
        return {k: _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_jsonable(v) for v in obj]
    return _plain(obj)


def _plain(v: Any) -> Any:
    """A value as JSON holds it: a Python number (an infinite one, a rigid support's "inf", as that string)."""
    v = v.item() if isinstance(v, np.generic) else v
    return str(v) if isinstance(v, float) and math.isinf(v) else v


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


def _read_samples_digest(base: Any) -> str:
    """SHA-256 of the numbers the base scenario read from files (a trace, initial fields): the scenario's data
    holds only their names, so a changed file had left the sweep's hash, and a resumed store, as they were."""
    h = hashlib.sha256()
    ex = base.excitation
    arrays = [ex.times, ex.values] if ex.shape == "table" else []
    for profile in (base.initial.displacement_profile, base.initial.velocity_profile):
        if profile is not None:
            arrays += [profile.positions, profile.values]
    for a in arrays:
        h.update(np.ascontiguousarray(a, dtype=float).tobytes())
    return h.hexdigest()

