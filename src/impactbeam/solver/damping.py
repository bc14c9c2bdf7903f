"""The damping of each state in its own modal frame: the beam's model plus the engaged dashpots.

For a state with mass-normalised modes ``W_n`` and frequencies ``omega_n``
the damping matrix in its modal frame is (``[damping]``,
:class:`~impactbeam.model.damping.Damping`)

* ``"modal"``: ``diag(2 xi_n omega_n)`` with the state's ratios (paper eq. 9);
* ``"rayleigh"``: ``alpha I + beta diag(omega_n^2)`` (``C = alpha M + beta K``
  of the state, the engaged springs in ``K``);
* ``"free_modes"``: ``P D P^T`` with ``D = diag(2 xi_m omega_m)`` of the free
  state and ``P[n, m] = <W_n, W_m^free>`` the kinetic inner products (the
  free state's damping operator ``M Phi D Phi^T M`` seen by this state's
  modes; in the shared Ritz basis this is exact);

plus, for every engaged contactor with a dashpot ``c``,
``c W(a) W(a)^T`` (the force ``c d'`` at its point). A state whose matrix is
diagonal is integrated mode by mode as in the paper; any other one through
its blocks (:mod:`~impactbeam.solver.blocks`).

A contactor given by a coefficient of restitution ``e`` gets the dashpot
that gives the engaged state's *contact mode* (the mode that stores the
largest fraction of its strain energy in that contactor's spring,
``k W_n(a)^2 / omega_n^2``) the damping ratio ``xi(e)`` of a single
spring-dashpot impact with the same law (:func:`restitution_ratio`):
``c = 2 xi omega_n / W_n(a)^2``. For a rigid body hitting the stop this is
exactly the restitution; on a continuous beam the rebound velocity at the
contact point also depends on the other modes, so ``e`` is then a property
of the stop, not a measured beam quantity.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..model import Damping
from ..model.beam import Contactor

__all__ = ["restitution_of", "restitution_ratio", "dashpot_coefficient", "state_damping_matrix"]


def restitution_of(xi: float) -> float:
    """Coefficient of restitution of a single spring-dashpot impact with damping ratio ``xi``.

    The mass meets the spring-dashpot (``F = k d + c d'``, never pulling) at
    speed ``v0``; the contact ends when the force reaches 0, i.e. when the
    acceleration ``d''`` vanishes; ``e = -d'(t_end) / v0``. With ``d = v0
    (exp(l1 t) - exp(l2 t)) / (l1 - l2)`` and ``l1,2`` the roots of ``l^2 +
    2 xi l + 1 = 0`` (time in units of ``1/omega``), the release is at
    ``(l1 - l2) t = 2 log(l2 / l1)`` (the first positive root).

    Parameters
    ----------
    xi : float
        Damping ratio ``c / (2 sqrt(k m))``, >= 0.

    Returns
    -------
    float
        ``e`` in (0, 1]; 1 at ``xi = 0``, decreasing to 0 as ``xi`` grows.
    """
    if xi <= 0.0:
        return 1.0
    if xi < 1.0:
        wd = math.sqrt(1.0 - xi * xi)
        # d'' = 0: tan(wd t) = 2 xi wd / (2 xi^2 - 1), first positive root
        t = math.atan2(2.0 * xi * wd, 2.0 * xi * xi - 1.0) / wd
        dv = math.exp(-xi * t) * (math.cos(wd * t) - xi / wd * math.sin(wd * t))
    elif xi == 1.0:
        t = 2.0
        dv = math.exp(-t) * (1.0 - t)
    else:
        r = math.sqrt(xi * xi - 1.0)
        l1, l2 = -xi + r, -xi - r
        t = 2.0 * math.log(l2 / l1) / (l1 - l2)
        dv = (l1 * math.exp(l1 * t) - l2 * math.exp(l2 * t)) / (l1 - l2)
    return -dv


def restitution_ratio(e: float) -> float:
    """The damping ratio whose spring-dashpot impact has the restitution ``e`` (inverse of :func:`restitution_of`).

    Parameters
    ----------
    e : float
        Coefficient of restitution in (0, 1].
    """
    if e >= 1.0:
        return 0.0
    lo, hi = 0.0, 1.0
    while restitution_of(hi) > e:
        hi *= 2.0
    for _ in range(200):  # bisection to round-off: restitution_of is monotone
        mid = 0.5 * (lo + hi)
        if restitution_of(mid) > e:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 4e-16 * hi:
            break
    return 0.5 * (lo + hi)


def dashpot_coefficient(contactor: Contactor, omega: np.ndarray, W_at: np.ndarray) -> float:
    """The dashpot ``c`` [N s/m] of a contactor, from ``damping`` or from ``restitution``.

    Parameters
    ----------
    contactor : Contactor
    omega : ndarray, (n,)
        Frequencies of the state with this contactor alone engaged [rad/s].
    W_at : ndarray, (n,)
        Its mode shapes at the contactor.
    """
    if contactor.restitution is None:
        return float(contactor.damping)
    xi = restitution_ratio(contactor.restitution)
    if xi == 0.0:
        return 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        share = np.where(omega > 0.0, contactor.stiffness * W_at**2 / omega**2, 0.0)
    n = int(np.argmax(share))
    return float(2.0 * xi * omega[n] / W_at[n] ** 2)


def state_damping_matrix(damping: Damping, engaged: Sequence[int], omega: np.ndarray, Wc: np.ndarray,
                         dashpots: np.ndarray, free_overlap: np.ndarray | None = None,
                         free_omega: np.ndarray | None = None) -> tuple[np.ndarray, bool]:
    """The damping matrix of a state in its modal frame, and whether it is diagonal.

    Parameters
    ----------
    damping : Damping
    engaged : sequence of int
        The engaged contactors.
    omega : ndarray, (n,)
        The state's frequencies [rad/s].
    Wc : ndarray, (nc, n)
        Its mode shapes at the contactors.
    dashpots : ndarray, (nc,)
        Each contactor's dashpot [N s/m].
    free_overlap : ndarray, (n, m), optional
        ``<W_n, W_m^free>`` (``"free_modes"``, contact states).
    free_omega : ndarray, (m,), optional
        The free state's frequencies (``"free_modes"``, contact states).

    Returns
    -------
    C : ndarray, (n, n), [1/s]
    diagonal : bool
    """
    if damping.model == "free_modes" and engaged:
        D = 2.0 * damping.ratios(False, free_omega.size) * free_omega
        C = (free_overlap * D) @ free_overlap.T
    else:
        C = np.diag(2.0 * damping.decay_rates(bool(engaged), omega))
    for i in engaged:
        if dashpots[i] > 0.0:
            C = C + dashpots[i] * np.outer(Wc[i], Wc[i])
    off = C - np.diag(np.diag(C))
    diagonal = not np.any(np.abs(off) > 1e-14 * max(float(np.max(np.abs(C))), 1e-300))
    if not diagonal:
        C = 0.5 * (C + C.T)
    return C, diagonal
