"""The run tables of a scenario: ``[damping]``, ``[excitation]``, ``[initial]``, ``[solver]`` and ``[output]``."""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..model.beam import Beam, Contactor
from ..exceptions import ScenarioError
from ..model.loading import Excitation
from ..model.starting import InitialCondition, Preload, Profile
from ..model.fatigue import FatigueSpec
from ..model.psd import PowerSpectralDensity
from ..model import BASES, Damping, SolverOptions
from ..model.damping import DAMPING_MODELS, MODEL_KEYS
from ..units import describe_dimension, to_si
from .fields import (
    _choice,
    _fmt_m,
    _integer,
    _nonnegative,
    _on_beam,
    _position,
    _positive,
    _ratio,
    _relabel,
    _required,
    _string,
)
from .schema import (
    EXCITATION_DIMENSIONS,
    OUTPUT_FIELD_ALIASES,
    OUTPUT_FIELDS,
    PRELOAD_DIMENSIONS,
    PSD_DIMENSIONS,
    _HOLDS,
    _KINDS,
    _MEAN_STRESS,
    _SHAPES,
    _join,
    describe_value,
)
from .traces import read_table

__all__ = []


def _ratios(table: Mapping[str, Any], name: str) -> float | tuple[float, ...]:
    key = f"damping.{name}"
    value = table.get(name, 0.0)
    if isinstance(value, list):
        if not value:
            raise ScenarioError(f"{key}: the list of damping ratios is empty", key=key)
        return tuple(
            _nonnegative(_join(key, i), v, "dimensionless") for i, v in enumerate(value)
        )
    return _nonnegative(key, value, "dimensionless")


def _parse_damping(raw: Mapping[str, Any]) -> Damping:
    d = raw.get("damping", {})
    model = _choice("damping.model", d.get("model", "modal"), DAMPING_MODELS)
    used = MODEL_KEYS[model]
    for key in d:
        if key != "model" and key not in used:
            raise ScenarioError(
                f'damping.{key}: not used by damping.model = "{model}" (which reads {" and ".join(used)})',
                key=f"damping.{key}",
            )
    alpha = _nonnegative("damping.alpha", d.get("alpha", 0.0), "rate")
    beta = _nonnegative("damping.beta", d.get("beta", 0.0), "time")
    for key in ("free", "contact"):
        _warn_percent_as_ratio(f"damping.{key}", d.get(key))
    with _relabel("damping"):
        return Damping(_ratios(d, "free"), _ratios(d, "contact"), model, alpha, beta)  # type: ignore[arg-type]


def _warn_percent_as_ratio(key: str, value: Any) -> None:
    """Warn of a damping ratio of 1 or more written as a bare number: a percentage meant as a ratio?

    The paper gives its damping in percent (1.1 %); ``free = 1.1`` is a ratio
    of 110 % of critical, which stops the beam from ringing at all.
    """
    from .._warnings import emit_user_level_warning

    values = value if isinstance(value, list) else [value]
    large = [v for v in values if isinstance(v, (int, float)) and not isinstance(v, bool) and v >= 1.0]
    if large:
        emit_user_level_warning(
            f"{key}: {large[0]:g} is read as a ratio, {100 * large[0]:g} % of critical (at or above critical: "
            f'no ringing); if {large[0]:g} % was meant, write "{large[0]:g} %" or {large[0] / 100:g}'
        )


def _reject_unused(table: Mapping[str, Any], names: tuple[str, ...], why: str) -> None:
    for name in names:
        if name in table:
            key = f"excitation.{name}"
            raise ScenarioError(f"{key}: has no effect {why}", key=key)


