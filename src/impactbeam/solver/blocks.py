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
which :func:`slot_arrays` measures (``residual`` of the subspaces, the
inverse map, and the blocks' evolution against ``expm``,
:func:`exponential_error`) and refuses beyond it with a clear message.

Real eigenvalues are paired so that no block is nearly a multiple of the
identity (:func:`_pairs`): stiffness-proportional damping (Rayleigh
``beta``) puts the slow rates of all over-damped modes near ``1/beta``,
and two of them in one block have singular companion coordinates. When
more than half the real rates of a state crowd together, two must share a
block: that state is refused.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..exceptions import SimulationError

__all__ = ["SlotArrays", "slot_arrays", "classical_slot", "block_structure", "exponential_error"]

_CLUSTER = 1e-10  # relative size of an imaginary part under which an eigenvalue is real
_PARALLEL = 0.1  # sine of the angle under which two real eigenvectors are taken as one nearly defective pair
_APART = 0.1  # relative difference of magnitude from which two real eigenvalues may share a block


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


def _pairs(lam: np.ndarray, vec: np.ndarray, scale: float) -> list[tuple[int, int]]:
    """Indices of the eigenvalues taken two by two: conjugate pairs, then the real ones.

    Two real eigenvalues whose eigenvectors are nearly parallel (``sin`` of
    their angle below :data:`_PARALLEL`: a nearly defective pair, near
    critical damping) share a block, the largest cosine first. Each other
    real one goes with its nearest whose magnitude differs by :data:`_APART`
    or more, the one with the fewest such partners first (ties in order of
    the real part). Two nearly equal rates with independent eigenvectors
    would make a block that is nearly a multiple of the identity, whose
    companion coordinates are singular: stiffness-proportional damping
    (Rayleigh ``beta``) crowds the slow rates of every over-damped mode near
    ``1/beta``, mass-proportional damping the fast ones near ``alpha``. A
    rate with no such partner left takes its nearest (the checks of
    :func:`slot_arrays` then judge the blocks).
    """
    complex_ = np.abs(lam.imag) > _CLUSTER * scale
    used = np.zeros(lam.size, dtype=bool)
    out = []
    order = np.lexsort((np.abs(lam.imag), lam.real))
    for i in order:
        if used[i] or not complex_[i]:
            continue
        used[i] = True
        cand = np.where(used | ~complex_, np.inf, np.abs(lam - np.conj(lam[i])))
        j = int(np.argmin(cand))
        if not np.isfinite(cand[j]):
            raise SimulationError("non-proportional damping: an eigenvalue of a state has no partner")
        used[j] = True
        out.append((int(i), j))
    real = np.array([i for i in order if not used[i]], dtype=np.int64)
    if real.size % 2:
        raise SimulationError("non-proportional damping: an eigenvalue of a state has no partner")
    U = vec[:, real].real
    U = U / np.maximum(np.linalg.norm(U, axis=0), 1e-300)
    cos2 = (U.T @ U) ** 2
    parallel = cos2 >= 1.0 - _PARALLEL**2
    r = lam[real].real
    distance = np.abs(r[:, None] - r[None, :])
    apart = distance >= _APART * np.maximum(np.abs(r[:, None]), np.abs(r[None, :]))
    np.fill_diagonal(distance, np.inf)
    np.fill_diagonal(cos2, -1.0)
    left = np.ones(real.size, dtype=bool)

    def take(a: int, b: int) -> None:
        out.append((int(real[a]), int(real[b])))
        left[[a, b]] = False
        cos2[[a, b], :] = -1.0
        cos2[:, [a, b]] = -1.0

    while real.size:
        a, b = np.unravel_index(int(np.argmax(cos2)), cos2.shape)
        if cos2[a, b] < 1.0 - _PARALLEL**2:
            break
        take(int(a), int(b))
    while left.any():
        ok = (apart | parallel) & left[None, :] & left[:, None]
        np.fill_diagonal(ok, False)
        counts = np.where(left, ok.sum(axis=1), real.size + 1)
        a = int(np.argmin(counts))
        cand = np.where(left, np.where(ok[a], distance[a], np.inf), np.inf)
        if not np.isfinite(cand).any():
            cand = np.where(left, distance[a], np.inf)
        take(a, int(np.argmin(cand)))
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
    for i, j in _pairs(lam, vec, scale):
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
    """``S`` with ``S^-1 M S = [[0, 1], [-omega^2, -2a]]`` (best conditioned of a few ``e``), and ``a``, ``omega^2``.

    The condition is that of ``S`` with unit columns: the first column is of
    the size of the block's rates, the second of one, and a column's size is
    the scale of a coordinate, which no result depends on.
    """
    a = -0.5 * float(np.trace(M))
    w2 = float(np.linalg.det(M))
    N = M + 2.0 * a * np.eye(2)
    best, best_cond = None, np.inf
    for e in (np.array([1.0, 0.0]), np.array([0.0, 1.0]), np.array([1.0, 1.0]) / np.sqrt(2.0),
              np.array([1.0, -1.0]) / np.sqrt(2.0)):
        S = np.column_stack([N @ e, e])
        cond = np.linalg.cond(S / np.maximum(np.linalg.norm(S, axis=0), 1e-300))  # the columns' sizes do not matter
        if cond < best_cond:
            best, best_cond = S, cond
    if best is None or not np.isfinite(best_cond) or best_cond > 1e10:
        raise SimulationError(
            "non-proportional damping: a block of a state is a multiple of the identity (a repeated eigenvalue "
            "with two independent modes); change a damping value slightly"
        )
    return best, a, max(w2, 0.0)


