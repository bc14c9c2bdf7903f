"""Fatigue of the bending stress: exact turning points, rainflow counting, Basquin's curve and Miner's sum.

At each fatigue point ``x`` the outer-fibre bending stress ``sigma(x, t)``
(:meth:`~impactbeam.SimulationResult.bending_stress`, mode-acceleration
method) is reduced to its turning points over the analysis window: the
exact solution is scanned at ``SAMPLES_PER_PERIOD`` samples per period of
the highest retained frequency and at every event and load break (where the
stress may have a kink), and each local extremum of the scan is refined on
the closed form by golden-section search in its bracket of two scan steps
(to 1e-5 of the bracket: near an extremum the stress departs from its peak
quadratically, so the value carries a relative error of order
``(1e-5 omega_max dt)^2 ~ 1e-10``). The turning points of a result are kept
with it (per point and window), so a figure after the damage costs nothing. The window's ends are kept as the first and last points, as the
counting standard does.

The turning points are counted by the rainflow method of ASTM E1049-85
(section 5.4.4; the :mod:`rainflow` package): full cycles count 1, the
residue's half cycles 1/2. A cycle of range ``Delta S`` has amplitude
``S_a = Delta S / 2`` and mean ``S_m``. With Goodman's correction
(``mean_stress = "goodman"``) the equivalent fully reversed amplitude is
``S_a / (1 - S_m / S_u)`` for a tensile mean (no credit is taken for a
compressive mean; a mean at or above ``S_u`` fails at once). Cycles at or
below the endurance limit do no damage; the others last Basquin's
``N(S) = N_ref (S / S_ref)^(-m)`` cycles, and Miner's rule sums
``D = sum n_i / N(S_i)``. The damage rate is ``D / T`` over the window and
the life ``T / D``.

Both surfaces of the beam are counted: the stress on the other face is
``-sigma``, same ranges, opposite means. With a mean-stress correction they
differ, and the larger damage (the critical face) is reported.
"""

from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from ..exceptions import ImpactBeamWarning
from .window import analysis_window, scan_times

if TYPE_CHECKING:
    from ..model.fatigue import FatigueSpec
    from ..result.protocol import ResultLike

__all__ = ["stress_turning_points", "rainflow_cycles", "cycles_to_failure", "miner_damage", "fatigue_statistics"]

_CHUNK = 65536  # samples per call of bending_stress: ~10 MB of work arrays; each call has ~3 ms of Python
_GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0
_REFINE = 1e-5  # final bracket of the golden-section search over its initial two scan steps


Report = Callable[[float], None]


def _stress(result: Any, x: float, t: np.ndarray, report: Report | None = None) -> np.ndarray:
    """``sigma(x, t)`` in chunks; ``report(fraction)`` of ``t`` done after each chunk."""
    out = np.empty(t.size)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ImpactBeamWarning)  # the plain-sum warning: said once by fatigue_statistics
        for a in range(0, t.size, _CHUNK):
            out[a : a + _CHUNK] = result.bending_stress([x], t[a : a + _CHUNK])[0]
            if report is not None:
                report(min(a + _CHUNK, t.size) / t.size)
    return out