def _parse_excitation(raw: Mapping[str, Any], beam: Beam, base_dir: Path | None) -> Excitation:
    ex = raw.get("excitation", {})
    kind = _choice("excitation.kind", ex.get("kind", "none"), _KINDS)
    if kind == "none":
        _reject_unused(ex, tuple(k for k in ex if k != "kind"), 'with excitation.kind = "none"')
        return Excitation()
    shape = _choice("excitation.shape", ex.get("shape", "half_sine"), _SHAPES)
    dimension = EXCITATION_DIMENSIONS[kind]
    start = _nonnegative("excitation.start", ex.get("start", 0.0), "time")
    scale = to_si(ex.get("scale", 1.0), "dimensionless", "excitation.scale")

    amplitude = 0.0
    times = values = None
    hold = "constant"
    random: dict[str, Any] = {}
    if shape == "random":
        random = _parse_random(raw, ex, kind, start)
    else:
        _reject_unused(ex, ("psd", "seed", "stream", "sample_rate"), f'with shape = "{shape}" (only with shape = "random")')
    if shape == "random":
        _reject_unused(ex, ("amplitude", "file", "hold"), 'with shape = "random" (the psd sets the level; '
                       "excitation.scale multiplies the history, so the density by its square)")
    elif shape == "table":
        if "amplitude" in ex:
            raise ScenarioError(
                'excitation.amplitude: has no effect with shape = "table" (the file holds the '
                "values; use excitation.scale to scale them)",
                key="excitation.amplitude",
            )
        _required(ex, "excitation", "file", ' for shape = "table"')
        path, file = _file_path(ex["file"], "excitation.file", base_dir)
        times, values = read_table(path, value_dimension=dimension, key="excitation.file", label=file)
        hold = _choice("excitation.hold", ex.get("hold", "constant"), _HOLDS)
    else:
        _reject_unused(ex, ("file", "hold"), f'with shape = "{shape}" (only with shape = "table")')
        _required(ex, "excitation", "amplitude", f' for kind = "{kind}" ({describe_dimension(dimension)})')
        amplitude = to_si(ex["amplitude"], dimension, "excitation.amplitude")

    duration = random.pop("duration", None)
    if shape == "half_sine":
        _required(ex, "excitation", "duration", " for a half_sine pulse")
        duration = _positive(ex, "excitation", "duration", "time")
    elif shape == "random":
        _reject_unused(ex, ("duration",), 'with shape = "random" (the history lasts from excitation.start to '
                       "solver.end_time)")
    else:
        _reject_unused(ex, ("duration",), f'with shape = "{shape}" (only with shape = "half_sine")')

    frequency, phase = None, 0.0
    if shape == "harmonic":
        _required(ex, "excitation", "frequency", ' for shape = "harmonic" (a frequency, Hz)')
        frequency = _positive(ex, "excitation", "frequency", "frequency")
        phase = to_si(ex.get("phase", 0.0), "angle", "excitation.phase")
    else:
        _reject_unused(ex, ("frequency", "phase"), f'with shape = "{shape}" (only with shape = "harmonic")')

    position = None
    if kind == "point_force":
        position = _position(ex, "excitation", beam.length, required=True)
    else:
        _reject_unused(ex, ("position", "position_ratio"), f'with kind = "{kind}" (only with "point_force")')

    with _relabel("excitation"):
        return Excitation(
            kind=kind,  # type: ignore[arg-type]
            shape=shape,  # type: ignore[arg-type]
            amplitude=amplitude,
            duration=duration,
            start=start,
            position=position,
            times=times,
            values=values,
            hold=hold,  # type: ignore[arg-type]
            scale=scale,
            frequency=frequency,
            phase=phase,
            **random,
        )


