r"""Exact characteristic matrix, Wittrick-Williams count and roots of a beam state.

The engine of :mod:`impactbeam.modal`. A state of the beam is cut at its nodes
(ends, section steps, interior springs, point masses, engaged contact springs)
into ``s`` uniform segments. Segment ``j`` has ``EI_j``, ``rho A_j`` and the
wavenumber ``beta_j = r_j beta`` with ``r_j = ((rho A_j / EI_j) / (rho A_0 /
EI_0))^(1/4)``, ``beta`` the wavenumber of the reference (``[beam]``) section,
``omega = beta^2 sqrt(EI_0 / rho A_0)`` (paper, after eq. 5). On each segment
the shape is written in the bounded basis ``cos, sin, exp(-beta_j u),
exp(-beta_j (l - u))`` (Krylov-Duncan series on short segments).

Conditions at a node with translational spring ``k``, rotational spring
``K_t``, point mass ``m`` and rotary inertia ``J`` (any of them 0, the springs
possibly ``inf``): ``W`` and ``W'`` continuous,

.. math:: [EI W'']^+_- = (K_t - J\omega^2) W', \qquad
          -[EI W''']^+_- = (k - m\omega^2) W,

which for a spring alone are the paper's contact-state compatibilities and at
an end reduce to the end conditions after eq. (5); at a section step
(nothing attached) they are the continuity of ``EI W''`` and ``EI W'''``. Each
row is divided by ``1 + |kappa|`` (``kappa`` the joint term over
``EI_0 beta^3`` or ``EI_0 beta``) so that the entries stay bounded and an
infinite spring is exact.

The Wittrick-Williams count ``J(omega) = sum_j J0_j + s{K(omega)}`` uses the
exact member stiffnesses in node coordinates ``(w, theta / beta)`` and the
node terms ``k - m omega^2`` and ``K_t - J omega^2`` (a point mass is a
member without internal clamped frequencies).

References
----------
.. [1] W. Xu, E. K. Ervin, Shock and Vibration 20 (2013), section 2, eqs. (2)-(5).
.. [2] W. H. Wittrick, F. W. Williams, Q. J. Mech. Appl. Math. 24 (1971) 263-284.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from .roots import brentq
from ..model.beam import MERGE_DISTANCE, Beam
from ..exceptions import ModeSolveError, ParameterError

_GAUSS_ORDER = 20
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(_GAUSS_ORDER)


# --------------------------------------------------------------------------- configuration


@dataclass(frozen=True)
class Layout:
    """Segments and node terms of one state, springs merged.

    Node arrays have ``s + 1`` entries (node 0 = left end, node ``s`` = right end);
    segment arrays have ``s``.
    """

    nodes: np.ndarray  # segment boundaries [m]
    k: np.ndarray  # translational spring at each node [N/m]
    kt: np.ndarray  # rotational spring at each node [N m/rad]
    m: np.ndarray  # point mass at each node [kg]
    J: np.ndarray  # rotary inertia at each node [kg m^2]
    e: np.ndarray  # EI_j / EI_0 per segment
    rho: np.ndarray  # rho A_j / rho A_0 per segment
    EI: float  # reference EI_0 [N m^2]
    rhoA: float  # reference rho A_0 [kg/m]

    @property
    def n_segments(self) -> int:
        return self.nodes.size - 1

    @property
    def lengths(self) -> np.ndarray:
        return np.diff(self.nodes)

    @property
    def r(self) -> np.ndarray:
        """Wavenumber ratio ``beta_j / beta`` per segment."""
        return (self.rho / self.e) ** 0.25

    @property
    def rhoA_seg(self) -> np.ndarray:
        """rho A per segment [kg/m]."""
        return self.rhoA * self.rho


def layout(beam: Beam, springs: Iterable[tuple[float, float]] = ()) -> Layout:
    """Cut ``beam`` with the engaged contact ``springs`` (position [m], stiffness [N/m]) into segments.

    Section steps are kept exactly; interior springs, masses and contact
    springs closer than ``3e-5 L`` to an existing node (end, step, or an
    earlier attachment, in that order) are merged into it: a shorter segment
    makes the exact dynamic stiffness too ill-conditioned to count roots.
    """
    L = beam.length
    tol = MERGE_DISTANCE * L
    nodes: dict[float, list[float]] = {
        0.0: [beam.left.translational, beam.left.rotational, 0.0, 0.0],
        L: [beam.right.translational, beam.right.rotational, 0.0, 0.0],
    }
    pieces = beam.pieces()
    edges = np.concatenate([[0.0], np.cumsum([p.length for p in pieces])])
    edges[-1] = L
    for x in edges[1:-1]:
        nodes.setdefault(float(x), [0.0, 0.0, 0.0, 0.0])

    def add(x: float, vals: tuple[float, float, float, float]) -> None:
        if not any(vals):
            return
        near = min(nodes, key=lambda p: abs(p - x))
        key = near if abs(near - x) <= tol else x
        row = nodes.setdefault(key, [0.0, 0.0, 0.0, 0.0])
        for i, v in enumerate(vals):
            row[i] += v

    for sp in beam.springs:
        add(sp.position, (sp.translational, sp.rotational, 0.0, 0.0))
    for ms in beam.masses:
        add(ms.position, (0.0, 0.0, ms.mass, ms.rotary_inertia))
    for x, k in springs:
        x, k = float(x), float(k)
        if not (0.0 <= x <= L + tol):
            raise ParameterError(f"spring position {x:g} m is off the beam (length {L:g} m)")
        if k < 0.0 or math.isnan(k):
            raise ParameterError(f"spring stiffness must be >= 0, got {k!r}")
        add(min(x, L), (k, 0.0, 0.0, 0.0))
    xs = np.array(sorted(nodes))
    vals = np.array([nodes[x] for x in xs], dtype=float)
    mid = 0.5 * (xs[:-1] + xs[1:])
    piece = np.clip(np.searchsorted(edges, mid, side="right") - 1, 0, len(pieces) - 1)
    EI0, rhoA0 = beam.bending_stiffness, beam.mass_per_length
    e = np.array([pieces[i].bending_stiffness / EI0 for i in piece])
    rho = np.array([pieces[i].mass_per_length / rhoA0 for i in piece])
    return Layout(xs, vals[:, 0], vals[:, 1], vals[:, 2], vals[:, 3], e, rho, EI0, rhoA0)


def _joint_terms(lay: Layout, beta: float) -> tuple[np.ndarray, np.ndarray]:
    """Node terms ``(k - m w^2) / (EI_0 beta^3)`` and ``(K_t - J w^2) / (EI_0 beta)`` (inf kept)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        kap_t = np.where(np.isinf(lay.k), np.inf, lay.k / (lay.EI * beta**3) - lay.m * beta / lay.rhoA)
        kap_r = np.where(np.isinf(lay.kt), np.inf, lay.kt / (lay.EI * beta) - lay.J * beta**3 / lay.rhoA)
    return kap_t, kap_r