def exponential_error(As: np.ndarray, Gs: np.ndarray, Hs: np.ndarray, dec: np.ndarray, om: np.ndarray) -> float:
    """How far the blocks' own evolution departs from ``expm(As t)``, relative to the state's size.

    Each block's companion matrix ``[[0, 1], [-omega^2, -2a]]`` advanced by
    its 2 x 2 exponential and mapped by ``Gs`` (its inverse ``Hs``), against
    scipy's ``expm`` of the whole scaled matrix ``As``, from a fixed random
    state, at the times ``1 / r`` of the slowest and fastest nonzero rates
    ``r`` of the blocks and their geometric mean: an error in a block's
    rates or subspace shows where that block's motion does.

    Parameters
    ----------
    As : ndarray, (2n, 2n)
        The state's first-order matrix in the scaled coordinates (:func:`block_structure`).
    Gs, Hs : ndarray, (2n, 2n)
        The map from the blocks' coordinates ``(z0, z1)`` (all ``z0`` first) to
        the scaled coordinates, and its inverse.
    dec, om : ndarray, (n,)
        Each block's ``a`` and ``omega``.

    Returns
    -------
    float
        The largest difference, relative to the largest component of the exact state.
    """
    from scipy.linalg import expm

    n = dec.size
    w2 = om**2
    fast = np.abs(dec) + np.sqrt(np.abs(dec**2 - w2))
    rates = np.concatenate([fast, w2 / np.maximum(fast, 1e-300)])
    rates = rates[rates > 1e-300]
    if not rates.size:
        return 0.0
    lo, hi = float(rates.min()), float(rates.max())
    x0 = np.random.default_rng(0).standard_normal(2 * n)
    z0 = Hs @ x0
    companion = np.zeros((n, 2, 2))
    companion[:, 0, 1] = 1.0
    companion[:, 1, 0] = -w2
    companion[:, 1, 1] = -2.0 * dec
    worst = 0.0
    for t in (1.0 / hi, 1.0 / np.sqrt(lo * hi), 1.0 / lo):
        zt = np.einsum("kij,kj->ki", expm(t * companion), np.column_stack([z0[:n], z0[n:]]))
        z = np.concatenate([zt[:, 0], zt[:, 1]])
        exact = expm(t * As) @ x0
        worst = max(worst, float(np.max(np.abs(Gs @ z - exact))) / max(float(np.max(np.abs(exact))), 1e-300))
    return worst


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
        When the invariant subspaces are not accurate to 1e-8, the coordinates
        and their inverse map agree only to more than 1e-6, or the blocks'
        evolution departs from ``expm`` by more than 1e-6
        (:func:`exponential_error`): more than half of a state's real rates
        crowded together, a defective block of more than two.
    """
    n = omega.size
    As, dscale, blocks, residual = block_structure(omega, C)
    if len(blocks) != n or residual > 1e-8:
        raise SimulationError(
            f"non-proportional damping: the state's block decomposition is not accurate ({residual:.2g}); "
            "this damping cannot be integrated exactly"
        )
    Gs = np.zeros((2 * n, 2 * n))  # the map in the scaled coordinates: columns z0_k (k < n), then z1_k (n + k)
    reg = np.zeros(n, dtype=np.int64)
    dec = np.zeros(n)
    om = np.zeros(n)
    unscale = np.concatenate([1.0 / dscale, np.ones(n)])  # xs -> x
    # round-off floors: a block's entries carry errors of about the round-off of the largest rate (the
    # eigenvectors are of the whole matrix), so a decay rate below 1e-13 of it and an omega^2 below 1e-13 of it
    # times the block's size are zero: a rigid-body block gets exact polynomials, not A / omega^2 against its
    # homogeneous part. (Against the largest rate squared, the floor zeroed the omega^2 = r1 r2 of a block
    # pairing a slow rate with a moderate one when the damping's largest rate is 1e7 times larger.)
    rate = max(float(np.max(omega)), float(np.max(np.abs(C))), 1e-300)
    for k, Y in enumerate(blocks):
        M = Y.T @ As @ Y
        S, a, w2 = _companion(M)
        if w2 < 1e-13 * rate * float(np.max(np.abs(M))):
            w2 = 0.0
        if abs(a) < 1e-13 * rate:
            a = 0.0
        YS = Y @ S
        Gs[:, k] = YS[:, 0]
        Gs[:, n + k] = YS[:, 1]
        dec[k] = a
        om[k] = np.sqrt(w2)
    reg, wdh = _regimes(om, dec)
    # inverted with unit columns in the scaled coordinates: a block's two columns differ in size by its rates,
    # and the coordinates (d eta, eta') by d, which neither the accuracy of the map nor its inverse depends on
    norms = np.linalg.norm(Gs, axis=0)
    Gn = Gs / norms
    Hn = np.linalg.inv(Gn)
    miss = float(np.linalg.norm(Hn @ Gn - np.eye(2 * n), np.inf))
    Gm = unscale[:, None] * Gs
    Hm = Hn / norms[:, None] / unscale[None, :]
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
    error = exponential_error(As, Gs, Hn / norms[:, None], dec, om)
    if error > 1e-6:
        raise SimulationError(
            "non-proportional damping: the state's block coordinates reproduce its matrix exponential only to "
            f"{error:.1g}; lower that damping or the mode count, or run method = \"ivp\""
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