def _parse_random(raw: Mapping[str, Any], ex: Mapping[str, Any], kind: str, start: float) -> dict[str, Any]:
    """The fields of a random excitation: ``psd``, ``seed`` (drawn when absent), ``stream``, ``sample_rate``.

    A drawn seed is written into ``raw`` (the scenario's private copy), so the
    scenario's data, its TOML and every run made from it repeat the same history.
    """
    _required(ex, "excitation", "psd", ' for shape = "random" ([[frequency, level], ...], one-sided)')
    rows = ex["psd"]
    dims = ("frequency", PSD_DIMENSIONS[kind])
    freqs, levels = [], []
    for i, row in enumerate(rows):
        freqs.append(to_si(row[0], dims[0], f"excitation.psd.{i}.0"))
        levels.append(to_si(row[1], dims[1], f"excitation.psd.{i}.1"))
    with _relabel("excitation.psd"):
        psd = PowerSpectralDensity(freqs, levels)
    out: dict[str, Any] = {"psd": psd, "seed_drawn": "seed" not in ex}
    if "seed" in ex:
        out["seed"] = _integer("excitation.seed", ex["seed"])
    else:
        import secrets

        out["seed"] = secrets.randbits(32)
        raw["excitation"]["seed"] = out["seed"]  # type: ignore[index]
    if "stream" in ex:
        out["stream"] = _integer("excitation.stream", ex["stream"])
    for name in ("seed", "stream"):
        if out.get(name) is not None and out[name] < 0:
            raise ScenarioError(f"excitation.{name}: must be an integer >= 0, got {out[name]}", key=f"excitation.{name}")
    if "sample_rate" in ex:
        out["sample_rate"] = _positive(ex, "excitation", "sample_rate", "frequency")
    end = _parse_solver(raw).end_time
    if start >= end:
        raise ScenarioError(
            f"excitation.start: the random load starts at {start:g} s, at or after solver.end_time = {end:g} s",
            key="excitation.start",
        )
    out["duration"] = end - start
    return out


def _parse_fatigue(raw: Mapping[str, Any], beam: Beam) -> FatigueSpec | None:
    """``[fatigue]``: the points and the S-N curve (Basquin), or None when absent."""
    fat = raw.get("fatigue")
    if fat is None:
        return None
    _required(fat, "fatigue", "points", " (x positions where the damage is computed)")
    if not fat["points"]:
        raise ScenarioError("fatigue.points: the list is empty", key="fatigue.points")
    points = tuple(_on_beam(f"fatigue.points.{i}", to_si(v, "length", f"fatigue.points.{i}"), beam.length)
                   for i, v in enumerate(fat["points"]))
    for i, x in enumerate(points):
        if not math.isfinite(float(beam.fibre_distance_at([x])[0])):
            raise ScenarioError(
                f"fatigue.points.{i}: the section there is given by area and second_moment, so its outer-fibre "
                "distance (and the bending stress) is unknown; give width and height", key=f"fatigue.points.{i}")
    for name in ("sn_stress", "sn_cycles", "sn_exponent"):
        _required(fat, "fatigue", name, " (the S-N curve N(S) = sn_cycles (S / sn_stress)^-sn_exponent)")
    kw: dict[str, Any] = {
        "sn_stress": _positive(fat, "fatigue", "sn_stress", "stress"),
        "sn_cycles": _positive(fat, "fatigue", "sn_cycles", "dimensionless"),
        "sn_exponent": _positive(fat, "fatigue", "sn_exponent", "dimensionless"),
    }
    if "endurance_limit" in fat:
        kw["endurance_limit"] = _nonnegative("fatigue.endurance_limit", fat["endurance_limit"], "stress")
    kw["mean_stress"] = _choice("fatigue.mean_stress", fat.get("mean_stress", "none"), _MEAN_STRESS)
    if "ultimate_strength" in fat:
        kw["ultimate_strength"] = _positive(fat, "fatigue", "ultimate_strength", "stress")
    with _relabel("fatigue"):
        return FatigueSpec(points=points, **kw)


def _float_list(key: str, value: list[Any]) -> tuple[float, ...]:
    return tuple(to_si(v, "dimensionless", _join(key, i)) for i, v in enumerate(value))


def _file_path(value: Any, key: str, base_dir: Path | None) -> tuple[Path, str]:
    """A file name of the scenario, relative to its directory; and the name as written."""
    file = _string(key, value)
    path = Path(file).expanduser()
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    return path, file


