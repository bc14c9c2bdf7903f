"""The linear states of the piecewise-linear system and the projections between them.

A state is the set of engaged contactors (paper: free state T^f and contact
state T^c). Each has its own modes, damping and constant gap forces; states
are built on demand and cached, as are the projection matrices (paper eq. 12).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..model.beam import Beam, Contactor
from ..model.loading import Excitation, spatial_projection
from ..model.starting import Preload
from ..modal import ModeSet, mode_set
from ..model import Damping
from .damping import dashpot_coefficient, state_damping_matrix
from .equilibrium import preload_weights

__all__ = ["ModalDynamics", "StateModel", "StateSpace"]

@dataclass(frozen=True, eq=False)
class ModalDynamics:
    """Frequencies and decay rates of the modes of one state, with regime masks.

    ``decay = xi omega`` [1/s]; a mode is under-damped (``wd = sqrt(omega^2 -
    decay^2)``), over-damped (``wh = sqrt(decay^2 - omega^2)``) or critical;
    an undamped rigid-body mode (``omega = decay = 0``) counts as critical, a
    damped one (Rayleigh's ``alpha``) as over-damped.
    """

    omega: np.ndarray
    decay: np.ndarray

    @property
    def _disc(self) -> np.ndarray:
        return self.omega**2 - self.decay**2

    @property
    def under(self) -> np.ndarray:
        return self._disc > 0.0

    @property
    def over(self) -> np.ndarray:
        return self._disc < 0.0

    @property
    def wd(self) -> np.ndarray:
        return np.sqrt(np.where(self.under, self._disc, 0.0))

    @property
    def wh(self) -> np.ndarray:
        return np.sqrt(np.where(self.over, -self._disc, 0.0))


def _preload_key(preload: Preload | None) -> tuple:
    return () if preload is None else (preload.kind, preload.position, float(preload.amplitude))


# State models are pure functions of their inputs (all immutable), so they are
# shared between simulations: a parameter study that varies only the load or
# the gaps reuses modes, shapes at the points and projections.
_STATE_CACHE: dict[tuple, StateModel] = {}
_STATE_CACHE_SIZE = 256


@dataclass(frozen=True, eq=False)
class StateModel:
    """Everything the integrator needs about one state.

    Attributes
    ----------
    engaged : tuple of int
        Indices of the engaged contactors.
    modes : ModeSet
    dyn : ModalDynamics
    W_contact : ndarray, (n_contactors, n)
        ``W_n(a_c)`` for every contactor (engaged or not).
    W_out : ndarray, (n_points, n)
        Mode shapes at the output points.
    load_weights : ndarray, (n,)
        ``p_n`` with modal load ``p_n u(t)`` (paper eq. 8).
    preload_weights : ndarray, (n,)
        The preload's constant modal force (zero without a preload).
    damping_matrix : ndarray, (n, n), or None
        The damping in the state's modal frame when its modes do not
        diagonalise it (:mod:`~impactbeam.solver.damping`); None when
        ``dyn.decay`` says it all.
    """

    engaged: tuple[int, ...]
    modes: ModeSet
    dyn: ModalDynamics
    W_contact: np.ndarray
    W_out: np.ndarray
    load_weights: np.ndarray
    preload_weights: np.ndarray
    damping_matrix: np.ndarray | None = None

    @property
    def omega_max(self) -> float:
        return float(self.modes.omega.max())


class ProblemSpace:
    """What every state space of one problem holds: the system, the output points, the built states.

    Parameters
    ----------
    beam : Beam
    contactors : sequence of Contactor
    damping : Damping
    excitation : Excitation
    n_modes : int
        Retained modes per state (the paper's N).
    points : ndarray, [m]
        Output positions.
    preload : Preload, optional
        A constant load acting throughout (``[preload]``).
    """

    #: Whether each state has its own modes, so that a switch projects the state (paper eq. 12): the subclasses say.
    per_state: bool

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
        self.beam = beam
        self.contactors = tuple(contactors)
        self.damping = damping
        self.excitation = excitation
        self.preload = preload
        self.n_modes = n_modes
        self.points = np.asarray(points, dtype=float).reshape(-1)
        self.positions = np.array([c.position for c in self.contactors], dtype=float)
        self._states: dict[tuple[int, ...], StateModel] = {}
        self._proj: dict[tuple, np.ndarray] = {}  # projections / changes of coordinates between states
        self._dashpots: np.ndarray | None = None

    @property
    def states(self) -> dict[tuple[int, ...], StateModel]:
        """The states built so far, by their engaged contactors."""
        return self._states

    def undamped(self, engaged: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
        """Frequencies and shapes at the contactors of a state, without its damping (subclasses)."""
        raise NotImplementedError

    @property
    def dashpots(self) -> np.ndarray:
        """Each contactor's dashpot [N s/m] (from ``damping`` or ``restitution``)."""
        if self._dashpots is None:
            out = np.zeros(len(self.contactors))
            for i, c in enumerate(self.contactors):
                if c.dissipative:
                    omega, Wc = self.undamped((i,))
                    out[i] = dashpot_coefficient(c, omega, Wc[i])
            self._dashpots = out
        return self._dashpots

    def _dynamics(self, engaged: tuple[int, ...], omega: np.ndarray, Wc: np.ndarray, overlap_with_free
                  ) -> tuple[ModalDynamics, np.ndarray | None]:
        """Decay rates of the state's modes, or its damping matrix when they do not diagonalise it.

        ``overlap_with_free()`` gives ``<W_n, W_m^free>`` (called for ``"free_modes"`` contact states only).
        """
        overlap = free_omega = None
        if self.damping.model == "free_modes" and engaged:
            overlap = overlap_with_free()
            free_omega = self.state(()).modes.omega
        C, diagonal = state_damping_matrix(self.damping, engaged, omega, Wc, self.dashpots, overlap, free_omega)
        if diagonal:
            return ModalDynamics(omega, 0.5 * np.diag(C).copy()), None
        return ModalDynamics(omega, np.zeros_like(omega)), C

    def _preload_weights(self, modes) -> np.ndarray:
        """The preload's constant modal force on a state's modes (zero without a preload)."""
        if self.preload is None:
            return np.zeros(modes.count)
        return preload_weights(self.preload, modes, self.beam)


class StateSpace(ProblemSpace):
    """Builds and caches the states of one problem (the paper's per-state modes) and the projections between them."""

    #: Every state has its own modes: a switch moves the state by the projection of paper eq. (12).
    per_state = True

    def state(self, engaged: tuple[int, ...]) -> StateModel:
        st = self._states.get(engaged)
        if st is None:
            key = (
                self.beam, self.contactors, engaged, self.damping, self.excitation.kind,
                self.excitation.position, self.n_modes, tuple(self.points.tolist()), _preload_key(self.preload),
            )
            st = _STATE_CACHE.get(key)
            if st is None:
                st = self._build(engaged)
                if len(_STATE_CACHE) >= _STATE_CACHE_SIZE:
                    _STATE_CACHE.pop(next(iter(_STATE_CACHE)))
                _STATE_CACHE[key] = st
            self._states[engaged] = st
        return st

    def _modes(self, engaged: tuple[int, ...]) -> ModeSet:
        springs = [(self.contactors[i].position, self.contactors[i].stiffness) for i in engaged]
        return mode_set(self.beam, springs, self.n_modes)

    def undamped(self, engaged: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
        ms = self._modes(engaged)
        Wc = np.ascontiguousarray(ms.shapes(self.positions).T) if self.contactors else np.zeros((0, ms.count))
        return ms.omega, Wc

    def _build(self, engaged: tuple[int, ...]) -> StateModel:
        ms = self._modes(engaged)
        n = ms.count
        Wc = np.ascontiguousarray(ms.shapes(self.positions).T) if self.contactors else np.zeros((0, n))
        Wo = np.ascontiguousarray(ms.shapes(self.points).T) if self.points.size else np.zeros((0, n))
        integral, inertia = ms.integral(), ms.inertia_integral()
        p = spatial_projection(self.excitation, ms.shapes, integral, self.beam.mass_per_length, inertia=inertia)
        pre = self._preload_weights(ms)
        dyn, C = self._dynamics(engaged, ms.omega, Wc, lambda: ms.overlap(self.state(()).modes))
        return StateModel(engaged, ms, dyn, Wc, Wo, p, pre, C)

    def projection(self, to: tuple[int, ...], frm: tuple[int, ...]) -> np.ndarray:
        """``P[n, p] = rho A int W_n^to W_p^from dx`` (paper eq. 12)."""
        key = (to, frm)
        P = self._proj.get(key)
        if P is None:
            P = self.state(to).modes.overlap(self.state(frm).modes)
            self._proj[key] = P
        return P

    def transfer(self, to: tuple[int, ...], frm: tuple[int, ...], preserve_contacts: bool) -> np.ndarray:
        """Matrix ``T`` with ``eta_to = T @ eta_from`` (displacement and velocity alike).

        Without ``preserve_contacts`` this is the projection of eq. (12). With it,
        the nearest modal state (in the mass norm) to that projection whose
        deflection at every contactor equals the old one:
        ``T = P + C^T (C C^T)^+ (D - C P)`` with ``C = W_to(a)``, ``D = W_from(a)``.
        """
        key = (to, frm, preserve_contacts)
        T = self._proj.get(key)
        if T is None:
            P = self.projection(to, frm)
            if preserve_contacts and self.contactors:
                C = self.state(to).W_contact
                D = self.state(frm).W_contact
                T = P + C.T @ np.linalg.pinv(C @ C.T) @ (D - C @ P)
            else:
                T = P
            self._proj[key] = T
        return T
