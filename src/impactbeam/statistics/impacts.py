"""Impact statistics per contactor, from the exact events of any run.

Every quantity comes from the exact solution: contact intervals are the
exact impact and rebound times (not a threshold on samples), peak forces are
maxima of the closed form, impulses its integrals. The definitions follow
code_aster's post-processing of modal transients with shocks
(``POST_DYNA_MODA_T``, options ``USURE`` and ``IMPACT``; Code_Aster
Reference Manual R7.10.02), over the analysis window ``[lo, hi]`` of
duration ``T`` (:func:`~impactbeam.statistics.window.analysis_window`):

* ``n_impacts``: contact intervals that begin in the window; ``rate``
  ``= n_impacts / T`` [1/s] (code_aster's shocks per second);
* ``contact_time`` [s], ``contact_fraction = contact_time / T``;
* ``force_mean``, ``force_rms`` [N]: mean and RMS of the contact force over the
  total time (``MOYEN_T_TOTAL``, ``RMS_T_TOTAL``), ``force_rms_contact`` over the
  contact time only (``RMS_T_CHOC``);
* per impact (contacts that begin and end in the window, ``n_complete`` of them): peak force,
  impulse ``int F dt``, duration, impact and exit velocity, apparent
  restitution ``-v_out / v_in``; over the impacts ``peak_force_mean``,
  ``peak_force_max``, ``peak_force_std`` (``F_MAX_MOY``, ``F_MAX_ABS``,
  ``F_MAX_ETYPE``), ``duration_mean`` (``T_CHOC_MOYEN``), ``impulse_mean``,
  ``impact_velocity_mean``, ``restitution_mean``;
* ``work_rate`` [W]: the mean of ``|F v|`` over the contact time (the power
  the contact exchanges; with friction it would be Archard's wear power).

The contact force is :meth:`~impactbeam.model.beam.Contactor.force`,
``max(k d + c d', 0)`` (``c`` the contactor's dashpot); peak forces and
impulses are those of the result's impact table
(:func:`~impactbeam.result.metrics.contact_forces`). ``F^2`` and
``|F v|`` are integrated by Gauss-Legendre quadrature on each side of the
deepest compression (where ``|F v|`` has its kink), of every event (with
per-state modes, of every segment: :func:`~impactbeam.result.timegrid.cuts`)
and, with per-state modes, where the force changes sign
(:func:`~impactbeam.result.metrics.pushing_parts`), with panels of one
period of the highest retained frequency and 8 nodes each: exact for
polynomials of degree 15, so within 1e-5 for a sinusoid at that frequency
(``pi^16 / 16!``) and much closer for the lower modes that carry the force.
A state that decays faster than that (an over-damped coordinate: a stiff
dashpot, damping above critical) gets shorter panels where its transients
start (:func:`~impactbeam.result.timegrid.gauss_panels`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..result.metrics import contact_forces, pushing_parts
from ..result.timegrid import cuts, gauss_panels, gauss_rule, per_state, solution_rates
from .window import analysis_window

__all__ = ["ImpactStatistics", "impact_statistics", "IMPACT_UNITS"]

#: Units of the per-contactor impact statistics.
IMPACT_UNITS = {
    "n_impacts": "1", "n_complete": "1", "rate": "1/s", "contact_time": "s", "contact_fraction": "1", "force_mean": "N",
    "force_rms": "N", "force_rms_contact": "N", "peak_force_mean": "N", "peak_force_max": "N",
    "peak_force_std": "N", "duration_mean": "s", "impulse_mean": "N s", "impact_velocity_mean": "m/s",
    "restitution_mean": "1", "work_rate": "W",
}


@dataclass(frozen=True)
class ImpactStatistics:
    """Impacts of a run over its analysis window (module docstring).

    Attributes
    ----------
    impacts : list of dict
        One per contact that begins and ends in the window: ``contactor``,
        ``start``, ``end`` [s], ``duration`` [s], ``impact_velocity``,
        ``exit_velocity`` [m/s] (toward the stop positive), ``restitution``,
        ``peak_force`` [N], ``impulse`` [N s].
    contactors : list of dict
        Per contactor: ``contactor`` and the keys of :data:`IMPACT_UNITS`
        (``impacts_per_forcing_period`` too for a steady state). Means over no
        impact are NaN.
    duration : float, [s]
        Length ``T`` of the window.
    window : (float, float), [s]
    warnings : list of str
        Those of the steady state, when the statistics are of one.
    """

    impacts: list[dict[str, Any]] = field(default_factory=list)
    contactors: list[dict[str, Any]] = field(default_factory=list)
    duration: float = 0.0
    window: tuple[float, float] = (0.0, 0.0)
    warnings: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """Plain values for JSON: ``window``, ``duration``, ``contactors``, ``impacts``, ``warnings``."""
        return {"window": list(self.window), "duration": self.duration, "contactors": self.contactors,
                "impacts": self.impacts, "warnings": list(self.warnings)}


def _intervals(events: list, ci: int, t_end: float) -> list[tuple[float, float, float, float]]:
    """(start, end, entry w_t, exit w_t) of contactor ``ci``'s contacts; end = t_end and exit NaN if open."""
    out = []
    entry: tuple[float, float] | None = None
    for e in events:
        if e.contactor != ci:
            continue
        if e.kind == "impact":
            entry = (e.time, e.velocity)
        elif entry is not None:
            out.append((entry[0], e.time, entry[1], e.velocity))
            entry = None
    if entry is not None and entry[0] < t_end:
        out.append((entry[0], t_end, entry[1], math.nan))
    return out


