"""Bending moment and bending stress of a simulation, with the static correction of the mode-acceleration method.

The moment of the N-mode solution is the modal sum ``M = sum_j eta_j EI psi_j''``
(paper eq. 5 differentiated twice). Curvature converges much more slowly in
the modes than deflection near loads and stops, so by default the
mode-acceleration method is used (Williams 1945; Craig & Kurdila, *Fundamentals
of Structural Dynamics*, section 14.5): with every load written as an external
force on the free state (supports only) -- the excitation ``p(x) u(t)``, the
constant ``[preload]`` and the contact forces ``f_c(t)`` at the contactors,

.. math:: M(x, t) = M_{st}(x, t) + \\sum_j \\Big(\\eta_j(t) - \\frac{Q_j(t)}{\\lambda_j}\\Big) EI\\,\\psi_j''(x),
          \\qquad Q_j = p_j u(t) + \\sum_c f_c(t)\\,\\psi_j(a_c),

where ``psi_j, lambda_j`` are the free state's modes and eigenvalues (the
retained modes, plus the attachment shapes with the enriched basis),
``eta_j`` the solution's coordinates carried into that basis, and ``M_st`` the
exact static moment of the beam with its supports under the same loads at the
same instant (piecewise polynomial). The truncated modal sum then only carries
the dynamic part, which converges fast; at a static limit the moment is exact
for any number of modes.

The static moment (:mod:`impactbeam.modal.static`) is exact for every beam of the
model its supports hold (sections, springs, point masses, Timoshenko). A beam
that can move as a rigid body has no static solution: the plain modal sum is
returned with a warning.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..modal import static_moment
from .._warnings import emit_user_level_warning
from ..exceptions import ImpactBeamWarning
from .timegrid import SAMPLES_PER_PERIOD, scan_times

if TYPE_CHECKING:
    from .protocol import ResultLike

__all__ = ["bending_moment", "bending_stress", "max_bending_stress", "SAMPLES_PER_PERIOD"]


def _moment_rows(modes: Any, x: np.ndarray, bending_stiffness: float) -> np.ndarray:
    """``EI psi_j''(x)`` of a state's modes: shape (n, p)."""
    if hasattr(modes, "moment_shapes"):
        return np.asarray(modes.moment_shapes(x), dtype=float)
    return bending_stiffness * np.asarray(modes.shapes(x, 2), dtype=float)


def _excitation_static(beam: Any, excitation: Any, x: np.ndarray) -> np.ndarray:
    """Static moment at ``x`` per unit of the excitation's time history ``u``.

    A point force acts at its position; a distributed force is uniform; a
    base acceleration loads the beam with ``-rho A(x) u`` and each point mass
    with ``-m u`` (the loads whose modal weights the solver uses).
    """
    if excitation.kind == "none":
        return np.zeros(x.size)
    if excitation.kind == "point_force":
        return static_moment(beam, x, [(float(excitation.position), 1.0)])
    pieces = beam.pieces()
    if excitation.kind == "base_acceleration":
        return static_moment(beam, x, [(m.position, -m.mass) for m in beam.masses],
                             [-p.mass_per_length for p in pieces])
    return static_moment(beam, x, (), [1.0] * len(pieces))