def _profile(ini: Mapping[str, Any], name: str, dimension: str, beam: Beam, base_dir: Path | None) -> Profile | None:
    """``initial.<name>`` as rows ``[[x, value], ...]`` or ``initial.<name>_file``: a field along the beam."""
    key, file_key = f"initial.{name}", f"initial.{name}_file"
    rows = ini.get(name) if isinstance(ini.get(name), list) else None
    if rows is not None and f"{name}_file" in ini:
        raise ScenarioError(f"{file_key}: give the {name} as rows in {key} or in a file, not both", key=file_key)
    if rows is not None:
        x = [to_si(r[0], "length", f"{key}.{i}.0") for i, r in enumerate(rows)]
        v = [to_si(r[1], dimension, f"{key}.{i}.1") for i, r in enumerate(rows)]
    elif f"{name}_file" in ini:
        path, file = _file_path(ini[f"{name}_file"], file_key, base_dir)
        x, v = read_table(path, value_dimension=dimension, key=file_key, label=file, abscissa="length")
        key = file_key
    else:
        return None
    with _relabel(key):
        profile = Profile(np.asarray(x), np.asarray(v), key)
        profile.check_on(beam.length)
    return profile


def _parse_initial(raw: Mapping[str, Any], beam: Beam, base_dir: Path | None = None) -> InitialCondition:
    ini = raw.get("initial", {})
    tip = None
    if "tip_displacement" in ini:
        tip = to_si(ini["tip_displacement"], "length", "initial.tip_displacement")
    position = None
    if "position" in ini:
        if tip is None:
            raise ScenarioError(
                "initial.position: has no effect without initial.tip_displacement", key="initial.position"
            )
        position = _on_beam("initial.position", to_si(ini["position"], "length", "initial.position"), beam.length)
    if tip is not None and tip != 0.0:
        x0 = beam.length if position is None else position
        held = beam.fixed_at(x0)
        if held is not None:
            key = "initial.position" if position is not None else "initial.tip_displacement"
            raise ScenarioError(
                f"{key}: the deflection is imposed at x = {x0:g} m, at {held} where w = 0; no static load "
                "can move that point: give initial.position on the free part of the beam",
                key=key,
            )
    modal = {
        name: _float_list(f"initial.{name}", ini[name]) if name in ini else None
        for name in ("modal_displacement", "modal_velocity")
    }
    velocity = None
    if "velocity" in ini and not isinstance(ini["velocity"], list):
        velocity = to_si(ini["velocity"], "velocity", "initial.velocity")
    rotation = {name: to_si(ini[name], dim, f"initial.{name}") if name in ini else None
                for name, dim in (("angular_velocity", "angular_velocity"), ("pivot", "length"))}
    if rotation["pivot"] is not None:
        rotation["pivot"] = _on_beam("initial.pivot", rotation["pivot"], beam.length)
    for given, needs in (("angular_velocity", "pivot"), ("pivot", "angular_velocity")):
        if rotation[given] is not None and rotation[needs] is None:
            raise ScenarioError(
                f"initial.{needs}: required with initial.{given} (a rigid rotation at angular_velocity "
                f"[rad/s] about the point x = pivot [m])", key=f"initial.{needs}"
            )
    equilibrium = ini.get("equilibrium", False)
    if not isinstance(equilibrium, bool):
        raise ScenarioError(f"initial.equilibrium: expected true or false, got {describe_value(equilibrium)}",
                            key="initial.equilibrium")
    if equilibrium and "preload" not in raw:
        raise ScenarioError("initial.equilibrium: needs a [preload] table (the constant load the equilibrium "
                            "is taken under)", key="initial.equilibrium")
    profiles = {name: _profile(ini, name, dim, beam, base_dir)
                for name, dim in (("displacement", "length"), ("velocity", "velocity"))}
    with _relabel("initial"):
        return InitialCondition(
            tip, position, modal["modal_displacement"], modal["modal_velocity"], velocity,
            rotation["angular_velocity"], rotation["pivot"], profiles["displacement"], profiles["velocity"],
            equilibrium,
        )


