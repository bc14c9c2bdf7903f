"""One shared Ritz basis for every contact state (``solver.basis = "enriched"``).

The paper (section 2, eqs. 11-12) gives each state (set of engaged
contactors) its own exact modes and passes from one state to the next by the
L2 projection of eq. (12). With ``N`` retained modes and a contactor much
stiffer than the beam at its position, that projection is lossy at every
switch: ``N`` modes cannot represent the local deformation under the spring
(Melcher, Champneys & Wagg 2013), the energy jumps and the impact sequence
does not converge.

Here all states are integrated in ONE basis of ``N + n_a`` functions
(``n_a`` = number of distinct contactor positions, normally the number of
contactors):

* the ``N`` retained modes ``phi_i`` of the free state (paper eq. 5-7);
* one static attachment (residual-flexibility) shape per contactor position
  ``a``: the static deflection ``g_a`` under a unit force at ``a`` minus its
  part in the retained modes, ``r_a = g_a - sum_i phi_i phi_i(a) / omega_i^2``
  (that part is the exact mass projection, since ``K g_a = delta_a``), as in
  code_aster's static enrichment (MODE_STAT/MODE_CORR) and the MacNeal-Craig
  residual-flexibility method. ``r_a`` is mass- and stiffness-orthogonal to
  every retained mode; the ``r_a`` are mass-orthonormalised among themselves
  and diagonalise the free stiffness (pseudo-frequencies above ``omega_N``).

In that basis (mass matrix the identity) the stiffness of every state is exact
in the reduced coordinates,
``K_s = diag(omega^2, lambda_r) + sum_engaged k_c psi(a_c) psi(a_c)^T``,
and the gap adds the constant force ``s k c psi(a_c)`` (paper eqs. 8-9). The
modes of a state are the eigenvectors ``Phi_s`` of that small symmetric
eigenproblem, so each state still has ``N + n_a`` uncoupled modal equations
integrated in closed form; a switch is the exact change of coordinates
``eta_new = Phi_new^T Phi_old eta_old`` (orthogonal: no loss, displacement,
velocity and energy continuous to round-off) instead of eq. (12).

The static shape is the exact piecewise cubic of the beam with its end springs
(DESIGN.md section 1, springs 0..inf). When the supports allow rigid-body
motion (free-free, pinned-free, sliding-free...) no static solution exists;
then **inertia relief** is used: the unit force is balanced by the d'Alembert
load of the rigid-body modes, ``EI g'''' = delta_a - rho A sum_r phi_r(x)
phi_r(a)`` (a piecewise quintic), and the rigid-body part of ``g`` is removed.

Damping: each mode of a state gets that state's ratio (``damping.free`` or
``damping.contact``, per mode when a list), as the paper does per mode.

References
----------
.. [1] W. Xu, E. K. Ervin, Shock and Vibration 20 (2013), section 2, eqs. (5)-(12).
.. [2] R. H. MacNeal, "A hybrid method of component mode synthesis",
   Computers & Structures 1 (1971).
.. [3] F. Melcher, A. R. Champneys, D. J. Wagg, "The impacting cantilever:
   modal non-convergence and the importance of stiffness matching",
   Phil. Trans. R. Soc. A 371 (2013).
"""

from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Sequence

import numpy as np

from ..model.beam import Beam, Contactor
from ..exceptions import ParameterError
from ..model.loading import Excitation, InitialCondition, spatial_projection
from ..modal import mode_set
from ..model import Damping
from .states import ModalDynamics, StateModel

__all__ = ["RitzBasis", "RitzModes", "RitzStateSpace", "ritz_basis", "static_polynomial"]

_MERGE = 3e-5  # contactors closer than this fraction of L share one attachment shape
_DROP = 1e-11  # a residual shape smaller than this fraction of its static shape is dropped
_LOSSY = 1e-12  # below this fraction the residual keeps fewer than ~4 digits (cancellation): warn
_GX, _GW = np.polynomial.legendre.leggauss(20)


# --------------------------------------------------------------------------- static shapes


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
    end conditions of DESIGN.md section 1. A singular system (rigid-body motion)
    is solved in the least-squares sense; the caller removes the rigid-body part.
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


