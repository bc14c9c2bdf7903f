"""Closed-form response of damped modal oscillators to constant, linear and sinusoidal loads.

Each mode obeys (paper eq. 9)

.. math:: \\ddot\\eta + 2\\xi\\omega\\dot\\eta + \\omega^2\\eta = a + b\\tau + d\\sin(\\Omega\\tau + \\varphi),

over a segment ``0 <= tau <= T`` in which the state and the load form do not change.
The solution is a particular part for each load term plus the homogeneous part

.. math:: \\eta_h(\\tau) = e^{-\\xi\\omega\\tau}\\left[(C + \\xi\\omega S)\\,h_0 + S\\,\\dot h_0\\right],

with ``C, S = cos, sin(w_d tau)/w_d`` (under-damped), ``1, tau`` (critical, or
``omega = 0``: rigid-body modes) and ``cosh, sinh(w_h tau)/w_h`` (over-damped),
each evaluated without cancellation or overflow. This generalises the paper's
eq. (10) and its ``B1, B2`` form to every damping regime and to linear and
sinusoidal loads, so a half-sine pulse and a first-order-hold trace are
integrated exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["ModalDynamics", "LoadForm", "ClosedFormSegment"]


@dataclass(frozen=True, eq=False)
class ModalDynamics:
    """Frequencies and damping of the modes of one state, with regime masks."""

    omega: np.ndarray  # (n,)
    xi: np.ndarray  # (n,)

    def __post_init__(self) -> None:
        om, xi = self.omega, self.xi
        a = xi * om
        disc = om**2 * (1.0 - xi**2)
        under = disc > 0.0
        over = disc < 0.0
        object.__setattr__(self, "decay", a)
        object.__setattr__(self, "under", under)
        object.__setattr__(self, "over", over)
        object.__setattr__(self, "wd", np.sqrt(np.where(under, disc, 0.0)))
        object.__setattr__(self, "wh", np.sqrt(np.where(over, -disc, 0.0)))
        object.__setattr__(self, "rigid", om == 0.0)
        object.__setattr__(self, "all_under", bool(under.all()))
        object.__setattr__(self, "mu", -a + 1j * np.sqrt(np.where(under, disc, 0.0)))

    decay: np.ndarray = None  # type: ignore[assignment]
    under: np.ndarray = None  # type: ignore[assignment]
    over: np.ndarray = None  # type: ignore[assignment]
    wd: np.ndarray = None  # type: ignore[assignment]
    wh: np.ndarray = None  # type: ignore[assignment]
    rigid: np.ndarray = None  # type: ignore[assignment]
    all_under: bool = False
    mu: np.ndarray = None  # type: ignore[assignment]

    def grid_table(self, h: float, n: int) -> np.ndarray:
        """``exp(mu_n h j)``, ``mu_n = -a_n + i w_dn``, j = 0..n-1 (under-damped modes; cached).

        Each entry is computed directly (no recurrence), so a uniform grid costs
        one complex product per mode and point instead of exp, cos and sin.
        """
        cache = self.__dict__.setdefault("_tables", {})
        tab = cache.get(h)
        if tab is None or tab.shape[1] < n:
            m = max(n, 256 if tab is None else 2 * tab.shape[1])
            mu = (-self.decay + 1j * self.wd)[:, None]
            tab = np.exp(mu * (h * np.arange(m))[None, :])
            cache[h] = tab
        return tab[:, :n]

    def kernels(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``exp(-a tau) C(tau)`` and ``exp(-a tau) S(tau)``, shape (n, p)."""
        tau = np.asarray(tau, dtype=float)[None, :]
        a = self.decay[:, None]
        if self.all_under:
            wd = self.wd[:, None]
            e = np.exp(-a * tau)
            arg = wd * tau
            return e * np.cos(arg), e * np.sin(arg) / wd
        eC = np.empty((self.omega.size, tau.shape[1]))
        eS = np.empty_like(eC)
        u, o = self.under, self.over
        c = ~(u | o)
        if u.any():
            wd = self.wd[u, None]
            e = np.exp(-a[u] * tau)
            eC[u] = e * np.cos(wd * tau)
            eS[u] = e * np.sin(wd * tau) / wd
        if o.any():
            wh = self.wh[o, None]
            e = np.exp((-a[o] + wh) * tau)
            e2 = np.exp(-2.0 * wh * tau)
            eC[o] = 0.5 * e * (1.0 + e2)
            eS[o] = -0.5 * e * np.expm1(-2.0 * wh * tau) / wh
        if c.any():
            e = np.exp(-a[c] * tau)
            eC[c] = e
            eS[c] = e * tau
        return eC, eS


