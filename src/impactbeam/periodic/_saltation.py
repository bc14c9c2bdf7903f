"""Exact Jacobian of the event-driven flow map: segment transitions composed with saltation matrices.

Between two events the modal equations of a state are linear with constant
coefficients, so the derivative of the state at the end of a segment with
respect to the state at its start is the homogeneous transition matrix, per
mode

.. math:: \\Phi(\\tau) = \\begin{pmatrix} e_C + a e_S & e_S \\\\
          -\\omega^2 e_S & e_C - a e_S \\end{pmatrix},

with ``e_C, e_S`` the kernels of :mod:`impactbeam.solver._closed` (every
damping regime) and ``a = xi omega``. The load only shifts the particular
solution and drops out of the derivative. A state whose modes do not
diagonalise its damping (dashpots, free-mode damping) is integrated by 2 x 2
blocks (:mod:`impactbeam.solver.blocks`), each such an oscillator: its
transition is ``G Phi H`` (:func:`slot_transition`).

At a switch of contactor ``c`` at time ``t_e`` (its opening
``g(x) = base + v . eta`` crosses zero) the coordinates are carried into the
new state by the transfer matrix ``T`` (paper eq. 12, or the exact change of
basis of the shared Ritz basis). A perturbation of the state before the event
moves the event time by ``-grad g . dx / (grad g . f-)``, so the derivative
of the jump is the saltation matrix

.. math:: S = \\hat T + \\frac{(f^+ - \\hat T f^-)\\, \\nabla g^T}{\\nabla g \\cdot f^-},
          \\qquad \\hat T = \\operatorname{diag}(T, T),

with ``f-`` the vector field of the old state at the event and ``f+`` that
of the new state at the transferred point. A contactor spring engages with
zero force, so in the shared Ritz basis ``f+ = T f-`` and ``S = T``; with the
paper's per-state modes the lossy projection leaves a non-zero correction.
``grad g . f- ~ 0`` is a grazing contact, where the map is not smooth
(its derivative grows like ``1 / (grad g . f-)``). A dashpot contactor is
released where its force ``k d + c d'`` vanishes, and engaged again by that
force while still compressed: then ``g`` is the force and its gradient holds
the velocity (:func:`_switching_gradient`; the released phase is tracked as
the engine does, :func:`_released`). With the paper's basis a switch's
projection can leave another contactor on the wrong side, which the engine
switches at the same instant: that instant is the first switch's, so the
two jumps make one, ``S = T2 T1 + (f++ - T2 T1 f-) grad g1^T / (grad g1 . f-)``
(:func:`_off_surface` tells such a switch from a crossing). A contactor the
projection leaves on the wrong side with nothing else switching is switched
where the rate of its function vanishes (the engine's turn-back rule): that
rate, ``grad g . f``, times the event, so ``grad g`` becomes ``A^T grad g``
(``A = df/dx``) and the normal velocity ``grad g . (A f + df/dt)``. A switch
undone at the same instant leaves no event but, with the paper's basis, a
moved state: such pairs are restored from the states either side of the
instant (:func:`_restored`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..solver._codes import TOUCH

__all__ = ["FlowJacobian", "flow_jacobian", "segment_transition", "slot_transition", "to_free", "from_free",
           "energy_weights", "GRAZING"]

#: An event whose normal velocity is below this fraction of the orbit's velocity scale is grazing:
#: near a grazing contact the map grows like the square root of the penetration (its derivative
#: like 1/velocity), so a Jacobian there holds only in a tiny neighbourhood.
GRAZING = 1e-4
#: A switching function further than this fraction of the beam's length from zero at its switch was not
#: crossed there (:func:`_off_surface`); at a crossing it is round-off.
_OFF = 1e-9


@dataclass
class FlowJacobian:
    """Derivative of the final state (free-state coordinates) with respect to the initial one.

    Attributes
    ----------
    matrix : ndarray, (2 n, 2 n)
        ``d x(T) / d x(0)``, ``x = (eta, eta_t)`` in the free state's basis.
    final : ndarray, (2 n,)
        ``x(T)`` in the free state's basis.
    events : int
        Switching events crossed.
    grazing : list of (float, float)
        ``(time, ratio)`` of events whose normal velocity ``grad g . f-`` is below
        ``GRAZING`` (1e-4) of the orbit's velocity scale at the contactor.
    """

    matrix: np.ndarray
    final: np.ndarray
    events: int = 0
    grazing: list[tuple[float, float]] = field(default_factory=list)


def segment_transition(reg: np.ndarray, dec: np.ndarray, wdh: np.ndarray, om: np.ndarray, tau: float) -> np.ndarray:
    """Homogeneous transition matrix of one state over ``tau`` (module docstring), shape (2 n, 2 n)."""
    from ..solver._closed import kernel

    n = om.size
    eC = np.empty(n)
    eS = np.empty(n)
    for i in range(n):
        eC[i], eS[i] = kernel(int(reg[i]), float(dec[i]), float(wdh[i]), float(tau))
    out = np.zeros((2 * n, 2 * n))
    idx = np.arange(n)
    out[idx, idx] = eC + dec * eS
    out[idx, n + idx] = eS
    out[n + idx, idx] = -om * om * eS
    out[n + idx, n + idx] = eC - dec * eS
    return out


def slot_transition(pk, s: int, tau: float) -> np.ndarray:
    """Homogeneous transition of state slot ``s`` over ``tau`` in its modal coordinates ``(eta, eta_t)``.

    A state whose modes diagonalise its damping: :func:`segment_transition`.
    Otherwise its coordinates are the 2 x 2 blocks of
    :mod:`~impactbeam.solver.blocks`, each a damped oscillator in ``(z0, z1)``
    (the load only shifts ``z1``): ``x = G z``, ``z = H x``, so the
    transition is ``G Phi H`` with ``Phi`` the blocks' :func:`segment_transition`.
    """
    Phi = segment_transition(pk.reg[s], pk.dec[s], pk.wdh[s], pk.om[s], tau)
    if not pk.gen[s]:
        return Phi
    G = np.concatenate([pk.G[s, 0], pk.G[s, 1]], axis=1)
    H = np.concatenate([pk.H[s, 0], pk.H[s, 1]], axis=0)
    return G @ Phi @ H


def _block(T: np.ndarray) -> np.ndarray:
    n = T.shape[0]
    out = np.zeros((2 * n, 2 * n))
    out[:n, :n] = T
    out[n:, n:] = T
    return out


def _transfer(pk, to: int, frm: int) -> np.ndarray:
    return np.asarray(pk.space.transfer(pk.keys[to], pk.keys[frm], pk.preserve), dtype=float)


def _built_slot(pk, mask: int) -> int | None:
    """The slot of the state with engaged-contactor mask ``mask``, or None when it is not built."""
    hits = np.flatnonzero(pk.smask[: pk.nslots] == mask)
    return int(hits[0]) if hits.size else None


def _slot_of(pk, mask: int) -> int:
    slot = _built_slot(pk, mask)
    return int(pk.add_state(mask)) if slot is None else slot


def to_free(pk, slot: int) -> np.ndarray:
    """Block transfer ``diag(T, T)`` from state slot ``slot`` into the free state's basis (slot 0)."""
    n = pk.n_modes
    return np.eye(2 * n) if slot == 0 else _block(_transfer(pk, 0, slot))