def _static_coefficients(beam: Beam, alpha: float, q0: float, q1: float) -> np.ndarray:
    """Coefficients (2, 6) of ``ghat`` under a unit force at ``xi = alpha`` with ``ghat'''' = q0 + q1 xi``.

    The load is the inertia relief of rigid-body modes (zero without them).
    """
    return static_polynomial(beam, alpha, np.array([[q0, q1], [q0, q1]]), 1.0)


# --------------------------------------------------------------------------- the basis


class RitzBasis:
    """Retained free modes plus mass-orthonormal residual attachment shapes.

    Attributes
    ----------
    free : ModeSet
        The ``N`` retained modes of the free state.
    positions : ndarray, (n_a,)
        Distinct contactor positions that received an attachment shape.
    lam : ndarray, (N + n_a,)
        Free-state stiffness in the basis (diagonal): ``omega_i^2``, then the
        residual shapes' ``lambda_r``.
    count : int
        ``N + n_a``.
    """

    def __init__(self, beam: Beam, positions: Sequence[float], n_modes: int) -> None:
        self.beam = beam
        self.free = mode_set(beam, (), n_modes)
        L = beam.length
        pos: list[float] = []
        for a in sorted(float(p) for p in positions):
            if not pos or a - pos[-1] > _MERGE * L:
                pos.append(a)
        self._alpha = np.array(pos) / L
        self._x, self._w = self._quadrature()
        rhoA = beam.mass_per_length
        Rq = self._residuals_at(self._x, 0)  # (n_c, q)
        if self._alpha.size and self.free.count > self.free.n_rigid:
            # second Gram-Schmidt pass: r_c is a small difference of O(1) shapes
            # (~N^-3.5 of g_c), so remove what round-off left along the retained modes
            Fq = self.free.shapes(self._x)[self.free.n_rigid :]
            self.__dict__["_modal_static"] = self._modal_static + rhoA * (Fq * self._w) @ Rq.T
            Rq = self._residuals_at(self._x, 0)
        Mrr = rhoA * (Rq * self._w) @ Rq.T
        gq = self._static_at(self._x, 0)
        g_norm = np.sqrt(rhoA * (gq**2) @ self._w)
        r_norm = np.sqrt(np.maximum(np.diag(Mrr), 0.0))
        keep = r_norm > _DROP * g_norm
        lossy = keep & (r_norm < _LOSSY * g_norm)
        if lossy.any():
            warnings.warn(
                f"enriched basis: the attachment shape at x = {float(self._alpha[lossy][0] * L):.6g} m is "
                f"{float((r_norm / g_norm)[lossy].min()):.2g} of its static shape (very soft supports?): it keeps "
                "fewer than 4 significant digits; consider solver.basis = 'paper'",
                RuntimeWarning,
                stacklevel=3,
            )
        if not keep.all():
            self._alpha = self._alpha[keep]
            self.__dict__.pop("_static", None)
            self.__dict__.pop("_static_q", None)
            self.__dict__.pop("_modal_static", None)
        Mrr = Mrr[np.ix_(keep, keep)]
        self.positions = self._alpha * L
        n_a = int(keep.sum())
        if n_a:
            Ra = self._residuals_at(self.positions, 0)  # (n_a, n_a): r_c(a_d)
            Krr = 0.5 * (Ra + Ra.T)
            s, U = np.linalg.eigh(Mrr)
            ok = s > 1e-10 * s.max()
            Y = U[:, ok] / np.sqrt(s[ok])
            lr, V = np.linalg.eigh(Y.T @ Krr @ Y)
            self._Z = Y @ V  # r-combination -> orthonormal residual shapes
        else:
            lr = np.zeros(0)
            self._Z = np.zeros((0, 0))
        self.lam = np.concatenate([self.free.omega**2, lr])
        self.count = int(self.lam.size)
        self.integral = (self.values(self._x) @ self._w)
        self.integral.setflags(write=False)

    def _quadrature(self) -> tuple[np.ndarray, np.ndarray]:
        """Gauss-Legendre (20 points) on pieces of at most half the shortest retained wavelength, split at the contactors."""
        L = self.beam.length
        bmax = max(float(self.free.beta.max(initial=0.0)), 4.0 / L)
        breaks = np.unique(np.concatenate([[0.0, L], self._alpha * L]))
        xs, ws = [], []
        for a, b in zip(breaks[:-1], breaks[1:]):
            n = max(1, math.ceil((b - a) * bmax / math.pi))
            e = np.linspace(a, b, n + 1)
            half, mid = 0.5 * np.diff(e), 0.5 * (e[:-1] + e[1:])
            xs.append((mid[:, None] + half[:, None] * _GX).ravel())
            ws.append((half[:, None] * _GW).ravel())
        return np.concatenate(xs), np.concatenate(ws)

    @functools.cached_property
    def _static(self) -> list[np.ndarray]:
        """Polynomial coefficients (2, 6) of ``ghat`` for each contactor position (with inertia relief)."""
        beam, L = self.beam, self.beam.length
        r = self.free.n_rigid
        rigid = mode_set(beam, (), 2) if r else None
        out = []
        for al in self._alpha:
            q0 = q1 = 0.0
            if rigid is not None:
                # ghat'''' = L q(x), q = -rho A sum_r phi_r(x) phi_r(a); phi_r linear in x
                x01 = np.array([0.0, L])
                ph = rigid.shapes(x01)[:r]  # (r, 2)
                pa = rigid.shapes([al * L])[:r, 0]
                c0 = ph[:, 0]
                c1 = (ph[:, 1] - ph[:, 0])  # per unit xi
                q0 = -L * beam.mass_per_length * float(c0 @ pa)
                q1 = -L * beam.mass_per_length * float(c1 @ pa)
            out.append(_static_coefficients(beam, float(al), q0, q1))
        return out

    def _static_at(self, x: np.ndarray, derivative: int) -> np.ndarray:
        """Static shapes ``g_c`` [m/N] (or x-derivatives) at ``x``, rigid-body part removed: (n_c, p)."""
        beam, L = self.beam, self.beam.length
        xi = x / L
        scale = L**3 / beam.bending_stiffness / L**derivative
        out = np.empty((self._alpha.size, x.size))
        for j, (al, coef) in enumerate(zip(self._alpha, self._static)):
            c = [np.polynomial.polynomial.polyder(coef[s], derivative) if derivative else coef[s] for s in (0, 1)]
            right = xi >= al  # third derivative: the value just to the right at the force
            out[j] = scale * np.where(
                right, np.polynomial.polynomial.polyval(xi, c[1]), np.polynomial.polynomial.polyval(xi, c[0])
            )
        r = self.free.n_rigid
        if r:
            # remove the rigid-body part (mass projection) computed on the quadrature grid
            gq = self._static_q
            rig = self.free.shapes(x, derivative)[:r]
            out -= (gq @ self._rigid_q.T) @ rig
        return out

    @functools.cached_property
    def _static_q(self) -> np.ndarray:
        """Static shapes on the quadrature grid (before rigid-body removal)."""
        beam, L = self.beam, self.beam.length
        xi = self._x / L
        out = np.empty((self._alpha.size, xi.size))
        for j, (al, coef) in enumerate(zip(self._alpha, self._static)):
            out[j] = L**3 / beam.bending_stiffness * np.where(
                xi >= al, np.polynomial.polynomial.polyval(xi, coef[1]), np.polynomial.polynomial.polyval(xi, coef[0])
            )
        return out

    @functools.cached_property
    def _rigid_q(self) -> np.ndarray:
        """``rho A w_q phi_r(x_q)``: the rigid-body mass projection weights, (r, q)."""
        r = self.free.n_rigid
        return self.beam.mass_per_length * self.free.shapes(self._x)[:r] * self._w

    @functools.cached_property
    def _modal_static(self) -> np.ndarray:
        """``phi_i(a_c) / omega_i^2`` of the elastic retained modes: (N - r, n_c)."""
        ms = self.free
        r = ms.n_rigid
        return ms.shapes(self._alpha * self.beam.length)[r:] / (ms.omega[r:] ** 2)[:, None]

    def _residuals_at(self, x: np.ndarray, derivative: int) -> np.ndarray:
        """Residual shapes ``r_c = g_c - sum_i phi_i phi_i(a_c) / omega_i^2`` (or derivatives) at ``x``: (n_c, p)."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        g = self._static_at(x, derivative)
        r = self.free.n_rigid
        return g - self._modal_static.T @ self.free.shapes(x, derivative)[r:]

    def values(self, x: float | Sequence[float] | np.ndarray, derivative: int = 0) -> np.ndarray:
        """The ``N + n_a`` basis functions (or x-derivatives, 0..3) at ``x``: shape (n, p)."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        out = self.free.shapes(x, derivative)
        if self._Z.size:
            R = self._residuals_at(x, derivative)
            out = np.concatenate([out, self._Z.T @ R])
        return out


