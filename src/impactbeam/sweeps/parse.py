"""Sweep files (TOML) into a :class:`~impactbeam.sweeps.spec.SweepSpec`, every problem named by its key."""

from __future__ import annotations

import math
import os
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any
import numpy as np

from ..exceptions import ScenarioError
from ..result.metrics import METRIC_UNITS
from ..result.simulation_result import STRESS_METRIC_UNITS
from ..scenario import Scenario, load_scenario, parse_scenario
from ..scenario.schema import describe_value
from ..units import to_si
from .spec import DESIGNS, DISTRIBUTIONS, Histories, SweepParameter, SweepSpec

__all__ = ["load_sweep", "metric_units", "parse_sweep"]


_TOP_KEYS = ("base", "design", "samples", "seed", "parameters", "outputs", "name", "description")
_PARAM_KEYS = ("values", "range", "scale", "distribution", "low", "high", "mean", "std")
_OUTPUT_KEYS = ("metrics", "histories", "statistics")
_HISTORY_KEYS = ("points", "time_step")


def _dimension_of(path: str, base: Scenario) -> str | None:
    """The dimension of a swept path (None for a path outside the schema: reported when checked)."""
    try:
        return base.path_dimension(path)
    except ScenarioError:
        return None


class _Errors:
    """Builds one-line ScenarioErrors prefixed by the sweep file's name."""

    def __init__(self, source: Path | None) -> None:
        self.prefix = f"{source.name}: " if source is not None else ""

    def __call__(self, key: str, message: str) -> ScenarioError:
        return ScenarioError(f"{self.prefix}{key}: {message}", key=key)


def _count(err: _Errors, key: str, value: Any, *, minimum: int = 1) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or (
        isinstance(value, float) and not (math.isfinite(value) and value.is_integer())
    ):
        raise err(key, f"expected an integer, got {describe_value(value)}")
    if value < minimum:
        what = "a positive integer" if minimum == 1 else f"an integer >= {minimum}"
        raise err(key, f"must be {what}, got {int(value)}")
    return int(value)


def _number(err: _Errors, key: str, value: Any, dimension: str | None, what: str) -> float:
    """A number in SI: plain numbers, or strings with units when the dimension is known."""
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise err(key, f"{what}: expected a number, got {describe_value(value)}")
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
            raise err(key, f"values: expected a list, got {describe_value(raw)}")
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
            raise err(key, f"range: expected [start, stop, num], got {describe_value(raw)}")
        num_raw = raw[2]
        if isinstance(num_raw, (int, float)) and not isinstance(num_raw, bool) and num_raw < 1:
            raise err(key, f"range: num must be a positive integer, got {num_raw!r} (an empty range)")
        num = _count(err, f"{key}.range", num_raw)
        num_dim = "dimensionless" if dimension == "integer" else dimension
        start = _number(err, key, raw[0], num_dim, "range start")
        stop = _number(err, key, raw[1], num_dim, "range stop")
        scale = table.get("scale", "linear")
        if scale not in ("linear", "log"):
            raise err(key, f'scale: must be "linear" or "log", got {describe_value(scale)}')
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
        raise err(key, f'distribution: unknown {describe_value(kind)} (use {", ".join(DISTRIBUTIONS)})')
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
        raise err("sweep", f"expected a table, got {describe_value(data)}")
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
        raise err("base", f"expected a scenario path or a table, got {describe_value(raw_base)}")
    if base.excitation.seed_drawn:  # a new draw at every reading: the sweep could not be resumed or repeated
        raise err("base", "excitation.seed: a random load in a sweep needs its seed in the scenario (one is drawn "
                  f"otherwise, differently at every run); add excitation.seed = {base.excitation.seed}")

    # design
    design = data.get("design", "grid")
    if design not in DESIGNS:
        raise err("design", f'unknown design {describe_value(design)} (use {", ".join(DESIGNS)})')
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
            raise err(key, f"expected a table (values, range or distribution), got {describe_value(table)}")
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
        raise err("outputs", f"expected a table, got {describe_value(outputs)}")
    for k in outputs:
        if k not in _OUTPUT_KEYS:
            raise err(f"outputs.{k}", f"unknown key (use {', '.join(_OUTPUT_KEYS)})")
    metrics = _metric_names(err, outputs.get("metrics", "all"), base)
    histories = None
    if "histories" in outputs:
        histories = _histories(err, outputs["histories"], base)
    statistics = outputs.get("statistics", False)
    if not isinstance(statistics, bool):
        raise err("outputs.statistics", f"expected true or false, got {describe_value(statistics)}")

    name = data.get("name", src.stem if src is not None else "sweep")
    if not isinstance(name, str):
        raise err("name", f"expected a string, got {describe_value(name)}")
    spec = SweepSpec(base, design, tuple(params), samples, seed, metrics, histories, src, name, statistics)
    if histories is not None:
        spec.history_times()  # checks a bounded end time and the number of samples
    spec.check_memory()
    return spec


