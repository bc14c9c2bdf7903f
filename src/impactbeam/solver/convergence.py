"""Convergence in the number of modes: the error estimate, ``solver.modes = "auto"`` and the unconverged warning.

Modal truncation is the one approximation of the exact solver that the user
controls (paper section 2 used 4 modes free and 8 in contact). Every result
with ``N`` modes carries an **estimate of its truncation error** for each
Table-2 metric (:data:`CONVERGENCE_METRICS`) and for the peak force of every
impact: the largest change from the runs with the two largest counts up to
``3 N / 4`` on the ladder 1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128,
192 (for ``N`` on the ladder, the two counts before it: about ``N / 2`` and
``2 N / 3`` to ``3 N / 4``; :func:`coarser_counts`),

* a metric: ``|m_N - m_c| / scale`` with ``scale`` the larger magnitude of the
  two values (a displacement at least ``1e-6`` of the largest displacement
  metric and of the first contactor's gap, a time at least 1 ns); a metric
  defined at one count and undefined at the other counts as 1; ``t_max``
  counts as unchanged when ``max_response`` is zero to that floor in both
  runs (``u`` never positive: its largest value is the start's 0, reached
  again wherever ``u`` returns to 0, so its time is not a converging
  quantity);
* ``n_impacts``: the larger of the change of the count and the number of
  impacts without an overlapping impact of the same contactor in the other
  run (an impact that appears or vanishes with the modes), over the count;
* the peak force of an impact: ``|F_N - F_c| / max(F_N, F_c)`` against the
  impact of the same contactor whose contact interval overlaps it most, and
  1 when no impact overlaps it; at least the largest absolute change of the
  earlier impacts of that contactor over its own force (an impact starts
  from the state the earlier ones left, with their error).

What it guarantees, and where it does not. It is not a bound. It is the
error of the coarser run when the error falls at least by half from the
coarser counts to ``N``, which is how truncation behaves once ``N`` modes
resolve the contact (the enriched basis: errors fall as ``N^-2`` to ``N^-4``
for stiff stops). Comparing with two coarser counts guards against a
coarser run that happens to land near the answer. Where the error does not
fall with the modes (a quantity set by something else), where the
sequence of impacts changes with the count (chatter of a stiff stop, a
grazing contact: the error of a single impact is then of order 1 and so is
its estimate) and below the round-off of the basis, it says nothing. Measured
on the stiff and soft cases of the test suite against the finite-element
reference (tests/test_convergence.py, docs/convergence.md): never less than
half the error the finite elements resolve, and on average 3.6 to 13 times
it from 8 modes on.

``modes = "auto"`` runs :data:`AUTO_COUNTS` (the ladder from 4) in turn and
stops at the first count whose estimate is below ``solver.tolerance`` for
every Table-2 metric; the result reports the count (``result.n_modes``) and
its estimate (``result.convergence``), the same as a run with that fixed
count would.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = [
    "AUTO_COUNTS", "CONVERGENCE_METRICS", "LADDER", "NO_ESTIMATE", "UNSEEN_SHARE", "ConvergenceStudy", "can_decide",
    "coarser_counts", "estimate", "estimate_by_reruns", "impact_changes", "length_scale", "relative_changes",
    "unconverged_message", "unseen_flexibility", "worst",
]

#: The counts an estimate compares with: for ``N``, the two largest up to ``3 N / 4``.
LADDER = (1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128, 192)
#: Mode counts tried by ``solver.modes = "auto"``; the estimate of each compares it with the two before it.
AUTO_COUNTS = LADDER[3:]
#: The metrics whose estimate decides convergence (the paper's Table 2 quantities).
CONVERGENCE_METRICS = (
    "max_response", "t_max", "first_impact_time", "free_duration", "contact_duration", "min_response",
    "max_penetration", "n_impacts",
)
#: The warning of a run with one mode per state, which has no coarser run to compare with.
NO_ESTIMATE = ("no convergence estimate with 1 mode per state (no coarser run to compare with): the truncation "
               'error of the metrics is unknown; use more modes or solver.modes = "auto"')
_DISPLACEMENTS = ("max_response", "min_response", "max_penetration")
_TIME_FLOOR = 1e-9  # s
_DISPLACEMENT_FLOOR = 1e-6  # of the largest displacement metric


def coarser_counts(n: int) -> tuple[int, ...]:
    """The smaller mode counts a run with ``n`` modes is compared with: the two of :data:`LADDER` up to ``3 n / 4``.

    Parameters
    ----------
    n : int
        Modes per state of the run.
    """
    return tuple(c for c in LADDER if 4 * c <= 3 * n)[-2:]


#: A contactor with more than this share of its static flexibility outside the retained modes is out of the
#: estimate's sight (:func:`unseen_flexibility`).
UNSEEN_SHARE = 0.9


def unseen_flexibility(space: Any, n_modes: int) -> tuple[int, float] | None:
    """The contactor whose static flexibility the ``n_modes`` retained free modes carry least of, if under 10 %.

    The static flexibility at a contactor ``a`` is the exact static
    deflection there under a unit force there
    (:func:`~impactbeam.modal.static_state`); the modes carry
    ``sum_n W_n(a)^2 / omega_n^2`` of it (mass-normalised modes). The share
    is near 1 wherever the modes reach the contactor (Case 3: 0.99985 with 8
    modes; a stop at 0.01 L of a clamp: 0.22). Where a part of the beam is
    cut off from the rest (an overhang beyond a support rigid in deflection
    and rotation, whose own modes lie above the retained ones) the modes
    carry none of it: with the enriched basis the attachment shape alone
    reaches the contactor, at every smaller count too, so comparing with
    fewer modes sees no change while the missing modes change the answer
    (1.4 % in penetration); with the paper's basis nothing reaches it (a
    penetration of 1e-36 m for 2.3e-6 m). Then the run cannot be called
    converged, however small its estimate. A beam that can move as a rigid
    body has no static flexibility: None.

    Parameters
    ----------
    space : state space
        The run's (``solution.packed.space``, or the ``solve_ivp`` path's): its beam, contactors and free modes.
    n_modes : int
        Modes per state of the run.

    Returns
    -------
    (int, float) or None
        The contactor and the share outside the modes (above :data:`UNSEEN_SHARE`), or None.
    """
    from ..modal import static_state

    free = space.state(())
    omega = np.asarray(free.modes.omega, dtype=float)
    rows = np.asarray(free.W_contact, dtype=float)
    if not rows.size or free.modes.n_rigid:
        return None
    kept = np.argsort(omega, kind="stable")[:n_modes]
    modal = (rows[:, kept] ** 2 / omega[kept] ** 2).sum(axis=1)
    worst = None
    for c, contactor in enumerate(space.contactors):
        a = float(contactor.position)
        exact = float(static_state(space.beam, [a], [(a, 1.0)])[0][0])
        share = 1.0 - modal[c] / exact if exact > 0.0 else 0.0
        if share > UNSEEN_SHARE and (worst is None or share > worst[1]):
            worst = (c, float(share))
    return worst


def unconverged_message(n_modes: int, changes: Mapping[str, float], tolerance: float,
                        unseen: tuple[int, float] | None = None) -> str:
    """The warning of a run not converged in the number of modes (its largest estimate, or a contactor unseen).

    Parameters
    ----------
    n_modes : int
    changes : mapping of str -> float
        The run's estimate (:func:`estimate`).
    tolerance : float
        ``solver.tolerance``.
    unseen : (int, float), optional
        :func:`unseen_flexibility` of the run.
    """
    key, change = worst(changes)
    if unseen is not None:
        c, share = unseen
        return (f"not converged in the number of modes: {100 * share:.3g} % of the static flexibility at contactor "
                f"{c} lies outside the {n_modes} retained modes (only its attachment shape reaches it, at fewer "
                f"modes too), so the estimate ({key}: {change:.2g}) cannot see their error; use more modes or "
                'solver.modes = "auto"')
    return (f"not converged in the number of modes: with {n_modes} modes the estimated error of {key} is "
            f"{change:.2g} (relative; solver.tolerance = {tolerance:g}); use more modes or solver.modes = \"auto\"")


def can_decide(n: int) -> bool:
    """Whether the estimate of a run with ``n`` modes may decide convergence: both its coarser counts are
    among :data:`AUTO_COUNTS` (4 modes or more; ``modes = "auto"`` stops on no estimate against 2 or 3 modes,
    so from 8 modes on along its ladder, and :attr:`ConvergenceStudy.converged_count` follows the same rule).

    Parameters
    ----------
    n : int
        Modes per state of the run.
    """
    counts = coarser_counts(n)
    return bool(counts) and all(c in AUTO_COUNTS for c in counts)


def _intervals(impacts: Sequence[Mapping[str, Any]]) -> list[tuple[int, float, float, float]]:
    """``(contactor, start, end, peak_force)`` of each impact; a contact still under way ends at inf."""
    return [(int(r["contactor"]), float(r["start"]), math.inf if r["end"] is None else float(r["end"]),
             float(r["peak_force"])) for r in impacts]


def _partners(a: Sequence[tuple[int, float, float, float]], b: Sequence[tuple[int, float, float, float]]) -> list[int]:
    """For each impact of ``a``, the impact of ``b`` (same contactor) whose interval overlaps it most, or -1."""
    out = []
    for c, s, e, _ in a:
        best, most = -1, 0.0
        for j, (c2, s2, e2, _) in enumerate(b):
            if c2 == c:
                overlap = min(e, e2) - max(s, s2)
                if overlap > most or (overlap == most == 0.0 and s == s2):
                    best, most = j, overlap
        out.append(best)
    return out


def impact_changes(new: Sequence[Mapping[str, Any]], old: Sequence[Mapping[str, Any]]) -> np.ndarray:
    """Relative change of the peak force of each impact of ``new`` against ``old`` (1 without a partner).

    Parameters
    ----------
    new, old : sequence of mapping
        Per-impact rows (``contactor``, ``start``, ``end``, ``peak_force``), as in ``result.metrics()["impacts"]``.
    """
    a, b = _intervals(new), _intervals(old)
    out = np.ones(len(a))
    for i, j in enumerate(_partners(a, b)):
        if j >= 0:
            fa, fb = a[i][3], b[j][3]
            scale = max(abs(fa), abs(fb))
            out[i] = abs(fa - fb) / scale if scale > 0 else 0.0
    return out


def _unmatched(new: Sequence[Mapping[str, Any]], old: Sequence[Mapping[str, Any]]) -> int:
    """Impacts of either run with no overlapping impact of the same contactor in the other."""
    a, b = _intervals(new), _intervals(old)
    return sum(j < 0 for j in _partners(a, b)) + sum(j < 0 for j in _partners(b, a))


def relative_changes(new: Mapping[str, Any], old: Mapping[str, Any], length: float = 0.0) -> dict[str, float]:
    """Relative change of each convergence metric from ``old`` to ``new`` (see the module docstring).

    Parameters
    ----------
    new, old : mapping
        Metrics (``result.metrics()``); with an ``"impacts"`` list in both,
        ``n_impacts`` also counts the impacts that appear or vanish.
    length : float, [m]
        A length the displacements are also measured against: the first
        contactor's gap (:func:`length_scale`).
    """
    disp = max(max((abs(new[k]) for k in _DISPLACEMENTS if new.get(k) is not None), default=0.0), length)
    floor = _DISPLACEMENT_FLOOR * disp
    flat = all(m.get("max_response") is not None and abs(m["max_response"]) <= floor for m in (new, old))
    out: dict[str, float] = {}
    for key in CONVERGENCE_METRICS:
        a, b = new.get(key), old.get(key)
        if a is None and b is None:
            out[key] = 0.0
            continue
        if a is None or b is None:
            out[key] = 1.0
            continue
        change = 0.0 if (key == "t_max" and flat) else abs(a - b)
        scale = max(abs(a), abs(b))
        if key == "n_impacts":
            if "impacts" in new and "impacts" in old:
                change = max(change, _unmatched(new["impacts"], old["impacts"]))
            scale = max(scale, 1.0)
        elif key in _DISPLACEMENTS:
            scale = max(scale, floor)
        else:
            scale = max(scale, _TIME_FLOOR)
        out[key] = change / scale if scale > 0 else (0.0 if change == 0 else math.inf)
    return out


def length_scale(contactors: Sequence[Any]) -> float:
    """The length the displacement metrics' changes are also measured against: the first contactor's gap.

    Parameters
    ----------
    contactors : sequence of Contactor
    """
    return float(contactors[0].gap) if contactors else 0.0


def estimate(new: Mapping[str, Any], coarser: Sequence[Mapping[str, Any]],
             length: float = 0.0) -> tuple[dict[str, float], np.ndarray]:
    """The error estimate of a run from runs with fewer modes: per metric, and per impact's peak force.

    Parameters
    ----------
    new : mapping
        Metrics of the run (``result.metrics()``, with ``"impacts"``).
    coarser : sequence of mapping
        Metrics of the runs with fewer modes (at least one).
    length : float, [m]
        :func:`length_scale` of the run's contactors.

    Returns
    -------
    metrics : dict of str -> float
        The largest relative change of each Table-2 metric.
    peak_forces : ndarray, (n_impacts,)
        The largest relative change of each impact's peak force.
    """
    changes = [relative_changes(new, old, length) for old in coarser]
    metrics = {key: max(c[key] for c in changes) for key in CONVERGENCE_METRICS}
    impacts = new.get("impacts") or []
    peaks = np.zeros(len(impacts))
    for old in coarser:
        peaks = np.maximum(peaks, impact_changes(impacts, old.get("impacts") or []))
    # an impact inherits the absolute uncertainty of the earlier impacts of its contactor: the state it
    # starts from carries their error (in a chattering sequence a small sub-impact that all the runs
    # share can still be absent from the converged one)
    force = np.abs(np.array([float(r["peak_force"]) for r in impacts]))
    for c in {int(r["contactor"]) for r in impacts}:
        at = np.flatnonzero([int(r["contactor"]) == c for r in impacts])
        carried = np.maximum.accumulate(peaks[at] * force[at])
        with np.errstate(divide="ignore", invalid="ignore"):
            peaks[at] = np.maximum(peaks[at], np.where(force[at] > 0, np.minimum(1.0, carried / force[at]), 0.0))
    return metrics, peaks


def estimate_by_reruns(metrics: Mapping[str, Any], rerun: Callable[..., Any], n_modes: int, end_time: float,
                       progress: Callable[[float], None] | None = None, length: float = 0.0
                       ) -> tuple[dict[str, float], np.ndarray, tuple[int, ...]]:
    """:func:`estimate` of a run with ``n_modes`` modes against its re-runs at :func:`coarser_counts`.

    Parameters
    ----------
    metrics : mapping
        The run's own metrics (with its per-impact table).
    rerun : callable
        ``rerun(n)`` repeats the run with ``n`` modes (``rerun(n, report=f)``
        with a progress callback ``f(t)`` of the simulated time when
        ``progress`` is given).
    n_modes : int
    end_time : float, [s]
    progress : callable, optional
        Called with the re-runs done so far (fractions within one by its
        simulated time).
    length : float, [m]
        :func:`length_scale` of the run's contactors.

    Returns
    -------
    changes : dict
    peak_changes : ndarray
    counts : tuple of int
    """
    from .._warnings import WarningLog

    counts = coarser_counts(n_modes)
    coarse = []
    for i, c in enumerate(counts):
        with WarningLog():  # the coarser runs' warnings (their initial projection, ...) are not this run's
            if progress is None:
                res = rerun(c)
            else:
                res = rerun(c, report=lambda t, i=i: progress(i + t / end_time))
            coarse.append(res.metrics())
    changes, peaks = estimate(metrics, coarse, length)
    return changes, peaks, counts


def worst(changes: Mapping[str, float]) -> tuple[str, float]:
    """The metric with the largest estimate.

    Parameters
    ----------
    changes : mapping of str -> float
    """
    key = max(changes, key=lambda k: changes[k])
    return key, changes[key]


@dataclass(frozen=True)
class ConvergenceStudy:
    """The Table-2 metrics of one scenario against the number of modes, each with its error estimate.

    Attributes
    ----------
    name : str
        The scenario's name.
    counts : tuple of int
        Modes per state of the runs shown, ascending.
    functions : dict of int -> int
        Functions per state of each run (the enriched basis adds attachment
        shapes and, for stiff stops, more: :mod:`~impactbeam.solver.ritz`).
    metrics : dict of int -> dict
        The metrics of each run (SI, None where undefined).
    estimates : dict of int -> dict or None
        The estimated relative error of each metric (None where a coarser
        count is missing: the smallest counts).
    peak_forces : dict of int -> list of float
        Each run's impacts' peak forces [N].
    peak_force_estimates : dict of int -> list of float or None
        Their estimated relative errors.
    tolerance : float
        ``solver.tolerance`` of the scenario.
    unseen : dict of int -> (int, float) or None
        Each run's contactor out of its modes' reach (:func:`unseen_flexibility`), or None.
    """

    name: str
    counts: tuple[int, ...]
    functions: dict[int, int]
    metrics: dict[int, dict[str, Any]]
    estimates: dict[int, dict[str, float] | None]
    peak_forces: dict[int, list[float]] = field(default_factory=dict)
    peak_force_estimates: dict[int, list[float] | None] = field(default_factory=dict)
    tolerance: float = 2e-3
    unseen: dict[int, tuple[int, float] | None] = field(default_factory=dict)

    @property
    def converged_count(self) -> int | None:
        """The smallest count whose every Table-2 estimate is below the tolerance (None if none is).

        Only counts whose estimate may decide (:func:`can_decide`) and whose modes reach every contactor
        (:attr:`unseen`): the count ``modes = "auto"`` would stop at.
        """
        for n in self.counts:
            est = self.estimates.get(n)
            if (est is not None and can_decide(n) and max(est.values()) < self.tolerance
                    and self.unseen.get(n) is None):
                return n
        return None

    def as_dict(self) -> dict[str, Any]:
        """The study as plain data (the ``--json`` of ``impactbeam convergence``).

        Keys: ``scenario``, ``tolerance``, ``metrics`` (the Table-2 names),
        ``converged_modes`` (:attr:`converged_count`), ``runs``: one per count,
        ``{"modes", "functions", "values": {metric: value}, "estimates":
        {metric: relative error} or null, "peak_force": {"max": N,
        "max_estimate": relative error of the largest impact's peak force,
        "worst_estimate": largest over the impacts} or null}``.
        """
        runs = []
        for n in self.counts:
            forces = self.peak_forces.get(n) or []
            pest = self.peak_force_estimates.get(n)
            peak = None
            if forces:
                j = int(np.argmax(forces))
                peak = {"max": float(forces[j]),
                        "max_estimate": None if pest is None else float(pest[j]),
                        "worst_estimate": None if pest is None else float(max(pest))}
            runs.append({
                "modes": n,
                "functions": self.functions[n],
                "values": {k: self.metrics[n].get(k) for k in CONVERGENCE_METRICS},
                "estimates": self.estimates.get(n),
                "peak_force": peak,
            })
        return {"scenario": self.name, "tolerance": self.tolerance, "metrics": list(CONVERGENCE_METRICS),
                "converged_modes": self.converged_count, "runs": runs}
