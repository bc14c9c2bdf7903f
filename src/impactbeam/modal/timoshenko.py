r"""Exact natural frequencies and mode shapes of a Timoshenko beam.

The engine of :mod:`impactbeam.modal` for ``[beam] theory = "timoshenko"``.
On a uniform segment with bending stiffness ``EI``, shear stiffness
``kappa G A``, mass ``rho A`` and rotary inertia ``rho I`` per length, a
harmonic motion ``w = W(x) cos(omega t)``, ``psi = Psi(x) cos(omega t)``
(``psi`` the rotation of the cross-section) obeys

.. math:: \kappa G A (W'' - \Psi') + \rho A \omega^2 W = 0, \qquad
          E I \Psi'' + \kappa G A (W' - \Psi) + \rho I \omega^2 \Psi = 0,

the Timoshenko form of the paper's eq. (1) (its conclusions ask for shear).
With the bending moment ``M = EI Psi'`` and the shear force
``V = kappa G A (W' - Psi)`` the state ``y = (W, Psi, M, V)`` satisfies
``y' = A(omega) y``,

.. math:: A = \begin{pmatrix} 0 & 1 & 0 & 1/\kappa GA \\ 0 & 0 & 1/EI & 0 \\
          0 & -\rho I \omega^2 & 0 & -1 \\ -\rho A \omega^2 & 0 & 0 & 0 \end{pmatrix},

whose eigenvalues are ``+-mu_1`` and ``+-i k_2``: ``mu_1`` is real below the
cut-off ``omega_c = sqrt(kappa G A / rho I)`` of the second spectrum and
imaginary above it. Rather than switch between the two closed forms (which
degenerate at the cut-off), each segment is cut into ``n`` equal elements
short enough that ``k_2 h <= 1``, and the transfer matrix ``exp(A h)`` of an
element is summed as its Taylor series (26 terms: the truncation is below
``1e-26``), exact in both regimes and through the cut-off.

Nodes carry the end supports and attachments as for Euler-Bernoulli, acting
on the cross-section rotation: ``[M]^+_- = (K_t - J omega^2) Psi`` and
``-[V]^+_- = (k - m omega^2) W`` (an end spring alone gives the paper's end
conditions with ``W'`` replaced by ``Psi``).

Roots are counted with the Wittrick-Williams algorithm on the exact dynamic
stiffness of the elements. An element is short enough that its
clamped-clamped frequencies all lie above ``omega``: with zero end values,
Friedrichs' inequality ``int f^2 <= (h / pi)^2 int f'^2`` bounds the kinetic
energy by ``C (U_bending + U_shear)`` with
``C = max(2 rho A h^2 / (pi^2 kappa G A), (2 rho A h^4 / pi^2 + rho I h^2) / (pi^2 EI))``,
so ``omega^2 C < 1`` guarantees ``J_0 = 0``. The count is then the number of
negative eigenvalues of the assembled (banded) dynamic stiffness matrix, and a
root is the zero of its eigenvalue of the bracket's index, which decreases
monotonically with ``omega``.

References
----------
.. [1] W. Xu, E. K. Ervin, Shock and Vibration 20 (2013), eq. (1) and conclusions.
.. [2] S. P. Timoshenko, Phil. Mag. 41 (1921) 744-746.
.. [3] W. P. Howson, F. W. Williams, "Natural frequencies of frames with axially
   loaded Timoshenko members", J. Sound Vib. 26 (1973) 503-515.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .euler import Layout, bracket_wavenumbers
from .roots import brentq
from ..exceptions import ModeSolveError, ResourceError
from ..model.beam import Beam

__all__ = ["Segments", "TimoshenkoShapes", "negative_pivots", "segments", "solve"]

_TERMS = 26  # Taylor terms of exp(A h) with spectral radius <= 1: truncation < 1 / 27!
_FACT = np.array([math.factorial(n) for n in range(_TERMS + 1)], dtype=float)
_J0_MARGIN = 0.9  # omega^2 C <= 0.9 < 1: clamped element frequencies stay above omega


@dataclass(frozen=True)
class Segments:
    """Timoshenko properties of the uniform segments of a :class:`~impactbeam.modal.euler.Layout`."""

    lay: Layout
    EI: np.ndarray  # [N m^2]
    GA: np.ndarray  # kappa G A [N]
    rhoA: np.ndarray  # [kg/m]
    rhoI: np.ndarray  # [kg m]


def segments(beam: Beam, lay: Layout) -> Segments:
    """The properties of each segment of ``lay`` from the pieces of ``beam``."""
    pieces = beam.pieces()
    edges = np.concatenate([[0.0], np.cumsum([p.length for p in pieces])])
    mid = 0.5 * (lay.nodes[:-1] + lay.nodes[1:])
    idx = np.clip(np.searchsorted(edges, mid, side="right") - 1, 0, len(pieces) - 1)
    sel = [pieces[i] for i in idx]
    return Segments(
        lay,
        np.array([p.bending_stiffness for p in sel]),
        np.array([beam.shear_stiffness(p) for p in sel]),
        np.array([p.mass_per_length for p in sel]),
        np.array([p.density * p.second_moment for p in sel]),
    )


# --------------------------------------------------------------------------- elements


def wavenumbers(seg: Segments, omega: float) -> tuple[np.ndarray, np.ndarray]:
    """``k_2`` (propagating) and ``mu_1^2`` (> 0 below the cut-off, < 0 above) per segment."""
    w2 = omega * omega
    a = seg.rhoA * w2 / seg.GA
    c = seg.rhoI * w2 / seg.EI
    b4 = seg.rhoA * w2 / seg.EI
    disc = np.sqrt((a - c) ** 2 + 4.0 * b4)
    k2 = np.sqrt(0.5 * (a + c + disc))
    mu2 = 2.0 * (b4 - a * c) / np.maximum(disc + a + c, np.finfo(float).tiny)  # no cancellation
    return k2, mu2


def subdivision(seg: Segments, omega: float) -> np.ndarray:
    """Elements per segment valid for every frequency up to ``omega``: ``k_2 h <= 1`` and ``J_0 = 0``."""
    lens = seg.lay.lengths
    if omega <= 0.0:
        return np.ones(lens.size, dtype=int)
    k2, _ = wavenumbers(seg, omega)
    w2 = omega * omega
    pi2 = math.pi**2
    h_shear = np.sqrt(_J0_MARGIN * pi2 * seg.GA / (2.0 * seg.rhoA * w2))
    qa, qb = 2.0 * seg.rhoA / (pi2 * pi2 * seg.EI), seg.rhoI / (pi2 * seg.EI)  # qa X^2 + qb X <= 0.9 / w2
    X = 2.0 * (_J0_MARGIN / w2) / (qb + np.sqrt(qb * qb + 4.0 * qa * _J0_MARGIN / w2))
    h = np.minimum(np.minimum(1.0 / k2, h_shear), np.sqrt(X))
    return np.maximum(1, np.ceil(lens / h * (1.0 + 1e-12))).astype(int)


def _series(seg: Segments, h: np.ndarray, omega: float) -> np.ndarray:
    """``A_hat^n / n!`` for n = 0.._TERMS of each segment's element, scaled state: shape (s, N+1, 4, 4).

    The scaled state of an element of length ``h`` is ``(W, Psi h, M h^2/EI, V h^3/EI)`` in
    ``xi = u / h``, so the series has entries of order one.
    """
    w2 = omega * omega
    s = seg.EI.size
    A = np.zeros((s, 4, 4))
    A[:, 0, 1] = 1.0
    A[:, 0, 3] = seg.EI / (seg.GA * h * h)
    A[:, 1, 2] = 1.0
    A[:, 2, 1] = -seg.rhoI * w2 * h * h / seg.EI
    A[:, 2, 3] = -1.0
    A[:, 3, 0] = -seg.rhoA * w2 * h**4 / seg.EI
    out = np.empty((s, _TERMS + 1, 4, 4))
    out[:, 0] = np.eye(4)
    for n in range(1, _TERMS + 1):
        out[:, n] = out[:, n - 1] @ A / n
    return out


def _scale(seg: Segments, h: np.ndarray, ell: float, EI0: float) -> np.ndarray:
    """Diagonal taking an element's scaled state to the global one ``(W, Psi l, M l^2/EI0, V l^3/EI0)``."""
    return np.stack([np.ones_like(h), ell / h, ell**2 * seg.EI / (h**2 * EI0), ell**3 * seg.EI / (h**3 * EI0)], 1)


