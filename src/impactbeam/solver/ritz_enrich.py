"""Enrichment of the shared Ritz basis for stiff stops: the engaged state's modes and the stop's local shapes.

The plain shared basis (:mod:`impactbeam.solver.ritz`) holds the ``N``
retained free modes ``phi_i`` and one static attachment shape per contactor
position. For a stop much stiffer than the beam at its position that is not
enough (issue figures: the specimen with ``k = 1e7`` N/m at 0.484 L is 2.7 %
off in penetration at 16 modes):

* the **engaged state's lowest modes** have part of their shape outside the
  free modes and the attachment shape (a stop at a free end pins it), so the
  contact phase runs on approximate modes; the paper's method (one set of
  ``N`` exact modes per state) has them;
* the **impact itself is local**: a spring of stiffness ``k`` striking a beam
  (bending stiffness ``EI``, mass per length ``rho A``) is loaded over the
  time ``t_c = (EI^(1/4) (rho A)^(3/4) / k)^(2/3)`` in which a bending wave
  spreads over ``(EI / rho A)^(1/4) t_c^(1/2)`` (dimensional analysis of the
  infinite beam: its deflection under a step force grows as ``t^(3/2)``).
  For ``k = 1e7`` N/m on the specimen ``t_c = 2.2`` us and that length is
  1.6 mm: the first peak of the contact force is set by frequencies around
  ``omega_c = 1 / t_c`` (74 kHz), far above 16 free modes (38 kHz).

Both are computed in a **reference space** ``S`` of the free modes
``N + 1 .. M`` and the part of the attachment shapes beyond mode ``M``, in
which the mass matrix is the identity and the stiffness is known exactly from
modal identities (no quadrature of differences of shapes):

* for a supported beam ``K g_a = delta_a``, so the attachment shape's overlap
  with mode ``i`` is ``<phi_i, g_a> = phi_i(a) / omega_i^2`` and, for any
  function ``f``, ``<phi_i, K f> = omega_i^2 <phi_i, f>``;
* the engaged state's modes are the Rayleigh-Ritz modes of
  ``K + sum k b b^T`` in (retained modes + ``S``), exact to far more than the
  retained ones need;
* the **local shapes** are the beam's response to a unit force at the stop
  at the imaginary frequencies ``i sigma``: ``(K + sigma^2 M)^-1 delta_a``,
  which decays within a few ``(EI / (rho A sigma^2))^(1/4)`` of the stop (a
  beam on an elastic foundation), for ``sigma = omega_c, 2 omega_c, 4
  omega_c, 8 omega_c`` above the retained band. ``S`` holds the modes up to
  twice the largest ``sigma``.

The parts of these functions outside the plain basis join it (their singular
directions, so the result does not depend on round-off ties); a direction
with less than ``1e-3`` of its norm outside the rest is left out. Soft
contactors (the paper's Case 3) have neither (engaged modes within 1e-3,
``omega_c`` below the retained band) and keep the plain basis exactly: one
quadrature of the exact engaged modes says so before the reference space is
built (less than half the 1e-3 outside; Case 3: 1.8e-4).

References
----------
.. [1] W. Xu, E. K. Ervin, Shock and Vibration 20 (2013), section 2.
.. [2] M. Hetenyi, "Beams on Elastic Foundation", University of Michigan
   Press (1946): the Green's function of ``EI w'''' + k_f w = delta``.
.. [3] F. Melcher, A. R. Champneys, D. J. Wagg, Phil. Trans. R. Soc. A 371
   (2013) 20120434: modal non-convergence of impacting beams.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..model.beam import Beam
from ..modal import ModeSet, count_below, mode_set

__all__ = ["Enrichment", "contact_time", "enrich"]

NEW = 1e-3  # a direction must bring this fraction of its norm outside the basis
OCTAVES = 4  # local shapes at omega_c * 2**j, j = 0 .. OCTAVES - 1
_TAIL = 1e-12  # the attachment shapes' part beyond mode M is kept while its squared norm exceeds this
MAX_REFERENCE = 240  # largest reference space (free modes)


def contact_time(beam: Beam, position: float, stiffness: float) -> float:
    """Loading time of a stop of ``stiffness`` striking the beam at ``position`` [s].

    ``t_c = (EI^(1/4) (rho A)^(3/4) / k)^(2/3)`` with the beam's local ``EI``
    and ``rho A``: the time in which the infinite beam's deflection under a
    step force ``F`` (growing as ``F t^(3/2) / (EI^(1/4) (rho A)^(3/4))``)
    reaches ``F / k``.

    Parameters
    ----------
    beam : Beam
    position : float, [m]
    stiffness : float, [N/m]
    """
    x = np.array([position])
    EI = float(beam.bending_stiffness_at(x)[0])
    rA = float(beam.mass_per_length_at(x)[0])
    return float((EI**0.25 * rA**0.75 / stiffness) ** (2.0 / 3.0))


@dataclass(frozen=True)
class Enrichment:
    """Extra functions of the shared basis: ``f = A_phi^T phi_{N+1..M} + A_rho^T rho``.

    Attributes
    ----------
    modes : ModeSet
        The reference free modes ``1 .. M``.
    n_retained : int
        ``N``.
    A_phi : ndarray, (M - N, n_x)
        Coefficients on the free modes ``N + 1 .. M``.
    A_rho : ndarray, (n_r, n_x)
        Coefficients on the plain basis's residual functions.
    lam : ndarray, (n_x,)
        Free-state stiffness of the extra functions (diagonal; mass the identity).
    shifts : tuple of float
        The ``sigma`` [rad/s] of the local shapes used.
    n_engaged : int
        Engaged-state modes offered to the basis.
    """

    modes: ModeSet
    n_retained: int
    A_phi: np.ndarray
    A_rho: np.ndarray
    lam: np.ndarray
    shifts: tuple[float, ...]
    n_engaged: int

    def values(self, rho: np.ndarray, tail: np.ndarray) -> np.ndarray:
        """The extra functions from ``rho`` (n_r, p) and the modes ``N + 1 .. M`` (M - N, p): (n_x, p)."""
        return self.A_phi.T @ tail + self.A_rho.T @ rho


def _field(ms: ModeSet, x: np.ndarray, field: int | str) -> np.ndarray:
    """A field of a mode set at ``x``: (n, p)."""
    if field == "rot":
        return ms.rotations(x)
    if field == "moment":
        return ms.moment_shapes(x)
    return ms.shapes(x, int(field))


def _engaged_outside(beam: Beam, free: ModeSet, rho_at, samples, stops: dict[int, float],
                     positions: np.ndarray) -> float:
    """The largest fraction of the norm of the engaged state's lowest ``N`` exact modes outside the plain basis.

    On one quadrature of the retained modes, the residual functions and the
    exact engaged modes (which resolves them all).
    """
    N = free.count
    springs = [(float(positions[c]), k) for c, k in stops.items() if math.isfinite(k)]
    engaged = mode_set(beam, springs, N)
    S, _ = samples(lambda x, f: np.concatenate([_field(free, x, f), rho_at(x, f), _field(engaged, x, f)]),
                   float(engaged._beta_max), strain=False)
    inside = S[:, : S.shape[1] - N].T @ S[:, S.shape[1] - N:]
    return float(np.sqrt(np.maximum(1.0 - np.sum(inside**2, axis=0), 0.0)).max())


def _orthonormal_outside(E: np.ndarray, norms: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Orthonormal directions of the columns of ``E`` outside the orthonormal ``R``.

    A column keeps when at least ``NEW`` of its norm (``norms``: the whole
    function's, retained modes included) lies outside ``R``; the kept columns
    are normalised and their singular directions above ``NEW`` returned
    (rotation invariant, so no round-off tie picks a column).
    """
    for _ in range(2):
        E = E - R @ (R.T @ E)
    left = np.linalg.norm(E, axis=0)
    keep = left > NEW * norms
    if not keep.any():
        return np.zeros((E.shape[0], 0))
    U, s, _ = np.linalg.svd(E[:, keep] / left[keep], full_matrices=False)
    Q = U[:, s > NEW]
    for _ in range(2):
        Q = Q - R @ (R.T @ Q)
    Q, _ = np.linalg.qr(Q)
    return Q


