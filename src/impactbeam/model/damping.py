"""Modal damping of the free and the contact states (paper eq. 9, ``[damping]``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._validation import nonnegative_finite
from ..exceptions import ParameterError

__all__ = ["Damping"]


def _ratios(name: str, value: float | tuple[float, ...]) -> float | tuple[float, ...]:
    if isinstance(value, (list, tuple, np.ndarray)):
        if len(value) == 0:
            raise ParameterError(f"{name}: the list of damping ratios is empty")
        return tuple(nonnegative_finite(f"{name}[{i}]", v) for i, v in enumerate(value))
    return nonnegative_finite(name, value)


@dataclass(frozen=True)
class Damping:
    """Modal damping ratios ``xi_n`` of the free and of the contact states (paper eq. 9).

    Each is one ratio for every mode or a sequence per mode (the last value is
    repeated for modes beyond the sequence). 0 is undamped; >= 1 is allowed
    (critically and over-damped modes are integrated exactly too).

    Parameters
    ----------
    free : float or tuple of float
        Ratios of the free state (``damping.free``).
    contact : float or tuple of float
        Ratios of every contact state (``damping.contact``).
    """

    free: float | tuple[float, ...] = 0.0
    contact: float | tuple[float, ...] = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "free", _ratios("damping.free", self.free))
        object.__setattr__(self, "contact", _ratios("damping.contact", self.contact))

    def ratios(self, engaged: bool, n_modes: int) -> np.ndarray:
        """Damping ratios of ``n_modes`` modes of a free (False) or contact (True) state.

        Parameters
        ----------
        engaged : bool
            Whether any contactor is engaged in the state.
        n_modes : int

        Returns
        -------
        ndarray, (n_modes,)
        """
        spec = self.contact if engaged else self.free
        if isinstance(spec, tuple):
            out = np.full(n_modes, spec[-1], dtype=float)
            k = min(n_modes, len(spec))
            out[:k] = spec[:k]
            return out
        return np.full(n_modes, float(spec))