def _contactor(result: Any, ci: int, lo: float, hi: float, panel: float,
               decay: float) -> tuple[dict[str, Any], list[dict]]:
    """Summary and per-impact rows of contactor ``ci`` over ``[lo, hi]``."""
    sol = result.solution
    c = result.contactors[ci]
    s = c.direction
    dash = float(getattr(sol, "dashpots", np.zeros(ci + 1))[ci])
    all_iv = _intervals(result.events, ci, sol.t_end)
    started = [iv for iv in all_iv if lo <= iv[0] < hi]
    clipped = [(max(a, lo), min(b, hi)) for a, b, _, _ in all_iv if b > lo and a < hi]
    T = hi - lo
    f1 = f2 = fv = t_contact = 0.0
    if clipped:
        a = np.array([r[0] for r in clipped])
        b = np.array([r[1] for r in clipped])
        ext = sol.extrema([(c.position, ai, bi, s, -s * c.gap, ci) for ai, bi in zip(a, b)])
        tp = np.clip(np.nan_to_num(ext[:, 1], nan=0.5 * (a + b)), a, b)
        # panels end at the deepest compression and where a derivative or (per-state modes) the state jumps
        at = cuts(result, float(a.min()), float(b.max()))
        edges = np.unique(np.concatenate([a, tp, b, at]))
        if per_state(result):  # and where a projection left the force pulling: its sign changes
            edges = np.unique(np.concatenate([edges] + [np.ravel(pushing_parts(result, ci, ai, bi))
                                                        for ai, bi in zip(a, b)]))
        inside = [edges[(edges >= ai) & (edges <= bi)] for ai, bi in zip(a, b)]
        nodes, weights = gauss_rule(*gauss_panels(np.concatenate([e[:-1] for e in inside]),
                                                  np.concatenate([e[1:] for e in inside]), panel, decay))
        smp = sol.sample(np.array([c.position]), nodes)
        force = c.force(smp.w[:, 0], smp.w_t[:, 0], dash)
        f2 = float(np.sum(weights * force**2))
        fv = float(np.sum(weights * np.abs(force * smp.w_t[:, 0])))
        f1 = float(np.sum(contact_forces(result, [(ci, ai, bi) for ai, bi in zip(a, b)])[1]))
        t_contact = float(np.sum(b - a))
    rows: list[dict[str, Any]] = []
    whole = [iv for iv in started if iv[1] <= hi and math.isfinite(iv[3])]
    if whole:
        a = np.array([r[0] for r in whole])
        b = np.array([r[1] for r in whole])
        peaks, impulses = contact_forces(result, [(ci, ai, bi) for ai, bi in zip(a, b)])
        for (ta, tb, vin, vout), pk, imp in zip(whole, peaks, impulses):
            v_in, v_out = s * vin, s * vout
            rows.append({
                "contactor": ci, "start": ta, "end": tb, "duration": tb - ta, "impact_velocity": v_in,
                "exit_velocity": v_out, "restitution": -v_out / v_in if v_in != 0.0 else math.nan,
                "peak_force": float(pk), "impulse": float(imp),
            })

    def over(key: str, fn: Any = np.mean) -> float:
        return float(fn([r[key] for r in rows])) if rows else math.nan

    summary = {
        "contactor": ci, "n_impacts": len(started), "n_complete": len(rows), "rate": len(started) / T, "contact_time": t_contact,
        "contact_fraction": t_contact / T, "force_mean": f1 / T, "force_rms": math.sqrt(f2 / T),
        "force_rms_contact": math.sqrt(f2 / t_contact) if t_contact > 0 else math.nan,
        "peak_force_mean": over("peak_force"), "peak_force_max": over("peak_force", np.max),
        "peak_force_std": over("peak_force", np.std), "duration_mean": over("duration"),
        "impulse_mean": over("impulse"), "impact_velocity_mean": over("impact_velocity"),
        "restitution_mean": over("restitution"), "work_rate": fv / t_contact if t_contact > 0 else math.nan,
    }
    return summary, rows


def impact_statistics(run: Any, window: tuple[float, float] | None = None) -> ImpactStatistics:
    """Impact statistics per contactor of a run (module docstring).

    Parameters
    ----------
    run : SimulationResult or SteadyState
        A simulation result (statistics over
        :func:`~impactbeam.statistics.window.analysis_window`), or a steady
        state of :func:`impactbeam.steady_state` / a bifurcation point
        (over its recorded periods; ``impacts_per_forcing_period`` is added).
    window : (float, float), optional, [s]
        Override the window.

    Returns
    -------
    ImpactStatistics
    """
    steady = hasattr(run, "result") and hasattr(run, "window")
    result = run.result if steady else run
    if not hasattr(result, "solution") or not hasattr(result, "contactors"):
        raise TypeError(f"impact_statistics: expected a SteadyState or a SimulationResult, got {type(run).__name__}")
    lo, hi = analysis_window(result, run.window if steady and window is None else window)
    omega, decay = solution_rates(result)
    panel = 2.0 * math.pi / max(omega, 1e-300)  # one period of the highest mode
    per, impacts = [], []
    for ci in range(len(result.contactors)):
        summary, rows = _contactor(result, ci, lo, hi, panel, decay)
        if steady:
            summary["impacts_per_forcing_period"] = summary["n_impacts"] / (hi - lo) / float(run.frequency)
        per.append(summary)
        impacts.extend(rows)
    impacts.sort(key=lambda r: (r["start"], r["contactor"]))
    return ImpactStatistics(impacts, per, hi - lo, (lo, hi), list(getattr(run, "warnings", ())) if steady else [])