def from_free(pk, slot: int) -> np.ndarray:
    """Block transfer from the free state's basis (slot 0) into state slot ``slot``."""
    n = pk.n_modes
    return np.eye(2 * n) if slot == 0 else _block(_transfer(pk, slot, 0))


class _Field:
    """Vector field ``f(x, t)`` of each state of a solution (the modal equations, paper eq. 9)."""

    def __init__(self, sol) -> None:
        self.sol = sol
        self.pk = sol.packed
        self.gap, self.side, self.kst = sol.contactor_arrays
        self.pt0, _, self.pconst, self.pslope, self.pamp, self.pOm, self.pphase = sol.pieces

    def force(self, s: int, kp: int, t: float) -> np.ndarray:
        """Modal load of slot ``s`` under load piece ``kp`` at time ``t`` (as the engine's segment set-up)."""
        from ..solver._loop import load_value

        pk = self.pk
        u = load_value(kp, t, self.pt0, self.pconst, self.pslope, self.pamp, self.pOm, self.pphase)
        F = pk.pw[s] * u + pk.pre[s]
        mask = int(pk.smask[s])
        for c in range(self.gap.size):
            if (mask >> c) & 1 and self.gap[c] != 0.0:
                F = F + self.side[c] * self.kst[c] * self.gap[c] * pk.Wc[s, c]
        return F

    def __call__(self, s: int, kp: int, t: float, x: np.ndarray) -> np.ndarray:
        """``(eta_t, eta_tt)`` in slot ``s``'s modal frame: its frequencies and damping matrix (dashpots in it)."""
        pk = self.pk
        n = pk.n_modes
        eta, deta = x[:n], x[n:]
        damp = pk.Cd[s] @ deta if pk.gen[s] else 2.0 * pk.dec[s] * deta
        acc = self.force(s, kp, t) - damp - pk.omo[s] ** 2 * eta
        return np.concatenate([deta, acc])

    def linear(self, s: int) -> np.ndarray:
        """``d f / d x`` in slot ``s`` (the field is affine in the state)."""
        pk = self.pk
        n = pk.n_modes
        damp = pk.Cd[s] if pk.gen[s] else np.diag(2.0 * pk.dec[s])
        return np.block([[np.zeros((n, n)), np.eye(n)], [-np.diag(pk.omo[s] ** 2), -damp]])

    def rate(self, s: int, kp: int, t: float) -> np.ndarray:
        """``d f / d t`` at fixed state in slot ``s``, load piece ``kp``: the rate of the load."""
        pk = self.pk
        tau = t - self.pt0[kp]
        du = self.pslope[kp] + self.pamp[kp] * self.pOm[kp] * math.cos(self.pOm[kp] * tau + self.pphase[kp])
        return np.concatenate([np.zeros(pk.n_modes), pk.pw[s] * du])

    def end_state(self, j: int, at_start: bool = False) -> np.ndarray:
        """Modal state at the end of segment ``j`` (or at its start), in the closed form of the engine's kernels."""
        from ..solver._closed import segment_setup, state_at, workspace
        from ..solver._elementary import kernel_work

        sol, pk = self.sol, self.pk
        s, kp = int(sol.slot[j]), int(sol.piece[j])
        eta = np.array(sol.eta0[j], dtype=float)
        deta = np.array(sol.deta0[j], dtype=float)
        h0, dh0, P, lA, lB, lD, lE, AL = workspace(pk.n_modes)
        Om, phi = segment_setup(s, kp, float(sol.t0[j]), eta, deta, pk.reg, pk.dec, pk.om, pk.LW[:, 0], pk.LW[:, 1],
                                pk.CW[:, 0], pk.CW[:, 1], pk.LW[:, 2], pk.LW[:, 3], pk.smask, self.gap, self.side,
                                self.kst, self.pt0, self.pconst, self.pslope, self.pamp, self.pOm, self.pphase,
                                h0, dh0, P, lA, lB, lD, lE, AL)
        e = np.empty(pk.n_modes)
        d = np.empty(pk.n_modes)
        tau = 0.0 if at_start else float(sol.t1[j] - sol.t0[j])
        state_at(tau, pk.reg[s], pk.dec[s], pk.wdh[s], pk.om[s], h0, dh0, P, Om, phi, e, d, kernel_work(pk.n_modes))
        if pk.gen[s]:  # block coordinates (z, z') into the modal frame, as the engine's samples
            from ..solver._closed import alpha_at
            from ..solver._loop import to_modal

            alpha = np.empty(pk.n_modes)
            alpha_at(AL, tau, Om, phi, alpha)
            z, dz = e.copy(), d.copy()
            to_modal(1, pk.G[s], z, dz, alpha, e, d)
        return np.concatenate([e, d])