def _stiffness(T: np.ndarray) -> np.ndarray:
    """Dynamic stiffness (s, 4, 4) of elements from their transfer matrices (global scaling).

    Degrees of freedom ``(W0, Psi0 l, W1, Psi1 l)``; the conjugate end loads are
    ``(-V0, -M0, V1, M1)`` scaled like the state.
    """
    Tdd, Tdg, Tgd, Tgg = T[:, :2, :2], T[:, :2, 2:], T[:, 2:, :2], T[:, 2:, 2:]
    inv = np.linalg.inv(Tdg)
    swap = np.array([[0.0, 1.0], [1.0, 0.0]])
    K = np.empty(T.shape)
    K[:, :2, :2] = swap @ (inv @ Tdd)
    K[:, :2, 2:] = -swap @ inv
    K[:, 2:, :2] = swap @ (Tgd - Tgg @ inv @ Tdd)
    K[:, 2:, 2:] = swap @ (Tgg @ inv)
    return 0.5 * (K + np.swapaxes(K, 1, 2))


# --------------------------------------------------------------------------- the assembled problem


@dataclass(frozen=True)
class Mesh:
    """Elements of every segment, fixed for all frequencies up to the one it was made for."""

    seg: Segments
    n: np.ndarray  # elements per segment
    ell: float  # global length scale [m]

    @property
    def h(self) -> np.ndarray:
        return self.seg.lay.lengths / self.n

    @property
    def first_node(self) -> np.ndarray:
        """Global node index of each layout node."""
        return np.concatenate([[0], np.cumsum(self.n)])

    @property
    def edges(self) -> np.ndarray:
        """Element boundaries [m]."""
        nodes = self.seg.lay.nodes
        parts = [np.linspace(a, b, k + 1)[:-1] for a, b, k in zip(nodes[:-1], nodes[1:], self.n)]
        return np.concatenate(parts + [nodes[-1:]])

    def transfer(self, omega: float) -> tuple[np.ndarray, np.ndarray]:
        """Element series (s, N+1, 4, 4) and global-scaled transfer matrices (s, 4, 4)."""
        P = _series(self.seg, self.h, omega)
        D = _scale(self.seg, self.h, self.ell, self.seg.lay.EI)
        return P, D[:, :, None] * P.sum(axis=1) / D[:, None, :]

    def band(self, omega: float) -> np.ndarray:
        """Lower band storage (4, 2 n_nodes) of the dynamic stiffness with the node terms."""
        lay = self.seg.lay
        Ke = _stiffness(self.transfer(omega)[1])
        ne = int(self.n.sum())
        per = np.repeat(Ke, self.n, axis=0)  # (ne, 4, 4)
        base = 2 * np.arange(ne)
        ab = np.zeros((4, 2 * ne + 2))
        for r in range(4):
            for c in range(r + 1):
                np.add.at(ab[r - c], base + c, per[:, r, c])
        EI0, ell, w2 = lay.EI, self.ell, omega * omega
        dof = 2 * self.first_node
        scale = np.abs(ab[0]).max(initial=1.0)
        for node, d in enumerate(dof):
            for j, (spring, inertia, factor) in enumerate(
                ((lay.k[node], lay.m[node], ell**3 / EI0), (lay.kt[node], lay.J[node], ell / EI0))
            ):
                if math.isinf(spring):  # a rigid support: the row and column become a positive constant
                    g = d + j
                    ab[0, g] = scale
                    for off in (1, 2, 3):
                        ab[off, g] = 0.0
                        if g - off >= 0:
                            ab[off, g - off] = 0.0
                else:
                    ab[0, d + j] += (spring - inertia * w2) * factor
        return ab

    def count(self, omega: float) -> int:
        """Natural frequencies below ``omega`` (valid for omega up to the mesh's frequency)."""
        return negative_pivots(self.band(omega))

    def eigen(self, omega: float, lo: int, hi: int) -> tuple[np.ndarray, np.ndarray]:
        """Eigenvalues ``lo..hi`` (ascending, inclusive) of the dynamic stiffness and their vectors."""
        from scipy.linalg import eig_banded

        return eig_banded(self.band(omega), lower=True, select="i", select_range=(lo, hi))

    def null_vector(self, omega: float, index: int) -> np.ndarray:
        """The null vector of the dynamic stiffness at a simple root ``omega`` (eigenvalue ``index``), by inverse iteration.

        At a root refined to a few units of round-off the matrix is singular
        to working precision, so two banded solves (LU with partial pivoting,
        ``O(nodes)``) from a fixed start leave the null direction alone; the
        eigenvectors of :meth:`eigen` cost ``O(nodes^2)`` (18 ms a mode at
        200 modes of the thick example, against ~1 ms).
        """
        from scipy.linalg import solve_banded

        ab = self.band(omega)
        n = ab.shape[1]
        full = np.zeros((7, n))  # general band storage, 3 diagonals above and below: full[3 + i - j, j] = K[i, j]
        for r in range(4):
            full[3 + r, : n - r] = ab[r, : n - r]
            full[3 - r, r:] = ab[r, : n - r]
        x = np.cos(0.7 * np.arange(n) + 0.3)  # a fixed start, not orthogonal to any mode in practice
        for _ in range(2):
            with np.errstate(all="ignore"):
                x = solve_banded((3, 3), full, x / np.abs(x).max(), check_finite=False)
            if not np.all(np.isfinite(x)):  # exactly singular: the factorisation's zero pivot
                return self.eigen(omega, index, index)[1][:, 0]
        return x / np.linalg.norm(x)


