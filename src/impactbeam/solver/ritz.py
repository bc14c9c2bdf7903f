"""One shared Ritz basis for every contact state (``solver.basis = "enriched"``).

The paper (section 2, eqs. 11-12) gives each state (set of engaged
contactors) its own exact modes and passes from one state to the next by the
L2 projection of eq. (12). With ``N`` retained modes and a contactor much
stiffer than the beam at its position, that projection is lossy at every
switch: ``N`` modes cannot represent the local deformation under the spring
(Melcher, Champneys & Wagg 2013), the energy jumps and the impact sequence
does not converge.

Here all states are integrated in ONE basis of ``N + n_r`` functions
(``n_r`` residual functions, normally one per contactor):

* the ``N`` retained modes ``phi_i`` of the free state (paper eq. 5-7);
* one static attachment (residual-flexibility) shape per contactor position
  ``a``: the static deflection ``g_a`` under a unit force at ``a`` minus its
  part in the retained modes, ``r_a = g_a - sum_i phi_i phi_i(a) / omega_i^2``
  (that part is the exact mass projection, since ``K g_a = delta_a``), as in
  code_aster's static enrichment (MODE_STAT/MODE_CORR) and the MacNeal-Craig
  residual-flexibility method. ``r_a`` is mass- and stiffness-orthogonal to
  every retained mode; the ``r_a`` are mass-orthonormalised among themselves
  and diagonalise the free stiffness (pseudo-frequencies above ``omega_N``).

* when these do not give the first ``N`` frequencies of the state with every
  contactor engaged to ``1e-4`` (a stop much stiffer than the beam there,
  e.g. at a free end: those modes reach above the retained band), that
  state's first ``N`` exact modes ``psi_j`` as well, each through its part
  outside the retained modes, ``psi_j - sum_i P_ij phi_i`` with
  ``P = <phi, psi>`` (paper eq. 12). Every state's lowest ``N`` modes are then
  in the basis, as in the paper's method, which keeps ``N`` per state. Their
  free stiffness follows from modal identities, ``K psi = K_s psi - sum k
  psi(a) delta_a``. A direction with less than 1e-3 of its norm outside the
  others is left out (it would amplify round-off); supported beams only (the
  free state has no rigid-body mode).

In that basis (mass matrix the identity) the stiffness of every state is exact
in the reduced coordinates,
``K_s = diag(omega^2, lambda_r) + sum_engaged k_c psi(a_c) psi(a_c)^T``,
and the gap adds the constant force ``s k c psi(a_c)`` (paper eqs. 8-9). The
modes of a state are the eigenvectors ``Phi_s`` of that small symmetric
eigenproblem, so each state still has ``N + n_r`` uncoupled modal equations
integrated in closed form; a switch is the exact change of coordinates
``eta_new = Phi_new^T Phi_old eta_old`` (orthogonal: no loss, displacement,
velocity and energy continuous to round-off) instead of eq. (12).

The static shape is the exact piecewise cubic of the beam with its end springs
(the paper's end conditions, springs 0..inf). When the supports allow rigid-body
motion (free-free, pinned-free, sliding-free...) no static solution exists;
then **inertia relief** is used: the unit force is balanced by the d'Alembert
load of the rigid-body modes, ``EI g'''' = delta_a - rho A sum_r phi_r(x)
phi_r(a)`` (a piecewise quintic), and the rigid-body part of ``g`` is removed.

Any other beam of the model its supports hold (sections, point masses,
interior springs, Timoshenko) gets its static shape from the exact static
solver (:mod:`impactbeam.modal.static`), and every inner product of the basis is
the kinetic one of that beam: ``rho A(x)`` on the quadrature, ``rho I(x)`` on
the rotations of a Timoshenko beam, ``m`` and ``J`` at the point masses. Such
a beam that can move as a rigid body keeps the paper's basis.

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
import scipy.linalg

from ..model.beam import Beam
from ..modal import ModeSet, mode_set, static_coefficients, static_state

__all__ = ["RitzBasis", "ritz_basis"]

_MERGE = 3e-5  # contactors closer than this fraction of L share one attachment shape
_DROP = 1e-11  # a residual shape smaller than this fraction of its static shape is dropped
_LOSSY = 1e-12  # below this fraction the residual keeps fewer than ~4 digits (cancellation): warn
_NEW = 1e-3  # a contact-state mode must bring at least this fraction of its norm outside the basis
_UNION = 1e-4  # the engaged state's first N frequencies must come out this close, else its modes join
_GX, _GW = np.polynomial.legendre.leggauss(20)


# --------------------------------------------------------------------------- the basis




def _mode_field(ms: ModeSet, x: np.ndarray, field: int | str) -> np.ndarray:
    """A field of a mode set at ``x``: (n, p)."""
    if field == "rot":
        return ms.rotations(x)
    if field == "moment":
        return ms.moment_shapes(x)
    return ms.shapes(x, int(field))


class RitzBasis:
    """Retained free modes plus mass-orthonormal residual attachment shapes.

    Attributes
    ----------
    free : ModeSet
        The ``N`` retained modes of the free state.
    positions : ndarray, (n_a,)
        Distinct contactor positions that received an attachment shape.
    lam : ndarray, (N + n_r,)
        Free-state stiffness in the basis (diagonal): ``omega_i^2``, then the
        residual functions' ``lambda_r``.
    count : int
        ``N + n_r``: one residual function per contactor position, plus those
        of the engaged state's modes when they join.
    """

    def __init__(self, beam: Beam, positions: Sequence[float], n_modes: int,
                 contact: Sequence[tuple[float, float]] = ()) -> None:
        self.beam = beam
        self.free = mode_set(beam, (), n_modes)
        L = beam.length
        pos: list[float] = []
        for a in sorted(float(p) for p in positions):
            if not pos or a - pos[-1] > _MERGE * L:
                pos.append(a)
        self._alpha = np.array(pos) / L
        self._contact: ModeSet | None = None
        # the engaged state's modes may join (supported beams only: with rigid-body modes the
        # inertia-relief attachment shapes are not K-orthogonal to them in the same sense)
        engaged = mode_set(beam, contact, n_modes) if contact and pos and not self.free.n_rigid else None
        self._x, self._w = self._quadrature(engaged)
        self._keep_attachments()
        self.positions = self._alpha * L
        self._P = np.zeros((self.free.count, 0))
        self._C = np.zeros((self.free.count, 0))
        lr = np.zeros(0)
        self._Z = np.zeros((0, 0))
        if self._alpha.size:
            lr = self._orthonormalise(())
            if engaged is not None and self._misses_contact_modes(lr, contact, engaged):
                self._contact = engaged
                self._P = self.free.overlap(engaged)
                self._C = np.zeros((self.free.count, 0))
                lr = self._orthonormalise(contact)
        self.lam = np.concatenate([self.free.omega**2, lr])
        self.count = int(self.lam.size)
        self.integral = (self.values(self._x) @ self._w)
        self.integral.setflags(write=False)
        self.inertia = self._sample(self.values, rows="translation").T @ self._sample_weights()
        self.inertia.setflags(write=False)

    def _sample_weights(self) -> np.ndarray:
        """``sqrt`` of the translational kinetic weights of :meth:`_sample` (quadrature and point masses)."""
        lay = self.free._layout
        at = lay.m > 0.0
        return np.concatenate([np.sqrt(self.beam.mass_per_length_at(self._x) * self._w), np.sqrt(lay.m[at])])

    def _sample(self, fn, rows: str = "all") -> np.ndarray:
        """Functions ``fn(x, field)`` weighted so that ``S^T S`` is their kinetic inner product: (rows, n).

        Rows: the quadrature with ``rho A(x) w``, the point masses with ``m``;
        then (``rows="all"``) the rotations, with ``rho I(x) w`` for a
        Timoshenko beam and ``J`` at the point masses.
        """
        lay = self.free._layout
        at, atJ = lay.m > 0.0, lay.J > 0.0
        parts = [(fn(self._x, 0) * np.sqrt(self.beam.mass_per_length_at(self._x) * self._w)).T]
        if at.any():
            parts.append((fn(lay.nodes[at], 0) * np.sqrt(lay.m[at])).T)
        if rows == "all":
            if self.beam.is_timoshenko:
                parts.append((fn(self._x, "rot") * np.sqrt(self.beam.rotary_inertia_at(self._x) * self._w)).T)
            if atJ.any():
                parts.append((fn(lay.nodes[atJ], "rot") * np.sqrt(lay.J[atJ])).T)
        return np.concatenate(parts)

    def _free_at(self, x: np.ndarray, field: int | str) -> np.ndarray:
        return _mode_field(self.free, x, field)

    def _keep_attachments(self) -> None:
        """Second Gram-Schmidt pass on the attachment shapes; drop those the retained modes already hold."""
        L = self.beam.length
        r = self.free.n_rigid
        Rq = self._sample(self._residuals_at)  # (rows, n_c)
        if self._alpha.size and self.free.count > r:
            # r_c is a small difference of O(1) shapes (~N^-3.5 of g_c), so remove
            # what round-off left along the retained modes
            Fq = self._sample(self._free_at)[:, r:]
            self.__dict__["_modal_static"] = self._modal_static + Fq.T @ Rq
            Rq = self._sample(self._residuals_at)
        g_norm = np.linalg.norm(self._sample(self._static_at), axis=0)
        r_norm = np.linalg.norm(Rq, axis=0)
        keep = r_norm > _DROP * g_norm
        lossy = keep & (r_norm < _LOSSY * g_norm)
        if lossy.any():
            warnings.warn(
                f"enriched basis: the attachment shape at x = {float(self._alpha[lossy][0] * L):.6g} m is "
                f"{float((r_norm / g_norm)[lossy].min()):.2g} of its static shape (very soft supports?): it keeps "
                "fewer than 4 significant digits; consider solver.basis = 'paper'",
                RuntimeWarning,
                stacklevel=4,
            )
        if not keep.all():
            self._alpha = self._alpha[keep]
            for name in ("_static", "_static_q", "_modal_static"):
                self.__dict__.pop(name, None)

    def _misses_contact_modes(self, lr: np.ndarray, contact: Sequence[tuple[float, float]], engaged: ModeSet) -> bool:
        """Whether this basis gives the first N frequencies of the ``engaged`` state worse than ``_UNION``.

        Rayleigh-Ritz in the basis (free modes, attachment shapes) against the
        exact modes of the state with every ``contact`` spring engaged.
        """
        lam = np.concatenate([self.free.omega**2, lr])
        xs = [x for x, _ in contact]
        at = np.concatenate([self.free.shapes(xs), self._Z.T @ self._extra_at(np.asarray(xs, dtype=float), 0)])
        K = np.diag(lam) + sum(k * np.outer(at[:, j], at[:, j]) for j, (_, k) in enumerate(contact))
        exact = engaged.omega
        ritz = np.sqrt(np.maximum(np.linalg.eigvalsh(0.5 * (K + K.T)), 0.0))[: exact.size]
        scale = max(float(exact.max(initial=0.0)), 1e-300)
        return bool(np.max(np.abs(ritz - exact[: ritz.size]) / np.maximum(exact[: ritz.size], 1e-9 * scale)) > _UNION)

    def _extra_at(self, x: np.ndarray, derivative: int | str) -> np.ndarray:
        """The residual functions before orthonormalisation: attachment shapes, then ``psi_j - sum_i P_ij phi_i``."""
        R = self._residuals_at(x, derivative)
        if self._contact is not None:
            F = self._free_at(x, derivative)
            R = np.concatenate([R, _mode_field(self._contact, x, derivative) - self._P.T @ F])
        if self._C.shape[1]:
            R = R - self._C.T @ self._free_at(x, derivative)
        return R

    def _extra_stiffness(self, contact: Sequence[tuple[float, float]]) -> np.ndarray:
        """Free-state stiffness ``<f, K f>`` of the residual functions, exact from the modal data.

        ``r_c^T K r_d = r_c(a_d)``; with the contact-state modes ``psi`` (springs
        ``k_s`` at ``a_s`` engaged), ``K psi = K_s psi - sum_s k_s psi(a_s) delta_s``:
        ``psi~^T K psi~ = Omega_c^2 - sum_s k_s psi(a_s) psi(a_s)^T - P^T Omega^2 P`` and
        ``r_c^T K psi~ = psi(a_c) - P^T phi(a_c)``. Every residual function is
        K-orthogonal to the retained modes.
        """
        Ra = self._residuals_at(self.positions, 0)
        K = 0.5 * (Ra + Ra.T)
        if self._contact is None:
            return K
        cm, P = self._contact, self._P
        xs = np.array([x for x, _ in contact], dtype=float)
        ks = np.array([k for _, k in contact], dtype=float)
        psa = cm.shapes(xs)
        Kpp = np.diag(cm.omega**2) - (psa * ks) @ psa.T - P.T @ (self.free.omega[:, None] ** 2 * P)
        K1p = (cm.shapes(self.positions) - P.T @ self.free.shapes(self.positions)).T
        return np.block([[K, K1p], [K1p.T, 0.5 * (Kpp + Kpp.T)]])

    def _orthonormalise(self, contact: Sequence[tuple[float, float]]) -> np.ndarray:
        """Mass-orthonormal residual functions that diagonalise the free stiffness; returns their ``lambda_r``.

        On the quadrature the weighted functions are projected out of the
        retained modes twice (classical Gram-Schmidt; the coefficients are kept
        in ``_C``), then orthonormalised by a column-pivoted QR; a direction
        whose part outside the earlier ones is below ``_NEW`` of its norm (a
        contact-state mode the free modes already hold) is dropped, so no
        combination amplifies round-off by more than ``1 / _NEW``.
        """
        F = self._sample(self._free_at)  # (rows, N), orthonormal columns
        B = self._sample(self._extra_at)
        C = np.zeros((F.shape[1], B.shape[1]))
        for _ in range(2):
            c = F.T @ B
            B = B - F @ c
            C += c
        self._C = C
        norm = np.linalg.norm(B, axis=0)
        n_a = self._alpha.size
        # a contact-state mode (unit norm) that the free modes hold to _NEW (one the
        # springs do not move, e.g. antisymmetric about a stop) is left out: what remains
        # of it is round-off
        cols = np.flatnonzero((np.arange(B.shape[1]) < n_a) | (norm > _NEW))
        d = 1.0 / norm[cols]
        _, Rt, piv = scipy.linalg.qr(B[:, cols] * d, mode="economic", pivoting=True)
        k = int(np.sum(np.abs(np.diag(Rt)) > _NEW))
        Y = np.zeros((B.shape[1], k))
        Y[cols[piv[:k]]] = d[piv[:k], None] * np.linalg.inv(Rt[:k, :k])
        K = self._extra_stiffness(contact) + C.T @ (self.free.omega[:, None] ** 2 * C)
        lr, V = np.linalg.eigh(Y.T @ K @ Y)
        self._Z = Y @ V
        return lr

    def _quadrature(self, engaged: ModeSet | None) -> tuple[np.ndarray, np.ndarray]:
        """Gauss-Legendre (20 points) on pieces of at most half the shortest retained wavelength, split at the contactors.

        The wavelengths are those of the free modes and of the ``engaged`` state's modes.
        """
        L = self.beam.length
        bmax = max(float(self.free._beta_max), 4.0 / L)
        if engaged is not None:
            bmax = max(bmax, float(engaged._beta_max))
        breaks = np.unique(np.concatenate([[0.0, L], self._alpha * L, self.free.nodes]))
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
            out.append(static_coefficients(beam, float(al), q0, q1))
        return out

    def _static_at(self, x: np.ndarray, derivative: int | str) -> np.ndarray:
        """Static shapes ``g_c`` [m/N] (or a field) at ``x``, rigid-body part removed: (n_c, p).

        The paper's uniform beam: the polynomials (inertia relief with
        rigid-body modes); any other beam its supports hold: the exact static
        solver (:func:`impactbeam.modal.static.static_state`).
        """
        beam, L = self.beam, self.beam.length
        x = np.atleast_1d(np.asarray(x, dtype=float))
        if not beam.is_uniform:
            index = {0: 0, 1: 4, 2: 5, 3: 6, "rot": 1, "moment": 2}[derivative]
            return np.array([static_state(beam, x, [(float(a * L), 1.0)])[index] for a in self._alpha]).reshape(-1, x.size)
        if derivative == "moment":
            return beam.bending_stiffness * self._static_at(x, 2)
        if derivative == "rot":
            derivative = 1
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

    def _residuals_at(self, x: np.ndarray, derivative: int | str) -> np.ndarray:
        """Residual shapes ``r_c = g_c - sum_i phi_i phi_i(a_c) / omega_i^2`` (or a field) at ``x``: (n_c, p)."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        g = self._static_at(x, derivative)
        r = self.free.n_rigid
        return g - self._modal_static.T @ self._free_at(x, derivative)[r:]

    def values(self, x: float | Sequence[float] | np.ndarray, derivative: int | str = 0) -> np.ndarray:
        """The ``N + n_r`` basis functions at ``x``: shape (n, p).

        ``derivative``: 0..3 for ``d^k W / dx^k``, ``"rot"`` for the
        cross-section rotation, ``"moment"`` for the bending moment per unit
        coordinate (``EI W''``, or ``EI Psi'`` for a Timoshenko beam).
        """
        x = np.atleast_1d(np.asarray(x, dtype=float))
        out = self._free_at(x, derivative)
        if self._Z.size:
            out = np.concatenate([out, self._Z.T @ self._extra_at(x, derivative)])
        return out


@functools.lru_cache(maxsize=64)
def _cached_basis(beam: Beam, positions: tuple[float, ...], n_modes: int,
                  contact: tuple[tuple[float, float], ...]) -> RitzBasis:
    return RitzBasis(beam, positions, n_modes, contact)


def ritz_basis(beam: Beam, positions: Sequence[float], n_modes: int,
               contact: Sequence[tuple[float, float]] = ()) -> RitzBasis:
    """The shared basis of ``n_modes`` free modes, the attachment shapes at ``positions`` and (with
    ``contact``, the engaged springs as (position, stiffness)) that contact state's modes (cached)."""
    key = tuple(sorted((float(x), float(k)) for x, k in contact))
    return _cached_basis(beam, tuple(sorted(float(p) for p in positions)), int(n_modes), key)