def _switching_gradient(fld: _Field, s: int, mask: int, c: int, x: np.ndarray, phase: np.ndarray) -> np.ndarray:
    """Gradient (up to a factor) of the function whose zero switches contactor ``c`` out of slot ``s``.

    The engine's rows (:func:`~impactbeam.solver._loop.contactor_rows`): the
    opening or penetration ``d = s w(a) - gap``, whose gradient is
    ``(W(a), 0)``; with a dashpot, a release where the force ``k d + c_d d'``
    vanishes and a re-engagement while still compressed (the released phase,
    ``phase[c]``: :func:`_released`), both ``(W(a), (c_d / k) W(a))``.
    """
    pk = fld.pk
    W = pk.Wc[s, c]
    r = 0.0
    dash = float(pk.dash[c]) if pk.dash.size else 0.0
    if dash > 0.0 and ((mask >> c) & 1 or phase[c]):
        r = dash / fld.kst[c]
    return np.concatenate([W, r * W])


def _phase_ends(fld: _Field, s: int, x: np.ndarray, phase: np.ndarray) -> None:
    """End the released phase of the contactors whose penetration at ``x`` is back within the touch tolerance.

    The engine ends it where the penetration returns to zero (a segment
    boundary without a switch); a switch at the same point sees it ended.
    """
    touch = TOUCH * float(fld.pk.space.beam.length)
    for c in np.flatnonzero(phase):
        if _penetration(fld, s, int(c), x) <= touch:
            phase[c] = False