# --------------------------------------------------------------------------- basis functions


_KRYLOV_LIMIT = 1.5  # segments with beta l below this use the Krylov-Duncan basis
_KRYLOV_TERMS = 9
_FACT = np.array([math.factorial(n) for n in range(4 * _KRYLOV_TERMS + 4)], dtype=float)
_POWERS = np.arange(4 * _KRYLOV_TERMS + 4, dtype=float)


def _krylov(z: np.ndarray, deriv: int) -> tuple[np.ndarray, ...]:
    """Krylov-Duncan functions S1..S4 (``(cosh z + cos z)/2`` ...) by their power series.

    ``S_j(z) = sum_m z^(4m+j-1) / (4m+j-1)!``, accurate to round-off for |z| <= 1.5
    (no cancellation, unlike the cosh/cos form). ``d/dz S_j = S_(j-1)`` cyclically.
    """
    out = []
    for j in range(1, 5):
        jj = (j - 1 - deriv) % 4  # power offset of the differentiated function
        acc = np.zeros_like(z)
        for m in range(_KRYLOV_TERMS - 1, -1, -1):
            n = 4 * m + jj
            acc = acc + z**n / _FACT[n]
        out.append(acc)
    return tuple(out)


def _basis(z: np.ndarray, zl: np.ndarray, deriv: int, krylov: np.ndarray | bool = False) -> tuple[np.ndarray, ...]:
    """Basis functions at ``z = beta u`` (``zl = beta l``), ``deriv``-th derivative in ``z``.

    The exponential basis is ``cos z, sin z, exp(-z), exp(-(zl - z))``; where
    ``krylov`` is True the Krylov-Duncan functions ``S1..S4`` are used instead
    (well conditioned on short segments, ``zl <= 1.5``).
    """
    z = np.asarray(z, dtype=float)
    zl = np.asarray(zl, dtype=float)
    krylov = np.asarray(krylov, dtype=bool)
    d = deriv % 4
    out_exp = None
    if not krylov.all():
        c, s = np.cos(z), np.sin(z)
        e1 = np.exp(-z)
        e2 = np.exp(-(zl - z))
        trig = ((c, s), (-s, c), (-c, -s), (s, -c))[d]
        sign = -1.0 if deriv % 2 else 1.0
        out_exp = (trig[0], trig[1], sign * e1, e2 * np.ones_like(z))
        if not krylov.any():
            return out_exp
    zk = np.where(krylov, z, 0.0) if out_exp is not None else z
    out_kry = _krylov(zk, deriv)
    if out_exp is None:
        return out_kry
    return tuple(np.where(krylov, a, b) for a, b in zip(out_kry, out_exp))


