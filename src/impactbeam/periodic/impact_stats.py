"""Per-impact statistics over a recorded steady state.

For every contact interval that begins and ends inside the record, and for
each contactor:

* impact velocity ``v_in`` [m/s]: ``w_t`` at the contactor when it engages,
  counted positive toward the stop (``s w_t``, ``s = +1`` above, ``-1`` below);
* apparent coefficient of restitution ``e = -v_out / v_in`` (exit over entry
  velocity at the contactor; not a material constant: the contactor is a
  spring and the beam flexes);
* peak force [N] and impulse [N s] (exact, closed form, as
  :mod:`impactbeam.result.metrics`);
* over the record: mean and RMS contact force [N] (time averages over the
  record, zero while open), and the impact work rate [W], the mean of
  ``|F v|`` over the time in contact; ``F^2`` and ``|F v|`` are integrated
  by Gauss-Legendre quadrature (32 panels of 8 points, which resolve the
  highest retained mode) on each side of the
  deepest compression, where they are smooth (``|F v|`` has its kink
  there), so to round-off for the closed-form deflection.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from ..result import SimulationResult
    from .strobe import SteadyState

__all__ = ["ImpactStatistics", "impact_statistics"]

_PANELS, _NODES = 32, 8


@dataclass(frozen=True)
class ImpactStatistics:
    """Impacts of a steady state.

    Attributes
    ----------
    impacts : list of dict
        One per contact interval in the record: ``contactor``, ``start``,
        ``end`` [s], ``impact_velocity``, ``exit_velocity`` [m/s] (toward the
        stop positive), ``restitution``, ``peak_force`` [N], ``impulse`` [N s].
    contactors : list of dict
        Per contactor: ``n_impacts``, ``impacts_per_forcing_period``, the mean
        of ``impact_velocity``, ``restitution``, ``peak_force`` and ``impulse``
        over its impacts, ``mean_force``, ``rms_force`` [N] over the record and
        ``work_rate`` [W] (mean ``|F v|`` in contact).
    duration : float, [s]
        Length of the record.
    warnings : list of str
        Those of the steady state (e.g. no period found: the averages are
        over a record that may not be a steady state) or of the run.
    """

    impacts: list[dict[str, Any]] = field(default_factory=list)
    contactors: list[dict[str, Any]] = field(default_factory=list)
    duration: float = 0.0
    warnings: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {"duration": self.duration, "contactors": self.contactors, "impacts": self.impacts,
                "warnings": list(self.warnings)}


def _intervals(events: list, ci: int, lo: float, hi: float) -> list[tuple[float, float, float, float]]:
    """(start, end, entry w_t, exit w_t) of contactor ``ci``'s contacts inside [lo, hi]."""
    out = []
    entry: tuple[float, float] | None = None
    for e in events:
        if e.contactor != ci:
            continue
        if e.kind == "impact":
            entry = (e.time, e.velocity)
        elif entry is not None:
            if entry[0] >= lo and e.time <= hi:
                out.append((entry[0], e.time, entry[1], e.velocity))
            entry = None
    return out