def negative_pivots(ab: np.ndarray) -> int:
    """Negative eigenvalues of the banded dynamic stiffness: its inertia by a block ``L D L^T`` over the nodes.

    The matrix (lower band storage ``ab``, 2 degrees of freedom per node,
    elements joining neighbouring nodes) is block tridiagonal with 2x2
    blocks ``A_g`` on the diagonal and ``B_g`` below it. The Schur
    complements ``S_g = A_g - B_{g-1} S_{g-1}^{-1} B_{g-1}^T`` have together
    the inertia of the matrix (Haynsworth), so the count is the number of
    negative eigenvalues of the ``S_g``: the Wittrick-Williams sign count in
    ``O(nodes)`` operations (Gaussian elimination without interchanges, as
    Wittrick and Williams count), against ``O(nodes^2)`` for the eigenvalues.
    A singular ``S_g`` (``omega`` exactly at a frequency of the part of the
    beam up to that node) is moved off zero by one unit of round-off.

    Parameters
    ----------
    ab : ndarray, (4, 2 n_nodes)
        Lower band storage: ``ab[r, c] = K[c + r, c]``.

    Returns
    -------
    int
    """
    return _block_pivots(ab, False)[0]


def log_determinant(ab: np.ndarray) -> tuple[float, float]:
    """Sign and ``log |det|`` of the banded dynamic stiffness: the product of the ``det S_g`` of
    :func:`negative_pivots`' elimination (one pass, no overflow)."""
    _, sign, logdet = _block_pivots(ab, True)
    return sign, logdet


