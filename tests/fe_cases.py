"""Scenarios run by the finite-element reference, and their metrics read from its grid.

The glue between a :class:`impactbeam.Scenario` and ``fe_reference.fe_transient``
(which imports nothing from the package): the beam, supports, sections,
masses, springs, the first contactor, the load (base acceleration or point
force, half-sine or step) and the modal damping ratios are passed as plain
numbers. Runs are cached for the test session (a slow FE run is shared by
every test that needs it), and kept small: the grid of time, the deflection
at the first contactor, its force and the events.

The metrics are those of the package's definitions (``result.metrics()``),
read from the FE grid: extrema are grid samples refined by a parabola through
the largest sample and its neighbours; event times are the FE's, located
inside the step by Brent's method.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

import fe_reference as fr

__all__ = ["FERun", "fe_run", "fe_metrics", "fe_peak_forces", "fe_changes"]

_CACHE: dict = {}


@dataclass(frozen=True)
class FERun:
    """A compact FE run: grid, deflection and force of the first contactor, events."""

    t: np.ndarray
    w: np.ndarray  # (n_t, n_x) deflection at the output points (first: the first contactor)
    force: np.ndarray  # (n_t,) force of the first contactor on the beam [N], >= 0
    events: list
    side: str
    gap: float
    stiffness: float
    dt: float


def _load(sc) -> dict | None:
    exc = sc.excitation
    if exc.kind == "none":
        return None
    shape = exc.shape
    if shape not in ("half_sine", "step"):
        raise ValueError(f"FE reference: load shape {shape!r} not supported here")
    load = dict(kind=exc.kind, shape=shape, amplitude=exc.amplitude * exc.scale, start=exc.start)
    if shape == "half_sine":
        load["duration"] = exc.duration
    if exc.kind == "point_force":
        load["position"] = exc.position
    elif exc.kind != "base_acceleration":
        raise ValueError(f"FE reference: load kind {exc.kind!r} not supported here")
    return load


def fe_run(sc, n_elements: int, dt: float, end_time: float | None = None) -> FERun:
    """The FE run of scenario ``sc`` (first contactor only), cached per scenario and settings."""
    end = sc.solver.end_time if end_time is None else end_time
    key = (repr(sc.beam), repr(sc.contactors), repr(sc.excitation), repr(sc.damping), n_elements, dt, end)
    hit = _CACHE.get(key)
    if hit is not None:
        return hit
    beam, c = sc.beam, sc.contactors[0]
    supp = lambda s: (s.translational, s.rotational)  # noqa: E731
    structure = {
        "sections": [(p.length, p.bending_stiffness, p.mass_per_length) for p in beam.sections],
        "masses": [(m.position, m.mass, m.rotary_inertia) for m in beam.masses],
        "springs": [(s.position, s.translational) for s in beam.springs if s.translational],
        "rotational_springs": [(s.position, s.rotational) for s in beam.springs if s.rotational],
    }
    r = fr.fe_transient(
        beam.length, beam.bending_stiffness, beam.mass_per_length, left=supp(beam.left), right=supp(beam.right),
        contactors=[dict(position=c.position, stiffness=c.stiffness, gap=c.gap, side=c.side)], load=_load(sc),
        damping=(float(sc.damping.free), float(sc.damping.contact)), dt=dt, t_end=end, n_elements=n_elements,
        output_x=[c.position, beam.length], **structure,
    )
    run = FERun(r.t, r.w, r.contact_force[:, 0] * (-1.0 if c.side == "above" else 1.0),
                [(t, kind) for t, kind, i in r.events if i == 0], c.side, c.gap, c.stiffness, dt)
    _CACHE[key] = run
    return run


def _peak(t: np.ndarray, y: np.ndarray, i: int) -> tuple[float, float]:
    """The extremum near grid sample ``i`` of ``y`` by a parabola through it and its neighbours."""
    if 0 < i < y.size - 1:
        a, b, c = y[i - 1], y[i], y[i + 1]
        den = a - 2 * b + c
        if den != 0:
            s = 0.5 * (a - c) / den
            if abs(s) <= 1:
                return float(b - 0.25 * (a - c) * s), float(t[i] + s * (t[1] - t[0]))
    return float(y[i]), float(t[i])


def _intervals(run: FERun) -> list[tuple[float, float]]:
    out, start = [], None
    for t, kind in run.events:
        if kind == "impact":
            start = t
        elif start is not None:
            out.append((start, t))
            start = None
    if start is not None:
        out.append((start, math.inf))
    return out


def fe_peak_forces(run: FERun) -> list[dict]:
    """Per impact: ``contactor``, ``start``, ``end``, ``peak_force`` (grid maximum, parabola-refined)."""
    rows = []
    for a, b in _intervals(run):
        sel = np.flatnonzero((run.t >= a) & (run.t <= b))
        if sel.size == 0:
            peak = 0.0
        else:
            i = int(sel[np.argmax(run.force[sel])])
            peak = max(_peak(run.t, run.force, i)[0], float(run.force[i]))
        rows.append({"contactor": 0, "start": a, "end": None if math.isinf(b) else b, "peak_force": peak})
    return rows


def fe_metrics(run: FERun) -> dict:
    """The Table-2 metrics of the package's definitions, from the FE run (with ``impacts``)."""
    u = (-1.0 if run.side == "above" else 1.0) * run.w[:, 0]
    k = int(np.argmax(u))
    max_response, t_max = _peak(run.t, u, k)
    iv = _intervals(run)
    prev_end, nxt = 0.0, None
    for a, b in iv:
        if b <= t_max:
            prev_end = b
        elif a >= t_max:
            nxt = a
            break
    after = [(a, b) for a, b in iv if a >= t_max]
    out = {
        "max_response": max_response, "t_max": t_max, "n_impacts": len(iv),
        "first_impact_time": iv[0][0] if iv else None,
        "free_duration": None if nxt is None else nxt - prev_end,
        "contact_duration": None, "min_response": None,
        "max_penetration": float(run.force.max()) / run.stiffness if iv else None,
        "impacts": fe_peak_forces(run),
    }
    if after:
        a, b = after[0]
        if math.isfinite(b):
            out["contact_duration"] = b - a
        sel = np.flatnonzero((run.t >= a) & (run.t <= b))
        if sel.size:
            i = int(sel[np.argmin(u[sel])])
            out["min_response"] = -_peak(run.t, -u, i)[0]
    return out


def fe_changes(fine: dict, coarse: dict) -> dict:
    """Relative difference of two FE runs' metrics: the FE's own error (the same rules as the estimate)."""
    from impactbeam.solver.convergence import relative_changes

    return relative_changes(fine, coarse)