def _parse_preload(raw: Mapping[str, Any], beam: Beam) -> Preload | None:
    """``[preload]``: a constant gravity, base acceleration or point force acting during the whole run."""
    if "preload" not in raw:
        return None
    pre = raw["preload"]
    _required(pre, "preload", "kind", f" ({', '.join(repr(k) for k in PRELOAD_DIMENSIONS)})")
    kind = _choice("preload.kind", pre["kind"], tuple(PRELOAD_DIMENSIONS))
    dimension = PRELOAD_DIMENSIONS[kind]
    _required(pre, "preload", "amplitude", f' for kind = "{kind}" ({describe_dimension(dimension)})')
    amplitude = to_si(pre["amplitude"], dimension, "preload.amplitude")
    position = None
    if kind == "point_force":
        position = _position(pre, "preload", beam.length, required=True)
    else:
        for name in ("position", "position_ratio"):
            if name in pre:
                raise ScenarioError(f'preload.{name}: has no effect with kind = "{kind}" (only with "point_force")',
                                    key=f"preload.{name}")
    with _relabel("preload"):
        return Preload(kind, amplitude, position)  # type: ignore[arg-type]


def _parse_solver(raw: Mapping[str, Any]) -> SolverOptions:
    s = raw.get("solver", {})
    kw: dict[str, Any] = {}
    if isinstance(s.get("modes"), str) and s["modes"].strip().lower() == "auto":
        kw["modes"] = "auto"
    elif "modes" in s:
        kw["modes"] = _integer("solver.modes", s["modes"])
    if "max_events" in s:
        kw["max_events"] = _integer("solver.max_events", s["max_events"])
    if "tolerance" in s:
        kw["tolerance"] = to_si(s["tolerance"], "dimensionless", "solver.tolerance")
    for name in ("time_step", "end_time", "event_tolerance"):
        if name in s:
            kw[name] = to_si(s[name], "time", f"solver.{name}")
    if "projection" in s:
        kw["projection"] = _choice("solver.projection", s["projection"], ("contact", "paper"))
    if "basis" in s:
        kw["basis"] = _choice("solver.basis", s["basis"], BASES)
    with _relabel("solver"):
        return SolverOptions(**kw)


def _parse_output(raw: Mapping[str, Any], beam: Beam, contactors: tuple[Contactor, ...]) -> tuple[float, ...]:
    out = raw.get("output", {})
    if "points" in out and "point_ratios" in out:
        raise ScenarioError(
            "output.points: give either output.points or output.point_ratios, not both", key="output.points"
        )
    if "points" not in out and "point_ratios" not in out:
        points: list[float] = []
        for x in [c.position for c in contactors] + [beam.length]:
            if x not in points:
                points.append(x)
        return tuple(points)
    name = "points" if "points" in out else "point_ratios"
    values = out[name]
    if not values:
        raise ScenarioError(f"output.{name}: the list is empty", key=f"output.{name}")
    points = []
    seen: set[float] = set()
    for i, v in enumerate(values):
        key = f"output.{name}.{i}"
        x = _ratio(key, v) * beam.length if name == "point_ratios" else to_si(v, "length", key)
        x = _on_beam(key, x, beam.length)
        if x in seen:
            raise ScenarioError(f"{key}: {_fmt_m(x)} is listed twice", key=key)
        seen.add(x)
        points.append(x)
    return tuple(points)


def _parse_output_fields(raw: Mapping[str, Any], beam: Beam) -> tuple[str, ...]:
    """``[output] fields``: the fields of result files by their canonical names, each once.

    The stress needs the outer-fibre distance ``height / 2`` of every section:
    a section given as area and second moment has none, so the field is
    refused rather than written as NaN.
    """
    values = raw.get("output", {}).get("fields", [])
    out: list[str] = []
    for i, v in enumerate(values):
        key = f"output.fields.{i}"
        v = OUTPUT_FIELD_ALIASES.get(v, v) if isinstance(v, str) else v
        name = _choice(key, v, OUTPUT_FIELDS)
        if name in out:
            raise ScenarioError(f"{key}: {name!r} is listed twice", key=key)
        if name == "stress" and any(p.height is None for p in beam.pieces()):
            raise ScenarioError(
                f'{key}: "stress" needs the outer-fibre distance (height / 2), and a section given as area and '
                "second_moment has none; give width and height, or ask for \"moment\" (M; the stress is M c / I)",
                key=key,
            )
        out.append(name)
    return tuple(out)