@dataclass(frozen=True, eq=False)
class LoadForm:
    """Modal load ``a + b tau + d sin(Omega tau + phi)`` on a segment (arrays over modes)."""

    a: np.ndarray
    b: np.ndarray | None = None
    d: np.ndarray | None = None
    Omega: float = 0.0
    phi: float = 0.0


class ClosedFormSegment:
    """Exact modal response of one state over one segment.

    Parameters
    ----------
    dyn : ModalDynamics
    load : LoadForm
    eta0, deta0 : ndarray, shape (n,)
        Modal displacement and velocity at ``tau = 0``.
    """

    __slots__ = ("dyn", "load", "h0", "dh0", "_Hc", "_res", "_A", "_B", "_pcoef")

    def __init__(self, dyn: ModalDynamics, load: LoadForm, eta0: np.ndarray, deta0: np.ndarray) -> None:
        self.dyn = dyn
        self.load = load
        om2 = dyn.omega**2
        self._Hc = None
        self._res = None
        if load.d is not None:
            W = load.Omega
            den = om2 - W**2 + 2j * dyn.xi * dyn.omega * W
            res = (np.abs(den) <= 1e-12 * np.maximum(om2, W**2)) & ~dyn.rigid
            self._res = res if res.any() else None
            safe = np.where(res | dyn.rigid, 1.0, den)
            self._Hc = np.where(dyn.rigid | res, 0.0, 1.0 / safe)
        self._pcoef = None
        p0, dp0 = self._particular_at(0.0)
        self.h0 = eta0 - p0
        self.dh0 = deta0 - dp0
        # under-damped homogeneous part: eta_h = Re(A E), eta_h' = Re(B E), E = exp(mu tau)
        wd = np.where(dyn.under, dyn.wd, 1.0)
        a = dyn.decay
        self._A = np.where(dyn.under, self.h0 - 1j * (a * self.h0 + self.dh0) / wd, 0.0)
        self._B = np.where(dyn.under, self.dh0 - 1j * (-(dyn.omega**2) * self.h0 - a * self.dh0) / wd, 0.0)

    def _particular_coefficients(self) -> np.ndarray:
        """Per-mode coefficients of the particular solution on the basis
        ``1, tau, tau^2, tau^3, Im(z), sin(theta), tau cos(theta)`` (``z = exp(i theta)``,
        ``theta = Omega tau + phi``), complex for the ``Im(z)`` column: shape (n, 7)."""
        if self._pcoef is not None:
            return self._pcoef
        dyn, ld = self.dyn, self.load
        n = dyn.omega.size
        C = np.zeros((n, 7), dtype=complex)
        rig = dyn.rigid
        om = np.where(rig, 1.0, dyn.omega)
        om2 = om**2
        C[:, 0] = np.where(rig, 0.0, ld.a / om2)
        C[:, 2] = np.where(rig, 0.5 * ld.a, 0.0)
        if ld.b is not None:
            C[:, 0] += np.where(rig, 0.0, -2.0 * dyn.xi * ld.b / (om * om2))
            C[:, 1] = np.where(rig, 0.0, ld.b / om2)
            C[:, 3] = np.where(rig, ld.b / 6.0, 0.0)
        if ld.d is not None:
            C[:, 4] = ld.d * self._Hc
            if rig.any():
                C[:, 5] = np.where(rig, -ld.d / ld.Omega**2, 0.0)
            if self._res is not None:
                C[:, 6] = np.where(self._res, -ld.d / (2.0 * om), 0.0)
        self._pcoef = C
        return C

    def _particular_at(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """Per-mode particular part and its derivative at one ``tau``."""
        C = self._particular_coefficients()
        c0, c1, c2, c3 = C[:, 0].real, C[:, 1].real, C[:, 2].real, C[:, 3].real
        val = c0 + tau * (c1 + tau * (c2 + tau * c3))
        der = c1 + tau * (2.0 * c2 + 3.0 * c3 * tau)
        ld = self.load
        if ld.d is not None:
            W = ld.Omega
            th = W * tau + ld.phi
            z = complex(math.cos(th), math.sin(th))
            cz = C[:, 4] * z
            c5, c6 = C[:, 5].real, C[:, 6].real
            val = val + cz.imag + c5 * z.imag + c6 * tau * z.real
            der = der + W * cz.real + W * c5 * z.real + c6 * (z.real - W * tau * z.imag)
        return val, der

    def state_at(self, tau: float) -> tuple[np.ndarray, np.ndarray]:
        """Modal displacement and velocity at one ``tau`` (shape (n,) each)."""
        dyn = self.dyn
        if not dyn.all_under:
            e, d = self.evaluate(np.array([tau]))
            return e[:, 0], d[:, 0]
        E = np.exp(dyn.mu * tau)
        P, dP = self._particular_at(tau)
        return (self._A * E).real + P, (self._B * E).real + dP

    def _particular_grid(self, V: np.ndarray | None, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``V @ P(tau)`` and its derivative (V None: per mode)."""
        C = self._particular_coefficients()
        if V is not None:
            C = V @ C
        t = tau[None, :]
        ld = self.load
        c1 = C[:, 1:2].real
        val = C[:, 0:1].real + c1 * t
        der = np.empty_like(val)
        der[...] = c1
        if np.any(C[:, 2]) or np.any(C[:, 3]):
            val = val + C[:, 2:3].real * t**2 + C[:, 3:4].real * t**3
            der = der + 2.0 * C[:, 2:3].real * t + 3.0 * C[:, 3:4].real * t**2
        if ld.d is not None:
            W = ld.Omega
            theta = W * tau + ld.phi
            z = np.exp(1j * theta)[None, :]
            cz = C[:, 4:5] * z
            val = val + cz.imag
            der = der + W * cz.real
            if np.any(C[:, 5]):
                val = val + C[:, 5:6].real * z.imag
                der = der + W * C[:, 5:6].real * z.real
            if np.any(C[:, 6]):
                val = val + C[:, 6:7].real * t * z.real
                der = der + C[:, 6:7].real * (z.real - W * t * z.imag)
        return val, der

    def projector(self, v: np.ndarray, offset: float = 0.0):
        """Fast scalar ``tau -> (offset + v @ eta(tau), v @ eta'(tau))`` for root finding."""
        dyn = self.dyn
        if not dyn.all_under:
            def general(tau: float) -> tuple[float, float]:
                e, d = self.evaluate(np.array([tau]))
                return offset + float(v @ e[:, 0]), float(v @ d[:, 0])

            return general
        mu = -dyn.decay + 1j * dyn.wd
        vA = v * self._A
        vB = v * self._B
        c = v @ self._particular_coefficients()
        c0, c1, c2, c3 = (float(c[i].real) for i in range(4))
        c4 = complex(c[4])
        c5, c6 = float(c[5].real), float(c[6].real)
        ld = self.load
        W, phi = ld.Omega, ld.phi
        has_sin = ld.d is not None
        exp = np.exp

        def f(tau: float) -> tuple[float, float]:
            E = exp(mu * tau)
            val = offset + (vA @ E).real + c0 + tau * (c1 + tau * (c2 + tau * c3))
            der = (vB @ E).real + c1 + tau * (2.0 * c2 + 3.0 * c3 * tau)
            if has_sin:
                th = W * tau + phi
                z = complex(math.cos(th), math.sin(th))
                cz = c4 * z
                val += cz.imag + c5 * z.imag + c6 * tau * z.real
                der += W * cz.real + W * c5 * z.real + c6 * (z.real - W * tau * z.imag)
            return float(val), float(der)

        return f

    def evaluate_grid(self, tau0: float, h: float, n: int, V: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Response on the uniform grid ``tau0 + h j`` (j < n), optionally projected.

        Returns ``V @ eta`` and ``V @ eta'`` (shape (m, n)), or the modal arrays
        (n_modes, n) when ``V`` is None. Exact, like :meth:`evaluate`.
        """
        dyn = self.dyn
        tau = tau0 + h * np.arange(n)
        P, dP = self._particular_grid(V, tau)
        under = dyn.under
        if under.any():
            R = dyn.grid_table(h, n)
            mu = -dyn.decay + 1j * dyn.wd
            e0 = np.exp(mu * tau0)
            A = self._A * e0
            B = self._B * e0
            if V is None:
                E = R * 1.0
                val = (A[:, None] * E).real
                der = (B[:, None] * E).real
            else:
                val = ((V * A[None, :]) @ R).real
                der = ((V * B[None, :]) @ R).real
        else:
            shape = P.shape
            val = np.zeros(shape)
            der = np.zeros(shape)
        if not dyn.all_under:
            other = ~under
            eC, eS = ModalDynamics(dyn.omega[other], dyn.xi[other]).kernels(tau)
            a = dyn.decay[other][:, None]
            h0 = self.h0[other][:, None]
            dh0 = self.dh0[other][:, None]
            om2 = (dyn.omega[other] ** 2)[:, None]
            eta = (eC + a * eS) * h0 + eS * dh0
            deta = -om2 * eS * h0 + (eC - a * eS) * dh0
            if V is None:
                val[other] += eta
                der[other] += deta
            else:
                val = val + V[:, other] @ eta
                der = der + V[:, other] @ deta
        return val + P, der + dP

    def _particular(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        dyn, ld = self.dyn, self.load
        t = np.asarray(tau, dtype=float)[None, :]
        om = dyn.omega[:, None]
        rig = dyn.rigid[:, None]
        om2 = np.where(rig, 1.0, om**2)
        a = ld.a[:, None]
        P = np.where(rig, 0.5 * a * t**2, a / om2)
        dP = np.where(rig, a * t, 0.0)
        if ld.b is not None:
            b = ld.b[:, None]
            xi = dyn.xi[:, None]
            om_safe = np.where(rig, 1.0, om)
            P = P + np.where(rig, b * t**3 / 6.0, b * (t - 2.0 * xi / om_safe) / om2)
            dP = dP + np.where(rig, 0.5 * b * t**2, b / om2)
        if ld.d is not None:
            d = ld.d[:, None]
            W = ld.Omega
            theta = W * t + ld.phi
            z = np.exp(1j * theta)  # (1, p)
            Hz = self._Hc[:, None] * z
            P = P + d * Hz.imag
            dP = dP + d * W * Hz.real
            if dyn.rigid.any():
                r = dyn.rigid[:, None]
                P = P + np.where(r, -d * np.sin(theta) / W**2, 0.0)
                dP = dP + np.where(r, -d * np.cos(theta) / W, 0.0)
            if self._res is not None:
                r = self._res[:, None]
                w = np.where(rig, 1.0, om)
                P = P + np.where(r, -d * t * np.cos(theta) / (2.0 * w), 0.0)
                dP = dP + np.where(r, -d * np.cos(theta) / (2.0 * w) + 0.5 * d * t * np.sin(theta), 0.0)
        return P, dP

    def evaluate(self, tau: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Modal displacement and velocity at ``tau`` (shape (p,)): two arrays (n, p)."""
        dyn = self.dyn
        eC, eS = dyn.kernels(tau)
        a = dyn.decay[:, None]
        h0 = self.h0[:, None]
        dh0 = self.dh0[:, None]
        om2 = (dyn.omega**2)[:, None]
        eta = (eC + a * eS) * h0 + eS * dh0
        deta = -om2 * eS * h0 + (eC - a * eS) * dh0
        P, dP = self._particular(tau)
        return eta + P, deta + dP

    def acceleration(self, tau: float) -> np.ndarray:
        """Modal acceleration at one ``tau`` from the equation of motion."""
        eta, deta = self.evaluate(np.array([tau]))
        dyn, ld = self.dyn, self.load
        f = ld.a.copy()
        if ld.b is not None:
            f = f + ld.b * tau
        if ld.d is not None:
            f = f + ld.d * np.sin(ld.Omega * tau + ld.phi)
        return f - 2.0 * dyn.decay * deta[:, 0] - dyn.omega**2 * eta[:, 0]

    def force(self, tau: np.ndarray) -> np.ndarray:
        """Modal force ``f_n(tau)``, shape (n, p)."""
        ld = self.load
        t = np.asarray(tau, dtype=float)[None, :]
        f = np.broadcast_to(ld.a[:, None], (ld.a.size, t.shape[1])).copy()
        if ld.b is not None:
            f += ld.b[:, None] * t
        if ld.d is not None:
            f += ld.d[:, None] * np.sin(ld.Omega * t + ld.phi)
        return f
