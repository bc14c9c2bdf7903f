"""Response metrics of a simulation (the paper's Table 2 quantities and more).

Definitions (DESIGN.md section 3). On ``u = w`` at the first contactor for a
contactor ``below`` (``u = -w`` for one ``above``; ``u = w`` at the first output
point without contactor), so that ``u`` is positive away from the contactor:

* ``max_response``: max of ``u``; ``t_max`` its time (refined on the exact solution);
* ``free_duration``: the free interval containing ``t_max``;
* ``contact_duration``, ``min_response``: the first contact interval after
  ``t_max`` and the minimum of ``u`` in it;
* ``max_penetration``: the largest compression of the contactor over the run;
* ``n_impacts``: contact intervals begun; ``first_impact_time``: the first one's start.

Per impact (``impacts``): start, end, duration, peak force and impulse.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.optimize import brentq

if TYPE_CHECKING:
    from .result import SimulationResult

__all__ = ["compute_metrics", "contact_intervals", "METRIC_UNITS"]

#: Units of the scalar metrics (for labelled outputs).
METRIC_UNITS = {
    "max_response": "m",
    "t_max": "s",
    "first_impact_time": "s",
    "n_impacts": "1",
    "free_duration": "s",
    "contact_duration": "s",
    "min_response": "m",
    "max_penetration": "m",
    "n_events": "1",
    "energy_residual": "J",
}


def contact_intervals(result: SimulationResult, contactor: int = 0) -> list[tuple[float, float]]:
    """Contact intervals ``(start, end)`` of one contactor; ``end`` is inf if still engaged."""
    out: list[tuple[float, float]] = []
    start: float | None = None
    for ev in result.events:
        if ev.contactor != contactor:
            continue
        if ev.kind == "impact":
            start = ev.time
        elif start is not None:
            out.append((start, ev.time))
            start = None
    if start is not None:
        out.append((start, math.inf))
    return out


def _refine_extremum(result: SimulationResult, x: float, sign: float, t_grid: np.ndarray, k: int) -> tuple[float, float]:
    """Refine the extremum of ``sign * w(x, t)`` found at grid index ``k`` on the exact solution.

    The velocity changes sign between the neighbouring samples; Brent's method
    on the closed form of the segment holding them locates the extremum.
    """
    t_k = float(t_grid[k])
    val = float(sign * result.displacement([x], [t_k])[0, 0])
    lo = float(t_grid[max(k - 1, 0)])
    hi = float(t_grid[min(k + 1, t_grid.size - 1)])
    f = result._scalar(x, lo, hi)
    if f is None:  # no single closed-form segment: the general dense output

        def fun(tau: float) -> tuple[float, float]:
            return (
                float(result.displacement([x], [tau])[0, 0]),
                float(result.velocity([x], [tau])[0, 0]),
            )

        seg_t0 = 0.0
    else:
        seg_t0, fun = f

    def dv(t: float) -> float:
        return sign * fun(t - seg_t0)[1]

    candidates = []
    if lo < t_k and dv(lo) > 0 > dv(t_k):
        candidates.append(brentq(dv, lo, t_k, xtol=1e-14))
    if t_k < hi and dv(t_k) > 0 > dv(hi):
        candidates.append(brentq(dv, t_k, hi, xtol=1e-14))
    for tc in candidates:
        vc = sign * fun(tc - seg_t0)[0]
        if vc > val:
            t_k, val = float(tc), float(vc)
    return t_k, val


def compute_metrics(result: SimulationResult) -> dict[str, Any]:
    """The metrics dictionary of :meth:`SimulationResult.metrics`."""
    t = result.time
    has_c = len(result.contactors) > 0
    if has_c:
        c0 = result.contactors[0]
        x = c0.position
        sign = -1.0 if c0.side == "above" else 1.0
        w = result.w_contact[:, 0]
    else:
        x = float(result.points[0])
        sign = 1.0
        w = result.w[:, 0]
    u = sign * w
    valid = np.isfinite(u)
    out: dict[str, Any] = {k: None for k in METRIC_UNITS}
    if not valid.any():
        out["events"] = []
        out["impacts"] = []
        return out
    k_max = int(np.nanargmax(u))
    t_max, u_max = _refine_extremum(result, x, 1.0 * sign, t, k_max)
    out["max_response"] = u_max
    out["t_max"] = t_max
    out["n_events"] = len(result.events)
    ev_list = [{"time": e.time, "kind": e.kind, "contactor": e.contactor} for e in result.events]
    if has_c:
        iv = contact_intervals(result, 0)
        out["n_impacts"] = len(iv)
        out["first_impact_time"] = iv[0][0] if iv else None
        # free interval containing t_max
        prev_end = 0.0
        nxt_start = None
        for a, b in iv:
            if b <= t_max:
                prev_end = b
            elif a >= t_max:
                nxt_start = a
                break
        out["free_duration"] = (nxt_start - prev_end) if nxt_start is not None else None
        after = [(a, b) for a, b in iv if a >= t_max]
        if after:
            a, b = after[0]
            if math.isfinite(b):
                out["contact_duration"] = b - a
            inside = (t >= a) & (t <= min(b, t[-1])) & valid
            if inside.any():
                kk = int(np.nonzero(inside)[0][np.argmin(u[inside])])
                tm, um = _refine_extremum(result, x, -sign, t, kk)
                out["min_response"] = -um if a <= tm <= b else float(u[kk])
        pen = np.nanmax(result.contact_force[:, 0]) / c0.stiffness if result.contact_force.size else 0.0
        out["max_penetration"] = float(pen) if np.isfinite(pen) else 0.0
    else:
        out["min_response"] = float(np.nanmin(u))
    out["energy_residual"] = float(result.energy["residual"][np.isfinite(result.energy["residual"])][-1]) if np.isfinite(result.energy["residual"]).any() else None
    out["events"] = ev_list
    out["impacts"] = _impacts(result)
    return out


def _impacts(result: SimulationResult) -> list[dict[str, Any]]:
    """Duration, peak force and impulse of every contact interval.

    The contact force ``k max(0, -g)`` is evaluated on the exact solution at
    129 points per interval; the impulse is its Simpson integral.
    """
    n = 129
    rows = []
    for ci, c in enumerate(result.contactors):
        for a, b in contact_intervals(result, ci):
            b_eff = min(b, float(result.time[-1]))
            if b_eff > a:
                rows.append((ci, a, b, b_eff))
    if not rows:
        return []
    out = []
    weights = np.ones(n)
    weights[1:-1:2] = 4.0
    weights[2:-1:2] = 2.0
    for ci in {r[0] for r in rows}:
        c = result.contactors[ci]
        mine = [r for r in rows if r[0] == ci]
        ts = np.concatenate([np.linspace(a, be, n) for _, a, _, be in mine])
        wa = result.displacement([c.position], ts)[0].reshape(len(mine), n)
        force = c.stiffness * np.maximum(0.0, -(c.gap - c.direction * wa))
        for (_, a, b, be), fr in zip(mine, force):
            h = (be - a) / (n - 1)
            out.append(
                {
                    "contactor": ci,
                    "start": a,
                    "end": b if math.isfinite(b) else None,
                    "duration": (b - a) if math.isfinite(b) else None,
                    "peak_force": float(fr.max()),
                    "impulse": float(h / 3.0 * (weights @ fr)),
                }
            )
    out.sort(key=lambda d: (d["start"], d["contactor"]))
    return out
