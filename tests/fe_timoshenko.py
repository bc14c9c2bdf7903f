"""Independent Timoshenko finite-element reference for the tests (imports nothing from impactbeam).

Interdependent-interpolation elements (J. N. Reddy, "On locking-free shear
deformable beam finite elements", Comput. Methods Appl. Mech. Engrg. 149
(1997) 113-132): on an element of length ``h`` the deflection is cubic and the
rotation is the one that makes the element exact in statics,

    W = a0 + a1 x + a2 x^2 + a3 x^3,    Psi = a1 + 2 a2 x + 3 a3 x^2 + 6 a3 EI / kGA,

so that the shear force ``kGA (W' - Psi) = -6 EI a3`` is constant. The four
coefficients are mapped to the nodal values ``(W0, Psi0, W1, Psi1)``;

    K_e = int EI Psi'^T Psi' + kGA (W' - Psi)^T (W' - Psi) dx,
    M_e = int rhoA W^T W + rhoI Psi^T Psi dx

by 4-point Gauss quadrature (exact: the integrands are polynomials of degree
at most 6). Two DOFs per node, ``W`` and ``Psi``. End and interior
translational springs act on ``W``, rotational springs on ``Psi``; point masses
add ``m`` to ``W`` and ``J`` to ``Psi``; an infinite spring removes the DOF.
With this consistent mass the frequencies converge as ``h^2`` (the rotation
field is only quadratic); :func:`extrapolated_frequencies` removes the ``h^2``
and ``h^4`` terms (two Richardson steps) from three meshes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import scipy.linalg

_GX, _GW = np.polynomial.legendre.leggauss(4)


def element(h: float, EI: float, kGA: float, rhoA: float, rhoI: float) -> tuple[np.ndarray, np.ndarray]:
    """Stiffness and mass (4 x 4) of one interdependent-interpolation element."""
    phi = 6.0 * EI / kGA

    def w_row(x: float, d: int = 0) -> np.ndarray:
        return np.array([[1.0, x, x * x, x**3], [0.0, 1.0, 2 * x, 3 * x * x]][d])

    def psi_row(x: float, d: int = 0) -> np.ndarray:
        return np.array([[0.0, 1.0, 2 * x, 3 * x * x + phi], [0.0, 0.0, 2.0, 6 * x]][d])

    C = np.array([w_row(0.0), psi_row(0.0), w_row(h), psi_row(h)])
    Ci = np.linalg.inv(C)
    K = np.zeros((4, 4))
    M = np.zeros((4, 4))
    for gx, gw in zip(_GX, _GW):
        x, wt = 0.5 * h * (gx + 1.0), 0.5 * h * gw
        Nw, Np = w_row(x) @ Ci, psi_row(x) @ Ci
        dNp = psi_row(x, 1) @ Ci
        gam = w_row(x, 1) @ Ci - Np
        K += wt * (EI * np.outer(dNp, dNp) + kGA * np.outer(gam, gam))
        M += wt * (rhoA * np.outer(Nw, Nw) + rhoI * np.outer(Np, Np))
    return K, M


def frequencies(
    pieces: Sequence[tuple[float, float, float, float, float]],
    ends: tuple[tuple[float, float], tuple[float, float]],
    n_elements: int,
    n_modes: int,
    attachments: Sequence[tuple[float, float, float, float, float]] = (),
) -> np.ndarray:
    """Natural frequencies [rad/s] of a piecewise-uniform Timoshenko beam.

    ``pieces``: ``(length, EI, kGA, rhoA, rhoI)`` from x = 0; ``ends``:
    ``((k_left, Kt_left), (k_right, Kt_right))``; ``attachments``:
    ``(x, k, Kt, m, J)`` at interior or end points (a mesh node is put there).
    About ``n_elements`` elements in all, proportionally to length.
    """
    L = math.fsum(p[0] for p in pieces)
    edges = np.concatenate([[0.0], np.cumsum([p[0] for p in pieces])])
    marks = np.unique(np.concatenate([edges, [a[0] for a in attachments]]))
    xs = [np.linspace(a, b, max(1, round(n_elements * (b - a) / L)) + 1)[:-1] for a, b in zip(marks[:-1], marks[1:])]
    nodes = np.concatenate(xs + [[L]])
    n = nodes.size
    K = np.zeros((2 * n, 2 * n))
    M = np.zeros((2 * n, 2 * n))
    for e in range(n - 1):
        mid = 0.5 * (nodes[e] + nodes[e + 1])
        j = min(int(np.searchsorted(edges, mid, side="right")) - 1, len(pieces) - 1)
        _, EI, kGA, rhoA, rhoI = pieces[j]
        Ke, Me = element(nodes[e + 1] - nodes[e], EI, kGA, rhoA, rhoI)
        sl = slice(2 * e, 2 * e + 4)
        K[sl, sl] += Ke
        M[sl, sl] += Me
    keep = np.ones(2 * n, dtype=bool)
    terms = [(0.0, *ends[0], 0.0, 0.0), (L, *ends[1], 0.0, 0.0), *attachments]
    for x, k, kt, m, J in terms:
        i = int(np.argmin(np.abs(nodes - x)))
        for dof, spring, inertia in ((2 * i, k, m), (2 * i + 1, kt, J)):
            if math.isinf(spring):
                keep[dof] = False
            else:
                K[dof, dof] += spring
                M[dof, dof] += inertia
    Kr, Mr = K[np.ix_(keep, keep)], M[np.ix_(keep, keep)]
    lam = scipy.linalg.eigh(Kr, Mr, eigvals_only=True, subset_by_index=[0, n_modes - 1])
    return np.sqrt(np.maximum(lam, 0.0))


def extrapolated_frequencies(*args, n_elements: int = 100, **kwargs) -> np.ndarray:
    """Richardson extrapolation of :func:`frequencies` on ``n``, ``2 n`` and ``4 n`` elements (h^2, h^4 removed)."""
    f1, f2, f4 = (frequencies(*args, n_elements=k * n_elements, **kwargs) for k in (1, 2, 4))
    r1, r2 = f2 + (f2 - f1) / 3.0, f4 + (f4 - f2) / 3.0
    return r2 + (r2 - r1) / 15.0


def count_below(*args, omega: float, n_elements: int = 400, **kwargs) -> int:
    """Number of FE frequencies below ``omega`` (for counts well away from a root)."""
    f = frequencies(*args, n_elements=n_elements, n_modes=2 * n_elements, **kwargs)
    return int(np.sum(f < omega))
