"""States whose modes do not diagonalise their damping: exact coordinates by blocks.

A state's modal equations with a damping matrix ``C`` (in its own modal
frame, ``M = I``, stiffness ``diag(omega^2)``) are the first-order system

.. math:: \\dot x = A x + \\begin{bmatrix}0\\\\ f(t)\\end{bmatrix}, \\qquad
          A = \\begin{bmatrix}0 & I\\\\ -\\Omega^2 & -C\\end{bmatrix},
          \\quad x = \\begin{bmatrix}\\eta\\\\ \\dot\\eta\\end{bmatrix}.

``A`` is split into real 2 x 2 blocks ``A Y_k = Y_k M_k`` (``Y_k`` an
orthonormal basis of the invariant subspace of a conjugate pair of
eigenvalues, or of two real ones taken together, so that a defective or
nearly defective pair, e.g. near critical damping, is one well-conditioned
block). Each block is written in companion coordinates: with ``a = -tr M /
2``, ``omega^2 = det M`` and any vector ``e`` that is not an eigenvector,
``S = [(M + 2a I) e, e]`` gives ``S^{-1} M S = [[0, 1], [-omega^2, -2a]]``,
so the block's coordinates ``(z0, z1)`` obey

.. math:: \\dot z_0 = z_1 + \\alpha(t), \\qquad \\dot z_1 = -\\omega^2 z_0 - 2a z_1 + \\beta(t),

i.e. ``z0'' + 2a z0' + omega^2 z0 = beta + 2a alpha + alpha'``: the damped
oscillator of paper eq. (9) that the compiled closed form integrates in
every regime, with ``z1 = z0' - alpha``. Rigid-body modes that the damping
does not touch stay modes of their own (the pair ``(eta, eta')`` with
``M = [[0, 1], [0, 0]]``). The maps ``x = G (z, z' - alpha)`` and back
``H`` are exact linear algebra; nothing is approximated beyond round-off,
which :func:`slot_arrays` measures (``residual``) and refuses above 1e-8.

A cluster of more than two eigenvalues within 1e-10 of each other (which
would make the blocks ill-conditioned) is refused with a clear message.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..exceptions import SimulationError

__all__ = ["SlotArrays", "slot_arrays", "classical_slot", "block_structure"]

_CLUSTER = 1e-10  # relative distance under which eigenvalues belong to one block


@dataclass(frozen=True, eq=False)
class SlotArrays:
    """What the compiled loop needs of one state slot (see :mod:`~impactbeam.solver._loop`).

    ``reg, dec, wdh, om`` per coordinate; ``LW`` (4, n): ``bu, au`` per unit
    of the excitation's time law, ``bp, ap`` of the preload; ``CW`` (2, nc,
    n): ``Bc, Ac`` per unit point force at each contactor; ``RW`` (4, nc, n):
    deflection and velocity rows at the contactors; ``gen``; ``G`` (2, 2n,
    n) and ``H`` (2, n, 2n); ``Cd`` (n, n) the damping matrix in the modal
    frame (zero for a classical state, whose ``dec`` says it all).
    """

    reg: np.ndarray
    dec: np.ndarray
    wdh: np.ndarray
    om: np.ndarray
    LW: np.ndarray
    CW: np.ndarray
    RW: np.ndarray
    gen: int
    G: np.ndarray
    H: np.ndarray
    Cd: np.ndarray
    residual: float = 0.0


def _clustered(values: np.ndarray) -> int:
    """How many of ``values`` (complex) lie within 1 % of another one (in magnitude)."""
    v = np.asarray(values, dtype=complex)
    d = np.abs(v[:, None] - v[None, :])
    np.fill_diagonal(d, np.inf)
    return int(np.count_nonzero(np.any(d <= 0.01 * np.abs(v)[:, None], axis=1)))


def _regimes(om: np.ndarray, dec: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Regime codes (0 under, 1 critical, 2 over) and damped frequencies."""
    disc = om**2 - dec**2
    reg = np.where(disc > 0.0, 0, np.where(disc < 0.0, 2, 1)).astype(np.int64)
    return reg, np.sqrt(np.abs(disc))


def classical_slot(omega: np.ndarray, decay: np.ndarray, Wc: np.ndarray, pw: np.ndarray,
                   pre: np.ndarray) -> SlotArrays:
    """A state whose modes diagonalise its damping: the coordinates are its modal coordinates.

    Parameters
    ----------
    omega, decay : ndarray, (n,)
        Frequencies [rad/s] and decay rates ``xi omega`` [1/s].
    Wc : ndarray, (nc, n)
        Mode shapes at the contactors.
    pw, pre : ndarray, (n,)
        Modal weights of the excitation and of the preload.
    """
    n = omega.size
    nc = Wc.shape[0]
    reg, wdh = _regimes(omega, decay)
    zero = np.zeros(n)
    LW = np.stack([pw, zero, pre, zero])
    CW = np.stack([Wc, np.zeros((nc, n))])
    RW = np.stack([Wc, np.zeros((nc, n)), np.zeros((nc, n)), Wc])
    return SlotArrays(reg, decay.astype(float), wdh, omega.astype(float), LW, CW, RW, 0,
                      np.zeros((2, 2 * n, n)), np.zeros((2, n, 2 * n)), np.zeros((n, n)))