def _check_alternatives(err: _Errors, paths: list[str]) -> None:
    seen = set(paths)
    for p in paths:
        for a, b in (("position", "position_ratio"), ("points", "point_ratios")):
            if p.endswith("." + a) and p[: -len(a)] + b in seen:
                raise err(f'parameters."{p}"', f'and "{p[: -len(a)] + b}" set the same field; vary one of them')


def metric_units(base: Scenario) -> dict[str, str]:
    """The scalar metrics a sweep of ``base`` can store and their units: the response metrics, and the
    maximum bending stress (its value, time and place) when the base asks for ``[output] fields = ["stress"]``."""
    return {**METRIC_UNITS, **(STRESS_METRIC_UNITS if "stress" in base.output_fields else {})}


def _metric_names(err: _Errors, value: Any, base: Scenario) -> tuple[str, ...]:
    known = metric_units(base)
    if value == "all":
        return tuple(known)
    if not isinstance(value, list) or not value or not all(isinstance(v, str) for v in value):
        raise err("outputs.metrics", f'expected "all" or a list of metric names, got {describe_value(value)}')
    for v in value:
        if v not in known:
            hint = ' (add [output] fields = ["stress"] to the base scenario)' if v in STRESS_METRIC_UNITS else ""
            raise err("outputs.metrics", f'unknown metric "{v}" (use {", ".join(known)}){hint}')
    if len(set(value)) != len(value):
        raise err("outputs.metrics", "a metric is listed twice")
    return tuple(v for v in known if v in value)  # canonical order


def _histories(err: _Errors, value: Any, base: Scenario) -> Histories:
    key = "outputs.histories"
    if not isinstance(value, Mapping):
        raise err(key, f"expected a table {{ points = [...], time_step = ... }}, got {describe_value(value)}")
    for k in value:
        if k not in _HISTORY_KEYS:
            raise err(f"{key}.{k}", f"unknown key (use {', '.join(_HISTORY_KEYS)})")
    for k in _HISTORY_KEYS:
        if k not in value:
            raise err(key, f'"{k}" is missing')
    pts = value["points"]
    if not isinstance(pts, list) or not pts:
        raise err(f"{key}.points", f"expected a non-empty list of positions, got {describe_value(pts)}")
    points = tuple(_number(err, f"{key}.points", p, "length", f"points[{i}]") for i, p in enumerate(pts))
    for x in points:
        if not 0.0 <= x <= base.beam.length * (1 + 1e-12):
            raise err(f"{key}.points", f"{x!r} m is off the beam (length {base.beam.length:g} m)")
    dt = _number(err, f"{key}.time_step", value["time_step"], "time", "time_step")
    if not dt > 0:
        raise err(f"{key}.time_step", f"must be > 0, got {dt!r}")
    return Histories(points, dt)


def load_sweep(path: str | os.PathLike[str]) -> SweepSpec:
    """Read and validate a sweep file; a relative ``base`` is resolved against its directory.

    Parameters
    ----------
    path : str or path-like
        The sweep file (TOML).
    """
    from .._io import read_text_file
    from ..scenario.core import SCENARIO_MEMORY_FACTOR

    p = Path(path)

    def fail(detail: str) -> ScenarioError:
        return ScenarioError(f"{p}: the sweep file {detail}", key="sweep")

    text = read_text_file(p, fail, not_found="does not exist (no such sweep file)", memory_factor=SCENARIO_MEMORY_FACTOR)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f"{p.name}: invalid TOML: {exc}", key="sweep") from None
    return parse_sweep(data, base_dir=p.resolve().parent, source=p)