def enrich(
    beam: Beam,
    free: ModeSet,
    positions: np.ndarray,
    Z: np.ndarray,
    rho_at: Callable[[np.ndarray, int | str], np.ndarray],
    samples: Callable[[Callable[[np.ndarray, int | str], np.ndarray], float], tuple[np.ndarray, np.ndarray]],
    contact: Sequence[tuple[float, float]],
    loads: Sequence[float] = (),
) -> Enrichment | None:
    """The engaged state's modes and the stops' local shapes outside the plain basis, or None.

    Parameters
    ----------
    beam : Beam
        A supported beam (no rigid-body mode).
    free : ModeSet
        The ``N`` retained free modes.
    positions : ndarray, (n_a,), [m]
        Positions of the attachment shapes.
    Z : ndarray, (n_a, n_r)
        The residual functions ``rho_j = sum_c Z[c, j] r_c`` of the plain basis
        (``r_c``: attachment shape at ``positions[c]`` minus its part in the
        retained modes).
    rho_at : callable
        ``rho_at(x, field)``: the ``rho_j`` (or a field of them) at ``x``, (n_r, p).
    samples : callable
        ``samples(fn, bmax)``: weighted samples ``(S, E)`` of the functions
        ``fn(x, field)`` whose products ``S^T S`` and ``E^T E`` are their
        kinetic and strain-energy inner products, on a quadrature resolving
        the wavenumber ``bmax``.
    contact : sequence of (position, stiffness)
        Every contactor engaged: the state whose modes are offered.
    loads : sequence of float, [m]
        Positions of point forces; one at a stop adds its second load-dependent Ritz vector.
    """
    N = free.count
    stops: dict[int, float] = {}
    for x, k in contact:
        c = int(np.argmin(np.abs(positions - x)))
        stops[c] = stops.get(c, 0.0) + float(k)
    omega_next = float(mode_set(beam, (), N + 1).omega[N])
    shifts = sorted({
        (c, s) for c, k in stops.items() if math.isfinite(k)
        for s in (2.0**j / contact_time(beam, float(positions[c]), k) for j in range(OCTAVES)) if s > omega_next
    }, key=lambda cs: (cs[0], cs[1]))
    pos = np.array([float(positions[c]) for c in stops])
    at_stop = [x for x in loads if np.min(np.abs(pos - x)) <= 1e-9 * beam.length]
    if not shifts and not at_stop and _engaged_outside(beam, free, rho_at, samples, stops, positions) < 0.5 * NEW:
        return None  # a soft contactor: the plain basis holds the engaged state's modes (cheap check)
    sigma_max = max((s for _, s in shifts), default=0.0)
    M = 2 * N + 8
    if sigma_max > 0.0:
        M = max(M, min(count_below(beam, 2.0 * sigma_max) + 1, MAX_REFERENCE))
    big = mode_set(beam, (), M)
    om2 = big.omega[N:] ** 2
    shifts = [(c, s) for c, s in shifts if s <= 0.5 * float(big.omega[-1])]
    # rho in the modes N+1..M: <phi_i, rho> (= phi_i(a) / omega_i^2 Z for the exact shapes, K g_a = delta_a),
    # on the quadrature, so that it matches rho as evaluated (whose last digits carry the cancellation of
    # the attachment residual), and the tails t = rho - B^T phi_tail (rho beyond mode M): their mass and
    # stiffness also on the quadrature, as I - B^T B and diag(lam_rho) - B^T Omega^2 B would keep only
    # the digits of the earlier quadrature divided by the tails' share of rho's norm, (N / M)^7, and of
    # its strain energy, (N / M)^3
    n_r = Z.shape[1]
    S, E = samples(lambda x, f: np.concatenate([rho_at(x, f), _field(big, x, f)[N:]]), float(big._beta_max))
    B = S[:, n_r:].T @ S[:, :n_r]  # (M - N, n_r)
    S_tail, E_tail = S[:, :n_r] - S[:, n_r:] @ B, E[:, :n_r] - E[:, n_r:] @ B
    mass = np.concatenate([S_tail, S[:, n_r:]], axis=1)
    mass = mass.T @ mass
    strain = np.concatenate([E_tail, E[:, n_r:]], axis=1)
    strain = strain.T @ strain
    tau, U = np.linalg.eigh(0.5 * (mass[:n_r, :n_r] + mass[:n_r, :n_r].T))
    on = tau > _TAIL
    tau, U = tau[on], U[:, on]
    S_t = U / np.sqrt(tau)  # t_hat = S_t^T (rho - B^T phi_tail)
    # stiffness in S: the modes' omega^2 (exact), the tails' strain energy and their coupling to the
    # modes (zero for exact shapes, omega_i^2 <phi_i, t> = 0; here that of the functions as evaluated)
    K_S = np.zeros((M - N + tau.size,) * 2)
    K_S[: M - N, : M - N] = np.diag(om2)
    K_S[M - N:, M - N:] = S_t.T @ strain[:n_r, :n_r] @ S_t
    K_S[: M - N, M - N:] = strain[n_r:, :n_r] @ S_t
    K_S = 0.5 * (K_S + K_S.T)
    R = np.concatenate([B, np.sqrt(tau)[:, None] * U.T])  # rho in S (orthonormal columns)
    # the functions at the stops: retained modes, then S
    tail_a = big.shapes(pos)[N:]
    s_a = np.concatenate([tail_a, S_t.T @ (rho_at(pos, 0) - B.T @ tail_a)])
    f_a = free.shapes(pos)
    cols, norms = [], []
    # the engaged state's lowest N modes (Rayleigh-Ritz in retained modes + S)
    K = np.zeros((N + K_S.shape[0],) * 2)
    K[:N, :N] = np.diag(free.omega**2)
    K[N:, N:] = K_S
    for j, k in enumerate(stops.values()):
        if math.isfinite(k):
            b = np.concatenate([f_a[:, j], s_a[:, j]])
            K += k * np.outer(b, b)
    _, V = np.linalg.eigh(0.5 * (K + K.T))
    cols.append(V[N:, :N])
    norms.append(np.ones(N))
    # the local shapes (K + sigma^2)^-1 delta_a
    index = {c: j for j, c in enumerate(stops)}
    for c, s in shifts:
        j = index[c]
        e = np.linalg.solve(K_S + s**2 * np.eye(K_S.shape[0]), s_a[:, j])
        head = f_a[:, j] / (free.omega**2 + s**2)
        cols.append(e[:, None])
        norms.append(np.array([math.sqrt(float(e @ e + head @ head))]))
    # the second load-dependent Ritz vector of a point force at a stop: the static response beyond the
    # retained modes to the inertia of the first (the attachment shape), K_S^-1 (K_S^-1 s_a)
    for x in at_stop:
        c = int(np.argmin(np.abs(pos - x)))
        e = np.linalg.solve(K_S, np.linalg.solve(K_S, s_a[:, c]))
        cols.append(e[:, None])
        norms.append(np.array([math.sqrt(float(e @ e))]))  # its part beyond the retained modes
    Q = _orthonormal_outside(np.concatenate(cols, axis=1), np.concatenate(norms), R)
    if Q.shape[1] == 0:
        return None
    X = np.concatenate([R, Q], axis=1)
    lam, W = np.linalg.eigh(0.5 * ((X.T @ K_S @ X) + (X.T @ K_S @ X).T))
    A = X @ W
    A_rho = S_t @ A[M - N:]
    A_phi = A[: M - N] - B @ A_rho
    return Enrichment(big, N, A_phi, A_rho, lam, tuple(s for _, s in shifts), N)
