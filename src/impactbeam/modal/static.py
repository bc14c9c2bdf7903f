r"""Exact static response of a beam of the model: moments under point forces and distributed loads.

Any beam of :class:`~impactbeam.model.beam.Beam` held by its supports and
permanent springs (sections, Euler-Bernoulli or Timoshenko; point masses do
not act in statics) under point forces and a distributed load that is
constant on each section. On a uniform piece with ``EI``, shear stiffness
``kappa G A`` (infinite for Euler-Bernoulli) and load ``q`` [N/m] along +w,
the static form of eq. (1) in state form (``M = EI Psi'``, ``V = -M'``),

.. math:: V' = -q, \quad M' = -V, \quad \Psi' = M / EI, \quad W' = \Psi + V / \kappa G A,

integrates to polynomials of degree four. The beam is cut at its nodes
(ends, steps, springs) and at the points where forces act; each piece's
exact stiffness and fixed-end forces are assembled with the node springs
(an infinite one fixes its degree of freedom) and solved, and the moment
anywhere is the piece's polynomial. This is the ``M_st`` of the
mode-acceleration correction of :mod:`impactbeam.result.stress`.

References
----------
.. [1] W. Xu, E. K. Ervin, Shock and Vibration 20 (2013), eq. (1) and the end
   conditions after eq. (5).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence

import numpy as np

from .euler import layout, rigid_modes
from ..exceptions import ParameterError
from ..model.beam import Beam

__all__ = ["static_moment", "static_state"]


def _element(h: float, EI: float, flex: float, q: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stiffness (4, 4), fixed-end loads (4,) and the map to ``(M0, V0)`` of one piece.

    Degrees of freedom ``(W0, Psi0, W1, Psi1)``; end loads ``(-V0, -M0, V1, M1)``.
    ``flex = 1 / kappa G A`` (0 for Euler-Bernoulli). Returns ``K, f, G`` with
    ``(M0, V0) = G @ [d, 1]`` (the constant column is the load's part).
    """
    # W1 - W0 - Psi0 h = M0 a + V0 b + q c ;  Psi1 - Psi0 = M0 e + V0 g + q s
    a, b, c = h * h / (2 * EI), -(h**3) / (6 * EI) + flex * h, h**4 / (24 * EI) - flex * h * h / 2
    e, g, s = h / EI, -h * h / (2 * EI), h**3 / (6 * EI)
    F = np.array([[a, b], [e, g]])
    Fi = np.linalg.inv(F)
    D = np.array([[-1.0, -h, 1.0, 0.0], [0.0, -1.0, 0.0, 1.0]])  # (W1 - W0 - Psi0 h, Psi1 - Psi0)
    G = np.zeros((2, 5))
    G[:, :4] = Fi @ D
    G[:, 4] = -Fi @ np.array([c, s]) * q
    M1 = np.array([1.0, -h]) @ G  # M(h) = M0 - V0 h + q h^2 / 2
    M1[4] += q * h * h / 2
    V1 = np.array([0.0, 1.0]) @ G  # V(h) = V0 - q h
    V1[4] -= q * h
    loads = np.array([-G[1], -G[0], V1, M1])  # (4, 5)
    return loads[:, :4], loads[:, 4], G