def _refine(result: Any, x: float, lo: np.ndarray, hi: np.ndarray, sign: np.ndarray,
            tol: float, report: Report | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Maximisers of ``sign * sigma(x, t)`` on each ``[lo, hi]``: golden-section search in lockstep.

    ``tol`` is the final bracket over the initial one; ``report(fraction)``
    of the iterations done after each.
    """
    a, b = lo.copy(), hi.copy()
    c, d = b - _GOLDEN * (b - a), a + _GOLDEN * (b - a)
    fc, fd = sign * _stress(result, x, c), sign * _stress(result, x, d)
    n_iter = int(math.ceil(math.log(tol) / math.log(_GOLDEN)))
    for i in range(n_iter):
        left = fc >= fd  # the maximum lies in [a, d]: drop (d, b]; else in [c, b]: drop [a, c)
        b = np.where(left, d, b)
        a = np.where(left, a, c)
        new_c = np.where(left, b - _GOLDEN * (b - a), d)
        new_d = np.where(left, c, a + _GOLDEN * (b - a))
        fp = sign * _stress(result, x, np.where(left, new_c, new_d))
        fc, fd = np.where(left, fp, fd), np.where(left, fc, fp)
        if report is not None:
            report((i + 1) / n_iter)
        c, d = new_c, new_d
    t = np.where(fc >= fd, c, d)
    return t, sign * np.maximum(fc, fd)


def stress_turning_points(result: ResultLike, x: float, lo: float, hi: float,
                          progress: Report | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Times and values of the turning points of ``sigma(x, t)`` on ``[lo, hi]`` (module docstring).

    Parameters
    ----------
    result : SimulationResult
    x : float, [m]
        Position on the beam.
    lo, hi : float, [s]
    progress : callable, optional
        Called with the fraction done (0 to 1): the scan's samples count for
        the first half, the refinement's iterations for the second.

    Returns
    -------
    times : ndarray, [s]
    values : ndarray, [Pa]
        Alternating maxima and minima, with the window's ends first and last.
    """
    cache = result.__dict__.setdefault("_turning_points", {}) if hasattr(result, "__dict__") else {}
    key = (float(x), float(lo), float(hi))
    if key in cache:
        return cache[key]
    cache[key] = out = _turning_points(result, float(x), lo, hi, progress)
    if progress is not None:
        progress(1.0)
    return out


def _turning_points(result: Any, x: float, lo: float, hi: float,
                    progress: Report | None) -> tuple[np.ndarray, np.ndarray]:
    """:func:`stress_turning_points` without the cache."""
    scan_done = refine_done = None
    if progress is not None:  # the scan's samples the first half, the refinement's iterations the second
        def scan_done(f: float) -> None:
            progress(0.5 * f)

        def refine_done(f: float) -> None:
            progress(0.5 + 0.5 * f)
    t = scan_times(result, lo, hi)
    s = _stress(result, float(x), t, scan_done)
    keep = np.concatenate([[True], np.diff(s) != 0.0])  # drop repeated values (a stress held constant)
    t, s = t[keep], s[keep]
    if t.size < 3:
        return t, s
    d = np.sign(np.diff(s))
    interior = np.flatnonzero(d[1:] != d[:-1]) + 1  # sample i is a local extremum of the scan
    if interior.size == 0:
        return t[[0, -1]], s[[0, -1]]
    sign = np.where(d[interior - 1] > 0, 1.0, -1.0)  # +1 at a maximum
    bl, bh = t[interior - 1], t[interior + 1]
    te, ve = _refine(result, float(x), bl, bh, sign, _REFINE, refine_done)
    better = sign * ve >= sign * s[interior]  # never worse than the scan sample itself
    te = np.where(better, te, t[interior])
    ve = np.where(better, ve, s[interior])
    return np.concatenate([[t[0]], te, [t[-1]]]), np.concatenate([[s[0]], ve, [s[-1]]])


def rainflow_cycles(series: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rainflow cycles of a sequence (ASTM E1049-85, 5.4.4): ranges, means and counts (1 or 0.5).

    Parameters
    ----------
    series : array_like
        The turning points (any sequence: reversals are extracted first).

    Returns
    -------
    range, mean, count : ndarray
    """
    import rainflow

    s = np.asarray(series, dtype=float).ravel()
    if s.size == 2 and s[0] != s[1]:  # a monotone record: one half cycle (rainflow 3.2 yields none for two points)
        return np.array([abs(s[1] - s[0])]), np.array([0.5 * (s[0] + s[1])]), np.array([0.5])
    cyc = list(rainflow.extract_cycles(s.tolist()))
    if not cyc:
        return np.zeros(0), np.zeros(0), np.zeros(0)
    arr = np.array([c[:3] for c in cyc], dtype=float)
    return arr[:, 0], arr[:, 1], arr[:, 2]


def cycles_to_failure(amplitude: np.ndarray, mean: np.ndarray, spec: FatigueSpec) -> np.ndarray:
    """Cycles to failure of each cycle: Goodman (optional), endurance limit, Basquin (module docstring).

    Parameters
    ----------
    amplitude : array_like, [Pa]
        Stress amplitudes ``S_a`` (half ranges).
    mean : array_like, [Pa]
        Mean stresses ``S_m``.
    spec : FatigueSpec

    Returns
    -------
    ndarray
        ``N`` (inf below the endurance limit, 0 for a mean at or above the ultimate strength).
    """
    sa = np.abs(np.asarray(amplitude, dtype=float))
    sm = np.asarray(mean, dtype=float)
    seq = sa.copy()
    broken = np.zeros(sa.shape, dtype=bool)
    if spec.mean_stress == "goodman":
        su = float(spec.ultimate_strength)  # type: ignore[arg-type]
        tensile = sm > 0.0
        broken = sm >= su
        with np.errstate(divide="ignore"):
            seq = np.where(tensile & ~broken, sa / (1.0 - sm / su), sa)
    with np.errstate(divide="ignore", over="ignore"):
        n = spec.sn_cycles * (seq / spec.sn_stress) ** (-spec.sn_exponent)
    n = np.where(seq <= spec.endurance_limit, np.inf, n)
    return np.where(broken, 0.0, n)


def miner_damage(series: np.ndarray, spec: FatigueSpec) -> tuple[float, dict[str, np.ndarray]]:
    """Miner's sum ``D = sum n_i / N(S_i)`` of the rainflow cycles of ``series``.

    Parameters
    ----------
    series : array_like, [Pa]
        Turning points of the stress.
    spec : FatigueSpec

    Returns
    -------
    damage : float
    cycles : dict
        ``range``, ``mean``, ``count`` and ``cycles_to_failure`` of every counted cycle.
    """
    rng, mean, count = rainflow_cycles(series)
    n = cycles_to_failure(0.5 * rng, mean, spec)
    with np.errstate(divide="ignore"):
        damage = float(np.sum(np.where(np.isinf(n), 0.0, count / n))) if rng.size else 0.0
    return damage, {"range": rng, "mean": mean, "count": count, "cycles_to_failure": n}


def fatigue_statistics(result: ResultLike, spec: FatigueSpec | None = None,
                       window: tuple[float, float] | None = None,
                       progress: Report | None = None) -> list[dict[str, Any]]:
    """Rainflow damage, damage rate and life at each fatigue point (module docstring).

    Parameters
    ----------
    result : SimulationResult
    spec : FatigueSpec, optional
        Default: the scenario's ``[fatigue]``.
    window : (float, float), optional, [s]
        Default :func:`~impactbeam.statistics.window.analysis_window`.
    progress : callable, optional
        Called with the points done so far (fractions within a point: a 100 s
        record's scan takes seconds per point).

    Returns
    -------
    list of dict
        Per point: ``point`` [m], ``damage`` (Miner's sum over the window),
        ``damage_rate`` [1/s], ``life`` [s] (inf without damage), ``cycles``
        (counted, half cycles as 1/2), ``max_range`` [Pa], ``face`` (+1: the
        stress as signed by ``bending_stress``, -1: the other face), ``duration`` [s].
    """
    if spec is None:
        spec = getattr(getattr(result, "scenario", None), "fatigue", None)
    if spec is None:
        return []
    lo, hi = analysis_window(result, window)
    packed = getattr(result.solution, "packed", None)
    if packed is not None and packed.space.state(()).modes.n_rigid:
        from .._warnings import emit_user_level_warning

        emit_user_level_warning("fatigue: the stress is the plain modal sum (no static correction for a beam that "
                                "can move as a rigid body); it converges slowly near loads and stops")
    out = []
    for k, x in enumerate(spec.points):
        _, values = stress_turning_points(result, x, lo, hi,
                                          None if progress is None else (lambda f, k=k: progress(k + f)))
        best = None
        for face in (1.0, -1.0):
            damage, cyc = miner_damage(face * values, spec)
            if best is None or damage > best[0]:
                best = (damage, cyc, face)
            if spec.mean_stress == "none":
                break
        damage, cyc, face = best  # type: ignore[misc]
        broken = int(np.count_nonzero(cyc["cycles_to_failure"] == 0.0))
        if broken:
            from .._warnings import emit_user_level_warning

            emit_user_level_warning(
                f"fatigue: at x = {x:.6g} m, {broken} cycle(s) have a mean stress at or above "
                f"fatigue.ultimate_strength ({spec.ultimate_strength:g} Pa; Goodman): the damage is infinite and the "
                "life 0 (null in JSON); check the strength and its unit"
            )
        rate = damage / (hi - lo)
        out.append({
            "point": float(x), "damage": damage, "damage_rate": rate, "life": 1.0 / rate if rate > 0 else math.inf,
            "cycles": float(np.sum(cyc["count"])), "max_range": float(np.max(cyc["range"], initial=0.0)),
            "face": face, "duration": hi - lo,
        })
    return out
