"""Private validation helpers: one clear message naming the parameter."""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any

from .exceptions import ParameterError


def _as_float(name: str, value: Any) -> float:
    if isinstance(value, bool):
        raise ParameterError(f"{name}: expected a number, got {value!r}")
    try:
        out = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: expected a number, got {value!r}") from None
    if math.isnan(out):
        raise ParameterError(f"{name}: expected a number, got NaN")
    return out


def positive_finite(name: str, value: Any) -> float:
    """Return ``value`` as a float, requiring 0 < value < inf."""
    out = _as_float(name, value)
    if not (out > 0.0 and math.isfinite(out)):
        raise ParameterError(f"{name}: must be positive and finite, got {out!r}")
    return out


def nonnegative_finite(name: str, value: Any) -> float:
    """Return ``value`` as a float, requiring 0 <= value < inf."""
    out = _as_float(name, value)
    if not (out >= 0.0 and math.isfinite(out)):
        raise ParameterError(f"{name}: must be zero or positive and finite, got {out!r}")
    return out


def finite(name: str, value: Any) -> float:
    """Return ``value`` as a float, requiring a finite number."""
    out = _as_float(name, value)
    if not math.isfinite(out):
        raise ParameterError(f"{name}: must be finite, got {out!r}")
    return out


def stiffness(name: str, value: Any) -> float:
    """Return a spring stiffness: 0 (free) .. inf (rigid); NaN and negatives rejected.

    The string ``"inf"`` is accepted for a rigid spring.
    """
    if isinstance(value, str) and value.strip().lower() in {"inf", "infinity", "rigid"}:
        return math.inf
    out = _as_float(name, value)
    if out < 0.0:
        raise ParameterError(f"{name}: must be >= 0 (0 = free, inf = rigid), got {out!r}")
    return out


def choice(name: str, value: Any, allowed: Iterable[str]) -> str:
    """Return ``value`` if it is one of ``allowed``; the message lists them."""
    allowed = tuple(allowed)
    if not isinstance(value, str) or value not in allowed:
        raise ParameterError(
            f"{name}: must be one of {', '.join(repr(a) for a in allowed)}, got {value!r}"
        )
    return value