def _quadrature(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of composite Gauss-Legendre on each [a_i, b_i]: arrays (n, P*Q)."""
    xg, wg = np.polynomial.legendre.leggauss(_NODES)
    edges = np.linspace(0.0, 1.0, _PANELS + 1)
    u = ((edges[:-1, None] + edges[1:, None]) / 2 + (edges[1:, None] - edges[:-1, None]) / 2 * xg[None, :]).ravel()
    wu = np.tile(wg / 2 / _PANELS, _PANELS)
    h = (b - a)[:, None]
    return a[:, None] + h * u[None, :], h * wu[None, :]


def _record(run: Any) -> tuple[Any, tuple[float, float], float, list[str]]:
    """The result, window, forcing period (NaN without one) and warnings of a steady state or a transient."""
    if hasattr(run, "window") and hasattr(run, "result"):  # a SteadyState
        return run.result, tuple(run.window), 1.0 / run.frequency, list(run.warnings)
    if hasattr(run, "solution") and hasattr(run, "contactors") and hasattr(run, "events"):  # a SimulationResult
        if not hasattr(run.solution, "extrema"):
            raise TypeError('impact_statistics: the result of method = "ivp" has no exact extrema; '
                            'simulate with method = "exact"')
        ex = getattr(getattr(run, "scenario", None), "excitation", None)
        f = ex.frequency if ex is not None and ex.shape == "harmonic" and ex.frequency else None
        return run, (0.0, float(run.solution.t_end)), (1.0 / f if f else math.nan), list(run.warnings)
    raise TypeError(f"impact_statistics: expected a SteadyState or a SimulationResult, got {type(run).__name__}")


def impact_statistics(steady: SteadyState | SimulationResult) -> ImpactStatistics:
    """Per-impact statistics of a recorded steady state or of a whole transient run (module docstring).

    Parameters
    ----------
    steady : SteadyState or SimulationResult
        From :func:`~impactbeam.periodic.strobe.steady_state` or a bifurcation
        point (the record window), or from :func:`impactbeam.simulate` (the
        whole run; ``impacts_per_forcing_period`` is NaN unless the load is
        harmonic).

    Returns
    -------
    ImpactStatistics

    Raises
    ------
    TypeError
        For anything else, or a result of ``method = "ivp"``.
    """
    res, (lo, hi), T, warnings = _record(steady)
    sol = res.solution
    duration = hi - lo
    impacts: list[dict[str, Any]] = []
    per: list[dict[str, Any]] = []
    for ci, c in enumerate(res.contactors):
        s = c.direction
        iv = _intervals(res.events, ci, lo, hi)
        rows: list[dict[str, Any]] = []
        f2 = fv = t_contact = 0.0
        if iv:
            a = np.array([r[0] for r in iv])
            b = np.array([r[1] for r in iv])
            ext = sol.extrema([(c.position, ai, bi, s, -s * c.gap, ci) for ai, bi in zip(a, b)])
            peaks, tp = ext[:, 0], np.clip(np.nan_to_num(ext[:, 1], nan=0.5 * (a + b)), a, b)
            ints = sol.integrals([(c.position, ai, bi) for ai, bi in zip(a, b)])
            n1, w1 = _quadrature(a, tp)
            n2, w2 = _quadrature(tp, b)
            nodes, weights = np.hstack([n1, n2]), np.hstack([w1, w2])
            smp = sol.sample(np.array([c.position]), nodes.ravel())
            force = c.stiffness * np.maximum(s * smp.w[:, 0] - c.gap, 0.0).reshape(nodes.shape)
            vel = smp.w_t[:, 0].reshape(nodes.shape)
            f2 = float(np.sum(weights * force**2))
            fv = float(np.sum(weights * np.abs(force * vel)))
            t_contact = float(np.sum(b - a))
            for (ta, tb, vin, vout), pk, iw in zip(iv, peaks, ints):
                v_in, v_out = s * vin, s * vout
                rows.append({
                    "contactor": ci, "start": ta, "end": tb, "impact_velocity": v_in, "exit_velocity": v_out,
                    "restitution": -v_out / v_in if v_in != 0.0 else math.nan,
                    "peak_force": c.stiffness * max(float(pk), 0.0),
                    "impulse": c.stiffness * (s * float(iw) - c.gap * (tb - ta)),
                })
        impacts.extend(rows)

        def mean(key: str) -> float:
            return float(np.mean([r[key] for r in rows])) if rows else math.nan

        total_impulse = float(sum(r["impulse"] for r in rows))
        per.append({
            "contactor": ci, "n_impacts": len(rows), "impacts_per_forcing_period": len(rows) * T / duration,
            "impact_velocity": mean("impact_velocity"), "restitution": mean("restitution"),
            "peak_force": mean("peak_force"), "impulse": mean("impulse"),
            "mean_force": total_impulse / duration, "rms_force": math.sqrt(f2 / duration),
            "work_rate": fv / t_contact if t_contact > 0 else math.nan,
        })
    impacts.sort(key=lambda r: (r["start"], r["contactor"]))
    return ImpactStatistics(impacts, per, duration, warnings)
