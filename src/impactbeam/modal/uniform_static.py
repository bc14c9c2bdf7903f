"""Exact static deflections of the paper's uniform beam with end springs, as polynomials.

``EI g'''' = q(x)`` with a unit point force, polynomial loads on the two
sides of the force, and the end conditions of the paper (after its eq. 5:
springs 0..inf, exact at both limits). Used for the attachment shapes of
the shared Ritz basis (:mod:`impactbeam.solver.ritz`).

References
----------
.. [1] W. Xu, E. K. Ervin, Shock and Vibration 20 (2013), eq. (1) and the end
   conditions after eq. (5).
"""

from __future__ import annotations

import math

import numpy as np

from ..model.beam import Beam

__all__ = ["static_polynomial", "static_coefficients"]


def _bc_rows(beam: Beam) -> tuple[np.ndarray, np.ndarray]:
    """Weights of the end conditions on (g, g', g'', g''') in ``xi = x / L``, ``g = L^3/EI ghat``.

    Rows ``(p, 0, 0, q)`` etc. with ``p = K/(K + scale)``: exact for K = 0 and inf.
    """
    L, EI = beam.length, beam.bending_stiffness

    def w(K: float, scale: float) -> tuple[float, float]:
        return (1.0, 0.0) if math.isinf(K) else (K / (K + scale), scale / (K + scale))

    p1, q1 = w(beam.left.translational, EI / L**3)
    t1, u1 = w(beam.left.rotational, EI / L)
    p2, q2 = w(beam.right.translational, EI / L**3)
    t2, u2 = w(beam.right.rotational, EI / L)
    left = np.array([[p1, 0.0, 0.0, q1], [0.0, t1, -u1, 0.0]])  # k1 g + EI g''' = 0 ; Kt1 g' - EI g'' = 0
    right = np.array([[p2, 0.0, 0.0, -q2], [0.0, t2, u2, 0.0]])  # k2 g - EI g''' = 0 ; Kt2 g' + EI g'' = 0
    return left, right


def _cubic_derivs(xi: float) -> np.ndarray:
    """Rows d^k/dxi^k of (1, xi, xi^2, xi^3) for k = 0..3, shape (4, 4)."""
    return np.array([
        [1.0, xi, xi**2, xi**3],
        [0.0, 1.0, 2 * xi, 3 * xi**2],
        [0.0, 0.0, 2.0, 6 * xi],
        [0.0, 0.0, 0.0, 6.0],
    ])


def static_polynomial(beam: Beam, alpha: float, loads: np.ndarray, jump: float) -> np.ndarray:
    """Coefficients (2 segments, powers of xi) of ``ghat`` with ``ghat'''' = loads[s](xi)`` on each side.

    ``loads`` (2, m) holds the polynomial load of the segments left and right
    of ``xi = alpha``; ``jump`` is ``ghat'''(alpha+) - ghat'''(alpha-)`` (1 for a
    unit point force there, 0 for none); ``ghat, ghat', ghat''`` are continuous;
    end conditions of the paper. A singular system (rigid-body motion) is
    solved in the least-squares sense; the caller removes the rigid-body part.

    Parameters
    ----------
    beam : Beam
        A uniform beam with end springs.
    alpha : float
        Position of the point force, as a fraction of the length.
    loads : ndarray, (2, m)
        Polynomial load (powers of ``xi``) left and right of ``alpha``.
    jump : float
        Jump of the third derivative at ``alpha``.
    """
    m = loads.shape[1]
    part = np.zeros((2, m + 4))
    for k in range(m):  # four integrations of xi^k
        part[:, k + 4] = loads[:, k] * math.factorial(k) / math.factorial(k + 4)
    dpart = [[np.polynomial.polynomial.polyder(part[s], k) if k else part[s] for k in range(4)] for s in (0, 1)]

    def pd(side: int, xi: float) -> np.ndarray:
        return np.array([np.polynomial.polynomial.polyval(xi, d) for d in dpart[side]])

    left, right = _bc_rows(beam)
    A = np.zeros((8, 8))
    b = np.zeros(8)
    A[0:2, 0:4] = left @ _cubic_derivs(0.0)
    b[0:2] = -left @ pd(0, 0.0)
    D = _cubic_derivs(alpha)
    A[2:6, 0:4] = D
    A[2:6, 4:8] = -D
    b[2:6] = pd(1, alpha) - pd(0, alpha)
    b[5] -= jump  # g'''(a-) - g'''(a+) = -jump
    A[6:8, 4:8] = right @ _cubic_derivs(1.0)
    b[6:8] = -right @ pd(1, 1.0)
    c, *_ = np.linalg.lstsq(A, b, rcond=1e-13)
    out = part.copy()
    out[0, :4] += c[:4]
    out[1, :4] += c[4:]
    return out


def static_coefficients(beam: Beam, alpha: float, q0: float, q1: float) -> np.ndarray:
    """Coefficients (2, 6) of ``ghat`` under a unit force at ``xi = alpha`` with ``ghat'''' = q0 + q1 xi``.

    The load is the inertia relief of rigid-body modes (zero without them).

    Parameters
    ----------
    beam : Beam
        A uniform beam with end springs.
    alpha : float
        Position of the unit force, as a fraction of the length.
    q0, q1 : float
        The distributed load ``q0 + q1 xi``.
    """
    return static_polynomial(beam, alpha, np.array([[q0, q1], [q0, q1]]), 1.0)
