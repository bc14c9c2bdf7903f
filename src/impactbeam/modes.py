"""Exact modal analysis of a beam with elastic end supports and interior springs.

The beam of :class:`~impactbeam.beam.Beam` with any set of engaged translational
springs (the contact springs) is cut at the springs into ``s`` uniform segments.
On each segment ``[x0, x1]`` (length ``l``) a mode shape is written in the
bounded basis

.. math:: W(x) = C_1 \\cos\\beta u + C_2 \\sin\\beta u + C_3 e^{-\\beta u} + C_4 e^{-\\beta (l - u)},
          \\qquad u = x - x_0,

which spans the same space as the paper's eq. (5) but never grows: every
entry of the characteristic matrix is bounded by one, so the frequencies and
shapes keep full precision up to hundreds of modes (the textbook
``cosh - sigma sinh`` form loses every digit past mode ~12).

The ``4 s`` conditions are the end conditions of the paper (after eq. 5),

.. math:: K_{t1} W'(0) = EI W''(0), \\quad EI W'''(0) = -k_1 W(0),\\quad
          -K_{t2} W'(L) = EI W''(L), \\quad EI W'''(L) = k_2 W(L),

and, at a spring ``k`` at ``x = a`` (paper, contact-state compatibilities),
continuity of ``W, W', W''`` and ``EI (W'''(a^-) - W'''(a^+)) = k W(a)``. Each
spring condition is written with the bounded weights ``p = K/(K + EI b)``,
``q = 1 - p`` so that an infinite spring is exact (``p = 1, q = 0``).

Every root is found exactly once: the Wittrick-Williams count
``J(omega) = sum J0 + s{K(omega)}`` (number of natural frequencies below
``omega``, from the sign count of the exact dynamic stiffness matrix) brackets
each root alone, and Brent's method refines it on the determinant of the
characteristic matrix. Rigid-body modes (zero frequency) are found from the
linear shapes the supports allow.

References
----------
.. [1] W. Xu, E. K. Ervin, "Parameters affecting the transient response of an
   impacting beam", Shock and Vibration 20 (2013), section 2, eqs. (2)-(5), (12).
.. [2] W. H. Wittrick, F. W. Williams, "A general algorithm for computing
   natural frequencies of elastic structures", Q. J. Mech. Appl. Math. 24 (1971).
.. [3] M. Goncalves, M. Brennan, S. Elliott, "Numerical evaluation of high-order
   modes of vibration in uniform Euler-Bernoulli beams", J. Sound Vib. 301 (2007).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from scipy.optimize import brentq

from .beam import Beam
from .exceptions import ModeSolveError, ParameterError

if TYPE_CHECKING:
    from .scenario import Scenario

__all__ = ["ModeSet", "ScenarioModes", "mode_set", "scenario_modes", "modes", "count_below"]

_MERGE_DISTANCE = 3e-5  # fraction of L
_GAUSS_ORDER = 20
_GAUSS_X, _GAUSS_W = np.polynomial.legendre.leggauss(_GAUSS_ORDER)


# --------------------------------------------------------------------------- configuration


@dataclass(frozen=True)
class _Layout:
    """Segments and springs of one state, all spring values merged and normalised."""

    nodes: np.ndarray  # segment boundaries, shape (s + 1,)
    k_left: float
    kt_left: float
    k_right: float
    kt_right: float
    k_joint: np.ndarray  # spring at each interior node, shape (s - 1,)
    EI: float
    rhoA: float

    @property
    def n_segments(self) -> int:
        return self.nodes.size - 1

    @property
    def lengths(self) -> np.ndarray:
        return np.diff(self.nodes)


def _merge_springs(beam: Beam, springs: Iterable[tuple[float, float]]) -> _Layout:
    L = beam.length
    # springs closer than this to an end or to each other are merged: a shorter
    # segment makes the exact dynamic stiffness too ill-conditioned to count roots
    tol = _MERGE_DISTANCE * L
    k_left, k_right = beam.left.translational, beam.right.translational
    interior: dict[float, float] = {}
    for x, k in springs:
        x, k = float(x), float(k)
        if not (0.0 <= x <= L + tol):
            raise ParameterError(f"spring position {x:g} m is off the beam (length {L:g} m)")
        if k < 0.0 or math.isnan(k):
            raise ParameterError(f"spring stiffness must be >= 0, got {k!r}")
        if k == 0.0:
            continue
        if x <= tol:
            k_left += k
        elif x >= L - tol:
            k_right += k
        else:
            key = next((p for p in interior if abs(p - x) <= tol), x)
            interior[key] = interior.get(key, 0.0) + k
    xs = sorted(interior)
    return _Layout(
        nodes=np.array([0.0, *xs, L]),
        k_left=k_left,
        kt_left=beam.left.rotational,
        k_right=k_right,
        kt_right=beam.right.rotational,
        k_joint=np.array([interior[x] for x in xs], dtype=float),
        EI=beam.bending_stiffness,
        rhoA=beam.mass_per_length,
    )


def _weights(K: float, scale: float) -> tuple[float, float]:
    """Bounded weights (p, q) of ``K * a + scale * b = 0``; exact for K = inf."""
    if math.isinf(K):
        return 1.0, 0.0
    den = K + scale
    return K / den, scale / den


# --------------------------------------------------------------------------- basis functions


_KRYLOV_LIMIT = 1.5  # segments with beta l below this use the Krylov-Duncan basis
_KRYLOV_TERMS = 9
_FACT = np.array([math.factorial(n) for n in range(4 * _KRYLOV_TERMS + 4)], dtype=float)


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
    """Scaled derivatives 0..3 of the 4 basis functions at a point: shape (4 derivs, 4 functions)."""
    out = np.empty((4, 4))
    for d in range(4):
        out[d] = np.array(_basis(np.asarray(z), np.asarray(zl), d, krylov), dtype=float)
    return out


# --------------------------------------------------------------------------- characteristic matrix


def _krylov_mask(lay: _Layout, beta: float) -> np.ndarray:
    """Which segments use the Krylov-Duncan basis at wavenumber ``beta``."""
    return beta * lay.lengths <= _KRYLOV_LIMIT


def _characteristic(lay: _Layout, beta: float, kry: np.ndarray | None = None) -> np.ndarray:
    """The 4s x 4s characteristic matrix (bounded entries) at wavenumber ``beta`` [1/m].

    ``kry`` fixes the basis of each segment (default: chosen from ``beta``); it
    must be held fixed while a root is refined so the determinant is continuous.
    """
    s = lay.n_segments
    lens = lay.lengths
    kry = _krylov_mask(lay, beta) if kry is None else kry
    EI = lay.EI
    A = np.zeros((4 * s, 4 * s))
    # left end, segment 0 at u = 0
    B0 = _basis_row(0.0, beta * lens[0], kry[0])
    p, q = _weights(lay.kt_left, EI * beta)
    A[0, 0:4] = p * B0[1] - q * B0[2]
    p, q = _weights(lay.k_left, EI * beta**3)
    A[1, 0:4] = q * B0[3] + p * B0[0]
    row = 2
    for j in range(s - 1):
        BL = _basis_row(beta * lens[j], beta * lens[j], kry[j])
        BR = _basis_row(0.0, beta * lens[j + 1], kry[j + 1])
        cl, cr = slice(4 * j, 4 * j + 4), slice(4 * j + 4, 4 * j + 8)
        for d in range(3):
            A[row + d, cl] = BL[d]
            A[row + d, cr] = -BR[d]
        p, q = _weights(lay.k_joint[j], EI * beta**3)
        A[row + 3, cl] = q * BL[3] - p * BL[0]
        A[row + 3, cr] = -q * BR[3]
        row += 4
    Bn = _basis_row(beta * lens[-1], beta * lens[-1], kry[-1])
    cn = slice(4 * (s - 1), 4 * s)
    p, q = _weights(lay.kt_right, EI * beta)
    A[row, cn] = p * Bn[1] + q * Bn[2]
    p, q = _weights(lay.k_right, EI * beta**3)
    A[row + 1, cn] = q * Bn[3] - p * Bn[0]
    return A


def _det(lay: _Layout, beta: float, kry: np.ndarray | None = None) -> float:
    return float(np.linalg.det(_characteristic(lay, beta, kry)))


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


def count_below(lay_or_beam: _Layout | Beam, omega: float, springs: Sequence[tuple[float, float]] = ()) -> int:
    """Number of natural frequencies strictly below ``omega`` [rad/s] (Wittrick-Williams).

    Rigid-body modes count as frequencies at zero.
    """
    lay = lay_or_beam if isinstance(lay_or_beam, _Layout) else _merge_springs(lay_or_beam, springs)
    beta = math.sqrt(omega) * (lay.rhoA / lay.EI) ** 0.25
    return _count(lay, beta)


def _count(lay: _Layout, beta: float) -> int:
    s = lay.n_segments
    lens = lay.lengths
    n = 2 * (s + 1)
    K = np.zeros((n, n))
    for j in range(s):
        sl = slice(2 * j, 2 * j + 4)
        K[sl, sl] += _segment_stiffness(beta, lens[j])
    scale3 = lay.EI * beta**3
    scale1 = lay.EI * beta
    keep = np.ones(n, dtype=bool)
    springs_w = [lay.k_left, *lay.k_joint, lay.k_right]
    for node, k in enumerate(springs_w):
        if math.isinf(k):
            keep[2 * node] = False
        else:
            K[2 * node, 2 * node] += k / scale3
    for node, kt in ((0, lay.kt_left), (s, lay.kt_right)):
        if math.isinf(kt):
            keep[2 * node + 1] = False
        else:
            K[2 * node + 1, 2 * node + 1] += kt / scale1
    Kr = K[np.ix_(keep, keep)]
    neg = int(np.sum(np.linalg.eigvalsh(Kr) < 0.0)) if Kr.size else 0
    return _clamped_count(beta * lens) + neg


# --------------------------------------------------------------------------- rigid-body modes


def _rigid_modes(lay: _Layout) -> np.ndarray:
    """Mass-normalised rigid-body modes ``W = c0 + c1 x``: array (r, 2) of (c0, c1)."""
    rows = []
    pts = [(0.0, lay.k_left), *zip(lay.nodes[1:-1], lay.k_joint), (lay.nodes[-1], lay.k_right)]
    for x, k in pts:
        if k > 0.0:
            rows.append([1.0, x])
    if lay.kt_left > 0.0 or lay.kt_right > 0.0:
        rows.append([0.0, 1.0])
    if rows:
        C = np.array(rows)
        scale = np.array([1.0, lay.nodes[-1]])
        _, sv, vt = np.linalg.svd(C * scale)
        rank = int(np.sum(sv > 1e-10 * sv[0]))
        null = (vt[rank:] * scale).T  # (2, r)
    else:
        null = np.eye(2)
    L = lay.nodes[-1]
    M = lay.rhoA * np.array([[L, L**2 / 2.0], [L**2 / 2.0, L**3 / 3.0]])
    if null.shape[1] == 2:  # free-free: translation first, then rotation about mid-span
        null = np.array([[1.0, -L / 2.0], [0.0, 1.0]])
    out = []
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


def _bracket_roots(lay: _Layout, n_needed: int, j0: int) -> list[tuple[float, float, int]]:
    """Brackets ``(lo, hi, index)`` of the first ``n_needed`` elastic wavenumbers."""
    if n_needed <= 0:
        return []
    target = j0 + n_needed
    L = lay.nodes[-1]
    hi = (n_needed + 1.5) * math.pi / L * 1.0137  # off any root of a classical beam
    jhi = _count(lay, hi)
    guard = 0
    while jhi < target:
        hi *= 1.6
        jhi = _count(lay, hi)
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
        jm = _count(lay, mid)
        stack.append((mid, up, jm, jup))
        stack.append((lo, mid, jlo, jm))
    out.sort(key=lambda b: b[2])
    return out[:n_needed]


def _refine(lay: _Layout, lo: float, hi: float, index: int) -> float:
    """Refine one isolated root in (lo, hi) to machine precision."""
    # narrow the bracket on the exact count first, so one basis serves the whole
    # bracket and its lower end is away from beta = 0
    while hi - lo > 0.05 * hi:
        mid = 0.5 * (lo + hi)
        if _count(lay, mid) > index:
            hi = mid
        else:
            lo = mid
    kry = _krylov_mask(lay, hi)
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
        if _count(lay, mid) > index:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def _null_vector(lay: _Layout, beta: float, kry: np.ndarray) -> np.ndarray:
    A = _characteristic(lay, beta, kry)
    _, _, vt = np.linalg.svd(A)
    return vt[-1]


# --------------------------------------------------------------------------- quadrature


def _quadrature(breaks: np.ndarray, beta_max: float) -> tuple[np.ndarray, np.ndarray]:
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


# --------------------------------------------------------------------------- ModeSet


@dataclass(frozen=True, eq=False)
class ModeSet:
    """Natural frequencies and mass-normalised mode shapes of one state.

    Attributes
    ----------
    beam : Beam
    springs : tuple of (position [m], stiffness [N/m])
        Engaged interior springs (contact springs) of this state.
    omega : ndarray, shape (n,), [rad/s]
        Natural circular frequencies, ascending; 0 for rigid-body modes.
    beta : ndarray, shape (n,), [1/m]
        Wavenumbers, ``omega = beta^2 sqrt(EI / rho A)`` (paper, after eq. 5).
    n_rigid : int
        Number of rigid-body modes (they come first).

    Notes
    -----
    Shapes are normalised so that ``rho A int W_n W_m dx = delta_nm`` (paper,
    orthonormality after eq. 7); their sign makes the largest displacement
    positive.
    """

    beam: Beam
    springs: tuple[tuple[float, float], ...]
    omega: np.ndarray
    beta: np.ndarray
    n_rigid: int
    _layout: _Layout = field(repr=False)
    _coef: np.ndarray = field(repr=False)  # (n, s, 4) elastic coefficients
    _rigid: np.ndarray = field(repr=False)  # (n_rigid, 2)
    _kry: np.ndarray = field(repr=False)  # (n, s) True where a segment uses the Krylov basis

    def _repr_html_(self) -> str:
        """Compact summary table for Jupyter: the state's springs and first frequencies."""
        from ._html import modeset_html

        return modeset_html(self)

    @property
    def count(self) -> int:
        """Number of modes in the set."""
        return int(self.omega.size)

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Natural frequencies [Hz]."""
        return self.omega / (2.0 * np.pi)

    @property
    def nodes(self) -> np.ndarray:
        """Segment boundaries [m] (ends and spring positions)."""
        return self._layout.nodes

    def shapes(self, x: float | Sequence[float] | np.ndarray, derivative: int = 0) -> np.ndarray:
        """Mode shapes or their derivatives at ``x``.

        Parameters
        ----------
        x : array_like, shape (p,), [m]
        derivative : {0, 1, 2, 3}
            Order of the derivative in x.

        Returns
        -------
        ndarray, shape (n, p)
            ``d^k W_n / dx^k (x)`` in [kg^-0.5 m^-k]. At a spring position the
            third derivative is the value just to the right.
        """
        if derivative not in (0, 1, 2, 3):
            raise ParameterError(f"derivative: must be 0, 1, 2 or 3, got {derivative!r}")
        x = np.atleast_1d(np.asarray(x, dtype=float))
        lay = self._layout
        out = np.zeros((self.count, x.size))
        r = self.n_rigid
        if r:
            c = self._rigid
            if derivative == 0:
                out[:r] = c[:, :1] + c[:, 1:] * x[None, :]
            elif derivative == 1:
                out[:r] = c[:, 1:]
        if self.count > r:
            seg = np.clip(np.searchsorted(lay.nodes, x, side="right") - 1, 0, lay.n_segments - 1)
            u = x - lay.nodes[seg]
            ell = lay.lengths[seg]
            b = self.beta[r:, None]
            kry = self._kry[r:][:, seg]
            phi = _basis(b * u[None, :], b * ell[None, :], derivative, kry)
            coef = self._coef[r:][:, seg, :]  # (n_el, p, 4)
            val = sum(coef[:, :, k] * phi[k] for k in range(4))
            out[r:] = val * b**derivative
        return out

    def __call__(self, x: float | Sequence[float] | np.ndarray) -> np.ndarray:
        """Same as :meth:`shapes` with ``derivative=0``."""
        return self.shapes(x)

    @functools.cached_property
    def _quad(self) -> tuple[np.ndarray, np.ndarray]:
        return _quadrature(self.nodes, float(self.beta.max(initial=1.0 / self.beam.length)))

    @functools.cached_property
    def _integral(self) -> np.ndarray:
        x, w = self._quad
        out = self.shapes(x) @ w
        out.setflags(write=False)
        return out

    def integral(self) -> np.ndarray:
        """``int_0^L W_n dx`` [m kg^-0.5], shape (n,): modal weight of a uniform load."""
        return self._integral.copy()

    def mass_matrix(self) -> np.ndarray:
        """``rho A int W_n W_m dx``: the identity up to round-off (a check)."""
        return self.overlap(self)

    def overlap(self, other: ModeSet) -> np.ndarray:
        """Projection matrix ``P[n, p] = rho A int W_n^self W_p^other dx`` (paper eq. 12).

        ``eta_self = P @ eta_other`` carries modal coordinates of ``other`` into
        this set (displacement and velocity alike).
        """
        if other.beam != self.beam:
            raise ParameterError("overlap: the two mode sets belong to different beams")
        cache = self.__dict__.setdefault("_overlaps", {})
        hit = cache.get(id(other))
        if hit is not None and hit[0] is other:
            return hit[1].copy()
        breaks = np.union1d(self.nodes, other.nodes)
        bmax = max(float(self.beta.max(initial=0.0)), float(other.beta.max(initial=0.0)), 1.0 / self.beam.length)
        x, w = _quadrature(breaks, bmax)
        P = self.beam.mass_per_length * (self.shapes(x) * w) @ other.shapes(x).T
        P.setflags(write=False)
        cache[id(other)] = (other, P)
        return P.copy()

    def static_coordinates(self, position: float, force: float = 1.0) -> np.ndarray:
        """Modal coordinates of the static deflection under a point ``force`` at ``position``.

        ``eta_n = F W_n(a) / omega_n^2``: the exact projection of the static shape.
        """
        if self.n_rigid:
            raise ParameterError(
                "initial.tip_displacement: the supports allow rigid-body motion, so a static load shape does not exist"
            )
        return force * self.shapes([position])[:, 0] / self.omega**2


def _build(lay: _Layout, beam: Beam, springs: tuple[tuple[float, float], ...], count: int) -> ModeSet:
    rigid = _rigid_modes(lay)
    r = min(rigid.shape[0], count)
    brackets = _bracket_roots(lay, count - r, rigid.shape[0])
    betas = np.array([_refine(lay, lo, hi, j) for lo, hi, j in brackets], dtype=float)
    s = lay.n_segments
    coef = np.zeros((count, s, 4))
    kry = np.zeros((count, s), dtype=bool)
    i = 0
    while i < betas.size:
        j = i + 1
        while j < betas.size and betas[j] - betas[j - 1] <= 1e-7 * betas[j]:
            j += 1
        b_mid = float(np.mean(betas[i:j]))
        mask = _krylov_mask(lay, b_mid)
        if j - i == 1:
            coef[r + i] = _null_vector(lay, betas[i], mask).reshape(s, 4)
        else:  # (nearly) repeated root: the null space of the cluster
            _, _, vt = np.linalg.svd(_characteristic(lay, b_mid, mask))
            for m in range(j - i):
                coef[r + i + m] = vt[-(m + 1)].reshape(s, 4)
                betas[i + m] = betas[i + m]
        kry[r + i : r + j] = mask
        i = j
    beta_all = np.concatenate([np.zeros(r), betas])
    c2 = math.sqrt(lay.EI / lay.rhoA)
    ms = ModeSet(beam, springs, beta_all**2 * c2, beta_all, r, lay, coef, rigid[:r], kry)
    # normalise elastic shapes: rho A int W^2 = 1, largest displacement positive
    if count > r:
        x, w = _quadrature(lay.nodes, float(betas.max()))
        # mass-orthonormalise within clusters of repeated roots (Gram-Schmidt)
        i = 0
        while i < betas.size:
            j = i + 1
            while j < betas.size and betas[j] - betas[j - 1] <= 1e-7 * betas[j]:
                j += 1
            if j - i > 1:
                Wc = ms.shapes(x)[r + i : r + j]
                G = lay.rhoA * (Wc * w) @ Wc.T
                Lc = np.linalg.cholesky(G)
                T = np.linalg.inv(Lc)
                coef[r + i : r + j] = np.einsum("ab,bsk->ask", T, coef[r + i : r + j])
            i = j
        W = ms.shapes(x)[r:]
        norms = np.sqrt(lay.rhoA * (W**2) @ w)
        idx = np.argmax(np.abs(W), axis=1)
        sign = np.sign(W[np.arange(W.shape[0]), idx])
        coef[r:] *= (sign / norms)[:, None, None]
    return ms


@functools.lru_cache(maxsize=512)
def _cached(beam: Beam, springs: tuple[tuple[float, float], ...], count: int) -> ModeSet:
    return _build(_merge_springs(beam, springs), beam, springs, count)


def mode_set(beam: Beam, springs: Iterable[tuple[float, float]] = (), count: int = 8) -> ModeSet:
    """Compute (or fetch from the cache) the first ``count`` modes of a beam state.

    Parameters
    ----------
    beam : Beam
    springs : iterable of (position [m], stiffness [N/m])
        Engaged translational springs; at an end they add to the support, two
        at one point add up; ``inf`` pins the point.
    count : int
        Number of modes, rigid-body modes included.

    Returns
    -------
    ModeSet

    Examples
    --------
    >>> import impactbeam as ib
    >>> beam = ib.Beam.rectangular(1.0, 0.01, 0.01, 2e11, 7800.0, "clamped", "free")
    >>> ms = ib.mode_set(beam, count=3)
    >>> lam = (ms.omega / ms.omega[0]) ** 0.5 * 1.875104069
    >>> [round(v, 6) for v in lam]
    [1.875104, 4.694091, 7.854757]
    """
    if isinstance(count, bool) or int(count) != count or count < 1:
        raise ParameterError(f"count: must be a positive integer, got {count!r}")
    key = tuple(sorted((float(x), float(k)) for x, k in springs))
    return _cached(beam, key, int(count))


@dataclass(frozen=True)
class ScenarioModes:
    """Mode sets of a scenario: the free state and the state with all contactors engaged."""

    free: ModeSet
    contact: ModeSet | None

    def _repr_html_(self) -> str:
        """Both states side by side for Jupyter."""
        from ._html import modeset_html

        parts = [modeset_html(self.free).replace("ModeSet", "Free state", 1)]
        if self.contact is not None:
            parts.append(modeset_html(self.contact).replace("ModeSet", "Contact state", 1))
        cells = "".join(f'<div style="margin-right:2em">{p}</div>' for p in parts)
        return f'<div style="display:flex;flex-wrap:wrap">{cells}</div>'


def scenario_modes(scenario: Scenario, count: int | None = None) -> ScenarioModes:
    """Free-state and all-engaged contact-state modes of a scenario.

    Parameters
    ----------
    scenario : Scenario
    count : int, optional
        Modes per state; default the scenario's ``solver.modes``.
    """
    n = scenario.solver.modes if count is None else count
    free = mode_set(scenario.beam, (), n)
    contact = None
    if scenario.contactors:
        contact = mode_set(scenario.beam, [(c.position, c.stiffness) for c in scenario.contactors], n)
    return ScenarioModes(free, contact)


#: ``ib.modes(scenario)`` (see the API reference).
modes = scenario_modes
