"""The static equilibrium under a constant preload, with the contactors it engages.

A preload (:class:`~impactbeam.model.starting.Preload`: gravity, a constant
base acceleration or a point force) acts during the whole run; with
``initial.equilibrium = true`` the run starts from the static equilibrium of
the run's own model under it. That is a contact problem: each contactor is a
one-sided spring, engaged (``g = gap - s w(a) < 0``, force ``k (-g)`` pushing
the beam back) or not (``g >= 0``, no force), and which ones are engaged is
part of the answer.

In the modal model of the run a state ``A`` (set of engaged contactors) has
its own modes, stiffness ``diag(omega_A^2)`` and constant loads: the
preload's modal weights (:func:`preload_weights`, paper eq. 8) and the gaps'
forces ``s k gap W_A(a)``; its equilibrium is ``eta_A = f_A / omega_A^2``
(a rigid-body mode must carry no load, else the state has none). The
equilibrium of the model is the state whose solution is consistent
(engaged contactors penetrated, the others open). It is found as

1. the linear complementarity problem (LCP) in the free state's coordinates:
   with ``K = diag(omega^2)`` and ``b_c = W(a_c)`` the contact forces
   ``lambda >= 0`` satisfy ``(diag(1/k) + G) lambda - d0 >= 0``, complementary
   to ``lambda``, with ``G = S B K^-1 B^T S`` and ``d0 = S B K^-1 p - gap``;
   the matrix is positive definite, so the LCP has one solution, obtained
   exactly (finite active-set algorithm) as a non-negative least-squares
   problem after a Cholesky factorisation. In the shared Ritz basis this is
   the model's equilibrium itself; in the paper's basis (each state its own
   modes) it proposes the engaged set, which is then checked in that
   state's modes;
2. when the free state has rigid-body modes (``K`` singular) or the proposed
   set is not consistent, every set of contactors (up to 12 contactors).

The same LCP with the exact flexibility of the continuum
(:func:`impactbeam.modal.static_state`) gives the exact static contact
solution, :func:`continuum_equilibrium`, against which the modal one is
checked (its truncation).

References
----------
.. [1] W. Xu, E. K. Ervin, Shock and Vibration 20 (2013), section 2, eqs. (8)-(9).
.. [2] R. W. Cottle, J.-S. Pang, R. E. Stone, *The Linear Complementarity
   Problem*, SIAM (2009), ch. 3 (positive definite LCPs as convex QPs).
.. [3] C. L. Lawson, R. J. Hanson, *Solving Least Squares Problems*, SIAM (1995), ch. 23 (NNLS).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..exceptions import ParameterError
from ..modal import static_state
from ..model.beam import Beam, Contactor, InteriorSpring
from ..model.loading import spatial_projection
from ..model.starting import Preload

__all__ = ["Equilibrium", "ContinuumEquilibrium", "preload_weights", "modal_equilibrium", "continuum_equilibrium"]

#: Largest number of contactors whose engaged sets are enumerated.
MAX_ENUMERATED = 12


@dataclass(frozen=True, eq=False)
class Equilibrium:
    """The static equilibrium of the run's modal model under the preload.

    Attributes
    ----------
    engaged : tuple of int
        The contactors the preload engages (the state of the equilibrium).
    eta : ndarray, (n,)
        Modal coordinates in that state's modes [m kg^0.5].
    deflection : ndarray, (n_contactors,), [m]
        ``w(a_c)`` at every contactor.
    forces : ndarray, (n_contactors,), [N]
        Contact force of every contactor (>= 0; 0 when not engaged).
    """

    engaged: tuple[int, ...]
    eta: np.ndarray
    deflection: np.ndarray
    forces: np.ndarray


@dataclass(frozen=True, eq=False)
class ContinuumEquilibrium:
    """The exact static contact solution of the beam (no modal truncation).

    Attributes
    ----------
    beam : Beam
        The beam the static solver sees (with the engaged contactors as
        springs when only they hold it).
    engaged : tuple of int
    forces : ndarray, (n_contactors,), [N]
        Contact force of every contactor (>= 0).
    loads : tuple of (position [m], force [N])
        Point forces along +w (preload, point masses, and the contact forces
        or, with the contactors as springs, their gaps' forces).
    per_length : tuple of float, [N/m]
        Distributed load per section along +w.
    """

    beam: Beam
    engaged: tuple[int, ...]
    forces: np.ndarray
    loads: tuple[tuple[float, float], ...]
    per_length: tuple[float, ...]

    def deflection(self, x: Sequence[float] | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Deflection [m] and cross-section rotation [rad] at ``x``.

        Parameters
        ----------
        x : array_like, [m]
            Positions on the beam.
        """
        state = static_state(self.beam, x, self.loads, self.per_length)
        return state[0], state[1]


def preload_weights(preload: Preload, modes, beam: Beam) -> np.ndarray:
    """The constant modal load ``<f, W_n>`` of the preload on a state's modes (paper eq. 8).

    The engine adds it to the modal load of every segment, so that the
    equilibrium is kept; the same weights as an excitation of the preload's
    kind (:func:`impactbeam.model.loading.spatial_projection`) times its amplitude.

    Parameters
    ----------
    preload : Preload
    modes : ModeSet or RitzModes
        The state's modes (``shapes``, ``integral``, ``inertia_integral``).
    beam : Beam

    Returns
    -------
    ndarray, (n,)
        [N kg^-0.5].
    """
    load = preload.excitation()
    weights = spatial_projection(load, modes.shapes, modes.integral(), beam.mass_per_length, modes.inertia_integral())
    return load.amplitude * np.asarray(weights, dtype=float)


def _sides(contactors: Sequence[Contactor]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    s = np.array([c.direction for c in contactors], dtype=float)
    k = np.array([c.stiffness for c in contactors], dtype=float)
    gap = np.array([c.gap for c in contactors], dtype=float)
    for i, c in enumerate(contactors):
        if not math.isfinite(c.stiffness):
            raise ParameterError(f"contactors.{i}.stiffness: the static equilibrium needs a finite stiffness")
    return s, k, gap


def _lcp(flex: np.ndarray, d0: np.ndarray, k: np.ndarray) -> np.ndarray:
    """Contact forces ``lambda >= 0`` with ``(diag(1/k) + S F S) lambda - d0`` complementary (module notes).

    ``flex`` is ``S F S`` (positive semi-definite); the LCP matrix is
    positive definite, so ``lambda`` minimises ``1/2 l^T M l - d0^T l`` over
    ``l >= 0``: ``M = R^T R`` turns it into ``min |R l - R^-T d0|`` (NNLS).
    """
    if d0.size == 0:
        return np.zeros(0)
    # imported here: SciPy's linear algebra and optimiser cost ~0.2 s and ~0.15 s to import, and few runs
    # start from an equilibrium (a short run on the interpreted kernels, its mode sets stored, needs neither;
    # numba's compiled target imports the linear algebra itself)
    import scipy.linalg
    from scipy.optimize import nnls

    M = 0.5 * (flex + flex.T) + np.diag(1.0 / k)
    R = scipy.linalg.cholesky(M, lower=False)
    rhs = scipy.linalg.solve_triangular(R, d0, trans="T")

    lam, _ = nnls(R, rhs, maxiter=50 * d0.size + 100)
    return lam


def _state_solution(space, beam: Beam, preload: Preload, contactors: Sequence[Contactor],
                    engaged: tuple[int, ...], tol: float) -> Equilibrium | None:
    """The equilibrium of state ``engaged`` in its own modes, or None when it is not consistent."""
    s, k, gap = _sides(contactors)
    st = space.state(engaged)
    om = np.asarray(st.modes.omega, dtype=float)
    Wc = np.asarray(st.W_contact, dtype=float).reshape(len(contactors), om.size)
    f = preload_weights(preload, st.modes, beam)
    for c in engaged:
        f = f + s[c] * k[c] * gap[c] * Wc[c]
    rigid = om == 0.0
    scale = float(np.max(np.abs(f), initial=0.0))
    if np.any(np.abs(f[rigid]) > 1e-9 * scale):
        return None  # a rigid-body mode is loaded: no equilibrium in this state
    eta = np.where(rigid, 0.0, f / np.where(rigid, 1.0, om**2))
    w = Wc @ eta
    g = gap - s * w
    on = np.zeros(len(contactors), dtype=bool)
    on[list(engaged)] = True
    if np.any(g[on] > tol) or np.any(g[~on] < -tol):
        return None
    forces = np.where(on, k * np.maximum(-g, 0.0), 0.0)
    return Equilibrium(engaged, eta, w, forces)


def _proposed(space, beam: Beam, preload: Preload, contactors: Sequence[Contactor]) -> tuple[int, ...] | None:
    """The engaged set of the LCP in the free state's coordinates (None if the free state has rigid modes)."""
    st = space.state(())
    om = np.asarray(st.modes.omega, dtype=float)
    if np.any(om == 0.0):
        return None
    s, k, gap = _sides(contactors)
    B = np.asarray(st.W_contact, dtype=float).reshape(len(contactors), om.size)
    p = preload_weights(preload, st.modes, beam)
    SB = s[:, None] * B / om[None, :] ** 2
    lam = _lcp(SB @ (B.T * s[None, :]), SB @ p - gap, k)
    return tuple(int(i) for i in np.flatnonzero(lam > 0.0))


def modal_equilibrium(space, beam: Beam, preload: Preload, contactors: Sequence[Contactor]) -> Equilibrium:
    """The static equilibrium of the run's modal model under ``preload`` (module notes).

    Parameters
    ----------
    space : StateSpace or RitzStateSpace
        The run's state space (its states' modes, at the contactor positions).
    beam : Beam
    preload : Preload
    contactors : sequence of Contactor
        The run's contactors with their gaps and sides (the space's own may be
        neutral copies).

    Returns
    -------
    Equilibrium

    Raises
    ------
    ParameterError
        When no equilibrium exists: the supports and the contactors the
        preload engages do not hold the beam (a free-free beam under gravity),
        or more than 12 contactors on a beam that can move as a rigid body.
    """
    contactors = tuple(contactors)
    tol = 1e-12 * beam.length
    proposed = _proposed(space, beam, preload, contactors)
    if proposed is not None:
        eq = _state_solution(space, beam, preload, contactors, proposed, tol)
        if eq is not None:
            return eq
    n = len(contactors)
    if n > MAX_ENUMERATED:
        raise ParameterError(
            f"initial.equilibrium: {n} contactors on a beam that can move as a rigid body (or whose proposed "
            f"contact set was not consistent): the static contact problem is enumerated up to {MAX_ENUMERATED} "
            "contactors"
        )
    for size in range(n + 1):
        for engaged in itertools.combinations(range(n), size):
            if engaged == proposed:
                continue
            eq = _state_solution(space, beam, preload, contactors, engaged, tol)
            if eq is not None:
                return eq
    try:
        exact = continuum_equilibrium(beam, preload, contactors)
    except ParameterError:
        exact = None
    if exact is not None:  # the beam has one: the truncated model's contact states are not consistent
        raise ParameterError(
            f"initial.equilibrium: the run's {space.n_modes}-mode model has no consistent static contact state "
            f"under the preload, though the beam has one (contactors {list(exact.engaged)} engaged): too few "
            "modes for these contactors' stiffness; add modes"
        )
    raise ParameterError(
        "initial.equilibrium: no static equilibrium exists under the preload: the supports and the contactors "
        "it engages do not hold the beam (it would move as a rigid body, e.g. a free-free beam under gravity); "
        "add a support or a contactor that holds it, or start from rest"
    )


def _preload_loads(beam: Beam, preload: Preload) -> tuple[list[tuple[float, float]], list[float]]:
    """Point forces and per-section distributed loads [N/m] of the preload, along +w."""
    load = preload.excitation()
    if load.kind == "point_force":
        assert load.position is not None
        return [(float(load.position), float(load.amplitude))], [0.0] * len(beam.pieces())
    acc = -float(load.amplitude)  # body force per unit mass of a base acceleration
    per_length = [p.mass_per_length * acc for p in beam.pieces()]
    return [(m.position, m.mass * acc) for m in beam.masses if m.mass], per_length


def _held_by(beam: Beam, contactors: Sequence[Contactor], engaged: Sequence[int]) -> Beam:
    """The beam with the engaged contactors as permanent springs (for the static solver)."""
    springs = tuple(InteriorSpring(contactors[i].position, contactors[i].stiffness) for i in engaged)
    return dataclasses.replace(beam, springs=beam.springs + springs)


def continuum_equilibrium(beam: Beam, preload: Preload, contactors: Sequence[Contactor]) -> ContinuumEquilibrium:
    """The exact static contact solution (continuum, no modes) under ``preload``.

    The same LCP as the modal problem, with the exact flexibility at the
    contactors from :func:`impactbeam.modal.static_state`; a beam that only
    its stops hold (free-free on two stops) by the engaged sets, each solved
    with its contactors as springs.

    Parameters
    ----------
    beam : Beam
    preload : Preload
    contactors : sequence of Contactor

    Returns
    -------
    ContinuumEquilibrium

    Raises
    ------
    ParameterError
        When nothing holds the beam against the preload (no equilibrium).
    """
    contactors = tuple(contactors)
    s, k, gap = _sides(contactors)
    loads, per_length = _preload_loads(beam, preload)
    a = [c.position for c in contactors]
    try:
        lam = np.zeros(len(contactors))
        w0 = static_state(beam, a or [0.0], loads, per_length)[0]  # refused when the supports let the beam move
        if contactors:
            F = np.array([static_state(beam, a, [(aj, 1.0)])[0] for aj in a]).T  # F[i, j]: w(a_i) per unit force at a_j
            lam = _lcp(s[:, None] * F * s[None, :], s * w0 - gap, k)
        engaged = tuple(int(i) for i in np.flatnonzero(lam > 0.0))
        contact = [(a[i], float(-s[i] * lam[i])) for i in engaged]
        return ContinuumEquilibrium(beam, engaged, lam, tuple(loads + contact), tuple(per_length))
    except ParameterError:
        pass  # the supports let the beam move: only its stops can hold it
    tol = 1e-12 * beam.length
    for size in range(1, min(len(contactors), MAX_ENUMERATED) + 1):
        for engaged in itertools.combinations(range(len(contactors)), size):
            held = _held_by(beam, contactors, engaged)
            gaps = [(a[i], float(s[i] * k[i] * gap[i])) for i in engaged]
            try:
                w = static_state(held, a, loads + gaps, per_length)[0]
            except ParameterError:
                continue
            g = gap - s * w
            on = np.zeros(len(contactors), dtype=bool)
            on[list(engaged)] = True
            if np.all(g[on] <= tol) and np.all(g[~on] >= -tol):
                forces = np.where(on, k * np.maximum(-g, 0.0), 0.0)
                return ContinuumEquilibrium(held, tuple(engaged), forces, tuple(loads + gaps), tuple(per_length))
    raise ParameterError(
        "initial.equilibrium: no static equilibrium exists under the preload: the supports and the contactors "
        "it engages do not hold the beam"
    )
