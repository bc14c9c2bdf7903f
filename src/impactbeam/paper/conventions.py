"""The response as the paper reads it (section 3.1): deflection from the contactor surface, peaks per
cycle, contact intervals (:class:`PaperMetrics`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..result.timegrid import scan_times
from .data import SPECIMEN

if TYPE_CHECKING:
    from ..result import SimulationResult

__all__ = ["PaperMetrics", "paper_metrics"]


@dataclass(frozen=True)
class PaperMetrics:
    """Response metrics on the paper's deflection ``d`` (from the contactor surface, positive away).

    All SI; NaN where undefined. ``d = u + c`` with the contactor (``u`` the
    project's metric deflection, from rest); ``d = -w(a)`` without one.

    Attributes
    ----------
    max_response : float, [m]
        Maximum of ``d`` (the first peak: the beam first moves away).
    t_max : float, [s]
    free_duration : float, [s]
        The free interval containing ``t_max`` (project metric).
    min_response : float, [m]
        Minimum of ``d`` in the first contact after ``t_max`` (negative:
        penetration); without contactor the first negative peak after ``t_max``.
    contact_duration : float, [s]
        The first contact interval after ``t_max``.
    first_impact_time : float, [s]
    n_impacts : int
        Contact intervals begun in the run.
    total_contact_time : float, [s]
        Sum of all contact intervals (clipped at the end of the run).
    cycle_time : float, [s]
        Time between the starts of the first two impact cycles; a cycle is a
        group of impacts separated by free flights shorter than a quarter of
        the free-state fundamental period.
    impacts_per_cycle : int
        Largest number of impacts in one cycle.
    contact_fraction : float
        Contact time within the first cycle divided by the cycle time.
    rebound_response : float, [m]
        Maximum of ``d`` after the first rebound.
    negative_lobe_duration : float, [s]
        Without contactor: duration of the first interval with ``d < 0`` after
        ``t_max`` (the paper's "time period in the first negative peak").
    gap : float, [m]
    max_response_rest, min_response_rest : float, [m]
        The project metrics ``u`` (from rest), for reference.
    open_engaged_time : float, [s]
        Consistency check: time during which the solver reports the contactor
        engaged while the gap function is open by more than 0.1 um (zero for a
        correct run: engaged means ``d <= 0``; with the paper's basis a
        projection can leave it open for microseconds), on the exact solution.
    """

    max_response: float
    t_max: float
    free_duration: float
    min_response: float
    contact_duration: float
    first_impact_time: float
    n_impacts: int
    total_contact_time: float
    cycle_time: float
    impacts_per_cycle: int
    contact_fraction: float
    rebound_response: float
    negative_lobe_duration: float
    gap: float
    max_response_rest: float
    min_response_rest: float
    open_engaged_time: float = 0.0

    def as_dict(self) -> dict[str, float]:
        """Field name -> value."""
        return {k: getattr(self, k) for k in self.__dataclass_fields__}


def _num(x: Any) -> float:
    return float("nan") if x is None else float(x)


def _cycles(intervals: Sequence[tuple[float, float]], min_flight: float) -> list[list[tuple[float, float]]]:
    groups: list[list[tuple[float, float]]] = []
    for a, b in intervals:
        if groups and a - groups[-1][-1][1] < min_flight:
            groups[-1].append((a, b))
        else:
            groups.append([(a, b)])
    return groups


def paper_metrics(result: SimulationResult, *, free_period: float | None = None) -> PaperMetrics:
    """The paper's metrics of one run (see :class:`PaperMetrics`).

    Parameters
    ----------
    result : SimulationResult
        With a contactor, the metrics are those of its first contactor;
        without one, of the output point nearest 0.4840 L.
    free_period : float, optional, [s]
        Free-state fundamental period used to group impacts into cycles
        (default: computed from the result's beam).
    """
    from ..result.metrics import contact_intervals
    from ..modal import mode_set

    m = result.metrics()
    t_end = float(result.time[-1])
    nan = float("nan")
    if len(result.contactors):
        c = result.contactors[0]
        gap = c.gap
        iv = contact_intervals(result, 0)
        if free_period is None:
            free_period = 1.0 / float(mode_set(result.beam, (), 1).frequencies_hz[-1])
        groups = _cycles(iv, 0.25 * free_period)
        total = sum(min(b, t_end) - a for a, b in iv)
        cycle = groups[1][0][0] - groups[0][0][0] if len(groups) > 1 else nan
        if len(groups) > 1:
            in_first = sum(min(b, t_end) - a for a, b in groups[0])
            fraction = in_first / cycle
        else:
            fraction = nan
        if iv and math.isfinite(iv[0][1]) and iv[0][1] < t_end:  # the largest d after the first contact, exact
            ext = result.solution.extrema([(c.position, float(iv[0][1]), t_end, -c.direction, -c.direction * gap,
                                            None)])
            rebound = float(ext[0, 0])
        else:
            rebound = nan
        open_engaged = _open_while_engaged(result, c, iv, t_end)
        return PaperMetrics(
            open_engaged_time=open_engaged,
            max_response=_num(m["max_response"]) + gap,
            t_max=_num(m["t_max"]),
            free_duration=_num(m["free_duration"]),
            min_response=_num(m["min_response"]) + gap,
            contact_duration=_num(m["contact_duration"]),
            first_impact_time=_num(m["first_impact_time"]),
            n_impacts=int(m["n_impacts"] or 0),
            total_contact_time=float(total),
            cycle_time=float(cycle),
            impacts_per_cycle=max((len(g) for g in groups), default=0),
            contact_fraction=float(fraction),
            rebound_response=rebound,
            negative_lobe_duration=nan,
            gap=gap,
            max_response_rest=_num(m["max_response"]),
            min_response_rest=_num(m["min_response"]),
        )
    # no contactor: d = -w at the output point nearest 0.4840 L, on the exact solution (not the output grid)
    a = SPECIMEN["contact_position_ratio"] * result.beam.length
    x = float(np.asarray(result.points)[int(np.argmin(np.abs(np.asarray(result.points) - a)))])
    sol = result.solution
    top, t_top = (float(v) for v in sol.extrema([(x, 0.0, t_end, -1.0, 0.0, None)])[0])
    lowest = -float(sol.extrema([(x, 0.0, t_end, 1.0, 0.0, None)])[0, 0])
    lobe_min, lobe = nan, nan
    tg = scan_times(result, t_top, t_end, breaks=False)  # locates the lobe's crossings; brentq refines them
    d = -result.displacement([x], tg)[0]
    neg = np.nonzero(d < 0.0)[0]
    if neg.size:
        i0 = int(neg[0])
        back = np.nonzero(d[i0:] >= 0.0)[0]
        down = _crossing(result, x, tg, d, i0)
        up = _crossing(result, x, tg, d, i0 + int(back[0])) if back.size else t_end
        lobe_min = -float(sol.extrema([(x, down, up, 1.0, 0.0, None)])[0, 0])
        lobe = up - down if back.size else nan
    return PaperMetrics(
        max_response=top, t_max=t_top, free_duration=nan, min_response=lobe_min,
        contact_duration=nan, first_impact_time=nan, n_impacts=0, total_contact_time=0.0, cycle_time=nan,
        impacts_per_cycle=0, contact_fraction=nan, rebound_response=nan, negative_lobe_duration=float(lobe),
        gap=0.0, max_response_rest=top, min_response_rest=lowest,
    )


def _crossing(result: SimulationResult, x: float, t: np.ndarray, d: np.ndarray, i: int) -> float:
    """The zero of ``d = -w(x)`` between samples ``i - 1`` and ``i`` of ``t``, on the exact solution."""
    from scipy.optimize import brentq

    if i == 0 or d[i] == 0.0:
        return float(t[i])
    return float(brentq(lambda s: float(result.displacement([x], [s])[0, 0]), float(t[i - 1]), float(t[i]),
                        xtol=1e-15))


def _open_while_engaged(result: SimulationResult, c: Any, intervals: list[tuple[float, float]],
                        t_end: float) -> float:
    """Time inside the contact intervals where ``d = gap - s w(a)`` exceeds 0.1 um, on the exact solution.

    Each interval is scanned (:func:`~impactbeam.result.timegrid.scan_times`), the crossings of the level
    are refined by Brent's method and the parts above it summed: the same at any output step.
    """
    from scipy.optimize import brentq

    def excess(s: float) -> float:
        return c.gap - c.direction * float(result.displacement([c.position], [s])[0, 0]) - 1e-7

    total = 0.0
    for a, b in intervals:
        b = min(b, t_end)
        if not b > a:
            continue
        t = scan_times(result, a, b, breaks=False)
        e = c.gap - c.direction * result.displacement([c.position], t)[0] - 1e-7
        flips = np.nonzero(e[:-1] * e[1:] < 0.0)[0]
        edges = [a, *(brentq(excess, float(t[i]), float(t[i + 1]), xtol=1e-15) for i in flips), b]
        total += sum(hi - lo for lo, hi in zip(edges[:-1], edges[1:]) if excess(0.5 * (lo + hi)) > 0.0)
    return float(total)