def _penetration(fld: _Field, s: int, c: int, x: np.ndarray) -> float:
    """``side w(a_c) - gap`` at the modal state ``x`` of slot ``s``."""
    n = fld.pk.n_modes
    return float(fld.side[c]) * float(fld.pk.Wc[s, c] @ x[:n]) - float(fld.gap[c])


def _released(fld: _Field, s: int, mask: int, c: int, x: np.ndarray, phase: np.ndarray) -> None:
    """Update ``phase[c]`` for a switch of ``c`` out of slot ``s`` at ``x`` (before its projection), as the engine.

    A dashpot contactor released while compressed beyond the touch tolerance
    (by the force ``k d + c_d d'`` changing sign) is in its released phase
    until its penetration returns to zero: meanwhile its force, not its
    opening, re-engages it (:func:`~impactbeam.solver._loop._switch`). The
    phase is judged on the penetration before the release's projection, which
    with the paper's basis may leave the contactor compressed after a release
    at zero penetration: that one is switched back by its opening's turn-back.
    """
    dash = float(fld.pk.dash[c]) if fld.pk.dash.size else 0.0
    engaging = not (mask >> c) & 1
    phase[c] = (not engaging and dash > 0.0
                and _penetration(fld, s, c, x) > TOUCH * float(fld.pk.space.beam.length))


def _off_surface(fld: _Field, grad: np.ndarray, c: int, x: np.ndarray) -> bool:
    """Whether contactor ``c``'s switching function (gradient ``grad``) is away from zero at ``x``.

    Its value is ``side grad . x - gap`` (the penetration, or the force over
    the stiffness); a switch made where it is zero crossed it, one made where
    it is not (beyond `_OFF` of the beam's length) was made because
    another switch at that instant (the paper's projection) left the
    contactor on the wrong side: the engine switches it at once, at a time
    its own function does not set.
    """
    value = float(fld.side[c]) * float(grad @ x) - float(fld.gap[c])
    return abs(value) > _OFF * float(fld.pk.space.beam.length)


