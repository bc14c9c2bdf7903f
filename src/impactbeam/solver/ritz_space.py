"""The states of the shared Ritz basis (``solver.basis = "enriched"``): modes per state, exact switches.

The basis itself (retained free modes, attachment shapes, the engaged
state's modes when they join) is :mod:`impactbeam.solver.ritz`. Here each
state's stiffness ``diag(lambda) + sum_engaged k psi(a) psi(a)^T`` (mass the
identity) is diagonalised, giving that state's modes (Rayleigh-Ritz), and a
switch is the exact orthogonal change of coordinates
``eta_new = Phi_new^T Phi_old eta_old`` instead of the paper's eq. (12).

References
----------
.. [1] W. Xu, E. K. Ervin, Shock and Vibration 20 (2013), section 2, eqs. (8)-(12).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..exceptions import ParameterError
from ..model import Damping
from ..model.beam import Beam, Contactor
from ..model.loading import Excitation, spatial_projection
from ..model.starting import Preload
from .ritz import RitzBasis, ritz_basis
from .states import ProblemSpace, StateModel

__all__ = ["RitzModes", "RitzStateSpace"]


# --------------------------------------------------------------------------- state modes


class RitzModes:
    """Modes of one state in the shared basis: ``W_m(x) = sum_j Phi[j, m] psi_j(x)``.

    Offers the part of :class:`~impactbeam.modal.ModeSet`'s interface the
    solver and the results use (``omega``, ``count``, ``frequencies_hz``,
    ``shapes``, ``integral``). They are mass-orthonormal
    (``rho A int W_n W_m dx = delta_nm``) and there are ``N + n_r`` of them:
    the approximation of the state's lowest ``N + n_r`` modes (Rayleigh-Ritz).
    """

    def __init__(self, basis: RitzBasis, Phi: np.ndarray, omega: np.ndarray) -> None:
        self.basis = basis
        self.Phi = Phi
        self.omega = omega
        self.beam = basis.beam

    @property
    def count(self) -> int:
        """Number of modes, ``N + n_r``."""
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

    def inertia_integral(self) -> np.ndarray:
        """``int rho A(x) W_n dx + sum_j m_j W_n(x_j)`` [kg^0.5], like :meth:`ModeSet.inertia_integral`."""
        return self.Phi.T @ self.basis.inertia

    def rotations(self, x: float | Sequence[float] | np.ndarray) -> np.ndarray:
        """Cross-section rotations at ``x``: (n, p), like :meth:`ModeSet.rotations`.

        Parameters
        ----------
        x : float or array_like, [m]
            Positions on the beam.
        """
        return self.Phi.T @ self.basis.values(x, "rot")

    def moment_shapes(self, x: float | Sequence[float] | np.ndarray) -> np.ndarray:
        """Bending moment per unit modal coordinate at ``x``: (n, p), like :meth:`ModeSet.moment_shapes`.

        Parameters
        ----------
        x : float or array_like, [m]
            Positions on the beam.
        """
        return self.Phi.T @ self.basis.values(x, "moment")


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


class RitzStateSpace(ProblemSpace):
    """Drop-in for :class:`~impactbeam.solver.states.StateSpace` on the shared Ritz basis.

    Every state has ``N + n_r`` modes (``N = n_modes`` retained free modes,
    ``n_r`` residual functions, normally one per contactor position);
    :attr:`count` gives it. ``transfer`` is the exact change of
    coordinates between two states (orthogonal), not the projection of eq. (12).
    """

    #: One basis shared by every state: a switch changes coordinates exactly, it moves no state.
    per_state = False

    def __init__(
        self,
        beam: Beam,
        contactors: Sequence[Contactor],
        damping: Damping,
        excitation: Excitation,
        n_modes: int,
        points: np.ndarray,
        preload: Preload | None = None,
    ) -> None:
        super().__init__(beam, contactors, damping, excitation, n_modes, points, preload)
        for i, c in enumerate(self.contactors):
            if not math.isfinite(c.stiffness):
                raise ParameterError(
                    f"contactors.{i}.stiffness: a rigid stop cannot be integrated in the enriched basis "
                    "(solver.basis); give a finite stiffness"
                )
        loads = [excitation.position] if excitation.kind == "point_force" and excitation.position is not None else []
        self.basis = ritz_basis(beam, self.positions, n_modes, [(c.position, c.stiffness) for c in self.contactors],
                                loads)
        self._psi_c = self.basis.values(self.positions) if self.contactors else np.zeros((self.basis.count, 0))
        self._psi_o = self.basis.values(self.points) if self.points.size else np.zeros((self.basis.count, 0))
        self._p = spatial_projection(excitation, self.basis.values, self.basis.integral, beam.mass_per_length,
                                     self.basis.inertia)

    @property
    def count(self) -> int:
        """Modes per state, ``N + n_r``."""
        return self.basis.count

    def state(self, engaged: tuple[int, ...]) -> StateModel:
        """The state with the contactors ``engaged`` (cached)."""
        st = self._states.get(engaged)
        if st is None:
            omega, Phi = self._eigen(engaged)
            ms = RitzModes(self.basis, Phi, omega)
            n = ms.count
            Wc = np.ascontiguousarray((Phi.T @ self._psi_c).T) if self.contactors else np.zeros((0, n))
            Wo = np.ascontiguousarray((Phi.T @ self._psi_o).T) if self.points.size else np.zeros((0, n))
            dyn, C = self._dynamics(engaged, omega, Wc, lambda: Phi.T @ self.state(()).modes.Phi)
            st = StateModel(engaged, ms, dyn, Wc, Wo, Phi.T @ self._p, self._preload_weights(ms), C)  # type: ignore[arg-type]
            self._states[engaged] = st
        return st

    def _eigen(self, engaged: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
        springs = [(i, self.contactors[i].stiffness) for i in engaged]
        return _state_eigen(self.basis, springs, self._psi_c)

    def undamped(self, engaged: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
        omega, Phi = self._eigen(engaged)
        Wc = np.ascontiguousarray((Phi.T @ self._psi_c).T) if self.contactors else np.zeros((0, omega.size))
        return omega, Wc

    def projection(self, to: tuple[int, ...], frm: tuple[int, ...]) -> np.ndarray:
        """The exact change of coordinates ``Phi_to^T Phi_from`` (replaces eq. 12)."""
        key = (to, frm)
        T = self._proj.get(key)
        if T is None:
            T = self.state(to).modes.Phi.T @ self.state(frm).modes.Phi  # type: ignore[attr-defined]
            self._proj[key] = T
        return T

    def transfer(self, to: tuple[int, ...], frm: tuple[int, ...], preserve_contacts: bool = False) -> np.ndarray:
        """``T`` with ``eta_to = T @ eta_from``; exact, so ``preserve_contacts`` changes nothing."""
        return self.projection(to, frm)
