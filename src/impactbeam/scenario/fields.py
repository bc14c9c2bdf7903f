"""Readers of single scenario values: numbers with units, positions on the beam, choices.

Each turns a raw value into SI and checks it, raising a ScenarioError whose
message starts with the value's dotted key.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from typing import Any

from .._validation import choice, nonnegative_finite, positive_finite
from ..exceptions import ParameterError, ScenarioError
from ..units import to_si
from .schema import describe_value, _join

__all__ = []


@contextmanager
def _relabel(key: str, rename: tuple[tuple[str, str], ...] = ()) -> Iterator[None]:
    """Turn a ParameterError from a data class into a ScenarioError led by a dotted key.

    ``rename`` maps message prefixes of the data class (``"contactor."``) to
    the scenario's dotted prefix (``"contactors.0."``). A message that does
    not start with a key gets ``key`` in front.
    """
    try:
        yield
    except ScenarioError:
        raise
    except ParameterError as exc:
        msg = str(exc)
        for old, new in rename:
            if msg.startswith(old):
                msg = new + msg[len(old):]
                break
        head, sep, rest = msg.partition(": ")
        if sep and " " not in head:
            head = re.sub(r"\[(\d+)\]", r".\1", head)
            raise ScenarioError(f"{head}: {rest}", key=head) from None
        raise ScenarioError(f"{key}: {msg}", key=key) from None


def _positive(table: Mapping[str, Any], prefix: str, name: str, dimension: str) -> float:
    key = _join(prefix, name)
    with _relabel(key):
        return positive_finite(key, to_si(table[name], dimension, key))


def _nonnegative(key: str, value: Any, dimension: str) -> float:
    with _relabel(key):
        return nonnegative_finite(key, to_si(value, dimension, key))


def _required(table: Mapping[str, Any], prefix: str, name: str, why: str = "") -> None:
    if name not in table:
        key = _join(prefix, name)
        raise ScenarioError(f"{key}: required{why}", key=key)


def _choice(key: str, value: Any, allowed: tuple[str, ...]) -> str:
    with _relabel(key):
        return choice(key, value, allowed)


def _string(key: str, value: Any) -> str:
    if not isinstance(value, str):
        raise ScenarioError(f"{key}: expected a string, got {describe_value(value)}", key=key)
    return value


def _integer(key: str, value: Any) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ScenarioError(f"{key}: expected an integer, got {describe_value(value)}", key=key)
    if isinstance(value, float) and not (math.isfinite(value) and value.is_integer()):
        raise ScenarioError(f"{key}: expected an integer, got {value!r}", key=key)
    return int(value)


def _fmt_m(x: float) -> str:
    return f"{x:g} m"


def _on_beam(key: str, position: float, length: float) -> float:
    """Check that ``position`` [m] lies on a beam of ``length``; round-off at the ends is accepted."""
    tol = 1e-12 * length
    if not (-tol <= position <= length + tol):
        raise ScenarioError(
            f"{key}: {_fmt_m(position)} is off the beam (length {_fmt_m(length)})", key=key
        )
    return min(max(position, 0.0), length)


def _ratio(key: str, value: Any) -> float:
    r = to_si(value, "dimensionless", key)
    if not 0.0 <= r <= 1.0:
        raise ScenarioError(f"{key}: must be between 0 and 1 (a fraction of the beam length), got {r!r}", key=key)
    return r


def _position(table: Mapping[str, Any], prefix: str, length: float, *, required: bool) -> float | None:
    """``position`` or ``position_ratio`` (exactly one when required) as metres on the beam."""
    has_pos, has_ratio = "position" in table, "position_ratio" in table
    if has_pos and has_ratio:
        key = _join(prefix, "position")
        raise ScenarioError(f"{key}: give either {key} or {key}_ratio, not both", key=key)
    if has_ratio:
        key = _join(prefix, "position_ratio")
        return _on_beam(key, _ratio(key, table["position_ratio"]) * length, length)
    if has_pos:
        key = _join(prefix, "position")
        return _on_beam(key, to_si(table["position"], "length", key), length)
    if required:
        raise ScenarioError(
            f"{_join(prefix, 'position')}: required (or position_ratio, a fraction of the length)",
            key=_join(prefix, "position"),
        )
    return None