def _pairs(lam: np.ndarray, scale: float) -> list[tuple[int, int]]:
    """Indices of the eigenvalues taken two by two: conjugate pairs, and real ones with their nearest."""
    order = np.lexsort((np.abs(lam.imag), lam.real))
    used = np.zeros(lam.size, dtype=bool)
    out = []
    for i in order:
        if used[i]:
            continue
        used[i] = True
        cand = np.where(used, np.inf, np.abs(lam - (np.conj(lam[i]) if abs(lam[i].imag) > _CLUSTER * scale else lam[i])))
        if abs(lam[i].imag) <= _CLUSTER * scale:
            cand = np.where(np.abs(lam.imag) > _CLUSTER * scale, np.inf, cand)
        j = int(np.argmin(cand))
        if not np.isfinite(cand[j]):
            raise SimulationError("non-proportional damping: an eigenvalue of a state has no partner")
        used[j] = True
        out.append((int(i), j))
    for i, j in out:
        near = (np.abs(lam - lam[i]) <= _CLUSTER * scale) | (np.abs(lam - lam[j]) <= _CLUSTER * scale)
        if np.count_nonzero(near) > 2:
            raise SimulationError(
                "non-proportional damping: more than two eigenvalues of a state coincide (a cluster at "
                f"{lam[i]:.6g}); the block decomposition needs them in pairs. Change a damping value slightly."
            )
    return out


def _invariant_pairs(At: np.ndarray) -> list[np.ndarray]:
    """Orthonormal bases (m, 2) of the invariant subspaces of the scaled matrix ``At``, two eigenvalues each.

    A conjugate pair: the real and imaginary parts of its eigenvector. Two
    real eigenvalues: their two eigenvectors, or, when these are nearly
    parallel (a nearly defective pair), the null space of the real
    ``(At - l1)(At - l2)``, which is well conditioned where the eigenvectors
    are not.
    """
    lam, vec = np.linalg.eig(At)
    scale = max(float(np.max(np.abs(lam))), 1.0)
    I = np.eye(At.shape[0])
    out = []
    for i, j in _pairs(lam, scale):
        if abs(lam[i].imag) > _CLUSTER * scale:
            Y = np.column_stack([vec[:, i].real, vec[:, i].imag])
        else:
            Y = np.column_stack([vec[:, i].real, vec[:, j].real])
        Y /= np.linalg.norm(Y, axis=0)
        if np.linalg.svd(Y, compute_uv=False)[-1] < 1e-6:
            l1, l2 = lam[i], lam[j]
            Pm = At @ At - (l1 + l2).real * At + (l1 * l2).real * I
            Y = np.linalg.svd(Pm)[2][-2:].T
        Y, _ = np.linalg.qr(Y)
        out.append(Y)
    return out


def block_structure(omega: np.ndarray, C: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[np.ndarray], float]:
    """The scaled first-order matrix of a state and its 2 x 2 blocks.

    In the coordinates ``xs = (d eta, eta')`` with ``d = max(omega, omega_ref)``
    (energy-like, so that every entry is of the order of a frequency) the
    matrix ``As = [[0, diag(d)], [-Omega^2 / d, -C]]``. Returns ``(As, d,
    blocks, residual)``: ``blocks[k]`` is ``Y_k`` (2N, 2), orthonormal and
    invariant under ``As``; ``residual`` the largest ``|As Y - Y M| / |As|``.
    """
    n = omega.size
    positive = omega[omega > 0.0]
    ref = float(positive.min()) if positive.size else max(float(np.max(np.abs(C))), 1.0)
    d = np.maximum(omega, ref)
    As = np.zeros((2 * n, 2 * n))
    As[:n, n:] = np.diag(d)
    As[n:, :n] = -np.diag(omega**2 / d)
    As[n:, n:] = -C
    # rigid-body modes the damping does not touch stay modes of their own (a coupling below 1e-10 of
    # the largest rate is the round-off of a rigid mode's shape at a dashpot, where it does not move)
    cmax = np.maximum(np.max(np.abs(C), axis=0), np.max(np.abs(C), axis=1))
    untouched = (omega == 0.0) & (cmax <= 1e-10 * max(float(np.max(np.abs(C))), 1e-300))
    blocks: list[np.ndarray] = []
    for m in np.flatnonzero(untouched):
        Y = np.zeros((2 * n, 2))
        Y[m, 0] = 1.0
        Y[n + m, 1] = 1.0
        blocks.append(Y)
    rest = np.concatenate([np.flatnonzero(~untouched), n + np.flatnonzero(~untouched)])
    if rest.size:
        for Ys in _invariant_pairs(As[np.ix_(rest, rest)]):
            Y = np.zeros((2 * n, 2))
            Y[rest] = Ys
            blocks.append(Y)
    anorm = max(float(np.linalg.norm(As, 2)), 1e-300)
    residual = 0.0
    for Y in blocks:
        M = Y.T @ As @ Y
        residual = max(residual, float(np.linalg.norm(As @ Y - Y @ M, 2)) / anorm)
    return As, d, blocks, residual