def _block_pivots(ab: np.ndarray, determinant: bool) -> tuple[int, float, float]:
    """The elimination of :func:`negative_pivots`: negative eigenvalues and, with ``determinant``, sign and
    ``log |det|`` (the count alone skips the logarithms: it runs at every bisection step)."""
    d0, d1, d2, d3 = (row.tolist() for row in ab)
    tiny = np.finfo(float).eps
    neg = 0
    sign, logdet = 1.0, 0.0
    s11 = s12 = s22 = det = 0.0
    for i in range(0, len(d0) - 1, 2):
        a11, a12, a22 = d0[i], d1[i], d0[i + 1]
        if i:
            b11, b12, b21, b22 = d2[i - 2], d1[i - 1], d3[i - 2], d2[i - 1]  # K[node g, node g-1]
            # B adj(S) B^T / det(S), adj(S) = [[s22, -s12], [-s12, s11]]
            u11, u12 = b11 * s22 - b12 * s12, b12 * s11 - b11 * s12
            u21, u22 = b21 * s22 - b22 * s12, b22 * s11 - b21 * s12
            a11 -= (u11 * b11 + u12 * b12) / det
            a12 -= (u11 * b21 + u12 * b22) / det
            a22 -= (u21 * b21 + u22 * b22) / det
        det = a11 * a22 - a12 * a12
        if det == 0.0:
            det = tiny * (abs(a11) + abs(a22)) ** 2 or tiny
        neg += 1 if det < 0.0 else (2 if a11 + a22 < 0.0 else 0)
        if determinant:
            if det < 0.0:
                sign = -sign
            logdet += math.log(abs(det))
        s11, s12, s22 = a11, a12, a22
    return neg, sign, logdet


#: Most elements of a mesh. 200 modes of a beam of L/h = 5 need 3875 at most; a mesh far finer means
#: a shear stiffness ``kappa G A`` negligible against ``E I / L^2`` (shear modes without end below
#: any frequency), and its shapes would take 4.5 kB per element and mode.
MAX_ELEMENTS = 200_000
_BYTES_PER_ELEMENT = 4608  # the series of a null vector (27 x 4 x 4 doubles) and its coefficients


