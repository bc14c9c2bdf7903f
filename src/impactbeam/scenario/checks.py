"""Scenario checks beyond single values: extreme magnitudes and inputs that need a word.

Two kinds of check, both run by :func:`impactbeam.scenario.parse_scenario`:

* :func:`check_magnitudes` (before the data classes are built) refuses values
  whose derived quantities would overflow or underflow in the modal analysis,
  naming the key the user wrote (``beam.height``, not the derived
  ``beam.second_moment``);
* :func:`warn_numeric_strings` emits an
  :class:`~impactbeam.exceptions.ImpactBeamWarning` for a number written as
  a string without a unit (``"109.2"``), taken as SI (the unit from
  :func:`~impactbeam.scenario.schema.path_dimension`).

The checks of the validated scenario (``warn_unusual``) are in :mod:`.core`.

The limits and why
------------------
The mode solver forms ``beta^4 = rho A omega^2 / (E I)`` and the solver
squares frequencies (``omega^2``) and products of the beam's section
properties, so the derived quantities ``A``, ``I``, ``E I``, ``rho A`` and the
beam's frequency scale ``omega_0 = sqrt(E I / (rho A)) / L^2`` [rad/s] must
stay within 10^+-150, whose squares (10^+-300) are still normal doubles
(max ~1.8e308, min normal ~2.2e-308). A contactor's stiffness relative to the
beam, ``kappa = k L^3 / (E I)``, is limited to 10^+-15: above 1e15 the
spring is rigid to within double round-off (1/kappa < 10 eps), below 1e-15
it changes nothing at that precision; either way the contact state's modes
cannot be computed meaningfully (use ``stiffness = "inf"`` for a rigid prop,
or remove the contactor).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from typing import Any

from .._warnings import emit_user_level_warning
from ..exceptions import ScenarioError
from ..units import DIMENSIONS, to_si
from .schema import path_dimension

__all__ = ["DERIVED_LIMIT", "STIFFNESS_RATIO_LIMIT", "check_magnitudes", "warn_numeric_strings"]

#: Derived quantities (A, I, E I, rho A, omega_0) must lie in [1/limit, limit] (SI).
DERIVED_LIMIT = 1e150
#: k L^3 / (E I) of a contactor must lie in [1/limit, limit] (or k = inf).
STIFFNESS_RATIO_LIMIT = 1e15

def _log10(raw: Mapping[str, Any], key: str, dimension: str) -> float | None:
    """log10 of the SI value at dotted ``key`` of ``raw``; None if absent, unreadable or not positive finite."""
    node: Any = raw
    for part in key.split("."):
        if not isinstance(node, Mapping) or part not in node:
            return None
        node = node[part]
    try:
        x = to_si(node, dimension, key)
    except ScenarioError:
        return None  # the ordinary parse reports it
    if not (isinstance(x, float) and math.isfinite(x) and x > 0.0):
        return None
    return math.log10(x)


def check_magnitudes(raw: Mapping[str, Any]) -> None:
    """Refuse values whose derived quantities overflow or underflow (see the module notes).

    Raises
    ------
    ScenarioError
        Naming the key the user wrote, the derived quantity and its magnitude.
    """
    beam = raw.get("beam")
    if not isinstance(beam, Mapping):
        return
    lim = math.log10(DERIVED_LIMIT)
    logs = {
        "beam.length": _log10(raw, "beam.length", "length"),
        "beam.youngs_modulus": _log10(raw, "beam.youngs_modulus", "modulus"),
        "beam.density": _log10(raw, "beam.density", "density"),
    }
    if "width" in beam or "height" in beam:
        w, h = _log10(raw, "beam.width", "length"), _log10(raw, "beam.height", "length")
        if w is None or h is None:
            return
        section = {"beam.width": w, "beam.height": h}
        log_a = w + h
        log_i = w + 3 * h - math.log10(12.0)
        i_terms = {"beam.width": w, "beam.height": h}
    else:
        a, i = _log10(raw, "beam.area", "area"), _log10(raw, "beam.second_moment", "second_moment")
        if a is None or i is None:
            return
        section = {"beam.area": a, "beam.second_moment": i}
        log_a, log_i = a, i
        i_terms = {"beam.second_moment": i}
    if any(v is None for v in logs.values()):
        return
    L, E, rho = logs["beam.length"], logs["beam.youngs_modulus"], logs["beam.density"]  # type: ignore[assignment]
    remedy = "check the value and its unit"
    checks = (
        ("an area A", log_a, {k: v for k, v in section.items() if k != "beam.second_moment"}),
        ("a second moment I", log_i, i_terms),
        ("a bending stiffness E I", E + log_i, {"beam.youngs_modulus": E, **i_terms}),
        ("a mass per length rho A", rho + log_a, {"beam.density": rho, **section}),
        ("a frequency scale sqrt(E I / rho A) / L^2 [rad/s]", 0.5 * (E + log_i - rho - log_a) - 2 * L,
         {"beam.length": -2 * L, "beam.youngs_modulus": 0.5 * E, "beam.density": -0.5 * rho,
          **{k: 0.5 * v for k, v in section.items()}}),
    )
    for what, value, terms in checks:
        if abs(value) > lim:
            # terms are signed contributions: pick the biggest in the direction of the excess
            _refuse_contribution(what, value, terms, raw, remedy)
    log_ei = E + log_i
    for i, c in enumerate(raw.get("contactors") or []):
        key = f"contactors.{i}.stiffness"
        if not isinstance(c, Mapping) or "stiffness" not in c:
            continue
        try:
            k = to_si(c["stiffness"], "stiffness", key)
        except ScenarioError:
            continue
        if not (math.isfinite(k) and k > 0):
            continue
        kappa = math.log10(k) + 3 * L - log_ei
        if abs(kappa) > math.log10(STIFFNESS_RATIO_LIMIT):
            hint = ('use stiffness = "inf" for a rigid prop' if kappa > 0
                    else "the contactor has no effect at double precision: remove it")
            raise ScenarioError(
                f"{key}: {k:g} N/m is ~1e{kappa:.0f} times the beam's bending stiffness E I / L^3 "
                f"(allowed: 1e-{math.log10(STIFFNESS_RATIO_LIMIT):.0f} to 1e{math.log10(STIFFNESS_RATIO_LIMIT):.0f}); {hint}",
                key=key,
            )


def _refuse_contribution(what: str, value: float, terms: dict[str, float], raw: Mapping[str, Any], remedy: str) -> None:
    sign = 1.0 if value > 0 else -1.0
    key = max(terms, key=lambda k: sign * terms[k])
    node: Any = raw
    for part in key.split("."):
        node = node[part]
    lim = math.log10(DERIVED_LIMIT)
    raise ScenarioError(
        f"{key}: {node!r} gives {what} of ~1e{value:.0f}, outside what the modal analysis can "
        f"represent (1e-{lim:.0f} to 1e{lim:.0f} in SI); {remedy}",
        key=key,
    )


def _walk(node: Any, prefix: str = "") -> Iterable[tuple[str, Any]]:
    if isinstance(node, Mapping):
        for k, v in node.items():
            yield from _walk(v, f"{prefix}.{k}" if prefix else str(k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from _walk(v, f"{prefix}.{i}")
    else:
        yield prefix, node


def _is_plain_number(text: str) -> bool:
    try:
        x = float(text)
    except ValueError:
        return False
    return math.isfinite(x)


def _si_unit(key: str, raw: Mapping[str, Any]) -> str | None:
    """The SI unit a unit-less number at ``key`` is read in; None for pure numbers and words."""
    excitation = raw.get("excitation")
    kind = excitation.get("kind") if isinstance(excitation, Mapping) else None
    preload = raw.get("preload")
    preload_kind = preload.get("kind") if isinstance(preload, Mapping) else None
    try:
        dimension = path_dimension(key, kind if isinstance(kind, str) else None,
                                   preload_kind if isinstance(preload_kind, str) else None)
    except ScenarioError:
        return None
    if dimension is None and key == "excitation.amplitude":
        return "SI (m/s^2, N or N/m by excitation.kind)"
    if dimension in (None, "integer", "dimensionless"):
        return None
    return DIMENSIONS[dimension].si_unit


def warn_numeric_strings(raw: Mapping[str, Any]) -> None:
    """Warn for each physical quantity written as a string with no unit (``"109.2"``).

    Decision (issue: a numeric string was silently taken as SI): such a value
    is still accepted as SI, as a plain number is, because a quoted number is
    legal TOML and sweeps and command-line overrides produce them; but it is
    most often a unit left out by mistake (``"109.2"`` meant as mm), so it is
    reported with the key and the SI unit assumed.
    """
    for key, value in _walk(raw):
        if not isinstance(value, str) or not _is_plain_number(value.strip()):
            continue
        unit = _si_unit(key, raw)
        if unit is None:
            continue
        emit_user_level_warning(
            f'{key}: "{value}" is a number written as a string without a unit; it is taken as SI ({unit}). '
            f"Write it as a number ({value.strip()}) or with its unit (e.g. \"{value.strip()} mm\")"
        )
