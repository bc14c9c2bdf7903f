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
  ``1/2 Kt W'(0)^2`` etc. reproduces the boundary conditions of DESIGN.md s.1.
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