@functools.lru_cache(maxsize=256)
def _solve(beam: Beam, forces: tuple[tuple[float, float], ...], per_length: tuple[float, ...],
           ) -> tuple[np.ndarray, np.ndarray]:
    """Piece starts and per-piece ``(W0, Psi0, M0, V0, q, EI, 1/kGA)`` of one static load case."""
    lay = layout(beam, [(x, 0.0) for x, _ in forces])
    nodes = np.unique(np.concatenate([lay.nodes, [x for x, _ in forces]]))
    pieces = beam.pieces()
    edges = np.concatenate([[0.0], np.cumsum([p.length for p in pieces])])
    n = nodes.size
    K = np.zeros((2 * n, 2 * n))
    f = np.zeros(2 * n)
    mats = []
    for j in range(n - 1):
        mid = 0.5 * (nodes[j] + nodes[j + 1])
        i = min(int(np.searchsorted(edges, mid, side="right")) - 1, len(pieces) - 1)
        p = pieces[i]
        flex = 1.0 / beam.shear_stiffness(p) if beam.is_timoshenko else 0.0
        Ke, fe, G = _element(nodes[j + 1] - nodes[j], p.bending_stiffness, flex, per_length[i])
        sl = slice(2 * j, 2 * j + 4)
        K[sl, sl] += Ke
        f[sl] -= fe
        mats.append((G, per_length[i], p.bending_stiffness, flex))
    for x, F in forces:
        f[2 * int(np.argmin(np.abs(nodes - x)))] += F
    free = np.ones(2 * n, dtype=bool)
    for x, k, kt in zip(lay.nodes, lay.k, lay.kt):
        i = int(np.argmin(np.abs(nodes - x)))
        for dof, spring in ((2 * i, k), (2 * i + 1, kt)):
            if math.isinf(spring):
                free[dof] = False
            else:
                K[dof, dof] += spring
    d = np.zeros(2 * n)
    if rigid_modes(lay).size:  # from the supports themselves, not from the conditioning of K
        raise ParameterError("static response: the supports let the beam move as a rigid body (no static solution)")
    Kf = K[np.ix_(free, free)]
    if Kf.size:
        # symmetric diagonal scaling: a stiff spring (1e15) or a short piece beside the rest is no
        # longer an ill-conditioning, and the solve keeps the accuracy of the scaled system
        scale = 1.0 / np.sqrt(np.abs(np.diag(Kf)))
        d[free] = scale * np.linalg.solve(Kf * scale[:, None] * scale[None, :], f[free] * scale)
    rows = [(*d[2 * j: 2 * j + 2], *(G @ np.append(d[2 * j: 2 * j + 4], 1.0)), q, EI, flex)
            for j, (G, q, EI, flex) in enumerate(mats)]
    return nodes, np.array(rows)


def static_state(beam: Beam, x: Sequence[float] | np.ndarray, forces: Sequence[tuple[float, float]] = (),
                 per_length: Sequence[float] | None = None) -> tuple[np.ndarray, ...]:
    """Static deflection and its derivatives at ``x`` under point forces and a distributed load.

    Returns ``(W, Psi, M, V, W1, W2, W3)``: deflection [m], cross-section
    rotation (``W'`` for Euler-Bernoulli), moment ``M = EI Psi'`` [N m], shear
    ``V = -M'`` [N], and the first three x-derivatives of ``W`` (from
    ``W' = Psi + V / kappa G A``); at a node, the values to the right.

    Parameters
    ----------
    beam : Beam
        A beam its supports hold (no rigid-body motion).
    x : array_like, (n,), [m]
        Where to evaluate.
    forces : sequence of (position [m], force [N])
        Point forces, positive along +w.
    per_length : sequence of float, [N/m], optional
        A uniform distributed load on each section (default none).
    """
    pieces = beam.pieces()
    q = tuple(float(v) for v in (per_length if per_length is not None else [0.0] * len(pieces)))
    if len(q) != len(pieces):
        raise ParameterError(f"per_length: one value per section ({len(pieces)}), got {len(q)}")
    key = tuple(sorted((float(a), float(F)) for a, F in forces))
    nodes, rows = _solve(beam, key, q)
    x = np.atleast_1d(np.asarray(x, dtype=float))
    j = np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, nodes.size - 2)
    u = x - nodes[j]
    W0, P0, M0, V0, qq, EI, flex = rows[j].T
    V = V0 - qq * u
    M = M0 - V0 * u + qq * u * u / 2.0
    Psi = P0 + (M0 * u - V0 * u * u / 2.0 + qq * u**3 / 6.0) / EI
    W = W0 + P0 * u + (M0 * u * u / 2.0 - V0 * u**3 / 6.0 + qq * u**4 / 24.0) / EI + flex * (V0 * u - qq * u * u / 2.0)
    return W, Psi, M, V, Psi + flex * V, M / EI - flex * qq, -V / EI


def static_moment(beam: Beam, x: Sequence[float] | np.ndarray, forces: Sequence[tuple[float, float]] = (),
                  per_length: Sequence[float] | None = None) -> np.ndarray:
    """Bending moment ``M = EI Psi'`` [N m] at ``x`` under static loads (sign as ``M = EI w''``).

    Parameters
    ----------
    beam : Beam
        Held by its supports and permanent springs (no rigid-body motion).
    x : array_like, [m]
        Positions; at a node the value to the right.
    forces : sequence of (position [m], force [N])
        Point forces along +w.
    per_length : sequence of float, [N/m], optional
        Distributed load along +w, one value per piece of :meth:`Beam.pieces`.

    Raises
    ------
    ParameterError
        If the supports allow rigid-body motion.
    """
    return static_state(beam, x, forces, per_length)[2]