def _companion(M: np.ndarray) -> tuple[np.ndarray, float, float]:
    """``S`` with ``S^-1 M S = [[0, 1], [-omega^2, -2a]]`` (best conditioned of a few ``e``), and ``a``, ``omega^2``."""
    a = -0.5 * float(np.trace(M))
    w2 = float(np.linalg.det(M))
    N = M + 2.0 * a * np.eye(2)
    best, best_cond = None, np.inf
    for e in (np.array([1.0, 0.0]), np.array([0.0, 1.0]), np.array([1.0, 1.0]) / np.sqrt(2.0),
              np.array([1.0, -1.0]) / np.sqrt(2.0)):
        S = np.column_stack([N @ e, e])
        cond = np.linalg.cond(S)
        if cond < best_cond:
            best, best_cond = S, cond
    if best is None or not np.isfinite(best_cond) or best_cond > 1e10:
        raise SimulationError(
            "non-proportional damping: a block of a state is a multiple of the identity (a repeated eigenvalue "
            "with two independent modes); change a damping value slightly"
        )
    return best, a, max(w2, 0.0)


def slot_arrays(omega: np.ndarray, C: np.ndarray, Wc: np.ndarray, pw: np.ndarray, pre: np.ndarray) -> SlotArrays:
    """The coordinates of a state with the damping matrix ``C`` (module docstring).

    Parameters
    ----------
    omega : ndarray, (n,)
        The state's natural frequencies [rad/s] (its modal frame).
    C : ndarray, (n, n)
        Its damping matrix in that frame [1/s] (mass-normalised modes).
    Wc : ndarray, (nc, n)
        Mode shapes at the contactors.
    pw, pre : ndarray, (n,)
        Modal weights of the excitation and of the preload.

    Raises
    ------
    SimulationError
        When the decomposition is not accurate to 1e-8 (a cluster of equal
        eigenvalues, a defective block of more than two).
    """
    n = omega.size
    As, dscale, blocks, residual = block_structure(omega, C)
    if len(blocks) != n or residual > 1e-8:
        raise SimulationError(
            f"non-proportional damping: the state's block decomposition is not accurate ({residual:.2g}); "
            "this damping cannot be integrated exactly"
        )
    Gm = np.zeros((2 * n, 2 * n))  # columns (z0_k, z1_k) interleaved by block
    reg = np.zeros(n, dtype=np.int64)
    dec = np.zeros(n)
    om = np.zeros(n)
    unscale = np.concatenate([1.0 / dscale, np.ones(n)])  # xs -> x
    # round-off floors, as the states' own rigid-body threshold (eigenvalues below 1e-13 of the largest):
    # a rigid-body block gets exact polynomials, not A / omega^2 against its homogeneous part
    rate = max(float(np.max(omega)), float(np.max(np.abs(C))), 1e-300)
    for k, Y in enumerate(blocks):
        M = Y.T @ As @ Y
        S, a, w2 = _companion(M)
        if w2 < 1e-13 * rate**2:
            w2 = 0.0
        if abs(a) < 1e-13 * rate:
            a = 0.0
        GS = unscale[:, None] * (Y @ S)
        Gm[:, k] = GS[:, 0]
        Gm[:, n + k] = GS[:, 1]
        dec[k] = a
        om[k] = np.sqrt(w2)
    reg, wdh = _regimes(om, dec)
    Hm = np.linalg.inv(Gm)
    miss = float(np.linalg.norm(Hm @ Gm - np.eye(2 * n), np.inf))
    if miss > 1e-6:
        near = _clustered(np.linalg.eigvals(As))
        why = (f"{near} of its {2 * n} eigenvalues lie within 1 % of another; stiffness-proportional damping of "
               "high modes, e.g. Rayleigh beta, puts their slow decay rates all near 1/beta); lower that damping or "
               "the mode count" if near else
               f"its {2 * n} coordinates and their inverse map agree only to {miss:.1g}); lower the mode count")
        raise SimulationError(
            f"non-proportional damping: the state's coordinates are too ill-conditioned to integrate exactly ({why}, "
            'or run method = "ivp"'
        )
    G = np.stack([Gm[:, :n], Gm[:, n:]])
    H = np.stack([Hm[:n], Hm[n:]])
    # loads: the modal force f enters x' as [0; f]; on the blocks (alpha, beta) = H [0; f]
    A1, B1 = Hm[:n, n:], Hm[n:, n:]
    LW = np.stack([B1 @ pw, A1 @ pw, B1 @ pre, A1 @ pre])
    CW = np.stack([Wc @ B1.T, Wc @ A1.T])
    top0, top1, bot0, bot1 = G[0, :n], G[1, :n], G[0, n:], G[1, n:]
    RW = np.stack([Wc @ top0, Wc @ top1, Wc @ bot0, Wc @ bot1])
    return SlotArrays(reg, dec, wdh, om, LW, CW, RW, 1, G, H, np.asarray(C, dtype=float), residual)