def _switches(sol, j: int) -> list[int]:
    """Contactors switched, in order, between segment ``j`` and ``j + 1``.

    Several switches at one instant may end in the state they began from
    (with the paper's basis, each projection leaving the next contactor on
    the wrong side): the events at the instant say which.
    """
    pk = sol.packed
    m0, m1 = int(pk.smask[sol.slot[j]]), int(pk.smask[sol.slot[j + 1]])
    te = float(sol.t1[j])
    ev_t, _, ev_c = sol.event_arrays[:3]
    order = [int(c) for c in ev_c[ev_t == te]]
    if m0 == m1 and not order:
        return []
    mask, out = m0, []
    for c in order:
        mask ^= 1 << c
        out.append(c)
    if mask != m1:  # events cancelled at one instant: toggle the differing bits in index order
        out = [c for c in range(len(sol.contactors)) if ((m0 ^ m1) >> c) & 1]
    return out


def _restored(fld: _Field, j: int, x: np.ndarray, recorded: list[int]) -> list[int]:
    """The switches made at the end of segment ``j``: ``recorded``, with the pairs the event record drops.

    The engine records a switch of a contactor followed at the same instant
    by its undoing as no event (they cancel: :func:`~impactbeam.solver._loop._switch`).
    With the shared basis the pair changes nothing (the recorded switches
    are returned as they are); with per-state modes its two projections
    (paper eq. 12) move the state. The
    switches are those whose projections carry ``x`` (the end of segment
    ``j``) to the start of segment ``j + 1`` (to 1e-9 of its norm): the
    recorded ones, else with one or two pairs ``(c, c)`` inserted.
    """
    sol, pk = fld.sol, fld.pk
    if not pk.space.per_state:  # exact changes of basis: a pair is no jump at all
        return recorded
    s, after = int(sol.slot[j]), int(sol.slot[j + 1])
    target = fld.end_state(j + 1, at_start=True)
    weights = energy_weights(pk.omo[after])
    tol = 1e-9 * max(float(np.linalg.norm(weights * target)), np.finfo(float).tiny)

    def lands(seq: list[int]) -> bool:
        xp, sl, mask = x, s, int(pk.smask[s])
        for c in seq:
            mask ^= 1 << c
            nxt = _built_slot(pk, mask)
            if nxt is None:  # a state the engine never entered
                return False
            xp, sl = _block(_transfer(pk, nxt, sl)) @ xp, nxt
        return sl == after and float(np.linalg.norm(weights * (xp - target))) <= tol

    if lands(recorded):
        return recorded
    tries = [recorded]
    for _ in range(2):
        tries = [t[:i] + [c, c] + t[i:] for t in tries for i in range(len(t) + 1) for c in range(fld.gap.size)]
        for seq in tries:
            if lands(seq):
                return seq
    return recorded


def energy_weights(om: np.ndarray) -> np.ndarray:
    """Weights of the energy norm ``|(omega eta, eta_t)|`` of a modal state with frequencies ``om``.

    A rigid-body coordinate (``omega = 0``) takes the lowest positive frequency.
    """
    om = np.asarray(om, dtype=float)
    positive = om[om > 0.0]
    ref = float(positive.min()) if positive.size else 1.0
    return np.concatenate([np.where(om > 0.0, om, ref), np.ones(om.size)])


def _velocity_scale(sol) -> float:
    """Largest velocity at a contactor at a segment start or an event [m/s] (the grazing yardstick)."""
    pk = sol.packed
    v = [abs(ev.velocity) for ev in sol.events]
    modal = pk.gen[sol.slot] == 0  # segments recorded in modal coordinates (the others in block coordinates)
    if modal.any() and pk.Wc.shape[1]:
        Wc = pk.Wc[sol.slot[modal]]  # (nseg, nc, n)
        v.append(float(np.abs(np.einsum("jcn,jn->jc", Wc, sol.deta0[modal])).max()))
    return max(v, default=0.0) or 1.0