@functools.lru_cache(maxsize=64)
def _cached_basis(beam: Beam, positions: tuple[float, ...], n_modes: int) -> RitzBasis:
    return RitzBasis(beam, positions, n_modes)


def ritz_basis(beam: Beam, positions: Sequence[float], n_modes: int) -> RitzBasis:
    """The shared basis of ``n_modes`` free modes and the attachment shapes at ``positions`` (cached)."""
    return _cached_basis(beam, tuple(sorted(float(p) for p in positions)), int(n_modes))


# --------------------------------------------------------------------------- state modes


class RitzModes:
    """Modes of one state in the shared basis: ``W_m(x) = sum_j Phi[j, m] psi_j(x)``.

    Offers the part of :class:`~impactbeam.modal.ModeSet`'s interface the
    solver and the results use (``omega``, ``count``, ``frequencies_hz``,
    ``shapes``, ``integral``). They are mass-orthonormal
    (``rho A int W_n W_m dx = delta_nm``) and there are ``N + n_a`` of them:
    the approximation of the state's lowest ``N + n_a`` modes (Rayleigh-Ritz).
    """

    def __init__(self, basis: RitzBasis, Phi: np.ndarray, omega: np.ndarray) -> None:
        self.basis = basis
        self.Phi = Phi
        self.omega = omega
        self.beam = basis.beam

    @property
    def count(self) -> int:
        """Number of modes, ``N + n_a``."""
        return int(self.omega.size)

    @property
    def n_rigid(self) -> int:
        """Number of zero-frequency modes."""
        return int(np.sum(self.omega == 0.0))

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Natural frequencies [Hz]."""
        return self.omega / (2.0 * np.pi)

    def shapes(self, x: float | Sequence[float] | np.ndarray, derivative: int = 0) -> np.ndarray:
        """Mode shapes (or x-derivatives 0..3) at ``x``: shape (n, p), like :meth:`ModeSet.shapes`."""
        if derivative not in (0, 1, 2, 3):
            raise ParameterError(f"derivative: must be 0, 1, 2 or 3, got {derivative!r}")
        return self.Phi.T @ self.basis.values(x, derivative)

    def __call__(self, x: float | Sequence[float] | np.ndarray) -> np.ndarray:
        return self.shapes(x)

    def integral(self) -> np.ndarray:
        """``int_0^L W_n dx`` [m kg^-0.5], shape (n,)."""
        return self.Phi.T @ self.basis.integral


def _state_eigen(basis: RitzBasis, springs: Sequence[tuple[int, float]], at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(omega, Phi)`` of ``diag(lam) + sum k b b^T`` (mass matrix the identity).

    ``at[:, j]`` is ``psi(a_j)``; ``springs`` are (column, stiffness). Without
    springs the free-state stiffness is already diagonal and ``Phi`` is the
    identity (so the basis reduces exactly to the free modes).
    """
    n = basis.count
    if not springs:
        order = np.argsort(basis.lam, kind="stable")
        Phi = np.eye(n)[:, order]
        return np.sqrt(np.maximum(basis.lam[order], 0.0)), Phi
    K = np.diag(basis.lam)
    for j, k in springs:
        K += k * np.outer(at[:, j], at[:, j])
    lam, Phi = np.linalg.eigh(0.5 * (K + K.T))
    lam = np.where(lam < 1e-13 * abs(lam).max(), 0.0, lam)
    # deterministic sign: largest component positive
    idx = np.argmax(np.abs(Phi), axis=0)
    Phi = Phi * np.sign(Phi[idx, np.arange(n)])
    return np.sqrt(lam), Phi


