"""Damping of the beam (``[damping]``): per-state modal ratios, free-mode damping or Rayleigh damping.

Three models, as the tools users come from write them:

* ``"modal"`` (default, the paper's eq. 9): each state damps its own modes,
  with the ratios ``free`` in the free state and ``contact`` in every state
  with a contactor engaged;
* ``"free_modes"``: the free state's modal ratios ``free`` define one damping
  matrix ``C = M Phi diag(2 xi omega) Phi^T M`` (``Phi`` the free state's
  modes), kept unchanged in every contact state (code_aster's and every FE
  tool's modal damping; a contact state's modes do not diagonalise it);
* ``"rayleigh"``: ``C = alpha M + beta K`` of each state (``K`` with the
  engaged contact springs), so each state's modes keep exactly the ratios
  ``alpha / (2 omega) + beta omega / 2``.

Contactor dashpots (``contactors.N.damping``) add to any of these in the
states where their contactor is engaged.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from .._validation import choice, nonnegative_finite
from ..exceptions import ParameterError

__all__ = ["Damping", "DAMPING_MODELS"]

DampingModel = Literal["modal", "free_modes", "rayleigh"]
#: The damping models of ``damping.model``.
DAMPING_MODELS: tuple[str, ...] = ("modal", "free_modes", "rayleigh")
#: The keys each model reads (any other is refused by name).
MODEL_KEYS: dict[str, tuple[str, ...]] = {
    "modal": ("free", "contact"),
    "free_modes": ("free",),
    "rayleigh": ("alpha", "beta"),
}


#: Largest damping ratio: the decay rates ``zeta omega`` of retained modes (up to ~1e57 rad/s, the
#: scenario checks) are squared in the closed form, finite up to ~1e77 as the load frequencies' are
#: (:data:`~impactbeam.model.loading.PULSE_OMEGA_LIMIT`); a mode 1e10 times critically damped is frozen
#: anyway (its slow root is omega / 2 zeta). Measured: 1e20 runs Case 3 in 0.8 s, 1e300 did not end.
RATIO_LIMIT = 1e10


def _ratio(name: str, value: float) -> float:
    out = nonnegative_finite(name, value)
    if out > RATIO_LIMIT:
        raise ParameterError(f"{name}: a damping ratio of {out:g} is above {RATIO_LIMIT:.0e} (a mode that damped is "
                             "frozen, and its decay rate would overflow); check the value")
    return out


def _ratios(name: str, value: float | tuple[float, ...]) -> float | tuple[float, ...]:
    if isinstance(value, (list, tuple, np.ndarray)):
        if len(value) == 0:
            raise ParameterError(f"{name}: the list of damping ratios is empty")
        return tuple(_ratio(f"{name}[{i}]", v) for i, v in enumerate(value))
    return _ratio(name, value)


def _spread(spec: float | tuple[float, ...], n_modes: int) -> np.ndarray:
    if isinstance(spec, tuple):
        out = np.full(n_modes, spec[-1], dtype=float)
        k = min(n_modes, len(spec))
        out[:k] = spec[:k]
        return out
    return np.full(n_modes, float(spec))


@dataclass(frozen=True)
class Damping:
    """Damping of the beam in every state (module docstring).

    Ratios are one value for every mode or a sequence per mode (the last value
    is repeated for modes beyond the sequence). 0 is undamped; >= 1 is allowed
    (critically and over-damped modes are integrated exactly too).

    Parameters
    ----------
    free : float or tuple of float
        Ratios of the free state (``damping.free``): models ``"modal"`` and ``"free_modes"``.
    contact : float or tuple of float
        Ratios of every contact state (``damping.contact``): model ``"modal"`` only.
    model : {"modal", "free_modes", "rayleigh"}
        ``damping.model``.
    alpha : float, [1/s]
        Mass-proportional coefficient of ``"rayleigh"``.
    beta : float, [s]
        Stiffness-proportional coefficient of ``"rayleigh"``.
    """

    free: float | tuple[float, ...] = 0.0
    contact: float | tuple[float, ...] = 0.0
    model: DampingModel = "modal"
    alpha: float = 0.0
    beta: float = 0.0

    def __post_init__(self) -> None:
        choice("damping.model", self.model, DAMPING_MODELS)
        object.__setattr__(self, "free", _ratios("damping.free", self.free))
        object.__setattr__(self, "contact", _ratios("damping.contact", self.contact))
        object.__setattr__(self, "alpha", nonnegative_finite("damping.alpha", self.alpha))
        object.__setattr__(self, "beta", nonnegative_finite("damping.beta", self.beta))
        defaults = {"free": 0.0, "contact": 0.0, "alpha": 0.0, "beta": 0.0}
        for key, zero in defaults.items():
            if key not in MODEL_KEYS[self.model] and getattr(self, key) != zero:
                uses = " and ".join(MODEL_KEYS[self.model])
                raise ParameterError(
                    f'damping.{key}: not used by damping.model = "{self.model}" (which reads {uses}); '
                    f"remove it or choose another model"
                )

    @property
    def proportional(self) -> bool:
        """Whether every state's own modes diagonalise the beam's damping (not ``"free_modes"``)."""
        return self.model != "free_modes"

    def ratios(self, engaged: bool, n_modes: int) -> np.ndarray:
        """Damping ratios of ``n_modes`` modes of a free (False) or contact (True) state.

        For ``"free_modes"`` these are the ratios of the free state's modes
        (the contact states' damping is that matrix, not ratios); Rayleigh
        damping has no ratios independent of the frequencies
        (:meth:`decay_rates`).

        Parameters
        ----------
        engaged : bool
            Whether any contactor is engaged in the state.
        n_modes : int

        Returns
        -------
        ndarray, (n_modes,)
        """
        if self.model == "rayleigh":
            raise ParameterError('damping.model = "rayleigh" has no fixed ratios; use decay_rates(omega)')
        return _spread(self.contact if engaged and self.model == "modal" else self.free, n_modes)

    def decay_rates(self, engaged: bool, omega: np.ndarray) -> np.ndarray:
        """``a_n = xi_n omega_n`` [1/s] of a state's modes when its modes diagonalise the damping.

        ``"modal"``: the state's ratios times its frequencies; ``"rayleigh"``:
        ``alpha / 2 + beta omega^2 / 2`` (a rigid-body mode keeps ``alpha / 2``);
        ``"free_modes"``: the free state only (``engaged`` False).

        Parameters
        ----------
        engaged : bool
            Whether any contactor is engaged in the state.
        omega : ndarray, (n,), [rad/s]
            The state's natural frequencies.

        Returns
        -------
        ndarray, (n,), [1/s]
        """
        omega = np.asarray(omega, dtype=float)
        if self.model == "rayleigh":
            return 0.5 * self.alpha + 0.5 * self.beta * omega**2
        if engaged and self.model == "free_modes":
            raise ParameterError('damping.model = "free_modes": a contact state has a damping matrix, not rates')
        return self.ratios(engaged, omega.size) * omega