def _mesh(seg: Segments, omega: float) -> Mesh:
    n = subdivision(seg, omega)
    total = int(n.sum())
    if total > MAX_ELEMENTS:
        raise ResourceError(
            f"Timoshenko modes: resolving frequencies up to {omega / (2 * math.pi):.3g} Hz needs {total:.3g} "
            f"elements (~{total * _BYTES_PER_ELEMENT / 2**30:.3g} GiB for the mode shapes), more than "
            f"{MAX_ELEMENTS}: the shear stiffness kappa G A = {float(np.min(seg.GA)):.3g} N is negligible "
            f"against the bending stiffness E I / L^2; check beam.shear_coefficient and beam.poisson_ratio "
            "(or shear_modulus), or use fewer modes"
        )
    return Mesh(seg, n, float(seg.lay.nodes[-1] / total))


def count_below(seg: Segments, omega: float) -> int:
    """Wittrick-Williams count of natural frequencies strictly below ``omega`` [rad/s]."""
    return _mesh(seg, omega).count(omega)


# --------------------------------------------------------------------------- shapes


@dataclass(frozen=True, eq=False)
class TimoshenkoShapes:
    """Elastic mode shapes as a Taylor series per element (scaled state, see :func:`_series`).

    Each mode has its own mesh, the coarsest valid at its frequency: a finer
    one would make the dynamic stiffness, and so the null vector, needlessly
    ill-conditioned (like a fine finite-element stiffness).
    """

    seg: Segments
    omega: np.ndarray  # (n,)
    meshes: tuple[Mesh, ...]  # per mode
    coef: list[np.ndarray]  # per mode: (elements, N+1, 4)

    def _locate(self, mesh: Mesh, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        edges = mesh.edges
        e = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, edges.size - 2)
        j = np.repeat(np.arange(mesh.n.size), mesh.n)[e]
        return e, j, (x - edges[e]) / mesh.h[j]

    def state(self, x: np.ndarray) -> tuple[np.ndarray, ...]:
        """``(W, Psi, M, V)`` per unit modal coordinate at ``x``: four arrays (n, p)."""
        out = np.zeros((4, self.omega.size, x.size))
        for m, (mesh, coef) in enumerate(zip(self.meshes, self.coef)):
            e, j, xi = self._locate(mesh, x)
            c = coef[e]  # (p, N+1, 4)
            acc = c[:, -1]
            for k in range(_TERMS - 1, -1, -1):
                acc = acc * xi[:, None] + c[:, k]
            h, EI = mesh.h[j], self.seg.EI[j]
            out[:, m] = (acc[:, 0], acc[:, 1] / h, acc[:, 2] * EI / h**2, acc[:, 3] * EI / h**3)
        return tuple(out)

    def derivative(self, x: np.ndarray, order: int) -> np.ndarray:
        """``d^order W / dx^order`` (order 0..3) from the state and the field equations."""
        W, Psi, M, V = self.state(x)
        if order == 0:
            return W
        nodes = self.seg.lay.nodes
        j = np.clip(np.searchsorted(nodes, x, side="right") - 1, 0, nodes.size - 2)
        GA, EI, rhoA, rhoI = self.seg.GA[j], self.seg.EI[j], self.seg.rhoA[j], self.seg.rhoI[j]
        w2 = (self.omega**2)[:, None]
        d1 = Psi + V / GA
        if order == 1:
            return d1
        if order == 2:
            return M / EI - rhoA * w2 * W / GA
        return -(V + rhoI * w2 * Psi) / EI - rhoA * w2 * d1 / GA

    def transform(self, T: np.ndarray) -> None:
        """Replace the shapes by ``T @ shapes`` in place (T mixes only modes that share a mesh)."""
        new = []
        for a in range(T.shape[0]):
            acc = np.zeros_like(self.coef[a])
            for b in np.flatnonzero(T[a]):
                if self.meshes[b] is not self.meshes[a]:
                    raise AssertionError("modes on different meshes cannot be mixed")
                acc += T[a, b] * self.coef[b]
            new.append(acc)
        self.coef[:] = new