def _basis_row(z: float, zl: float, krylov: bool) -> np.ndarray:
    """Scaled derivatives 0..3 of the 4 basis functions at a point: shape (4 derivs, 4 functions).

    The scalar form of :func:`_basis` (the same values), written out because
    the characteristic matrix and the dynamic stiffness call it for every node.
    """
    out = np.empty((4, 4))
    z = float(z)
    if krylov:
        q = z**_POWERS / _FACT[: _POWERS.size]
        for d in range(4):
            for j in range(4):
                out[d, j] = q[(j - d) % 4 :: 4][:_KRYLOV_TERMS][::-1].sum()
        return out
    c, s = math.cos(z), math.sin(z)
    e1, e2 = math.exp(-z), math.exp(-(float(zl) - z))
    out[0] = (c, s, e1, e2)
    out[1] = (-s, c, -e1, e2)
    out[2] = (-c, -s, e1, e2)
    out[3] = (s, -c, -e1, e2)
    return out


# --------------------------------------------------------------------------- characteristic matrix


def krylov_mask(lay: Layout, beta: float) -> np.ndarray:
    """Which segments use the Krylov-Duncan basis at reference wavenumber ``beta``."""
    return beta * lay.r * lay.lengths <= _KRYLOV_LIMIT


def _scaled_rows(lay: Layout, j: int, z: float, beta: float, kry: np.ndarray) -> np.ndarray:
    """Rows ``W, W'/beta, EI W''/(EI_0 beta^2), EI W'''/(EI_0 beta^3)`` of segment ``j`` at ``z = beta_j u``."""
    r, e = lay.r[j], lay.e[j]
    B = _basis_row(z, beta * r * lay.lengths[j], kry[j])
    return B * np.array([1.0, r, e * r**2, e * r**3])[:, None]


def _row(kappa: float, value: np.ndarray, jump: np.ndarray) -> np.ndarray:
    """Row of ``kappa * value - jump = 0`` divided by ``1 + |kappa|``; ``value = 0`` for ``kappa = inf``."""
    if math.isinf(kappa):
        return value
    return (kappa * value - jump) / (1.0 + abs(kappa))


def characteristic(lay: Layout, beta: float, kry: np.ndarray | None = None) -> np.ndarray:
    """The 4s x 4s characteristic matrix (bounded entries) at reference wavenumber ``beta`` [1/m].

    ``kry`` fixes the basis of each segment (default: chosen from ``beta``); it
    must be held fixed while a root is refined so the determinant is continuous.
    """
    s = lay.n_segments
    lens = lay.lengths
    kry = krylov_mask(lay, beta) if kry is None else kry
    kap_t, kap_r = _joint_terms(lay, beta)
    A = np.zeros((4 * s, 4 * s))
    z = np.zeros(4)
    # left end: EI W'' = (Kt - J w^2) W',  -EI W''' = (k - m w^2) W
    B0 = _scaled_rows(lay, 0, 0.0, beta, kry)
    A[0, 0:4] = _row(kap_r[0], B0[1], B0[2])
    A[1, 0:4] = _row(kap_t[0], B0[0], -B0[3])
    row = 2
    for j in range(s - 1):
        BL = _scaled_rows(lay, j, beta * lay.r[j] * lens[j], beta, kry)
        BR = _scaled_rows(lay, j + 1, 0.0, beta, kry)
        cl, cr = slice(4 * j, 4 * j + 4), slice(4 * j + 4, 4 * j + 8)
        A[row, cl], A[row, cr] = BL[0], -BR[0]
        A[row + 1, cl], A[row + 1, cr] = BL[1], -BR[1]
        # moment jump M+ - M- = (Kt - J w^2) W'(a);  shear jump V- - V+ = (k - m w^2) W(a)
        A[row + 2, cl], A[row + 2, cr] = _row(kap_r[j + 1], BL[1], -BL[2]), _row(kap_r[j + 1], z, BR[2])
        A[row + 3, cl], A[row + 3, cr] = _row(kap_t[j + 1], BL[0], BL[3]), _row(kap_t[j + 1], z, -BR[3])
        row += 4
    Bn = _scaled_rows(lay, s - 1, beta * lay.r[-1] * lens[-1], beta, kry)
    cn = slice(4 * (s - 1), 4 * s)
    # right end: -EI W'' = (Kt - J w^2) W',  EI W''' = (k - m w^2) W
    A[row, cn] = _row(kap_r[s], Bn[1], -Bn[2])
    A[row + 1, cn] = _row(kap_t[s], Bn[0], Bn[3])
    return A