def flow_jacobian(sol) -> FlowJacobian:
    """Exact ``d x(T) / d x(0)`` of a solution that starts at ``t = 0`` in the free state's coordinates.

    Parameters
    ----------
    sol : Solution
        The engine's exact piecewise solution over ``[0, T]``. An event whose
        normal velocity is below ``GRAZING`` (1e-4) of the largest velocity at a
        contactor in the solution is reported as grazing.

    Returns
    -------
    FlowJacobian
    """
    pk = sol.packed
    fld = _Field(sol)
    nseg = sol.n_segments
    if nseg == 0:
        raise ValueError("flow_jacobian: the solution has no segment")
    velocity_scale = _velocity_scale(sol)
    J = from_free(pk, int(sol.slot[0]))  # a state engaged already at t = 0 (strictly inside: no crossing)
    events = 0
    grazing: list[tuple[float, float]] = []
    phase = np.zeros(fld.gap.size, dtype=bool)  # dashpot contactors in their released phase (_released)
    # a grazing contact's saltation (normal velocity near 0) can overflow: the caller sees a matrix that is not
    # finite and says so (periodic orbit: no multipliers), rather than numpy's warnings
    with np.errstate(over="ignore", invalid="ignore"):
        for j in range(nseg):
            s = int(sol.slot[j])
            J = slot_transition(pk, s, float(sol.t1[j] - sol.t0[j])) @ J
            if j + 1 == nseg:
                break
            x = fld.end_state(j)
            _phase_ends(fld, s, x, phase)
            cs = _restored(fld, j, x, _switches(sol, j))
            if not cs:
                continue
            te = float(sol.t1[j])
            kp = int(sol.piece[j])
            mask = int(pk.smask[s])
            i = 0
            while i < len(cs):
                # a switch, with those made at once after it because it left their contactors on the wrong side
                # (the paper's projection): one jump at the instant the first one's function sets
                c = cs[i]
                grad = _switching_gradient(fld, s, mask, c, x, phase)
                T = np.eye(x.size)
                xp, s_new, mask_new, k = x, s, mask, i
                while k < len(cs) and (k == i or _off_surface(fld, _switching_gradient(fld, s_new, mask_new, cs[k],
                                                                                          xp, phase), cs[k], xp)):
                    _released(fld, s_new, mask_new, cs[k], xp, phase)
                    nxt = _slot_of(pk, mask_new ^ (1 << cs[k]))
                    Tb = _block(_transfer(pk, nxt, s_new))
                    T, xp, s_new, mask_new, k = Tb @ T, Tb @ xp, nxt, mask_new ^ (1 << cs[k]), k + 1
                f_minus = fld(s, kp, te, x)
                f_plus = fld(s_new, kp, te, xp)
                normal = float(grad @ f_minus)
                if _off_surface(fld, grad, c, x):
                    # the first switch of its instant, off its surface: a turn-back (the paper's projection left
                    # the contactor on the wrong side, and the engine switches it where the function's rate
                    # vanishes), whose instant is set by that rate: its gradient and its own rate along the flow
                    rate_grad = fld.linear(s).T @ grad
                    grad, normal = rate_grad, float(rate_grad @ f_minus + grad @ fld.rate(s, kp, te))
                if abs(normal) < GRAZING * velocity_scale:
                    grazing.append((te, abs(normal) / velocity_scale))
                S = T if normal == 0.0 else T + np.outer(f_plus - T @ f_minus, grad) / normal
                J = S @ J
                x, s, mask = xp, s_new, mask_new
                events += k - i
                i = k
    last = int(sol.slot[nseg - 1])
    final = to_free(pk, last) @ fld.end_state(nseg - 1)
    return FlowJacobian(to_free(pk, last) @ J, final, events, grazing)