def _free_coordinates(sol: Any, eta: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The solution's coordinates at ``t`` carried into the free state's basis: (n_t, n)."""
    space = sol.packed.space
    slots = np.asarray(sol.slot)[sol.segment_index(t)] if sol.n_segments else np.zeros(t.size, dtype=np.int64)
    out = np.empty_like(eta)
    for slot in np.unique(slots):  # one change of basis per visited state, not per time
        rows = slots == slot
        key = sol.packed.keys[int(slot)]
        T = space.transfer((), key, sol.packed.preserve) if key else None
        out[rows] = eta[rows] if T is None else eta[rows] @ T.T
    return out


def bending_moment(
    result: ResultLike, points: float | Sequence[float] | np.ndarray, times: float | Sequence[float] | np.ndarray,
    *, static_correction: bool = True,
) -> np.ndarray:
    """Bending moment ``M = EI w''`` [N m] at any positions and times (positive where ``w'' > 0``).

    Parameters
    ----------
    result : SimulationResult
    points : float or array_like, [m]
        Positions on the beam.
    times : float or array_like, [s]
        Times in ``[0, end_time]``.
    static_correction : bool
        Use the mode-acceleration method (module docstring); False gives the
        plain modal sum.

    Returns
    -------
    ndarray, (n_x, n_t), [N m]
    """
    sol = result.solution
    beam = result.beam
    x = result.check_points(points)
    t = sol.check_times(times, result.end_time)
    space = sol.packed.space
    free = space.state(())
    contactors = result.contactors
    positions = np.array([c.position for c in contactors], dtype=float)
    smp = sol.sample(positions if positions.size else x[:1], t, modal=True)
    eta = _free_coordinates(sol, smp.eta, t)
    rows = _moment_rows(free.modes, x, beam.bending_stiffness)  # (n, nx)
    M = eta @ rows
    if static_correction:
        if free.modes.n_rigid:
            emit_user_level_warning(
                "bending moment: no static correction for a beam that can move as a rigid body (no static "
                "solution); the plain modal sum converges slowly near loads and stops"
            )
        else:
            M += _static_part(result, space, free, x, t, smp, rows)
    return M.T


def _static_part(result: Any, space: Any, free: Any, x: np.ndarray, t: np.ndarray, smp: Any,
                 rows: np.ndarray) -> np.ndarray:
    """``M_st - sum_j Q_j / lambda_j EI psi_j''`` of the mode-acceleration method: (n_t, n_x)."""
    beam = result.beam
    excitation = result.solution.excitation  # this run's (the packed problem's may be another run's)
    u = np.asarray(excitation.history(t), dtype=float) if excitation.kind != "none" else np.zeros(t.size)
    Q = u[:, None] * np.asarray(free.load_weights, dtype=float)[None, :]
    out = u[:, None] * _excitation_static(beam, excitation, x)[None, :]
    if space.preload is not None:  # the constant [preload]: its modal force and its static moment, at every time
        held = space.preload.excitation()  # as a step from t = 0 (Preload.excitation: its one reading as a load)
        Q += np.asarray(free.preload_weights, dtype=float)[None, :]
        out += float(held.scale * held.amplitude) * _excitation_static(beam, held, x)[None, :]
    dash = result.solution.dashpots  # (the moment is the exact solution's: bending_moment reads sol.packed)
    for i, c in enumerate(result.contactors):
        # the force on the beam along +w: the contactor's law, k d + c d' (its dashpot's part too), while engaged
        f = np.where(smp.engaged[:, i], -c.direction * c.force(smp.w[:, i], smp.w_t[:, i], float(dash[i])), 0.0)
        Q += f[:, None] * free.W_contact[i][None, :]
        out += f[:, None] * static_moment(beam, x, [(c.position, 1.0)])[None, :]
    lam = free.modes.omega ** 2
    return out - (Q / lam[None, :]) @ rows


def bending_stress(
    result: ResultLike, points: float | Sequence[float] | np.ndarray, times: float | Sequence[float] | np.ndarray,
    *, static_correction: bool = True,
) -> np.ndarray:
    """Outer-fibre bending stress ``sigma = M c / I`` [Pa] (signed like ``M``; ``c`` from the section).

    Parameters
    ----------
    result : SimulationResult
    points : float or array_like, [m]
        Positions on the beam.
    times : float or array_like, [s]
        Times in ``[0, end_time]``.
    static_correction : bool
        As for :func:`bending_moment`.

    Returns
    -------
    ndarray, (n_x, n_t), [Pa]
        NaN where the section was given as area and second moment (no outer-fibre distance).
    """
    M = bending_moment(result, points, times, static_correction=static_correction)
    x = result.check_points(points)
    beam = result.beam
    factor = np.asarray(beam.fibre_distance_at(x), dtype=float) / np.asarray(beam.second_moment_at(x), dtype=float)
    return M * factor[:, None]


def max_bending_stress(result: ResultLike, *, points: int = 201) -> tuple[float, float, float]:
    """Largest ``|sigma|`` over the run: ``(value [Pa], time [s], position [m])``.

    Independent of the output step: the exact solution is scanned on the
    grid of :func:`~impactbeam.result.timegrid.scan_times`
    (``SAMPLES_PER_PERIOD`` points per period of the visited states' highest
    frequency, every event and break of the load, graded after them when a
    state decays faster than that) on ``points`` positions plus the ends, the
    contactors and a point load, then the best sample is refined by
    golden-section search between its neighbours in time and in position on
    the exact solution. The result is the maximum of the N-mode moment to the
    refinement's tolerance (1e-10 of the bracket in time, 1e-9 L in
    position); a peak narrower than the scan step could be missed, which the
    grid makes unlikely for a sum of the retained coordinates.

    Parameters
    ----------
    result : SimulationResult
    points : int
        Uniform positions scanned (the ends included).

    Returns
    -------
    (float, float, float)
        NaN when the section has no outer-fibre distance (area and second moment given).
    """
    sol, beam = result.solution, result.beam
    L, t_end = beam.length, sol.t_end
    t = scan_times(result, 0.0, t_end)
    extra = [c.position for c in result.contactors]
    excitation = sol.excitation
    if excitation.kind == "point_force":
        extra.append(float(excitation.position))
    x = np.unique(np.concatenate([np.linspace(0.0, L, points), extra]))
    best, bj, bx = -np.inf, 0, 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ImpactBeamWarning)  # said once, below
        for lo in range(0, t.size, 4096):
            S = np.abs(bending_stress(result, x, t[lo:lo + 4096]))
            if not np.isfinite(S).any():
                return float("nan"), float("nan"), float("nan")
            i, j = np.unravel_index(np.nanargmax(S), S.shape)
            if S[i, j] > best:
                best, bj, bx = float(S[i, j]), lo + int(j), float(x[i])
        step_x = L / (points - 1)
        ta, tb = float(t[max(bj - 1, 0)]), float(t[min(bj + 1, t.size - 1)])  # the best sample's neighbours
        bt = float(t[bj])
        for _ in range(2):  # alternate: time at the best place, place at the best time
            bt = _golden(lambda s: _abs_stress(result, bx, s), ta, tb, 1e-10 * (tb - ta))
            bx = _golden(lambda y: _abs_stress(result, y, bt), max(bx - step_x, 0.0), min(bx + step_x, L), 1e-9 * L)
        best = max(best, _abs_stress(result, bx, bt))
    if sol.packed.space.state(()).modes.n_rigid:
        emit_user_level_warning("max_bending_stress: from the plain modal sum (no static correction for a beam "
                                "that can move as a rigid body)")
    return best, bt, bx


def _abs_stress(result: Any, x: float, t: float) -> float:
    return float(abs(bending_stress(result, [x], [t])[0, 0]))


def _golden(f: Any, a: float, b: float, tol: float) -> float:
    """Maximiser of ``f`` on ``[a, b]`` by golden-section search (the best of the probes and the ends)."""
    g = (math.sqrt(5.0) - 1.0) / 2.0
    c, d = b - g * (b - a), a + g * (b - a)
    fc, fd = f(c), f(d)
    probes = [(f(a), a), (f(b), b)]
    while b - a > tol:
        if fc >= fd:
            b, d, fd = d, c, fc
            c = b - g * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + g * (b - a)
            fd = f(d)
    probes += [(fc, c), (fd, d)]
    return max(probes)[1]