def _det(lay: Layout, beta: float, kry: np.ndarray | None = None) -> float:
    return float(np.linalg.det(characteristic(lay, beta, kry)))


# --------------------------------------------------------------------------- Wittrick-Williams count


def _clamped_count(lam: np.ndarray) -> int:
    """Number of clamped-clamped natural frequencies of segments below ``lam = beta l``."""
    lam = np.asarray(lam, dtype=float)
    i = np.floor(lam / np.pi)
    sg = np.sign(1.0 / np.cosh(np.minimum(lam, 700.0)) - np.cos(lam))
    j0 = i - (1.0 - (-1.0) ** i * sg) / 2.0
    # below pi (first root 4.73) the count is 0; the formula cancels there
    return int(np.sum(np.where(lam < np.pi, 0.0, j0)))


def _segment_stiffness(beta: float, length: float) -> np.ndarray:
    """Dynamic stiffness of one segment, DOFs (w0, theta0/beta, w1, theta1/beta), divided by EI beta^3."""
    zl = beta * length
    kry = bool(zl <= _KRYLOV_LIMIT)
    B0 = _basis_row(0.0, zl, kry)
    B1 = _basis_row(zl, zl, kry)
    D = np.array([B0[0], B0[1], B1[0], B1[1]])
    F = np.array([B0[3], -B0[2], -B1[3], B1[2]])
    try:
        K = np.linalg.solve(D.T, F.T).T  # F D^{-1}
    except np.linalg.LinAlgError:  # exactly at a clamped-clamped root of the segment
        return _segment_stiffness(beta * (1.0 + 1e-12), length)
    return 0.5 * (K + K.T)


def count_below(lay_or_beam: Layout | Beam, omega: float, springs: Sequence[tuple[float, float]] = ()) -> int:
    """Number of natural frequencies strictly below ``omega`` [rad/s] (Wittrick-Williams).

    Rigid-body modes count as frequencies at zero.

    Parameters
    ----------
    lay_or_beam : Layout or Beam
        The beam (or its cut into segments).
    omega : float, [rad/s]
    springs : sequence of (position, stiffness)
        Engaged contact springs, [m] and [N/m].
    """
    lay = lay_or_beam if isinstance(lay_or_beam, Layout) else layout(lay_or_beam, springs)
    beta = math.sqrt(omega) * (lay.rhoA / lay.EI) ** 0.25
    return count(lay, beta)


def count(lay: Layout, beta: float) -> int:
    """Wittrick-Williams count of natural frequencies below reference wavenumber ``beta``."""
    s = lay.n_segments
    lens = lay.lengths
    r, e = lay.r, lay.e
    n = 2 * (s + 1)
    K = np.zeros((n, n))
    for j in range(s):
        sl = slice(2 * j, 2 * j + 4)
        T = np.array([1.0, 1.0 / r[j], 1.0, 1.0 / r[j]])
        K[sl, sl] += e[j] * r[j] ** 3 * (T[:, None] * _segment_stiffness(beta * r[j], lens[j]) * T[None, :])
    kap_t, kap_r = _joint_terms(lay, beta)
    keep = np.ones(n, dtype=bool)
    for node in range(s + 1):
        for dof, kap in ((2 * node, kap_t[node]), (2 * node + 1, kap_r[node])):
            if math.isinf(kap):
                keep[dof] = False
            else:
                K[dof, dof] += kap
    Kr = K[np.ix_(keep, keep)]
    return _clamped_count(beta * r * lens) + negative_eigenvalues(Kr)