# --------------------------------------------------------------------------- the state space


class RitzStateSpace:
    """Drop-in for :class:`~impactbeam.solver.states.StateSpace` on the shared Ritz basis.

    Every state has ``N + n_a`` modes (``N = n_modes`` retained free modes,
    ``n_a`` = number of distinct contactor positions, normally the number of
    contactors); :attr:`count` gives it. ``transfer`` is the exact change of
    coordinates between two states (orthogonal), not the projection of eq. (12).
    """

    def __init__(
        self,
        beam: Beam,
        contactors: Sequence[Contactor],
        damping: Damping,
        excitation: Excitation,
        n_modes: int,
        points: np.ndarray,
    ) -> None:
        self.beam = beam
        self.contactors = tuple(contactors)
        self.damping = damping
        self.excitation = excitation
        self.n_modes = n_modes
        self.points = np.asarray(points, dtype=float).reshape(-1)
        self.positions = np.array([c.position for c in self.contactors], dtype=float)
        for i, c in enumerate(self.contactors):
            if not math.isfinite(c.stiffness):
                raise ParameterError(
                    f"contactors.{i}.stiffness: a rigid stop cannot be integrated in the enriched basis "
                    "(solver.basis); give a finite stiffness"
                )
        self.basis = ritz_basis(beam, self.positions, n_modes)
        self._psi_c = self.basis.values(self.positions) if self.contactors else np.zeros((self.basis.count, 0))
        self._psi_o = self.basis.values(self.points) if self.points.size else np.zeros((self.basis.count, 0))
        self._p = spatial_projection(excitation, self.basis.values, self.basis.integral, beam.mass_per_length)
        self._states: dict[tuple[int, ...], StateModel] = {}
        self._T: dict[tuple[tuple[int, ...], tuple[int, ...]], np.ndarray] = {}

    @property
    def count(self) -> int:
        """Modes per state, ``N + n_a``."""
        return self.basis.count

    def state(self, engaged: tuple[int, ...]) -> StateModel:
        """The state with the contactors ``engaged`` (cached)."""
        st = self._states.get(engaged)
        if st is None:
            springs = [(i, self.contactors[i].stiffness) for i in engaged]
            omega, Phi = _state_eigen(self.basis, springs, self._psi_c)
            ms = RitzModes(self.basis, Phi, omega)
            n = ms.count
            dyn = ModalDynamics(omega, self.damping.ratios(bool(engaged), n))
            Wc = np.ascontiguousarray((Phi.T @ self._psi_c).T) if self.contactors else np.zeros((0, n))
            Wo = np.ascontiguousarray((Phi.T @ self._psi_o).T) if self.points.size else np.zeros((0, n))
            p = Phi.T @ self._p
            st = StateModel(engaged, ms, dyn, Wc, Wo, p)  # type: ignore[arg-type]
            self._states[engaged] = st
        return st

    def projection(self, to: tuple[int, ...], frm: tuple[int, ...]) -> np.ndarray:
        """The exact change of coordinates ``Phi_to^T Phi_from`` (replaces eq. 12)."""
        key = (to, frm)
        T = self._T.get(key)
        if T is None:
            T = self.state(to).modes.Phi.T @ self.state(frm).modes.Phi  # type: ignore[attr-defined]
            self._T[key] = T
        return T

    def transfer(self, to: tuple[int, ...], frm: tuple[int, ...], preserve_contacts: bool = False) -> np.ndarray:
        """``T`` with ``eta_to = T @ eta_from``; exact, so ``preserve_contacts`` changes nothing."""
        return self.projection(to, frm)

    @property
    def states(self) -> dict[tuple[int, ...], StateModel]:
        return self._states

    def initial_coordinates(self, initial: InitialCondition) -> tuple[np.ndarray, np.ndarray]:
        """Free-state modal displacement and velocity at t = 0 in this basis.

        ``initial.tip_displacement``: the static equilibrium of the reduced
        model under a point force at ``initial.position`` (default the tip),
        scaled so that the reduced model's deflection there is exactly the
        given one. ``modal_displacement`` / ``modal_velocity`` apply to the
        retained free modes (the first ``N`` coordinates of the free state).
        """
        st = self.state(())
        n = st.modes.count
        eta, deta = np.zeros(n), np.zeros(n)
        if initial.tip_displacement:
            ms: RitzModes = st.modes  # type: ignore[assignment]
            if ms.n_rigid:
                raise ParameterError(
                    "initial.tip_displacement: the supports allow rigid-body motion, so a static load shape does not exist"
                )
            x0 = self.beam.length if initial.position is None else initial.position
            w0 = ms.shapes([x0])[:, 0]
            q = w0 / ms.omega**2
            eta = q * (initial.tip_displacement / float(w0 @ q))
        # the free state's first N modes are the retained free modes, in order
        N = self.basis.free.count
        for src, dst in ((initial.modal_displacement, eta), (initial.modal_velocity, deta)):
            if src is not None:
                v = np.asarray(src, dtype=float)
                m = min(v.size, N)
                dst[:m] += v[:m]
        return eta, deta
