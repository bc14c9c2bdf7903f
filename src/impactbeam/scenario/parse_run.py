"""The run tables of a scenario: ``[damping]``, ``[excitation]``, ``[initial]``, ``[solver]`` and ``[output]``."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..model.beam import Beam, Contactor
from ..exceptions import ScenarioError
from ..model.loading import Excitation, InitialCondition
from ..model import BASES, Damping, SolverOptions
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
from .schema import OUTPUT_FIELD_ALIASES, OUTPUT_FIELDS, EXCITATION_DIMENSIONS, _HOLDS, _KINDS, _SHAPES, _join
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
    with _relabel("damping"):
        return Damping(_ratios(d, "free"), _ratios(d, "contact"))


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
    if shape == "table":
        if "amplitude" in ex:
            raise ScenarioError(
                'excitation.amplitude: has no effect with shape = "table" (the file holds the '
                "values; use excitation.scale to scale them)",
                key="excitation.amplitude",
            )
        _required(ex, "excitation", "file", ' for shape = "table"')
        file = _string("excitation.file", ex["file"])
        path = Path(file).expanduser()
        if not path.is_absolute() and base_dir is not None:
            path = Path(base_dir) / path
        times, values = read_table(path, value_dimension=dimension, key="excitation.file", label=file)
        hold = _choice("excitation.hold", ex.get("hold", "constant"), _HOLDS)
    else:
        _reject_unused(ex, ("file", "hold"), f'with shape = "{shape}" (only with shape = "table")')
        _required(ex, "excitation", "amplitude", f' for kind = "{kind}" ({describe_dimension(dimension)})')
        amplitude = to_si(ex["amplitude"], dimension, "excitation.amplitude")

    duration = None
    if shape == "half_sine":
        _required(ex, "excitation", "duration", " for a half_sine pulse")
        duration = _positive(ex, "excitation", "duration", "time")
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
        )


def _float_list(key: str, value: list[Any]) -> tuple[float, ...]:
    return tuple(to_si(v, "dimensionless", _join(key, i)) for i, v in enumerate(value))


def _parse_initial(raw: Mapping[str, Any], beam: Beam) -> InitialCondition:
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
    with _relabel("initial"):
        return InitialCondition(tip, position, modal["modal_displacement"], modal["modal_velocity"])


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