def negative_eigenvalues(K: np.ndarray) -> int:
    """Number of negative eigenvalues of a symmetric matrix, from its inertia (Sylvester's law).

    A symmetric indefinite factorisation ``K = L D L^T`` with Bunch-Kaufman
    pivoting (:func:`scipy.linalg.ldl`) has the inertia of ``K`` in its 1x1
    and 2x2 blocks ``D``. Unlike the eigenvalues, whose absolute error is
    ``eps`` times the largest entry, the pivots keep their relative
    accuracy when the entries span many decades: a support spring of 1e15
    beside the beam's stiffness, or a short stiff segment, is eliminated
    first and leaves the rest exact (with the eigenvalues, the count and
    with it the modes went wrong there).

    Parameters
    ----------
    K : ndarray, (n, n)
        Symmetric.

    Returns
    -------
    int
    """
    if K.size == 0:
        return 0
    from scipy.linalg import ldl

    _, D, _ = ldl(K, lower=True, hermitian=True)
    neg, i, n = 0, 0, D.shape[0]
    while i < n:
        if i + 1 < n and D[i + 1, i] != 0.0:  # a 2x2 block: one negative eigenvalue if its determinant is < 0
            a, b, c = D[i, i], D[i + 1, i], D[i + 1, i + 1]
            det = a * c - b * b
            neg += 1 if det < 0.0 else (2 if a + c < 0.0 else 0)
            i += 2
        else:
            neg += int(D[i, i] < 0.0)
            i += 1
    return neg


# --------------------------------------------------------------------------- rigid-body modes


def rigid_mass_matrix(lay: Layout, rotary: float = 0.0) -> np.ndarray:
    """Mass matrix of the rigid shapes ``(1, x)``: beam, point masses and rotary inertias.

    ``rotary`` is the beam's own rotary inertia ``int rho I dx`` [kg m^2]
    (a Timoshenko beam's cross-sections turn with a rigid rotation).
    """
    a, b = lay.nodes[:-1], lay.nodes[1:]
    rA = lay.rhoA_seg
    m01 = np.sum(rA * (b**2 - a**2)) / 2.0
    M = np.array([[np.sum(rA * (b - a)), m01], [m01, np.sum(rA * (b**3 - a**3)) / 3.0]])
    x, m = lay.nodes, lay.m
    M += np.array([[np.sum(m), np.sum(m * x)], [np.sum(m * x), np.sum(m * x**2) + np.sum(lay.J) + rotary]])
    return M


def rigid_modes(lay: Layout, rotary: float = 0.0) -> np.ndarray:
    """Mass-normalised rigid-body modes ``W = c0 + c1 x``: array (r, 2) of (c0, c1).

    ``rotary``: the beam's own rotary inertia, see :func:`rigid_mass_matrix`.
    """
    rows = [[1.0, x] for x, k in zip(lay.nodes, lay.k) if k > 0.0]
    if np.any(lay.kt > 0.0):
        rows.append([0.0, 1.0])
    L = lay.nodes[-1]
    if rows:
        # in the dimensionless unknowns (c0, c1 L), each constraint scaled to unit length: the rank
        # must not depend on the units (with (c0, c1 / L) a beam of 1e-10 m lost its clamp's rotation)
        scale = np.array([1.0, 1.0 / L])
        C = np.array(rows) * scale
        _, sv, vt = np.linalg.svd(C / np.linalg.norm(C, axis=1, keepdims=True))
        rank = int(np.sum(sv > 1e-10 * sv[0]))
        null = (vt[rank:] * scale).T  # (2, r)
    else:
        null = np.eye(2)
    M = rigid_mass_matrix(lay, rotary)
    if null.shape[1] == 2:  # free-free: translation first, then rotation about mid-span
        null = np.array([[1.0, -L / 2.0], [0.0, 1.0]])
    out: list[np.ndarray] = []
    for v in null.T:
        for u in out:
            v = v - (u @ M @ v) * u
        v = v / math.sqrt(v @ M @ v)
        # deterministic sign: positive mean displacement, else positive slope
        if (v[0] + v[1] * L / 2.0) < -1e-14 * abs(v).max() or (
            abs(v[0] + v[1] * L / 2.0) <= 1e-14 * abs(v).max() and v[1] < 0.0
        ):
            v = -v
        out.append(v)
    return np.array(out).reshape(-1, 2)

# --------------------------------------------------------------------------- root finding