def _null_space(mesh: Mesh, omega: float, first: int, last: int) -> list[np.ndarray]:
    """Series coefficients of the null vectors ``first..last`` of the dynamic stiffness at a root."""
    if first == last:
        vec = mesh.null_vector(omega, first)[:, None]
    else:  # a cluster of repeated roots: its null space
        _, vec = mesh.eigen(omega, first, last)
    P, T = mesh.transfer(omega)
    D = _scale(mesh.seg, mesh.h, mesh.ell, mesh.seg.lay.EI)
    inv = np.linalg.inv(T[:, :2, 2:])
    s = np.repeat(np.arange(mesh.n.size), mesh.n)
    out = []
    for i in range(vec.shape[1]):
        d = _rigid_dofs_zero(mesh, vec[:, i].reshape(-1, 2))
        d0, d1 = d[:-1], d[1:]  # (elements, 2)
        g0 = np.einsum("eab,eb->ea", inv[s], d1 - np.einsum("eab,eb->ea", T[s, :2, :2], d0))
        y0 = np.concatenate([d0, g0], axis=1) / D[s]  # element-scaled state at each element's start
        out.append(np.einsum("enab,eb->ena", P[s], y0))
    return out


def _rigid_dofs_zero(mesh: Mesh, d: np.ndarray) -> np.ndarray:
    """Zero the degrees of freedom held by rigid supports (their rows were decoupled)."""
    lay = mesh.seg.lay
    d = d.copy()
    for node, g in enumerate(mesh.first_node):
        if math.isinf(lay.k[node]):
            d[g, 0] = 0.0
        if math.isinf(lay.kt[node]):
            d[g, 1] = 0.0
    return d


def solve(seg: Segments, n_needed: int, j0: int) -> TimoshenkoShapes:
    """The first ``n_needed`` elastic modes above the ``j0`` rigid-body modes.

    Brackets each root alone on the count, narrows the bracket to 5 %, and
    refines the root on the coarsest mesh valid up to the bracket's top: the
    eigenvalue of the bracket's index of the dynamic stiffness changes sign
    there. Shapes are the null vectors on that mesh.
    """
    lay = seg.lay
    c = math.sqrt(lay.EI / lay.rhoA)
    bounds = bracket_wavenumbers(lambda beta: count_below(seg, beta * beta * c), lay, n_needed, j0)
    omegas, meshes = [], []
    for lo, hi, j in bounds:
        lo, hi = lo * lo * c, hi * hi * c
        while hi - lo > 0.05 * hi:
            mid = 0.5 * (lo + hi)
            if count_below(seg, mid) > j:
                hi = mid
            else:
                lo = mid
        meshes.append(_mesh(seg, hi))
        omegas.append(_refine(meshes[-1], lo, hi, j))
    index = [j for _, _, j in bounds]
    coef: list[np.ndarray] = []
    m = 0
    while m < len(omegas):  # a cluster of (nearly) repeated roots shares one null space and mesh
        q = m + 1
        while q < len(omegas) and omegas[q] - omegas[q - 1] <= 1e-7 * omegas[q]:
            q += 1
        for i in range(m + 1, q):
            meshes[i] = meshes[m]
        coef.extend(_null_space(meshes[m], float(np.mean(omegas[m:q])), index[m], index[q - 1]))
        m = q
    return TimoshenkoShapes(seg, np.array(omegas, dtype=float), tuple(meshes), coef)


def _refine(mesh: Mesh, lo: float, hi: float, index: int) -> float:
    """The root in (lo, hi): the ``index``-th eigenvalue of the dynamic stiffness crosses zero.

    In the bracket no other eigenvalue changes sign (the count rises by one
    across it) and the mesh has no element pole, so the determinant changes
    sign once, at the root, and is smooth: Brent's method on it, scaled by
    its value at ``lo`` (:func:`log_determinant`, an ``O(nodes)`` pass; the
    ``index``-th eigenvalue cost ~5x more per evaluation).
    """
    _, ref = log_determinant(mesh.band(lo))

    def f(omega: float) -> float:
        sign, logdet = log_determinant(mesh.band(omega))
        return sign * math.exp(min(logdet - ref, 700.0))

    flo, fhi = f(lo), f(hi)
    if flo * fhi > 0.0:  # a repeated root at the end of its bracket
        if abs(fhi) <= abs(flo):
            return hi
        raise ModeSolveError(f"Timoshenko modes: no sign change for root {index} in ({lo:g}, {hi:g}) rad/s")
    return float(brentq(f, lo, hi, xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=200))

