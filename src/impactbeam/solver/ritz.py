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
  (through their singular directions, so no round-off tie chooses a column)
  and diagonalise the free stiffness (pseudo-frequencies above ``omega_N``);
  their mass and strain energy come from one quadrature, so they are those of
  the functions as evaluated;

* for stiff stops (:mod:`~impactbeam.solver.ritz_enrich`): the engaged
  state's lowest ``N`` modes where they have more than 1e-3 of their norm
  outside the basis (a stop at a free end pins it), the stop's local shapes
  at the frequencies of its impact (``k = 1e7`` N/m on the paper's specimen
  loads the beam within 2 us), and the second load-dependent Ritz vector of a
  point force at a stop. Every state's lowest ``N`` modes are then in the
  basis, as in the paper's method. Soft contactors (the paper's cases) keep
  ``N + 1`` functions; supported beams only (the free state has no
  rigid-body mode).

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

from ..model.beam import MERGE_DISTANCE, Beam
from ..modal import ModeSet, mode_set, static_coefficients, static_state
from .ritz_enrich import Enrichment, enrich

__all__ = ["RitzBasis", "ritz_basis"]

_DROP = 1e-11  # a residual shape smaller than this fraction of its static shape is dropped
_LOSSY = 1e-12  # below this fraction the residual keeps fewer than ~4 digits (cancellation): warn
_NEW = 1e-3  # an attachment direction below this fraction of the largest is dropped
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
                 contact: Sequence[tuple[float, float]] = (), loads: Sequence[float] = ()) -> None:
        self.beam = beam
        self.free = mode_set(beam, (), n_modes)
        L = beam.length
        pos: list[float] = []
        for a in sorted(float(p) for p in positions):
            if not pos or a - pos[-1] > MERGE_DISTANCE * L:  # closer contactors share one attachment shape
                pos.append(a)
        self._alpha = np.array(pos) / L
        self._x, self._w = self._quadrature()
        self._keep_attachments()
        self.positions = self._alpha * L
        self._C = np.zeros((self.free.count, 0))
        lr = np.zeros(0)
        self._Z = np.zeros((0, 0))
        self.enrichment: Enrichment | None = None
        if self._alpha.size:
            lr = self._orthonormalise()
            # stiff stops get the engaged state's modes and their local shapes (supported beams only:
            # with rigid-body modes the inertia-relief attachment shapes obey another identity)
            if contact and not self.free.n_rigid:
                self.enrichment = enrich(beam, self.free, self.positions, self._Z, self._rho_at,
                                         self._samples, contact, loads)
                if self.enrichment is not None:
                    lr = self.enrichment.lam
        self.lam = np.concatenate([self.free.omega**2, lr])
        self.count = int(self.lam.size)
        self.integral = self._integral()
        self.integral.setflags(write=False)
        self.inertia = self._inertia()
        self.inertia.setflags(write=False)

    @property
    def roundoff(self) -> float:
        """Relative round-off of the basis functions' values and of their mass and stiffness (an estimate).

        The attachment residual ``r = g - sum phi_i phi_i(a) / omega_i^2`` is a
        difference of O(1) shapes: its values keep the round-off of the ``N``
        terms (a few ulps each) times ``|g| / |r|``, and its stiffness ``r(a)``
        that of ``g(a)`` times ``g(a) / r(a)`` (both grow as ``N^3`` to
        ``N^3.5``); an extra function of the enrichment combines the residual
        functions with coefficients up to ``|A_rho|_1`` (its part beyond the
        reference modes, divided by that part's small norm). So ``4 N eps
        max(|g| / |r|, g(a) / r(a)) max(1, |A_rho|_1)``: an independent
        quadrature finds the mass matrix within this of the identity and the
        stiffness within this times the largest ``lambda`` (tests/test_ritz.py).
        """
        enr = self.enrichment
        amp = 1.0 if enr is None else max(1.0, float(np.abs(enr.A_rho).sum(axis=0).max()))
        return float(4 * self.free.count * np.finfo(float).eps * getattr(self, "_cancellation", 1.0) * amp)

    def _integral(self) -> np.ndarray:
        """``int_0^L f dx`` of every basis function."""
        enr = self.enrichment
        if enr is None:
            return self.values(self._x) @ self._w
        rho = self._rho_at(self._x, 0) @ self._w
        return np.concatenate([self.free.integral(), enr.values(rho, enr.modes.integral()[enr.n_retained:])])

    def _inertia(self) -> np.ndarray:
        """``int rho A f dx + sum m f(x_m)`` of every basis function (the load of a base acceleration)."""
        enr = self.enrichment
        if enr is None:
            return self._sample(self.values, rows="translation").T @ self._sample_weights()
        rho = self._sample(self._rho_at, rows="translation").T @ self._sample_weights()
        tail = enr.modes.inertia_integral()[enr.n_retained:]
        return np.concatenate([self.free.inertia_integral(), enr.values(rho, tail)])

    def _sample_weights(self) -> np.ndarray:
        """``sqrt`` of the translational kinetic weights of :meth:`_sample` (quadrature and point masses)."""
        lay = self.free._layout
        at = lay.m > 0.0
        return np.concatenate([np.sqrt(self.beam.mass_per_length_at(self._x) * self._w), np.sqrt(lay.m[at])])

    def _sample(self, fn, rows: str = "all", quadrature: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
        """Functions ``fn(x, field)`` weighted so that ``S^T S`` is their kinetic inner product: (rows, n).

        Rows: the quadrature (``quadrature``, default the basis's) with
        ``rho A(x) w``, the point masses with ``m``; then (``rows="all"``) the
        rotations, with ``rho I(x) w`` for a Timoshenko beam and ``J`` at the
        point masses.
        """
        lay = self.free._layout
        at, atJ = lay.m > 0.0, lay.J > 0.0
        x, w = (self._x, self._w) if quadrature is None else quadrature
        parts = [(fn(x, 0) * np.sqrt(self.beam.mass_per_length_at(x) * w)).T]
        if at.any():
            parts.append((fn(lay.nodes[at], 0) * np.sqrt(lay.m[at])).T)
        if rows == "all":
            if self.beam.is_timoshenko:
                parts.append((fn(x, "rot") * np.sqrt(self.beam.rotary_inertia_at(x) * w)).T)
            if atJ.any():
                parts.append((fn(lay.nodes[atJ], "rot") * np.sqrt(lay.J[atJ])).T)
        return np.concatenate(parts)

    def _gram(self, fn, bmax: float) -> tuple[np.ndarray, np.ndarray]:
        """Kinetic and strain-energy inner products of the functions ``fn(x, field)`` (see :meth:`_samples`)."""
        S, E = self._samples(fn, bmax)
        assert E is not None
        return S.T @ S, E.T @ E

    def _samples(self, fn, bmax: float, strain: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Weighted samples ``(S, E)`` of the functions ``fn(x, field)``: ``S^T S`` and ``E^T E`` are their inner products.

        On a quadrature resolving the wavenumber ``bmax`` (split at the
        contactors and every node of the beam): the kinetic ``int rho A f g``
        (and the rotary terms, the point masses) and the strain energy
        ``int M_f M_g / EI`` (plus ``int kappa G A (f' - Psi_f)(g' - Psi_g)``
        for a Timoshenko beam) with the finite translational and rotational
        springs of the supports (``E`` is None without ``strain``). Linear in
        the functions, so the samples of a combination are the combination of
        the samples.
        """
        quad = self._quadrature(bmax)
        S = self._sample(fn, quadrature=quad)
        if not strain:
            return S, None
        x, w = quad
        beam = self.beam
        parts = [(fn(x, "moment") * np.sqrt(w / beam.bending_stiffness_at(x))).T]
        if beam.is_timoshenko:
            pieces = beam.pieces()
            ends = np.cumsum([p.length for p in pieces])[:-1]
            GA = np.array([beam.shear_stiffness(p) for p in pieces])[np.searchsorted(ends, x, side="right")]
            parts.append(((fn(x, 1) - fn(x, "rot")) * np.sqrt(w * GA)).T)
        lay = self.free._layout
        for xs, k, kt in zip(lay.nodes, lay.k, lay.kt):
            for value, field in ((k, 0), (kt, "rot")):
                if 0.0 < value < math.inf:
                    parts.append(math.sqrt(value) * fn(np.array([xs]), field).T)
        return S, np.concatenate(parts)

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
        # the residual r = g - (its part in the retained modes) is a difference: its values carry the
        # round-off of g's times |g| / |r|, and its stiffness matrix r_c(a_d) that of g_c(a_d) over the
        # smallest eigenvalue of r_c(a_d)
        at = self._alpha[keep] * L
        if at.size:
            Ga = self._static_at(at, 0)[keep]
            Ra = self._residuals_at(at, 0)[keep]
            smallest = float(np.linalg.eigvalsh(0.5 * (Ra + Ra.T)).min())
            stiff = float(np.abs(Ga).max()) / smallest if smallest > 0 else math.inf
            self._cancellation = float(max(np.max(g_norm[keep] / r_norm[keep]), stiff))
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

    def _extra_at(self, x: np.ndarray, derivative: int | str) -> np.ndarray:
        """The attachment residuals before orthonormalisation, cleared of round-off along the retained modes."""
        R = self._residuals_at(x, derivative)
        if self._C.shape[1]:
            R = R - self._C.T @ self._free_at(x, derivative)
        return R

    def _rho_at(self, x: np.ndarray, derivative: int | str) -> np.ndarray:
        """The plain basis's residual functions ``rho_j = sum_c Z[c, j] r_c`` at ``x``: (n_r, p)."""
        return self._Z.T @ self._extra_at(np.atleast_1d(np.asarray(x, dtype=float)), derivative)

    def _orthonormalise(self) -> np.ndarray:
        """Mass-orthonormal residual functions that diagonalise the free stiffness; returns their ``lambda_r``.

        On the quadrature the weighted attachment residuals are projected out
        of the retained modes twice (classical Gram-Schmidt; the coefficients
        are kept in ``_C``) and orthonormalised through their singular
        directions (no column is preferred, so round-off cannot pick one); a
        direction below ``_NEW`` of the largest is dropped. Their free
        stiffness is the strain energy on the same quadrature, so mass and
        stiffness are those of the functions as evaluated (the identity
        ``r_c^T K r_d = r_c(a_d)`` from ``K g_a = delta_a`` would carry the
        round-off of ``g(a)`` times ``g(a) / r(a)``, 1e-11 at 8 modes).
        """
        F = self._sample(self._free_at)  # (rows, N), orthonormal columns
        B = self._sample(self._extra_at)
        C = np.zeros((F.shape[1], B.shape[1]))
        for _ in range(2):
            c = F.T @ B
            B = B - F @ c
            C += c
        self._C = C
        d = 1.0 / np.linalg.norm(B, axis=0)
        _, s, Vt = np.linalg.svd(B * d, full_matrices=False)
        k = int(np.sum(s > _NEW * s[0]))
        Y = d[:, None] * (Vt[:k].T / s[:k])
        _, K = self._gram(self._extra_at, 0.0)
        lr, V = np.linalg.eigh(Y.T @ K @ Y)
        self._Z = Y @ V
        return lr

    def _quadrature(self, bmax: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
        """Gauss-Legendre (20 points) on pieces of at most half the shortest wavelength, split at the contactors.

        The wavelength is that of the retained modes, or of the wavenumber ``bmax`` when larger.
        """
        L = self.beam.length
        bmax = max(float(self.free._beta_max), 4.0 / L, bmax)
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
        enr = self.enrichment
        if enr is not None:
            tail = _mode_field(enr.modes, x, derivative)[enr.n_retained:]
            out = np.concatenate([out, enr.values(self._rho_at(x, derivative), tail)])
        elif self._Z.size:
            out = np.concatenate([out, self._rho_at(x, derivative)])
        return out


@functools.lru_cache(maxsize=64)
def _cached_basis(beam: Beam, positions: tuple[float, ...], n_modes: int,
                  contact: tuple[tuple[float, float], ...], loads: tuple[float, ...]) -> RitzBasis:
    return RitzBasis(beam, positions, n_modes, contact, loads)


def ritz_basis(beam: Beam, positions: Sequence[float], n_modes: int,
               contact: Sequence[tuple[float, float]] = (), loads: Sequence[float] = ()) -> RitzBasis:
    """The shared basis (cached).

    Parameters
    ----------
    beam : Beam
    positions : sequence of float, [m]
        Contactor positions: one attachment shape each.
    n_modes : int
        Retained free modes ``N``.
    contact : sequence of (position [m], stiffness [N/m])
        The contactors, all engaged: that state's modes and the stops' local
        shapes join the basis where it misses them (:mod:`~impactbeam.solver.ritz_enrich`).
    loads : sequence of float, [m]
        Positions of point forces (their second load-dependent Ritz vector joins at a stop).
    """
    key = tuple(sorted((float(x), float(k)) for x, k in contact))
    return _cached_basis(beam, tuple(sorted(float(p) for p in positions)), int(n_modes), key,
                         tuple(sorted(float(x) for x in loads)))