def bracket_roots(lay: Layout, n_needed: int, j0: int) -> list[tuple[float, float, int]]:
    """Brackets ``(lo, hi, index)`` of the first ``n_needed`` elastic wavenumbers."""
    return bracket_wavenumbers(lambda beta: count(lay, beta), lay, n_needed, j0)


def bracket_wavenumbers(
    count_fn: Callable[[float], int], lay: Layout, n_needed: int, j0: int
) -> list[tuple[float, float, int]]:
    """Brackets ``(lo, hi, index)`` of the first ``n_needed`` roots, each alone, by bisecting a count.

    ``count_fn(beta)`` is the number of natural frequencies below the
    reference wavenumber ``beta`` (Euler-Bernoulli or Timoshenko); ``j0``
    roots (the rigid-body modes) lie at zero.
    """
    if n_needed <= 0:
        return []
    target = j0 + n_needed
    L = lay.nodes[-1]
    hi = (n_needed + 1.5) * math.pi / L * 1.0137 / float(np.max(lay.r))  # off any root of a classical beam
    jhi = count_fn(hi)
    guard = 0
    while jhi < target:
        hi *= 1.6
        jhi = count_fn(hi)
        guard += 1
        if guard > 200:
            raise ModeSolveError("could not bound the requested natural frequencies")
    out: list[tuple[float, float, int]] = []
    stack = [(0.0, hi, j0, jhi)]
    while stack:
        lo, up, jlo, jup = stack.pop()
        if jlo >= target or jup == jlo:
            continue
        if jup - jlo == 1:
            out.append((lo, up, jlo))
            continue
        if up - lo <= 4.0 * np.finfo(float).eps * up:
            # an exactly repeated root: each copy shares the bracket
            out.extend((lo, up, j) for j in range(jlo, min(jup, target)))
            continue
        mid = 0.5 * (lo + up)
        jm = count_fn(mid)
        stack.append((mid, up, jm, jup))
        stack.append((lo, mid, jlo, jm))
    out.sort(key=lambda b: b[2])
    return out[:n_needed]


def refine(lay: Layout, lo: float, hi: float, index: int) -> float:
    """Refine one isolated root in (lo, hi) to machine precision."""
    # narrow the bracket on the exact count first, so one basis serves the whole
    # bracket and its lower end is away from beta = 0
    while hi - lo > 0.05 * hi:
        mid = 0.5 * (lo + hi)
        if count(lay, mid) > index:
            hi = mid
        else:
            lo = mid
    kry = krylov_mask(lay, hi)
    # the determinant changes sign at the isolated root; an end point lying
    # within round-off of a neighbouring root can hide that, so sample inside
    grid = np.linspace(lo, hi, 17)
    vals = np.array([_det(lay, b, kry) for b in grid])
    for i in range(16):
        if vals[i] * vals[i + 1] < 0.0:
            return float(
                brentq(
                    lambda b: _det(lay, b, kry), grid[i], grid[i + 1], xtol=1e-300,
                    rtol=4 * np.finfo(float).eps, maxiter=200,
                )
            )
    # no sign change (repeated root or determinant underflow): bisect the exact count
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if hi - lo <= 4 * np.finfo(float).eps * hi:
            break
        if count(lay, mid) > index:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def null_vector(lay: Layout, beta: float, kry: np.ndarray) -> np.ndarray:
    A = characteristic(lay, beta, kry)
    _, _, vt = np.linalg.svd(A)
    return vt[-1]


# --------------------------------------------------------------------------- quadrature


def quadrature(breaks: np.ndarray, beta_max: float) -> tuple[np.ndarray, np.ndarray]:
    """Piecewise Gauss-Legendre nodes and weights on [0, L], respecting every break.

    Each interval is cut into pieces no longer than ``pi / beta_max`` (half a
    wavelength of the highest mode) with 20 points each, which integrates the
    products of two mode shapes to round-off.
    """
    xs, ws = [], []
    for a, b in zip(breaks[:-1], breaks[1:]):
        if b <= a:
            continue
        n = max(1, math.ceil((b - a) * beta_max / math.pi))
        edges = np.linspace(a, b, n + 1)
        half = 0.5 * np.diff(edges)
        mid = 0.5 * (edges[:-1] + edges[1:])
        xs.append((mid[:, None] + half[:, None] * _GAUSS_X[None, :]).ravel())
        ws.append((half[:, None] * _GAUSS_W[None, :]).ravel())
    return np.concatenate(xs), np.concatenate(ws)


