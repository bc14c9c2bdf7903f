"""Scenarios and independent reference values for the random-vibration tests.

The reference values come from the exact modes (``impactbeam.mode_set``)
and numerical quadrature, not from the solver: the one-sided frequency
response of the N-mode model at a point under base acceleration,
``H(x, f) = sum_n W_n(x) p_n / (omega_n^2 - Omega^2 + 2 i xi omega_n Omega)``
with ``p_n = -int rho A W_n dx``.
"""

from __future__ import annotations

import numpy as np

import impactbeam as ib

G_LEVEL = "0.01 g^2/Hz"
BAND = (10.0, 300.0)
XI = 0.02
MODES = 4


def linear_data(end_time: float = 40.0, seed: int = 7, points=(0.1092, 0.06)) -> dict:
    """The specimen cantilever, no contactor, flat base-acceleration density on BAND."""
    return {
        "beam": {"length": "109.2 mm", "width": "9.93 mm", "height": "3.03 mm", "youngs_modulus": "1834 MPa",
                 "density": "951.98 kg/m^3"},
        "damping": {"free": XI, "contact": XI},
        "excitation": {"kind": "base_acceleration", "shape": "random",
                       "psd": [[f"{BAND[0]} Hz", G_LEVEL], [f"{BAND[1]} Hz", G_LEVEL]], "seed": seed},
        "solver": {"modes": MODES, "end_time": end_time, "basis": "paper"},
        "output": {"points": list(points)},
    }


class LinearReference:
    """Exact-mode frequency response and the variances it gives under the scenario's density."""

    def __init__(self, sc: ib.Scenario) -> None:
        ms = ib.mode_set(sc.beam, (), MODES)
        self.x = np.asarray(sc.output_points)
        self.W = ms.shapes(self.x)  # (n, p)
        self.p = -np.asarray(ms.inertia_integral())
        self.om = ms.omega
        self.psd = sc.excitation.psd

    def H(self, f: np.ndarray) -> np.ndarray:
        """(n_f, n_p) complex deflection per unit base acceleration."""
        Om = 2 * np.pi * np.atleast_1d(f)[:, None]
        return (self.p[None, :] / (self.om[None, :] ** 2 - Om**2 + 2j * XI * self.om[None, :] * Om)) @ self.W

    def variance(self, velocity: bool = False) -> np.ndarray:
        """``int |H|^2 G df`` (times ``(2 pi f)^2`` for the velocity), by adaptive quadrature."""
        from scipy.integrate import quad

        out = []
        for j in range(self.x.size):
            def g(f: float) -> float:
                w = (2 * np.pi * f) ** 2 if velocity else 1.0
                return float(abs(self.H(np.array([f]))[0, j]) ** 2 * self.psd(f)[0] * w)
            peaks = [w / 2 / np.pi for w in self.om if BAND[0] < w / 2 / np.pi < BAND[1]]
            out.append(quad(g, *BAND, points=peaks, limit=500, epsabs=0, epsrel=1e-10)[0])
        return np.array(out)

    def window_std(self, duration: float, window: float, velocity: bool = False) -> np.ndarray:
        """Relative standard deviation of a window's mean square over the random phases.

        The record is ``sum_k A_k cos(omega_k t + theta_k)`` on the lines ``f_k = k / duration``
        with independent uniform phases; over a window of length ``window`` the mean square
        differs from ``sum A_k^2 / 2`` by the window averages of the difference-frequency
        terms, whose variance is ``sum_{k<l} A_k^2 A_l^2 sinc^2((f_l - f_k) window) / 2``.
        """
        k = np.arange(1, int(BAND[1] * duration) + 1)
        f = k / duration
        a2 = 2 * self.psd(f) / duration
        out = []
        for j in range(self.x.size):
            A2 = np.abs(self.H(f)[:, j]) ** 2 * a2 * ((2 * np.pi * f) ** 2 if velocity else 1.0)
            n = 1 << int(np.ceil(np.log2(2 * A2.size)))
            F = np.fft.rfft(A2, n)
            R = np.fft.irfft(F * np.conj(F), n)[1 : A2.size]  # sum_k A_k^2 A_{k+d}^2, d >= 1
            d = np.arange(1, A2.size)
            var = 0.5 * np.sum(np.sinc(d * window / duration) ** 2 * R)
            out.append(np.sqrt(var) / (A2.sum() / 2))
        return np.array(out)
