"""Independent finite-element reference for the impactbeam tests.

This module is used ONLY by the test-suite.  It deliberately imports nothing
from ``impactbeam``: it is written from first principles with plain numpy and
scipy, so that agreement between it and the project's exact modal solver is
evidence, not an echo of shared code.

Method
------
* Euler-Bernoulli beam, uniform (``EI``, ``rhoA``), discretised by Hermite
  cubic elements: two degrees of freedom per node, ``w`` and ``theta = w'``.
  DOF numbering of the full system: node ``i`` has ``w`` at ``2*i`` and
  ``theta`` at ``2*i + 1``.  Element matrices (length ``l``)::

      K_e = EI/l^3 [[ 12,   6l,  -12,   6l ],      M_e = rhoA l/420 [[156,  22l,  54, -13l ],
                    [ 6l, 4l^2,  -6l, 2l^2 ],                        [22l, 4l^2, 13l, -3l^2],
                    [-12,  -6l,   12,  -6l ],                        [54,  13l, 156, -22l ],
                    [ 6l, 2l^2,  -6l, 4l^2 ]]                        [-13l,-3l^2,-22l, 4l^2]]

  (consistent mass).  Frequencies converge as h^4.
* End supports: a translational spring (on ``w``) and a rotational spring (on
  ``theta``) at each end, each 0 .. ``math.inf``.  A finite spring adds to the
  diagonal of K; an infinite one removes the DOF (constraint elimination, never
  a penalty number).  Interior translational springs ``(x, k)`` are handled
  the same way at the node placed exactly at ``x``.  The strain energy
  ``1/2 Kt W'(0)^2`` etc. reproduces the boundary conditions of the paper (after its eq. 5).
* Modes: ``scipy.linalg.eigh(K_r, M_r)`` on the reduced matrices; eigenvectors
  are mass-normalised (``phi^T M phi = 1``, i.e. ``rhoA int W^2 dx = 1`` up to
  discretisation); rigid-body modes are reported with omega = 0.
* Transient: implicit Newmark, average acceleration (gamma = 1/2, beta = 1/4),
  in physical coordinates, with one-sided contactors treated as state changes
  (piecewise-linear system, like the modal model): in a state the engaged
  contactors add ``k e_a e_a^T`` to K and the constant force ``s k c e_a``
  (``s = +1`` above, ``-1`` below).  A crossing of the gap function
  ``g = c - s w(a)`` inside a step is located by re-doing the step with a
  reduced step length found by Brent's method on ``g`` (to ~1e-13 s); the
  state is switched there and the remainder of the step is integrated in the
  new state.  Damping per state is modal, on ALL FE modes of that state:
  ``C = M Phi diag(2 xi omega) Phi^T M``.
* For a linear, undamped system the average-acceleration rule conserves the
  energy ``1/2 v^T M v + 1/2 u^T K u`` exactly (it is the trapezoidal rule);
  in general it satisfies the exact discrete balance
  ``E_{n+1} - E_n = 1/2 du.(f_n + f_{n+1}) - du^T C du / h``,
  which this module accumulates as ``work`` and ``dissipated``.
* Dissipation (:func:`fe_transient_dissipative`, Newmark, and
  :func:`fe_transient_exact`, the same FE model integrated exactly in time by
  matrix exponentials): a dashpot in parallel with each contactor (force
  ``k d + c d'`` while positive, released where it reaches 0, code_aster's
  ``AMOR_NOR`` law) and the beam damping models ``modal`` (per state),
  ``rayleigh`` (``alpha M + beta K_s``) and ``free_modes`` (the free state's
  modal damping matrix kept in every state). A dashpot's force jump at an
  impact excites the fast modes, which Newmark keeps with wrong phases (a
  release moves by microseconds); the exact integrator leaves only the mesh
  to converge.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np
import scipy.linalg as sla
from scipy.linalg.lapack import dpotrs as potrs
from scipy.optimize import brentq

__all__ = [
    "FEModel",
    "TransientResult",
    "assemble",
    "build_mesh",
    "element_matrices",
    "fe_modes",
    "fe_transient",
    "fe_transient_dissipative",
    "fe_transient_exact",
    "ExactResult",
    "DissipativeResult",
    "hermite_shape",
    "solve_modes",
    "strain_energy",
]


# --------------------------------------------------------------------------
# Elements and mesh
# --------------------------------------------------------------------------
def element_matrices(l: float, EI: float, rhoA: float) -> tuple[np.ndarray, np.ndarray]:
    """Hermite-cubic Euler-Bernoulli element stiffness and consistent mass.

    DOF order ``(w_i, theta_i, w_j, theta_j)``.
    """
    l2 = l * l
    k = EI / l**3 * np.array(
        [
            [12.0, 6 * l, -12.0, 6 * l],
            [6 * l, 4 * l2, -6 * l, 2 * l2],
            [-12.0, -6 * l, 12.0, -6 * l],
            [6 * l, 2 * l2, -6 * l, 4 * l2],
        ]
    )
    m = rhoA * l / 420.0 * np.array(
        [
            [156.0, 22 * l, 54.0, -13 * l],
            [22 * l, 4 * l2, 13 * l, -3 * l2],
            [54.0, 13 * l, 156.0, -22 * l],
            [-13 * l, -3 * l2, -22 * l, 4 * l2],
        ]
    )
    return k, m


def hermite_shape(xi: np.ndarray | float, l: float, derivative: int = 0) -> np.ndarray:
    """Hermite shape functions (or their x-derivative) at local ``xi`` in [0, 1].

    Returns an array ``(..., 4)`` multiplying ``(w_i, theta_i, w_j, theta_j)``.
    """
    xi = np.asarray(xi, dtype=float)
    if derivative == 0:
        n = [
            1 - 3 * xi**2 + 2 * xi**3,
            l * (xi - 2 * xi**2 + xi**3),
            3 * xi**2 - 2 * xi**3,
            l * (-(xi**2) + xi**3),
        ]
    elif derivative == 1:
        n = [
            (-6 * xi + 6 * xi**2) / l,
            1 - 4 * xi + 3 * xi**2,
            (6 * xi - 6 * xi**2) / l,
            -2 * xi + 3 * xi**2,
        ]
    else:
        raise ValueError("derivative must be 0 or 1")
    return np.stack(n, axis=-1)


def build_mesh(length: float, n_elements: int, points: Sequence[float] = ()) -> np.ndarray:
    """Graded mesh with a node exactly at every x in ``points``.

    [0, L] is split at the points (duplicates and points within 1e-9 L of
    each other or of an end are merged), then each piece gets
    ``max(1, round(n_elements * piece / L))`` equal elements.  The given
    coordinates are reproduced bit for bit.
    """
    if not (length > 0 and math.isfinite(length)):
        raise ValueError("length must be positive and finite")
    if n_elements < 1:
        raise ValueError("n_elements must be >= 1")
    tol = 1e-9 * length
    cuts = [0.0]
    for p in sorted(float(p) for p in points):
        if not (-tol <= p <= length + tol):
            raise ValueError(f"point {p} is off the beam [0, {length}]")
        if p - cuts[-1] > tol and length - p > tol:
            cuts.append(p)
    cuts.append(float(length))
    nodes = [0.0]
    for a, b in zip(cuts[:-1], cuts[1:]):
        n = max(1, int(round(n_elements * (b - a) / length)))
        inner = a + (b - a) * np.arange(1, n) / n
        nodes.extend(inner.tolist())
        nodes.append(b)
    return np.asarray(nodes, dtype=float)


# --------------------------------------------------------------------------
# Assembly
# --------------------------------------------------------------------------
@dataclass
class FEModel:
    """Assembled finite-element model.

    Attributes
    ----------
    x : (n_nodes,) node coordinates.
    K, M : (2 n_nodes, 2 n_nodes) full dense stiffness (including the finite
        support and interior springs) and consistent mass.
    free : int array of the free (not constrained) full DOF indices.
    K_r, M_r : the reduced matrices ``K[free][:, free]``, ``M[free][:, free]``.
    spring_diag : (n_dof,) the finite spring stiffnesses added to diag(K).
    """

    length: float
    EI: float
    rhoA: float
    x: np.ndarray
    K: np.ndarray
    M: np.ndarray
    free: np.ndarray
    K_r: np.ndarray = field(repr=False)
    M_r: np.ndarray = field(repr=False)
    spring_diag: np.ndarray = field(repr=False, default=None)
    EI_el: np.ndarray | None = field(repr=False, default=None)  # per element (stepped beams)

    @property
    def n_nodes(self) -> int:
        return len(self.x)

    @property
    def n_dof(self) -> int:
        return 2 * len(self.x)

    def node_index(self, x: float) -> int:
        """Index of the node at ``x`` (must be a mesh node to 1e-9 L)."""
        i = int(np.argmin(np.abs(self.x - x)))
        if abs(self.x[i] - x) > 1e-9 * self.length:
            raise ValueError(f"x = {x} is not a mesh node")
        return i

    def reduced_index(self, full_dof: int) -> int:
        """Position of a full DOF in the reduced vector (error if constrained)."""
        pos = np.searchsorted(self.free, full_dof)
        if pos >= len(self.free) or self.free[pos] != full_dof:
            raise ValueError(f"DOF {full_dof} is constrained")
        return int(pos)

    def expand(self, u_r: np.ndarray) -> np.ndarray:
        """Full DOF vector(s) from reduced one(s) (constrained DOFs = 0).

        ``u_r`` is ``(n_free,)`` or ``(n_free, k)``.
        """
        u_r = np.asarray(u_r)
        out = np.zeros((self.n_dof,) + u_r.shape[1:], dtype=u_r.dtype)
        out[self.free] = u_r
        return out

    def interpolation_matrix(self, xs: Sequence[float], derivative: int = 0) -> np.ndarray:
        """Matrix P (len(xs), n_dof) with ``w(xs) = P @ u_full`` (Hermite, not linear)."""
        xs = np.atleast_1d(np.asarray(xs, dtype=float))
        P = np.zeros((len(xs), self.n_dof))
        ne = len(self.x) - 1
        for r, xv in enumerate(xs):
            if not (-1e-12 * self.length <= xv <= self.length * (1 + 1e-12)):
                raise ValueError(f"x = {xv} is off the beam")
            e = int(np.clip(np.searchsorted(self.x, xv, side="right") - 1, 0, ne - 1))
            l = self.x[e + 1] - self.x[e]
            xi = min(max((xv - self.x[e]) / l, 0.0), 1.0)
            P[r, 2 * e : 2 * e + 4] = hermite_shape(xi, l, derivative)
        return P

    def nodal_vector(self, w: Callable | None = None, w_x: Callable | None = None) -> np.ndarray:
        """Full DOF vector interpolating a function ``w(x)`` and its slope ``w_x(x)``."""
        u = np.zeros(self.n_dof)
        if w is not None:
            u[0::2] = np.asarray(w(self.x), dtype=float) * np.ones(self.n_nodes)
        if w_x is not None:
            u[1::2] = np.asarray(w_x(self.x), dtype=float) * np.ones(self.n_nodes)
        return u


def _check_spring(k: float, name: str) -> float:
    k = float(k)
    if math.isnan(k) or k < 0:
        raise ValueError(f"{name} must be in [0, inf], got {k}")
    return k


def assemble(
    length: float,
    EI: float,
    rhoA: float,
    *,
    n_elements: int,
    left: tuple[float, float] = (math.inf, math.inf),
    right: tuple[float, float] = (0.0, 0.0),
    springs: Sequence[tuple[float, float]] = (),
    nodes_at: Sequence[float] = (),
    sections: Sequence[tuple[float, float, float]] = (),
    masses: Sequence[tuple[float, float, float]] = (),
    rotational_springs: Sequence[tuple[float, float]] = (),
) -> FEModel:
    """Assemble K and M of a Hermite-cubic beam (uniform, or piecewise uniform).

    Parameters
    ----------
    left, right : (translational k, rotational kt) end springs, each in
        [0, inf]; ``inf`` eliminates the DOF.
    springs : interior translational springs ``(x, k)``; ``k = inf`` constrains
        ``w`` at that node.  Springs at the same x add up.
    nodes_at : further x positions that must be mesh nodes (contactors,
        output points...).
    sections : ``(length, EI, rhoA)`` pieces from x = 0 (lengths summing to
        ``length``); empty: uniform ``EI``, ``rhoA``. Every step is a mesh node.
    masses : ``(x, m, J)`` point masses (lumped: ``m`` on ``w``, ``J`` on
        ``theta`` of the node at x).
    rotational_springs : interior rotational springs ``(x, kt)`` on ``theta``
        (``inf`` constrains it).

    Returns an :class:`FEModel`.
    """
    if EI <= 0 or rhoA <= 0:
        raise ValueError("EI and rhoA must be positive")
    springs = [(float(x), _check_spring(k, "spring stiffness")) for x, k in springs]
    rot = [(float(x), _check_spring(k, "rotational spring")) for x, k in rotational_springs]
    steps = list(np.cumsum([sec[0] for sec in sections])[:-1]) if sections else []
    x = build_mesh(
        length, n_elements,
        [s[0] for s in springs] + [r[0] for r in rot] + [m[0] for m in masses]
        + [float(p) for p in steps] + [float(p) for p in nodes_at],
    )
    n = len(x)
    K = np.zeros((2 * n, 2 * n))
    M = np.zeros((2 * n, 2 * n))
    EI_el = np.full(n - 1, float(EI))
    edges = np.concatenate([[0.0], np.cumsum([sec[0] for sec in sections])]) if sections else None
    for e in range(n - 1):
        EI_e, rhoA_e = EI, rhoA
        if sections:
            j = int(np.clip(np.searchsorted(edges, 0.5 * (x[e] + x[e + 1])) - 1, 0, len(sections) - 1))
            EI_e, rhoA_e = sections[j][1], sections[j][2]
        EI_el[e] = EI_e
        ke, me = element_matrices(x[e + 1] - x[e], EI_e, rhoA_e)
        sl = slice(2 * e, 2 * e + 4)
        K[sl, sl] += ke
        M[sl, sl] += me
    constrained: set[int] = set()
    spring_diag = np.zeros(2 * n)

    def add(dof: int, k: float) -> None:
        if math.isinf(k):
            constrained.add(dof)
        else:
            K[dof, dof] += k
            spring_diag[dof] += k

    k1, kt1 = (_check_spring(v, "left support") for v in left)
    k2, kt2 = (_check_spring(v, "right support") for v in right)
    add(0, k1)
    add(1, kt1)
    add(2 * (n - 1), k2)
    add(2 * (n - 1) + 1, kt2)
    model_tmp = FEModel(length, EI, rhoA, x, K, M, np.arange(2 * n), K, M)
    for xs, k in springs:
        add(2 * model_tmp.node_index(xs), k)
    for xs, k in rot:
        add(2 * model_tmp.node_index(xs) + 1, k)
    for xs, m, J in masses:
        i = model_tmp.node_index(xs)
        M[2 * i, 2 * i] += m
        M[2 * i + 1, 2 * i + 1] += J
    free = np.array(sorted(set(range(2 * n)) - constrained), dtype=int)
    K_r = K[np.ix_(free, free)].copy()
    M_r = M[np.ix_(free, free)].copy()
    spring_diag[sorted(constrained)] = 0.0
    return FEModel(float(length), float(EI), float(rhoA), x, K, M, free, K_r, M_r, spring_diag,
                   EI_el if sections else None)


# --------------------------------------------------------------------------
# Modes
# --------------------------------------------------------------------------
def _eig_all(K_r: np.ndarray, M_r: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """All eigenpairs of (K_r, M_r) by plain ``eigh``, mass-normalised.

    Used for the damping matrices, where the last digits of the low
    eigenvalues do not matter.  omega^2 below 1e3 eps lambda_max (round-off
    level of a true zero for this algorithm) is set to 0.
    """
    lam, phi = sla.eigh(K_r, M_r)
    lam_max = max(abs(lam[-1]), np.finfo(float).tiny)
    lam = np.where(lam < 1e3 * np.finfo(float).eps * lam_max, 0.0, lam)
    return lam, phi


def strain_energy(model: FEModel, u: np.ndarray) -> np.ndarray:
    """Strain energy 1/2 u^T K u of full DOF vector(s) ``u`` (n_dof[, k]), cancellation-free.

    ``u^T K u`` of a smooth vector loses ~ (L/h)^4 of the 16 digits to
    cancellation (200 elements: ~1e-7 relative).  Here the element energy is
    computed from the curvature, linear along a Hermite element:
    ``kappa(0) = (6 d - 4 t_i - 2 t_j)/l``, ``kappa(l) = (-6 d + 2 t_i + 4 t_j)/l``
    with ``d = (w_j - w_i)/l``, and ``EI/2 int kappa^2 = EI l/6 (k0^2 + k0 k1 + k1^2)``;
    plus ``1/2 k u^2`` of the finite support / interior springs.
    """
    u = np.asarray(u, dtype=float)
    w, th = u[0::2], u[1::2]
    l = np.diff(model.x)
    if u.ndim == 2:
        l = l[:, None]
    d = (w[1:] - w[:-1]) / l
    k0 = (6 * d - 4 * th[:-1] - 2 * th[1:]) / l
    k1 = (-6 * d + 2 * th[:-1] + 4 * th[1:]) / l
    EI = model.EI if model.EI_el is None else (model.EI_el if u.ndim == 1 else model.EI_el[:, None])
    beam = np.sum(EI * l / 6.0 * (k0 * k0 + k0 * k1 + k1 * k1), axis=0)
    sp = model.spring_diag if u.ndim == 1 else model.spring_diag[:, None]
    return beam + 0.5 * np.sum(sp * u * u, axis=0)


def solve_modes(model: FEModel, n_modes: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Natural frequencies and full-DOF mass-normalised mode vectors.

    Eigenvectors from the shifted inverse problem ``eigh(M_r, K_r + s M_r)``
    (s = EI/(rhoA L^4), so the low modes, which matter, are the well-resolved
    end of the spectrum and rigid modes are harmless); eigenvalues then from
    the Rayleigh quotient ``2 U(phi) / phi^T M phi`` with the cancellation-free
    :func:`strain_energy`.  The Rayleigh quotient is stationary, so the
    vector's round-off enters squared: omega of a smooth mode is accurate to
    ~1e-12 instead of ~eps (L/h)^4.  omega^2 < 1e-10 s is a rigid-body mode,
    reported as exactly 0.

    Returns ``(omega, Phi)`` with ``omega`` (n_modes,) in rad/s ascending and
    ``Phi`` (n_dof, n_modes) full DOF vectors, ``Phi^T M Phi = I``.  Sign
    convention: the nodal ``w`` of largest magnitude is positive.
    """
    s = model.EI / (model.rhoA * model.length**4)
    nf = len(model.free)
    B = model.K_r + s * model.M_r
    if n_modes is not None and n_modes + 4 < nf:
        # the n_modes + 4 largest mu (margin for re-ordering after refinement)
        mu, phi = sla.eigh(model.M_r, B, subset_by_index=[nf - n_modes - 4, nf - 1])
    else:
        mu, phi = sla.eigh(model.M_r, B)
    phi = phi[:, ::-1]
    mass = np.einsum("ij,ij->j", phi, model.M_r @ phi)
    phi = phi / np.sqrt(mass)
    full = model.expand(phi)
    lam = 2.0 * strain_energy(model, full)
    lam = np.where(lam < 1e-10 * s, 0.0, lam)
    order = np.argsort(lam, kind="stable")
    lam, full = lam[order], full[:, order]
    if n_modes is not None:
        lam, full = lam[:n_modes], full[:, :n_modes]
    w = full[0::2]
    for j in range(full.shape[1]):
        i = int(np.argmax(np.abs(w[:, j])))
        if w[i, j] < 0:
            full[:, j] *= -1
    return np.sqrt(lam), full


def fe_modes(
    length: float,
    EI: float,
    rhoA: float,
    *,
    n_elements: int = 200,
    left: tuple[float, float],
    right: tuple[float, float],
    springs: Sequence[tuple[float, float]] = (),
    n_modes: int = 10,
    nodes_at: Sequence[float] = (),
    **structure: Sequence,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """FE natural frequencies and mode shapes.

    Returns ``(omega, shapes, x)``:
    ``omega`` (n_modes,) rad/s ascending, rigid-body modes reported as 0.0;
    ``shapes`` (n_modes, n_nodes) the nodal deflection ``w`` of each
    mass-normalised mode (``shapes[j]`` is mode j; rhoA int W^2 dx = 1 in the
    FE sense), largest |w| positive; ``x`` (n_nodes,) node coordinates.
    ``structure``: ``sections``, ``masses``, ``rotational_springs`` of :func:`assemble`.
    """
    model = assemble(
        length, EI, rhoA, n_elements=n_elements, left=left, right=right,
        springs=springs, nodes_at=nodes_at, **structure,
    )
    omega, full = solve_modes(model, n_modes)
    return omega, full[0::2].T.copy(), model.x.copy()


# --------------------------------------------------------------------------
# Transient
# --------------------------------------------------------------------------
@dataclass
class TransientResult:
    """Output of :func:`fe_transient`.

    ``t`` (n_t,) regular grid ``k dt``; ``x_out`` (n_points,);
    ``w``, ``w_t`` (n_t, n_points) deflection and velocity at ``x_out``
    (Hermite interpolation); ``events`` list of ``(time, 'impact'|'rebound',
    contactor_index)``; ``event_gap`` the gap function g at each switch
    (should be ~0); ``contact_force`` (n_t, n_contactors) force on the beam
    along +w; ``engaged`` (n_t, n_contactors) bool; energies (n_t,):
    ``kinetic``, ``strain`` (beam + support/interior springs), ``contactor``
    (1/2 k g^2 of engaged contactors), ``total`` (their sum), ``work``
    (cumulative external-load work), ``dissipated`` (cumulative damping loss).
    ``balance`` = total - total[0] - work + dissipated (~0, discrete identity).
    """

    t: np.ndarray
    x_out: np.ndarray
    w: np.ndarray
    w_t: np.ndarray
    events: list
    event_gap: list
    contact_force: np.ndarray
    engaged: np.ndarray
    kinetic: np.ndarray
    strain: np.ndarray
    contactor: np.ndarray
    work: np.ndarray
    dissipated: np.ndarray
    x_nodes: np.ndarray
    n_factorisations: int = 0

    @property
    def total(self) -> np.ndarray:
        return self.kinetic + self.strain + self.contactor

    @property
    def balance(self) -> np.ndarray:
        return self.total - self.total[0] - self.work + self.dissipated


def _pulse(t: float, shape: str, amplitude: float, start: float, duration: float | None,
           frequency: float | None = None, phase: float = 0.0) -> float:
    if t < start:
        return 0.0
    if shape == "step":
        return amplitude
    if shape == "harmonic":
        return amplitude * math.sin(2.0 * math.pi * float(frequency) * (t - start) + phase)
    if shape == "half_sine":
        if duration is None or not duration > 0:
            raise ValueError("half_sine needs a positive duration")
        if t > start + duration:
            return 0.0
        return amplitude * math.sin(math.pi * (t - start) / duration)
    raise ValueError(f"unknown load shape {shape!r}")


def fe_transient(
    length: float,
    EI: float,
    rhoA: float,
    *,
    left: tuple[float, float],
    right: tuple[float, float],
    springs: Sequence[tuple[float, float]] = (),
    contactors: Sequence[dict] = (),
    load: dict | None = None,
    initial: dict | None = None,
    damping: tuple[float, float] = (0.0, 0.0),
    dt: float,
    t_end: float,
    output_x: Sequence[float] | None = None,
    n_elements: int = 50,
    **structure: Sequence,
) -> TransientResult:
    """Newmark (average acceleration) transient response with one-sided contactors.

    Parameters
    ----------
    contactors : dicts ``{"position", "stiffness", "gap", "side"}``; side
        ``"below"`` is engaged while ``w(a) < -gap`` and pushes with
        ``F = k(-gap - w(a))``; ``"above"`` while ``w(a) > gap`` with
        ``F = -k(w(a) - gap)``.  Gap function ``g = gap - s w(a)`` (s = +1
        above, -1 below); engaged iff g < 0.  A contactor starts engaged only
        if g < 0 at t = 0 (with zero gap at rest it engages at t = 0 as soon
        as the load pushes into it, recorded as an impact at 0).
    load : ``None`` / ``{"kind": "none"}``;
        ``{"kind": "base_acceleration", "amplitude", "duration", "start"=0,
        "shape"="half_sine"}`` (or ``"shape": "harmonic"`` with ``"frequency"``
        [Hz] and ``"phase"`` [rad]: ``amplitude sin(2 pi f (t - start) + phase)``
        for t >= start) -> distributed load ``-rhoA ug''(t)``, i.e.
        the consistent vector ``-ug''(t) M r`` (r = unit rigid translation);
        ``{"kind": "point_force", "position", "amplitude", "shape":
        "half_sine"|"step", "duration", "start"=0}``.
        Amplitudes are signed along +w.
    initial : ``None`` (rest); ``{"tip_displacement": d}`` (static shape of a
        point load at x = L scaled to w(L) = d, zero velocity); or callables
        ``{"w": f(x), "w_x": f'(x), "w_t": g(x), "w_xt": g'(x)}`` (any subset)
        interpolated at the nodes.
    damping : (xi_free, xi_contact): modal ratio applied to all FE modes of the
        free state / of any state with a contactor engaged,
        ``C = M Phi diag(2 xi omega) Phi^T M``, cached per state.
    dt, t_end : time step and end time; output on ``t = k dt``, k = 0..round(t_end/dt).
    output_x : output positions (default: contactor positions, then L).
    n_elements : about this many elements; nodes are placed at contactors,
        springs and the point-force position (output points need not be
        nodes: outputs use the Hermite interpolation).

    Method
    ------
    Incremental Newmark: ``K_eff du = f_{n+1} - K_s u_n + M(4/h v_n + a_n) + C_s v_n``
    with ``K_eff = K_s + 2/h C_s + 4/h^2 M``, Cholesky-factorised and cached
    per (state, dt).  If a contactor's g changes sign over a step, the step
    length tau with g(tau) = 0 is found by Brent's method (xtol 1e-14 s; each
    trial is a full Newmark step of length tau, factorised afresh), the step is
    taken to tau, the state switched, the acceleration re-computed from
    equilibrium in the new state (damping changes), and the remainder of the
    step integrated.  Several crossings in one step are handled in time order.
    """
    contactors = [dict(c) for c in contactors]
    sides = []
    for c in contactors:
        if c.get("side") not in ("above", "below"):
            raise ValueError("contactor side must be 'above' or 'below'")
        if not (c["stiffness"] > 0 and math.isfinite(c["stiffness"])):
            raise ValueError("contactor stiffness must be positive and finite")
        if not c["gap"] >= 0:
            raise ValueError("contactor gap must be >= 0")
        sides.append(1.0 if c["side"] == "above" else -1.0)
    load = dict(load) if load else {"kind": "none"}
    kind = load.get("kind", "none")
    if output_x is None:
        output_x = [c["position"] for c in contactors] + [length]
    extra_nodes = [c["position"] for c in contactors]
    if kind == "point_force":
        extra_nodes.append(load["position"])
    model = assemble(
        length, EI, rhoA, n_elements=n_elements, left=left, right=right,
        springs=springs, nodes_at=extra_nodes, **structure,
    )
    free = model.free
    Kr, Mr = model.K_r, model.M_r
    nf = len(free)
    xi_free, xi_contact = damping

    # contactor DOFs in the reduced vector
    cdof = [model.reduced_index(2 * model.node_index(c["position"])) for c in contactors]
    ck = np.array([float(c["stiffness"]) for c in contactors])
    cgap = np.array([float(c["gap"]) for c in contactors])
    cs = np.array(sides)
    nc = len(contactors)

    # load vector (reduced), as a function of time
    if kind in ("none", None):
        fvec = np.zeros(nf)

        def amp(t: float) -> float:
            return 0.0
    elif kind == "base_acceleration":
        r = np.zeros(model.n_dof)
        r[0::2] = 1.0
        fvec = -(model.M @ r)[free]
        shape = load.get("shape", "half_sine")
        a0_, st_, du_ = float(load["amplitude"]), float(load.get("start", 0.0)), load.get("duration")
        fr_, ph_ = load.get("frequency"), float(load.get("phase", 0.0))

        def amp(t: float) -> float:
            return _pulse(t, shape, a0_, st_, du_, fr_, ph_)
    elif kind == "point_force":
        fvec = np.zeros(nf)
        fvec[model.reduced_index(2 * model.node_index(load["position"]))] = 1.0
        shape = load.get("shape", "step")
        a0_, st_, du_ = float(load["amplitude"]), float(load.get("start", 0.0)), load.get("duration")
        fr_, ph_ = load.get("frequency"), float(load.get("phase", 0.0))

        def amp(t: float) -> float:
            return _pulse(t, shape, a0_, st_, du_, fr_, ph_)
    else:
        raise ValueError(f"unknown load kind {kind!r}")

    # states ---------------------------------------------------------------
    state_cache: dict[tuple, tuple] = {}
    factor_cache: dict[tuple, tuple] = {}
    n_fact = [0]

    def state(key: tuple) -> tuple:
        """(K_s, fc_s, C_s) for the engaged set ``key`` (tuple of bools)."""
        if key not in state_cache:
            Ks = Kr.copy()
            fc = np.zeros(nf)
            for i, on in enumerate(key):
                if on:
                    Ks[cdof[i], cdof[i]] += ck[i]
                    fc[cdof[i]] += cs[i] * ck[i] * cgap[i]
            xi = xi_contact if any(key) else xi_free
            if xi != 0.0:
                lam, phi = _eig_all(Ks, Mr)
                MP = Mr @ phi
                C = (MP * (2.0 * xi * np.sqrt(lam))) @ MP.T
                C = 0.5 * (C + C.T)
            else:
                C = np.zeros_like(Kr)
            state_cache[key] = (Ks, fc, C)
        return state_cache[key]

    def factor(key: tuple, h: float, cache: bool) -> tuple:
        """(Cholesky factor of K_eff(h), B = 4/h M + C) for the state."""
        fk = (key, h)
        if cache and fk in factor_cache:
            return factor_cache[fk]
        Ks, _, C = state(key)
        n_fact[0] += 1
        c, _lower = sla.cho_factor(Ks + (2.0 / h) * C + (4.0 / (h * h)) * Mr, lower=False, check_finite=False)
        out = (c, (4.0 / h) * Mr + C)
        if cache:
            factor_cache[fk] = out
        return out

    Mchol, _ = sla.cho_factor(Mr, lower=False, check_finite=False)

    def accel(key: tuple, u: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        """Acceleration from equilibrium M a = f - C v - K u (+ contact force)."""
        Ks, fc, C = state(key)
        x, info = potrs(Mchol, amp(t) * fvec + fc - Ks @ u - C @ v, lower=0)
        return x

    def newmark(key, u0, v0, a0, t0, h, fac):
        """One average-acceleration step of length h in state ``key``."""
        Ks, fc, C = state(key)
        c, B = fac
        rhs = amp(t0 + h) * fvec + fc - Ks @ u0 + B @ v0 + Mr @ a0
        du, info = potrs(c, rhs, lower=0)
        u1 = u0 + du
        v1 = (2.0 / h) * du - v0
        a1 = (4.0 / (h * h)) * du - (4.0 / h) * v0 - a0
        return u1, v1, a1, du

    def gap(u: np.ndarray, i: int) -> float:
        return float(cgap[i] - cs[i] * u[cdof[i]])

    # initial state --------------------------------------------------------
    u = np.zeros(nf)
    v = np.zeros(nf)
    if initial:
        if "tip_displacement" in initial:
            p = np.zeros(nf)
            itip = model.reduced_index(2 * (model.n_nodes - 1))
            p[itip] = 1.0
            us = sla.solve(Kr, p, assume_a="pos")
            u = us * (float(initial["tip_displacement"]) / us[itip])
        else:
            unknown = set(initial) - {"w", "w_x", "w_t", "w_xt"}
            if unknown:
                raise ValueError(f"unknown initial keys {sorted(unknown)}")
            u = model.nodal_vector(initial.get("w"), initial.get("w_x"))[free]
            v = model.nodal_vector(initial.get("w_t"), initial.get("w_xt"))[free]
    key = tuple(gap(u, i) < 0 for i in range(nc))
    a = accel(key, u, v, 0.0)

    # outputs ----------------------------------------------------------------
    n_steps = int(round(t_end / dt))
    nt = n_steps + 1
    x_out = np.asarray(output_x, dtype=float)
    P = model.interpolation_matrix(x_out)[:, free]
    block = 4096
    Ubuf = np.empty((block, nf))
    Vbuf = np.empty((block, nf))
    W = np.empty((nt, len(x_out)))
    V = np.empty((nt, len(x_out)))
    KE = np.empty(nt)
    SE = np.empty(nt)
    CE = np.empty(nt)
    WORK = np.empty(nt)
    DISS = np.empty(nt)
    FC = np.zeros((nt, nc))
    ENG = np.zeros((nt, nc), dtype=bool)
    events: list = []
    event_gap: list = []
    work = 0.0
    diss = 0.0
    cdof_arr = np.asarray(cdof, dtype=int)

    def flush(k0: int, k1: int) -> None:
        """Outputs and energies of grid points k0..k1-1 from the buffers."""
        U = Ubuf[: k1 - k0]
        Vv = Vbuf[: k1 - k0]
        W[k0:k1] = U @ P.T
        V[k0:k1] = Vv @ P.T
        KE[k0:k1] = 0.5 * np.einsum("ij,ij->i", Vv, Vv @ Mr)
        full = np.zeros((model.n_dof, k1 - k0))
        full[free] = U.T
        SE[k0:k1] = strain_energy(model, full)
        g = cgap[None, :] - cs[None, :] * U[:, cdof_arr]
        on = ENG[k0:k1]
        CE[k0:k1] = 0.5 * np.sum(np.where(on, ck * g * g, 0.0), axis=1)
        FC[k0:k1] = np.where(on, cs * ck * g, 0.0)

    def store(k: int) -> None:
        j = k % block
        Ubuf[j] = u
        Vbuf[j] = v
        ENG[k] = key
        WORK[k] = work
        DISS[k] = diss
        if j == block - 1 or k == nt - 1:
            flush(k - j, k + 1)

    def account(du: np.ndarray, t_a: float, t_b: float, C: np.ndarray, h: float) -> None:
        nonlocal work, diss
        work += 0.5 * (amp(t_a) + amp(t_b)) * float(du @ fvec)
        if xi_free != 0.0 or xi_contact != 0.0:
            diss += float(du @ (C @ du)) / h

    store(0)
    tiny = 1e-13  # s: below this a remaining sub-step is dropped / a root is "at the start"
    for n in range(n_steps):
        t_grid_end = (n + 1) * dt
        t = n * dt
        rem = dt
        toggled_at_t: set[int] = set()
        guard = 0
        while True:
            guard += 1
            if guard > 1000:
                raise RuntimeError(f"too many switches in step {n}")
            fac = factor(key, rem, cache=(rem == dt))
            u1, v1, a1, du = newmark(key, u, v, a, t, rem, fac)
            taus: dict[int, float] = {}
            for i in range(nc):
                g1 = gap(u1, i)
                if not ((not key[i] and g1 < 0) or (key[i] and g1 > 0)):
                    continue
                g0 = gap(u, i)
                # consistent side at the start?  free: g0 > 0; engaged: g0 < 0
                if not ((g0 > 0) if not key[i] else (g0 < 0)):
                    tau = 0.0
                else:
                    def gfun(h, i=i, g0=g0):
                        if h <= 0.0:
                            return g0
                        uh = newmark(key, u, v, a, t, h, factor(key, h, cache=False))[0]
                        return gap(uh, i)
                    tau = brentq(gfun, 0.0, rem, xtol=1e-14, rtol=4 * np.finfo(float).eps, maxiter=200)
                if tau <= tiny and i in toggled_at_t:
                    continue  # grazing chatter guard: no second zero-length toggle
                taus[i] = tau
            if not taus:
                account(du, t, t + rem, state(key)[2], rem)
                u, v, a = u1, v1, a1
                break
            tau = min(taus.values())
            switch = sorted(i for i, ti in taus.items() if ti <= tau + 1e-13)
            if tau > tiny:
                u1, v1, a1, du = newmark(key, u, v, a, t, tau, factor(key, tau, cache=False))
                account(du, t, t + tau, state(key)[2], tau)
                u, v = u1, v1
                t = t + tau
                toggled_at_t = set()
            newkey = list(key)
            for i in switch:
                gnow = gap(u, i)
                newkey[i] = not key[i]
                events.append((t, "impact" if newkey[i] else "rebound", i))
                event_gap.append(gnow)
                toggled_at_t.add(i)
                # the contactor energy 1/2 k g^2 (g ~ 1e-16) appears/vanishes:
                # book the round-off-level jump as work so the balance is exact
                work += (0.5 if newkey[i] else -0.5) * ck[i] * gnow * gnow
            key = tuple(newkey)
            a = accel(key, u, v, t)
            rem = t_grid_end - t
            if rem <= tiny:
                break
        store(n + 1)

    return TransientResult(
        t=np.arange(nt) * dt,
        x_out=x_out,
        w=W,
        w_t=V,
        events=events,
        event_gap=event_gap,
        contact_force=FC,
        engaged=ENG,
        kinetic=KE,
        strain=SE,
        contactor=CE,
        work=WORK,
        dissipated=DISS,
        x_nodes=model.x.copy(),
        n_factorisations=n_fact[0],
    )


# --------------------------------------------------------------------------
# Dissipative contact and beam damping models
# --------------------------------------------------------------------------
@dataclass
class DissipativeResult(TransientResult):
    """Output of :func:`fe_transient_dissipative` (the fields of :class:`TransientResult`, and):

    ``contact_force`` (n_t, n_contactors) is ``k d + c d'`` of the engaged
    contactors (>= 0, the magnitude pushing the beam back), ``penetration``
    (n_t, n_contactors) ``d = s w(a) - gap``; ``event_state`` per event
    ``(d, d', force before, force after)`` of the switching contactor;
    ``dashpot`` (n_t,) cumulative energy dissipated by the contactor dashpots
    (incl. the spring energy ``1/2 k d^2`` left in a contactor released at
    ``d > 0``, which its dashpot dissipates as it relaxes), ``dissipated`` the
    beam's and the dashpots' together; ``engagement_work`` (n_t,) cumulative
    ``1/2 k d^2`` of contactors engaged at ``d > 0`` (booked as work, so the
    balance stays exact).
    """

    penetration: np.ndarray = field(default=None)
    event_state: list = field(default_factory=list)
    dashpot: np.ndarray = field(default=None)
    engagement_work: np.ndarray = field(default=None)


def _beam_damping(model: FEModel, spec: dict, Ks: np.ndarray, engaged: bool, C_free: list) -> np.ndarray:
    """The beam's damping matrix in a state (reduced DOFs), by ``spec["model"]``.

    ``modal``: ``M Phi diag(2 xi omega) Phi^T M`` on all FE modes of the state
    (``xi = spec["free"]`` or ``spec["contact"]``); ``rayleigh``: ``alpha M +
    beta K_s`` (``K_s`` with the engaged contact springs); ``free_modes``: the
    modal matrix of the FREE state's FE modes with ``spec["free"]``, the same
    in every state (``C_free`` caches it).
    """
    kind = spec.get("model", "modal")
    Mr = model.M_r
    if kind == "rayleigh":
        return float(spec.get("alpha", 0.0)) * Mr + float(spec.get("beta", 0.0)) * Ks
    if kind == "free_modes":
        if not C_free:
            C_free.append(_beam_damping(model, {"model": "modal", "free": spec["free"]}, model.K_r, False, []))
        return C_free[0]
    if kind != "modal":
        raise ValueError(f"unknown damping model {kind!r}")
    xi = float(spec.get("contact", 0.0) if engaged else spec.get("free", 0.0))
    if xi == 0.0:
        return np.zeros_like(Mr)
    lam, phi = _eig_all(Ks, Mr)
    MP = Mr @ phi
    C = (MP * (2.0 * xi * np.sqrt(lam))) @ MP.T
    return 0.5 * (C + C.T)


def fe_transient_dissipative(
    length: float,
    EI: float,
    rhoA: float,
    *,
    left: tuple[float, float],
    right: tuple[float, float],
    contactors: Sequence[dict] = (),
    load: dict | None = None,
    initial: dict | None = None,
    damping: dict | None = None,
    dt: float,
    t_end: float,
    output_x: Sequence[float] | None = None,
    n_elements: int = 50,
    **structure: Sequence,
) -> DissipativeResult:
    """Newmark transient with contactor dashpots (force release) and the three beam damping models.

    Parameters as :func:`fe_transient`, except:

    contactors : dicts ``{"position", "stiffness", "gap", "side", "damping"=0}``.
        With the penetration ``d = s w(a) - gap`` (s = +1 above, -1 below) the
        contactor pushes the beam back with ``F = k d + c d'`` while engaged.
        It engages when ``d > 0`` and ``F > 0`` (at ``d = 0`` moving in: ``F =
        c d' > 0``; or, still penetrated after a release, when ``F`` turns
        positive) and is released when ``F`` reaches 0 (before ``d`` does when
        ``c > 0``): it never pulls. ``c = 0`` is the contactor of
        :func:`fe_transient`.
    damping : ``{"model": "modal", "free": xi_f, "contact": xi_c}`` (default,
        undamped), ``{"model": "rayleigh", "alpha": a, "beta": b}`` (``C = a M
        + b K_s``, ``K_s`` with the engaged springs), or ``{"model":
        "free_modes", "free": xi}`` (the free state's modal damping matrix on
        all its FE modes, kept in every state). The dashpots add to it.

    Method
    ------
    As :func:`fe_transient`; the switching function of contactor ``i`` is
    ``h = F/k`` while engaged (released where it falls to 0) and ``h =
    min(d, F/k)`` while free (engaged where it rises above 0), both located
    inside a step by Brent's method on re-done Newmark steps (xtol 1e-14 s),
    never snapped to the grid. Energies: the discrete balance of the
    average-acceleration rule, ``dissipated`` including the dashpots.
    """
    contactors = [dict(c) for c in contactors]
    sides = []
    for c in contactors:
        if c.get("side") not in ("above", "below"):
            raise ValueError("contactor side must be 'above' or 'below'")
        if not (c["stiffness"] > 0 and math.isfinite(c["stiffness"])):
            raise ValueError("contactor stiffness must be positive and finite")
        if not (c["gap"] >= 0 and c.get("damping", 0.0) >= 0):
            raise ValueError("contactor gap and damping must be >= 0")
        sides.append(1.0 if c["side"] == "above" else -1.0)
    spec = dict(damping) if damping else {"model": "modal"}
    load = dict(load) if load else {"kind": "none"}
    kind = load.get("kind", "none")
    if output_x is None:
        output_x = [c["position"] for c in contactors] + [length]
    extra_nodes = [c["position"] for c in contactors] + ([load["position"]] if kind == "point_force" else [])
    model = assemble(length, EI, rhoA, n_elements=n_elements, left=left, right=right, nodes_at=extra_nodes,
                     **structure)
    free = model.free
    Kr, Mr = model.K_r, model.M_r
    nf = len(free)
    cdof = [model.reduced_index(2 * model.node_index(c["position"])) for c in contactors]
    ck = np.array([float(c["stiffness"]) for c in contactors])
    cc = np.array([float(c.get("damping", 0.0)) for c in contactors])
    cgap = np.array([float(c["gap"]) for c in contactors])
    cs = np.array(sides)
    nc = len(contactors)

    fvec = np.zeros(nf)
    if kind == "base_acceleration":
        r = np.zeros(model.n_dof)
        r[0::2] = 1.0
        fvec = -(model.M @ r)[free]
    elif kind == "point_force":
        fvec[model.reduced_index(2 * model.node_index(load["position"]))] = 1.0
    elif kind not in ("none", None):
        raise ValueError(f"unknown load kind {kind!r}")
    a0_ = float(load.get("amplitude", 0.0))
    shape_ = load.get("shape", "half_sine" if kind == "base_acceleration" else "step")
    st_, du_ = float(load.get("start", 0.0)), load.get("duration")
    fr_, ph_ = load.get("frequency"), float(load.get("phase", 0.0))

    def amp(t: float) -> float:
        return 0.0 if kind in ("none", None) else _pulse(t, shape_, a0_, st_, du_, fr_, ph_)

    state_cache: dict[tuple, tuple] = {}
    factor_cache: dict[tuple, tuple] = {}
    C_free: list = []
    n_fact = [0]

    def state(key: tuple) -> tuple:
        """(K_s, fc_s, C_s) of the engaged set ``key``: springs, gap forces, beam damping + dashpots."""
        if key not in state_cache:
            Ks = Kr.copy()
            fc = np.zeros(nf)
            for i, on in enumerate(key):
                if on:
                    Ks[cdof[i], cdof[i]] += ck[i]
                    fc[cdof[i]] += cs[i] * ck[i] * cgap[i]
            C = _beam_damping(model, spec, Ks, any(key), C_free).copy()
            for i, on in enumerate(key):
                if on:
                    C[cdof[i], cdof[i]] += cc[i]
            state_cache[key] = (Ks, fc, C)
        return state_cache[key]

    def factor(key: tuple, h: float, cache: bool) -> tuple:
        fk = (key, h)
        if cache and fk in factor_cache:
            return factor_cache[fk]
        Ks, _, C = state(key)
        n_fact[0] += 1
        c, _lower = sla.cho_factor(Ks + (2.0 / h) * C + (4.0 / (h * h)) * Mr, lower=False, check_finite=False)
        out = (c, (4.0 / h) * Mr + C)
        if cache:
            factor_cache[fk] = out
        return out

    Mchol, _ = sla.cho_factor(Mr, lower=False, check_finite=False)

    def accel(key: tuple, u: np.ndarray, v: np.ndarray, t: float) -> np.ndarray:
        Ks, fc, C = state(key)
        return potrs(Mchol, amp(t) * fvec + fc - Ks @ u - C @ v, lower=0)[0]

    def newmark(key, u0, v0, a0, t0, h, fac):
        Ks, fc, C = state(key)
        c, B = fac
        rhs = amp(t0 + h) * fvec + fc - Ks @ u0 + B @ v0 + Mr @ a0
        du = potrs(c, rhs, lower=0)[0]
        return u0 + du, (2.0 / h) * du - v0, (4.0 / (h * h)) * du - (4.0 / h) * v0 - a0, du

    def pen(u: np.ndarray, v: np.ndarray, i: int) -> tuple[float, float, float]:
        d = float(cs[i] * u[cdof[i]] - cgap[i])
        dd = float(cs[i] * v[cdof[i]])
        return d, dd, ck[i] * d + cc[i] * dd

    def h_switch(u: np.ndarray, v: np.ndarray, i: int, on: bool) -> float:
        d, _, F = pen(u, v, i)
        return F / ck[i] if on else min(d, F / ck[i])

    u = np.zeros(nf)
    v = np.zeros(nf)
    if initial:
        if "tip_displacement" in initial:
            p = np.zeros(nf)
            itip = model.reduced_index(2 * (model.n_nodes - 1))
            p[itip] = 1.0
            us = sla.solve(Kr, p, assume_a="pos")
            u = us * (float(initial["tip_displacement"]) / us[itip])
        else:
            unknown = set(initial) - {"w", "w_x", "w_t", "w_xt"}
            if unknown:
                raise ValueError(f"unknown initial keys {sorted(unknown)}")
            u = model.nodal_vector(initial.get("w"), initial.get("w_x"))[free]
            v = model.nodal_vector(initial.get("w_t"), initial.get("w_xt"))[free]
    key = tuple(h_switch(u, v, i, False) > 0 for i in range(nc))
    a = accel(key, u, v, 0.0)

    n_steps = int(round(t_end / dt))
    nt = n_steps + 1
    x_out = np.asarray(output_x, dtype=float)
    P = model.interpolation_matrix(x_out)[:, free]
    W = np.empty((nt, len(x_out)))
    V = np.empty((nt, len(x_out)))
    KE = np.empty(nt)
    SE = np.empty(nt)
    CE = np.empty(nt)
    WORK = np.empty(nt)
    DISS = np.empty(nt)
    DASH = np.empty(nt)
    EWORK = np.empty(nt)
    FC = np.zeros((nt, nc))
    PEN = np.zeros((nt, nc))
    ENG = np.zeros((nt, nc), dtype=bool)
    events: list = []
    event_gap: list = []
    event_state: list = []
    acc = {"work": 0.0, "diss": 0.0, "dash": 0.0, "ework": 0.0}
    ucols = np.asarray(cdof, dtype=int)

    def store(k: int) -> None:
        W[k] = P @ u
        V[k] = P @ v
        KE[k] = 0.5 * float(v @ (Mr @ v))
        SE[k] = float(strain_energy(model, model.expand(u)))
        d = cs * u[ucols] - cgap if nc else np.zeros(0)
        dd = cs * v[ucols] if nc else np.zeros(0)
        on = np.asarray(key, dtype=bool)
        ENG[k] = on
        PEN[k] = d
        FC[k] = np.where(on, ck * d + cc * dd, 0.0)
        CE[k] = 0.5 * float(np.sum(np.where(on, ck * d * d, 0.0)))
        WORK[k], DISS[k], DASH[k], EWORK[k] = acc["work"], acc["diss"], acc["dash"], acc["ework"]

    def account(du: np.ndarray, t_a: float, t_b: float, h: float) -> None:
        acc["work"] += 0.5 * (amp(t_a) + amp(t_b)) * float(du @ fvec)
        C = state(key)[2]
        acc["diss"] += float(du @ (C @ du)) / h
        on = np.asarray(key, dtype=bool)
        if nc and on.any():
            dq = du[ucols]
            acc["dash"] += float(np.sum(np.where(on, cc * dq * dq, 0.0))) / h

    store(0)
    tiny = 1e-13
    for n in range(n_steps):
        t_grid_end = (n + 1) * dt
        t = n * dt
        rem = dt
        toggled_at_t: set[int] = set()
        guard = 0
        while True:
            guard += 1
            if guard > 1000:
                raise RuntimeError(f"too many switches in step {n}")
            u1, v1, a1, du = newmark(key, u, v, a, t, rem, factor(key, rem, cache=(rem == dt)))
            taus: dict[int, float] = {}
            for i in range(nc):
                on = key[i]
                h1 = h_switch(u1, v1, i, on)
                if not ((on and h1 <= 0.0) or (not on and h1 > 0.0)):
                    continue
                h0 = h_switch(u, v, i, on)
                if (on and h0 <= 0.0) or (not on and h0 > 0.0):
                    tau = 0.0
                else:
                    def hfun(hh, i=i, on=on, h0=h0):
                        if hh <= 0.0:
                            return h0
                        uh, vh, _, _ = newmark(key, u, v, a, t, hh, factor(key, hh, cache=False))
                        return h_switch(uh, vh, i, on)
                    tau = brentq(hfun, 0.0, rem, xtol=1e-14, rtol=4 * np.finfo(float).eps, maxiter=200)
                if tau <= tiny and i in toggled_at_t:
                    continue
                taus[i] = tau
            if not taus:
                account(du, t, t + rem, rem)
                u, v, a = u1, v1, a1
                break
            tau = min(taus.values())
            switch = sorted(i for i, ti in taus.items() if ti <= tau + 1e-13)
            if tau > tiny:
                u1, v1, a1, du = newmark(key, u, v, a, t, tau, factor(key, tau, cache=False))
                account(du, t, t + tau, tau)
                u, v = u1, v1
                t = t + tau
                toggled_at_t = set()
            newkey = list(key)
            for i in switch:
                d, dd, F_before = pen(u, v, i)
                newkey[i] = not key[i]
                F_after = ck[i] * d + cc[i] * dd if newkey[i] else 0.0
                if not key[i]:
                    F_before = 0.0
                events.append((t, "impact" if newkey[i] else "rebound", i))
                event_gap.append(-d)
                event_state.append((d, dd, F_before, F_after))
                toggled_at_t.add(i)
                e = 0.5 * ck[i] * d * d
                if newkey[i]:
                    acc["ework"] += e
                    acc["work"] += e
                else:
                    acc["dash"] += e
                    acc["diss"] += e
            key = tuple(newkey)
            a = accel(key, u, v, t)
            rem = t_grid_end - t
            if rem <= tiny:
                break
        store(n + 1)

    return DissipativeResult(
        t=np.arange(nt) * dt, x_out=x_out, w=W, w_t=V, events=events, event_gap=event_gap,
        contact_force=FC, engaged=ENG, kinetic=KE, strain=SE, contactor=CE, work=WORK, dissipated=DISS,
        x_nodes=model.x.copy(), n_factorisations=n_fact[0], penetration=PEN, event_state=event_state,
        dashpot=DASH, engagement_work=EWORK,
    )


# --------------------------------------------------------------------------
# Exact-in-time integration of the FE model (for dashpots and damping models)
# --------------------------------------------------------------------------
@dataclass
class ExactResult:
    """Output of :func:`fe_transient_exact`.

    ``t`` (n_t,) output grid ``k dt``; ``w``, ``w_t`` (n_t, n_points) at
    ``x_out``; ``contact_force``, ``penetration`` (n_t, n_contactors) as in
    :class:`DissipativeResult`; ``engaged`` (n_t, n_contactors);
    ``events`` list of ``(time, 'impact'|'rebound', contactor)``;
    ``event_state`` per event ``(d, d', force before, force after)``;
    ``peaks`` list of ``(time, force, contactor)``: the largest contact force
    of every contact interval, located exactly (Brent on ``dF/dt``, or the
    interval's end when the force is largest there); ``kinetic``, ``strain``,
    ``contactor`` energies on the grid; ``dashpot`` (n_t,) cumulative energy
    dissipated by the dashpots (``c d'^2`` by the trapezoidal rule on the grid
    and the exact sub-steps, plus ``1/2 k d^2`` at releases with ``d > 0``);
    ``event_residual`` the largest ``|h|`` [m] of a switching function at a
    located event (``F/k`` or ``min(d, F/k)``: round-off, ~1e-15 m).
    """

    t: np.ndarray
    x_out: np.ndarray
    w: np.ndarray
    w_t: np.ndarray
    contact_force: np.ndarray
    penetration: np.ndarray
    engaged: np.ndarray
    events: list
    event_state: list
    peaks: list
    kinetic: np.ndarray
    strain: np.ndarray
    contactor: np.ndarray
    dashpot: np.ndarray
    event_residual: float
    n_modes_fe: int


def _load_pieces(load: dict, t_end: float) -> list[tuple[float, float, float, float, float]]:
    """``(t0, t1, const, amp, Omega)``: the load ``const + amp sin(Omega (t - t0))`` on [t0, t1)."""
    kind = load.get("kind", "none")
    if kind in ("none", None):
        return [(0.0, math.inf, 0.0, 0.0, 0.0)]
    shape = load.get("shape", "half_sine" if kind == "base_acceleration" else "step")
    A, start = float(load["amplitude"]), float(load.get("start", 0.0))
    pieces = [(0.0, start, 0.0, 0.0, 0.0)] if start > 0 else []
    if shape == "step":
        pieces.append((start, math.inf, A, 0.0, 0.0))
    elif shape == "half_sine":
        T = float(load["duration"])
        pieces += [(start, start + T, 0.0, A, math.pi / T), (start + T, math.inf, 0.0, 0.0, 0.0)]
    else:
        raise ValueError(f"fe_transient_exact: load shape {shape!r} not supported (step, half_sine)")
    return [p for p in pieces if p[1] > p[0]]


def fe_transient_exact(
    length: float,
    EI: float,
    rhoA: float,
    *,
    left: tuple[float, float],
    right: tuple[float, float],
    contactors: Sequence[dict] = (),
    load: dict | None = None,
    initial: dict | None = None,
    damping: dict | None = None,
    dt: float,
    t_end: float,
    output_x: Sequence[float] | None = None,
    n_elements: int = 50,
    **structure: Sequence,
) -> ExactResult:
    """The FE model of :func:`fe_transient_dissipative` integrated EXACTLY in time between events.

    Same parameters (``load``: step or half-sine). The only approximation
    left is the spatial discretisation (Hermite cubics), so the reference
    converges by refining the mesh alone, and the fast components a dashpot
    force jump excites are integrated exactly (an average-acceleration step
    keeps them with wrong phases, which moves a dashpot's release time by
    microseconds).

    Method
    ------
    In the free state's FE modes ``u = Phi q`` (``Phi^T M Phi = I``) and the
    scaled state ``z = (S q, q', 1, s, c)`` with ``S = diag(sqrt(omega^2 +
    omega_1^2))`` (so ``|A| ~ omega_max``: a well-scaled matrix exponential),
    each state (engaged set) and load piece is the autonomous linear system
    ``z' = A z``: ``q'' = -K_s q - C_s q' + f_c + (const + amp s) f``, ``s' =
    Omega c``, ``c' = -Omega s`` (``s, c`` the sine and cosine of the load's
    phase). The grid steps are ``z <- expm(A dt) z`` (one exponential per
    state and piece, cached). A switching function (as in
    :func:`fe_transient_dissipative`) that changes sign over a step is located
    by Brent's method (xtol 1e-15 s) on ``z(tau) = V exp(Lambda tau) V^-1 z``
    (eigen-decomposition of ``A``), and the state at the root is
    ``expm(A tau) z``; ``event_residual`` reports the switching function there.
    Two crossings inside one grid step are not seen (choose ``dt`` below the
    shortest contact or separation).
    """
    contactors = [dict(c) for c in contactors]
    cs = np.array([1.0 if c["side"] == "above" else -1.0 for c in contactors])
    for c in contactors:
        if c.get("side") not in ("above", "below") or not (0 < c["stiffness"] < math.inf) or c["gap"] < 0:
            raise ValueError(f"bad contactor {c}")
    spec = dict(damping) if damping else {"model": "modal"}
    load = dict(load) if load else {"kind": "none"}
    kind = load.get("kind", "none")
    if output_x is None:
        output_x = [c["position"] for c in contactors] + [length]
    extra = [c["position"] for c in contactors] + ([load["position"]] if kind == "point_force" else [])
    model = assemble(length, EI, rhoA, n_elements=n_elements, left=left, right=right, nodes_at=extra, **structure)
    free = model.free
    nf = len(free)
    lam, Phi = sla.eigh(model.K_r, model.M_r)
    lam = np.where(lam < 1e-10 * model.EI / (model.rhoA * length**4), 0.0, lam)
    om2_ref = max(float(lam[lam > 0][0]) if np.any(lam > 0) else 0.0, model.EI / (model.rhoA * length**4))
    S = np.sqrt(lam + om2_ref)
    cdof = [model.reduced_index(2 * model.node_index(c["position"])) for c in contactors]
    phc = Phi[cdof, :] if contactors else np.zeros((0, nf))  # (nc, nf)
    ck = np.array([float(c["stiffness"]) for c in contactors])
    cc = np.array([float(c.get("damping", 0.0)) for c in contactors])
    cgap = np.array([float(c["gap"]) for c in contactors])
    nc = len(contactors)
    fvec = np.zeros(nf)
    if kind == "base_acceleration":
        r = np.zeros(model.n_dof)
        r[0::2] = 1.0
        fvec = -(model.M @ r)[free]
    elif kind == "point_force":
        fvec[model.reduced_index(2 * model.node_index(load["position"]))] = 1.0
    fq = Phi.T @ fvec
    pieces = _load_pieces(load, t_end)
    C_free: list = []
    n = 2 * nf + 3
    cache_A: dict = {}
    cache_P: dict = {}
    cache_E: dict = {}

    def system(key: tuple, ip: int) -> np.ndarray:
        if (key, ip) not in cache_A:
            Ks = np.diag(lam).astype(float)
            K_phys = model.K_r.copy()
            for i in range(nc):
                if key[i]:
                    K_phys[cdof[i], cdof[i]] += ck[i]
            Cs = Phi.T @ _beam_damping(model, spec, K_phys, any(key), C_free) @ Phi
            fc = np.zeros(nf)
            for i in range(nc):
                if key[i]:
                    Ks += ck[i] * np.outer(phc[i], phc[i])
                    Cs += cc[i] * np.outer(phc[i], phc[i])
                    fc += cs[i] * ck[i] * cgap[i] * phc[i]
            _, _, const, amp, Om = pieces[ip]
            A = np.zeros((n, n))
            A[:nf, nf:2 * nf] = np.diag(S)
            A[nf:2 * nf, :nf] = -Ks / S[None, :]
            A[nf:2 * nf, nf:2 * nf] = -0.5 * (Cs + Cs.T)
            A[nf:2 * nf, 2 * nf] = fc + const * fq
            A[nf:2 * nf, 2 * nf + 1] = amp * fq
            A[2 * nf + 1, 2 * nf + 2] = Om
            A[2 * nf + 2, 2 * nf + 1] = -Om
            cache_A[(key, ip)] = A
        return cache_A[(key, ip)]

    def prop(key: tuple, ip: int, h: float, cache: bool) -> np.ndarray:
        if cache and (key, ip, h) in cache_P:
            return cache_P[(key, ip, h)]
        P = sla.expm(system(key, ip) * h)
        if cache:
            cache_P[(key, ip, h)] = P
        return P

    def eig(key: tuple, ip: int):
        if (key, ip) not in cache_E:
            ev, V = np.linalg.eig(system(key, ip))
            cache_E[(key, ip)] = (ev, V, np.linalg.inv(V))
        return cache_E[(key, ip)]

    def contact(z: np.ndarray, i: int, zdot: np.ndarray | None = None) -> tuple[float, float, float, float]:
        """(d, d', F, dF/dt) of contactor i in state z."""
        q = z[:nf] / S
        d = float(cs[i] * phc[i] @ q - cgap[i])
        dd = float(cs[i] * phc[i] @ z[nf:2 * nf])
        ddd = float(cs[i] * phc[i] @ zdot[nf:2 * nf]) if zdot is not None else 0.0
        return d, dd, ck[i] * d + cc[i] * dd, ck[i] * dd + cc[i] * ddd

    def hsw(z: np.ndarray, i: int, on: bool) -> float:
        d, _, F, _ = contact(z, i)
        return F / ck[i] if on else min(d, F / ck[i])

    # initial state
    q0 = np.zeros(nf)
    v0 = np.zeros(nf)
    if initial:
        if "tip_displacement" in initial:
            p = np.zeros(nf)
            itip = model.reduced_index(2 * (model.n_nodes - 1))
            p[itip] = 1.0
            us = sla.solve(model.K_r, p, assume_a="pos")
            q0 = Phi.T @ (model.M_r @ (us * (float(initial["tip_displacement"]) / us[itip])))
        else:
            q0 = Phi.T @ (model.M_r @ model.nodal_vector(initial.get("w"), initial.get("w_x"))[free])
            v0 = Phi.T @ (model.M_r @ model.nodal_vector(initial.get("w_t"), initial.get("w_xt"))[free])

    def piece_at(t: float) -> int:
        for j, p in enumerate(pieces):
            if p[0] <= t < p[1]:
                return j
        return len(pieces) - 1

    def enter_piece(z: np.ndarray, ip: int, t: float) -> np.ndarray:
        z = z.copy()
        z[2 * nf] = 1.0
        Om, t0 = pieces[ip][4], pieces[ip][0]
        z[2 * nf + 1], z[2 * nf + 2] = math.sin(Om * (t - t0)), math.cos(Om * (t - t0))
        return z

    z = np.concatenate([S * q0, v0, [1.0, 0.0, 1.0]])
    ip = piece_at(0.0)
    z = enter_piece(z, ip, 0.0)
    key = tuple(hsw(z, i, False) > 0 for i in range(nc))

    n_steps = int(round(t_end / dt))
    nt = n_steps + 1
    x_out = np.asarray(output_x, dtype=float)
    Pout = model.interpolation_matrix(x_out)[:, free] @ Phi
    W = np.empty((nt, len(x_out)))
    Vv = np.empty((nt, len(x_out)))
    KE, SE, CE, DASH = (np.empty(nt) for _ in range(4))
    FC = np.zeros((nt, nc))
    PEN = np.zeros((nt, nc))
    ENG = np.zeros((nt, nc), dtype=bool)
    events, event_state, peaks = [], [], []
    resid = 0.0
    dash = [0.0]
    open_peak: dict[int, tuple[float, float]] = {}

    def advance(z0: np.ndarray, h: float, cache: bool) -> np.ndarray:
        return prop(key, ip, h, cache) @ z0

    def z_at(z0: np.ndarray, tau: float) -> np.ndarray:
        ev, V, Vi = eig(key, ip)
        return np.real(V @ (np.exp(ev * tau) * (Vi @ z0)))

    def kinematics(Z: np.ndarray, AZ: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
        """(d, d', F, dF/dt) of every contactor at every row of Z: (m, nc) each."""
        d = cs * ((Z[:, :nf] / S) @ phc.T) - cgap
        dd = cs * (Z[:, nf:2 * nf] @ phc.T)
        ddd = cs * (AZ[:, nf:2 * nf] @ phc.T) if AZ is not None else np.zeros_like(dd)
        return d, dd, ck * d + cc * dd, ck * dd + cc * ddd

    def first_switch(Z: np.ndarray) -> int:
        """Index of the first row where a contactor's switching condition holds (len(Z) if none)."""
        if nc == 0:
            return len(Z)
        d, _, F, _ = kinematics(Z)
        on = np.asarray(key, dtype=bool)
        bad = np.where(on, F / ck <= 0.0, np.minimum(d, F / ck) > 0.0).any(axis=1)
        return int(np.argmax(bad)) if bad.any() else len(Z)

    def accept(k0: int, z0: np.ndarray, Z: np.ndarray, t0: float, h: float) -> None:
        """Book the states ``Z`` (rows at ``t0 + (j + 1) h``) reached from ``z0``: outputs from grid index ``k0``."""
        Zall = np.vstack([z0[None, :], Z])
        on = np.asarray(key, dtype=bool)
        if nc and on.any():
            A = system(key, ip)
            d, dd, F, Fd = kinematics(Zall, Zall @ A.T)
            rate = np.sum(np.where(on, cc * dd * dd, 0.0), axis=1)
            inc = np.cumsum(0.5 * h * (rate[:-1] + rate[1:]))
            for i in np.flatnonzero(on):
                best = open_peak.get(i, (t0, -math.inf))
                j = int(np.argmax(F[:, i]))
                if F[j, i] > best[1]:
                    best = (t0 + j * h, float(F[j, i]))
                near = [jj for jj in (j - 1, j) if 0 <= jj < len(Zall) - 1]  # the maximum's neighbourhood only
                for j in [jj for jj in near if Fd[jj, i] > 0.0 >= Fd[jj + 1, i]]:
                    zj = Zall[j]
                    g = lambda tau, i=i, zj=zj: kinematics(z_at(zj, tau)[None], (A @ z_at(zj, tau))[None])[3][0, i]
                    tau = brentq(g, 0.0, h, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)
                    FF = float(kinematics(z_at(zj, tau)[None])[2][0, i])
                    if FF > best[1]:
                        best = (t0 + j * h + tau, FF)
                open_peak[i] = best
        else:
            d, dd, F, _ = kinematics(Zall)
            inc = np.zeros(len(Z))
        if k0 < 0:  # a sub-step: no grid output
            dash[0] += float(inc[-1]) if len(inc) else 0.0
            return
        m = len(Z)
        Q = Z[:, :nf] / S
        W[k0:k0 + m] = Q @ Pout.T
        Vv[k0:k0 + m] = Z[:, nf:2 * nf] @ Pout.T
        KE[k0:k0 + m] = 0.5 * np.sum(Z[:, nf:2 * nf] ** 2, axis=1)
        SE[k0:k0 + m] = 0.5 * (Q * Q) @ lam
        if nc:
            PEN[k0:k0 + m] = d[1:]
            ENG[k0:k0 + m] = on
            FC[k0:k0 + m] = np.where(on, F[1:], 0.0)
            CE[k0:k0 + m] = 0.5 * np.sum(np.where(on, ck * d[1:] ** 2, 0.0), axis=1)
        DASH[k0:k0 + m] = dash[0] + inc
        dash[0] += float(inc[-1]) if m else 0.0

    accept(0, z, np.zeros((0, n)), 0.0, dt)
    zero = z[None, :]
    Q0 = z[:nf] / S
    W[0], Vv[0], KE[0], SE[0] = Pout @ Q0, Pout @ z[nf:2 * nf], 0.5 * z[nf:2 * nf] @ z[nf:2 * nf], 0.5 * lam @ Q0**2
    if nc:
        d0, _, F0, _ = kinematics(zero)
        PEN[0], ENG[0], FC[0] = d0[0], key, np.where(key, F0[0], 0.0)
        CE[0] = 0.5 * float(np.sum(np.where(key, ck * d0[0] ** 2, 0.0)))
    DASH[0] = 0.0
    block = 512
    k, t = 0, 0.0
    while k < n_steps:
        if t >= pieces[ip][1] - 1e-9 * dt and ip + 1 < len(pieces):
            ip += 1
            z = enter_piece(z, ip, t)
        room = pieces[ip][1] - t
        m = min(block, n_steps - k, int(math.floor(room / dt + 1e-9)) if math.isfinite(room) else block)
        if m >= 1:
            P = prop(key, ip, dt, True)
            Z = np.empty((m, n))
            zz = z
            for j in range(m):
                zz = P @ zz
                Z[j] = zz
            jb = first_switch(Z)
            if jb:
                accept(k + 1, z, Z[:jb], t, dt)
                z = Z[jb - 1]
                k += jb
                t = k * dt
            if jb == m:
                continue
        # one grid step with its events (or a load piece ending inside it)
        t_grid = (k + 1) * dt
        guard = 0
        toggled: set[int] = set()
        while t < t_grid - 1e-9 * dt:
            guard += 1
            if guard > 1000:
                raise RuntimeError(f"too many switches near t = {t}")
            if t >= pieces[ip][1] - 1e-9 * dt and ip + 1 < len(pieces):
                ip += 1
                z = enter_piece(z, ip, t)
            t_stop = min(t_grid, pieces[ip][1])
            h = t_stop - t
            z1 = advance(z, h, False)
            taus = {}
            for i in range(nc):
                on = key[i]
                h1 = hsw(z1, i, on)
                if not ((on and h1 <= 0.0) or (not on and h1 > 0.0)):
                    continue
                h0 = hsw(z, i, on)
                if (on and h0 <= 0.0) or (not on and h0 > 0.0):
                    tau = 0.0
                else:
                    f = lambda tau, i=i, on=on, h0=h0: h0 if tau <= 0.0 else hsw(z_at(z, tau), i, on)
                    tau = brentq(f, 0.0, h, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)
                if tau <= 1e-14 and i in toggled:
                    continue
                taus[i] = tau
            if not taus:
                accept(-1, z, z1[None, :], t, h)
                z, t = z1, t_stop
                continue
            tau = min(taus.values())
            switch = sorted(i for i, ti in taus.items() if ti <= tau + 1e-14)
            if tau > 1e-14:
                z1 = advance(z, tau, False)
                accept(-1, z, z1[None, :], t, tau)
                z, t = z1, t + tau
                toggled = set()
            newkey = list(key)
            for i in switch:
                d, dd, F, _ = contact(z, i)
                resid = max(resid, abs(hsw(z, i, key[i])))
                newkey[i] = not key[i]
                events.append((t, "impact" if newkey[i] else "rebound", i))
                event_state.append((d, dd, F if key[i] else 0.0, F if newkey[i] else 0.0))
                toggled.add(i)
                if key[i]:
                    dash[0] += 0.5 * ck[i] * d * d
                    tp, Fp = open_peak.pop(i)
                    peaks.append((tp, Fp, i))
                else:
                    open_peak[i] = (t, F)
            key = tuple(newkey)
        k += 1
        t = k * dt
        accept(k, z, np.zeros((0, n)), t, dt)
        Qk = z[:nf] / S
        W[k], Vv[k], KE[k], SE[k] = Pout @ Qk, Pout @ z[nf:2 * nf], 0.5 * z[nf:2 * nf] @ z[nf:2 * nf], 0.5 * lam @ Qk**2
        if nc:
            dk, _, Fk, _ = kinematics(z[None, :])
            PEN[k], ENG[k], FC[k] = dk[0], key, np.where(key, Fk[0], 0.0)
            CE[k] = 0.5 * float(np.sum(np.where(key, ck * dk[0] ** 2, 0.0)))
        DASH[k] = dash[0]
    for i, (tp, Fp) in open_peak.items():
        peaks.append((tp, Fp, i))
    peaks.sort()
    return ExactResult(
        t=np.arange(nt) * dt, x_out=x_out, w=W, w_t=Vv, contact_force=FC, penetration=PEN, engaged=ENG,
        events=events, event_state=event_state, peaks=peaks, kinetic=KE, strain=SE, contactor=CE, dashpot=DASH,
        event_residual=resid, n_modes_fe=nf,
    )
