"""Physical quantities in scenario files: numbers (SI) or strings with units.

A scenario value is either a plain number, taken as SI, or a string with a
unit that :mod:`pint` understands (``"0.229 mm"``, ``"15 ms"``, ``"1834 MPa"``,
``"4030 N/m"``). Two conventions go beyond pint:

* for accelerations, ``g`` means standard gravity, 9.80665 m/s^2
  (``"15 g"``, ``"0.5 g"``), also in acceleration spectral densities
  (``"0.01 g^2/Hz"``); pint's own ``g`` is the gram;
* ``"inf"`` (or ``"infinity"``) is accepted for stiffnesses only, meaning rigid;
* a frequency is cyclic (Hz): an angular frequency is converted as such,
  ``"60 rad/s"`` is 9.549 Hz and ``"60 rpm"`` 1 Hz (pint alone takes the
  radian as dimensionless and would read them as 60 Hz and 6.283 Hz).

NaN is rejected everywhere. Every error is a :class:`~impactbeam.exceptions.ScenarioError`
whose message starts with the dotted key of the field, names the value received
and the unit expected, e.g.::

    excitation.amplitude: "15 kg" is a mass, expected an acceleration (m/s^2)

The pint registry is created on first use (it takes a noticeable fraction of a
second), so importing this module is cheap.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from typing import Any

from .exceptions import ScenarioError

__all__ = [
    "DIMENSIONS",
    "STANDARD_GRAVITY",
    "to_si",
    "unit_scale",
    "scale_decimal",
    "describe_dimension",
    "registry",
    "COMMON_UNITS",
]

#: Standard gravity [m/s^2] (the "g" of accelerations).
STANDARD_GRAVITY = 9.80665


@dataclass(frozen=True)
class _Dimension:
    si_unit: str  # as written for users
    pint_unit: str  # as given to pint
    noun: str  # "an acceleration"


#: The physical dimensions a scenario field can have, with their SI unit.
DIMENSIONS: dict[str, _Dimension] = {
    "length": _Dimension("m", "m", "a length"),
    "stiffness": _Dimension("N/m", "N/m", "a stiffness"),
    "rotational_stiffness": _Dimension("N m/rad", "N*m/rad", "a rotational stiffness"),
    "modulus": _Dimension("Pa", "Pa", "a modulus"),
    "density": _Dimension("kg/m^3", "kg/m^3", "a density"),
    "area": _Dimension("m^2", "m^2", "an area"),
    "second_moment": _Dimension("m^4", "m^4", "a second moment of area"),
    "time": _Dimension("s", "s", "a time"),
    "acceleration": _Dimension("m/s^2", "m/s^2", "an acceleration"),
    "force": _Dimension("N", "N", "a force"),
    "force_per_length": _Dimension("N/m", "N/m", "a force per length"),
    "mass": _Dimension("kg", "kg", "a mass"),
    "frequency": _Dimension("Hz", "Hz", "a frequency"),
    "angle": _Dimension("rad", "rad", "an angle"),
    "rotary_inertia": _Dimension("kg m^2", "kg*m^2", "a rotary inertia"),
    "damping_coefficient": _Dimension("N s/m", "N*s/m", "a damping coefficient"),
    "rate": _Dimension("1/s", "1/s", "a rate (per second)"),
    "stress": _Dimension("Pa", "Pa", "a stress"),
    # one-sided power spectral densities (random loads): the square of the load's unit per hertz
    "acceleration_psd": _Dimension("(m/s^2)^2/Hz", "m**2/s**4/Hz", "an acceleration spectral density"),
    "force_psd": _Dimension("N^2/Hz", "N**2/Hz", "a force spectral density"),
    "force_per_length_psd": _Dimension("(N/m)^2/Hz", "N**2/m**2/Hz", "a spectral density of force per length"),
    "velocity": _Dimension("m/s", "m/s", "a velocity"),
    "angular_velocity": _Dimension("rad/s", "rad/s", "an angular velocity"),
    "dimensionless": _Dimension("", "dimensionless", "a dimensionless number"),
}

_STIFFNESSES = {"stiffness", "rotational_stiffness"}
#: Dimensions in which ``g`` is standard gravity (``"15 g"``, ``"0.01 g^2/Hz"``).
_GRAVITY_DIMENSIONS = {"acceleration", "acceleration_psd"}

# Names for the dimensionality of a string that did not match, for the message.
_KNOWN_DIMENSIONALITIES: tuple[tuple[str, str], ...] = (
    ("m", "a length"),
    ("kg", "a mass"),
    ("s", "a time"),
    ("m^2", "an area"),
    ("m^3", "a volume"),
    ("m^4", "a second moment of area"),
    ("m/s", "a velocity"),
    ("N*s/m", "a damping coefficient"),
    ("m/s^2", "an acceleration"),
    ("m^2/s^3", "an acceleration spectral density ((m/s^2)^2/Hz)"),
    ("N^2/Hz", "a force spectral density"),
    ("N", "a force"),
    ("N/m", "a stiffness or force per length"),
    ("Pa", "a pressure or modulus"),
    ("J", "an energy or moment (N m)"),
    ("kg/m^3", "a density"),
    ("kg/m", "a mass per length"),
    ("Hz", "a frequency"),
    ("W", "a power"),
    ("dimensionless", "a dimensionless number"),
    ("K", "a temperature"),
    ("A", "an electric current"),
    ("V", "a voltage"),
)

_UREG: Any = None
# one number (a decimal point, no separators: "0,229 mm" and "1 000 um" are refused, not read as 0), then the unit
_NUMBER_UNIT = re.compile(
    r"^\s*(?P<number>[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?(?i:inf(?:inity)?|nan))(?![\d.,])"
    r"\s*(?P<unit>\S.*?)\s*$"
)
_GRAVITY_G = re.compile(r"(?<![\w.])g(?![^\W²³]|\.)")  # g alone, or squared with a superscript (g²)


def registry() -> Any:
    """The module's pint ``UnitRegistry``, created on first use."""
    global _UREG
    if _UREG is None:
        import pint

        _UREG = pint.UnitRegistry()
    return _UREG


def scale_decimal(number: str, factor: float) -> float:
    """``float(number) * factor``, rounded once: ``scale_decimal("3.03", 1e-3) == 3.03e-3``.

    The product is formed in decimal arithmetic from the written number and
    the shortest repr of ``factor``, so ``"3.03 mm"`` gives exactly the float
    ``3.03e-3`` (a binary product would be one ulp off).

    Parameters
    ----------
    number : str
        The number as written.
    factor : float
        The SI factor of its unit.

    Returns
    -------
    float
    """
    try:
        return float(Decimal(number.strip()) * Decimal(repr(factor)))
    except (InvalidOperation, ValueError):
        return float(number) * factor


class _UnitProblem(Exception):
    """A conversion problem; the message lacks the key, which the caller adds."""


def describe_dimension(dimension: str) -> str:
    """``"an acceleration (m/s^2)"``: the expected kind of quantity, for messages.

    Parameters
    ----------
    dimension : str
        One of :data:`DIMENSIONS`.

    Returns
    -------
    str
    """
    dim = _dimension(dimension)
    return f"{dim.noun} ({dim.si_unit})" if dim.si_unit else dim.noun


def _dimension(dimension: str) -> _Dimension:
    try:
        return DIMENSIONS[dimension]
    except KeyError:
        raise ValueError(
            f"unknown dimension {dimension!r}; expected one of {', '.join(DIMENSIONS)}"
        ) from None


def _name_of(dimensionality: Any) -> str:
    ureg = registry()
    for unit, noun in _KNOWN_DIMENSIONALITIES:
        if ureg.parse_units(unit).dimensionality == dimensionality:
            return noun
    return f"of dimension {dimensionality}"


#: Dimensions whose SI unit holds an angle (rad), as the power of the radian in it.
_ANGLE_POWER = {"angle": 1, "angular_velocity": 1, "rotational_stiffness": -1}
_PSDS = {"acceleration_psd", "force_psd", "force_per_length_psd"}


def _quantity_to_si(quantity: Any, text: str, dimension: str) -> float:
    """Convert a pint quantity to the SI unit of ``dimension``, the angles in its unit kept.

    pint takes the radian as dimensionless; here an angle counts. A unit's
    angle must be the dimension's (``"0.5 deg"`` is no position ratio, ``"1e6
    cycles"`` no count), except that a cycle is 2 pi rad where frequencies
    meet angles: a frequency per angle of time (:func:`_cyclic_frequency`), an
    angular velocity in hertz (``"1 Hz"`` is 2 pi rad/s), a spectral density
    per angular frequency (``"1 N^2/(rad/s)"`` is 2 pi N^2/Hz); and a
    rotational stiffness may leave its radian out (``"5 N*m"``).
    """
    ureg = registry()
    dim = _dimension(dimension)
    target = ureg.parse_units(dim.pint_unit)
    if quantity.dimensionality != target.dimensionality:
        hint = ""
        if dimension in _GRAVITY_DIMENSIONS and re.search(r"(?<![A-Za-z])mg(?![A-Za-z])", text):
            example = "15 g" if dimension == "acceleration" else "0.01 g^2/Hz"
            hint = f' (g written alone is standard gravity here, "{example}"; "mg" is a milligram)'
        raise _UnitProblem(
            f'"{text}" is {_name_of(quantity.dimensionality)}, expected {describe_dimension(dimension)}{hint}'
        )
    if dimension == "frequency":
        return _cyclic_frequency(quantity, text)
    angle = _root_powers(quantity)[1]
    value = float(quantity.to(target).magnitude)
    wanted = _ANGLE_POWER.get(dimension, 0)
    if angle == wanted or (dimension == "rotational_stiffness" and angle == 0):
        return value
    if dimension == "angular_velocity" and angle == 0 and "hertz" in str(quantity.units):
        return 2.0 * math.pi * value  # cycles per second
    if dimension in _PSDS and angle == -1:
        return 2.0 * math.pi * value  # per rad/s: S(f) = 2 pi S(omega)
    if wanted:
        hint = "; give it in rad/s, deg/s, rpm or Hz (revolutions)" if dimension == "angular_velocity" else ""
        raise _UnitProblem(f'"{text}" has no angle in its unit, expected {describe_dimension(dimension)}{hint}')
    hint = " (a count of cycles is a plain number: 1e6)" if dimension == "dimensionless" and "cycle" in text else ""
    raise _UnitProblem(f'"{text}" has an angle in its unit, expected {describe_dimension(dimension)}{hint}')


def _root_powers(quantity: Any) -> tuple[dict[str, float], float, float]:
    """The quantity in root units: the powers of its units but the radian, the radian's power, the magnitude."""
    root = quantity.to_root_units()
    powers = dict(root.units._units)
    return powers, powers.pop("radian", 0), float(root.magnitude)


def _cyclic_frequency(quantity: Any, text: str) -> float:
    """A frequency in Hz (cycles per second) from a cyclic or an angular quantity.

    pint takes the radian as dimensionless, so it would read ``"60 rad/s"``
    as 60 Hz and ``"60 rpm"`` (a revolution is 2 pi rad) as 2 pi Hz. Here the
    angle in the unit is kept: a unit without an angle (``Hz``, ``1/s``,
    ``1/min``) counts cycles; one with an angle per time (``rad/s``,
    ``deg/s``, ``rpm``, ``turn/s``, ``cycle/s``) is an angular frequency,
    divided by 2 pi rad per cycle. ``"60 rad/s"`` is 9.549 Hz, ``"60 rpm"``
    and ``"1 cycle/s"`` are 1 Hz.
    """
    powers, angle, magnitude = _root_powers(quantity)
    if powers != {"second": -1} or angle not in (0, 1):
        raise _UnitProblem(f'"{text}" is not a frequency (cycles or an angle per time), expected '
                           f"{describe_dimension('frequency')}")
    return magnitude / (2.0 * math.pi) if angle == 1 else magnitude


def _parse_unit(unit: str, dimension: str, shown: str) -> Any:
    """One of ``unit`` as a pint quantity (``g`` = standard gravity for accelerations).

    A unit only: a number or arithmetic in it (``"000 um"``, ``"m + 1 m"``)
    is refused. ``shown`` is the string quoted in error messages.
    """
    ureg = registry()
    expr = _GRAVITY_G.sub("g_0", unit) if dimension in _GRAVITY_DIMENSIONS else unit
    try:
        units = ureg.parse_units(expr)
    except Exception as exc:  # pint raises many types (UndefinedUnitError, tokenize, scaling factor, ...)
        detail = str(exc).strip() or type(exc).__name__
        raise _UnitProblem(
            f'cannot read "{shown}": "{unit}" is not a unit ({detail}); expected one number (a decimal point, '
            f"no separators) and a unit, {describe_dimension(dimension)}"
        ) from None
    quantity = ureg.Quantity(1.0, units)
    if not quantity._is_multiplicative:  # dB, octave, decade, degC: a number in them is not a multiple of a unit
        raise _UnitProblem(
            f'cannot read "{shown}": "{unit}" is a logarithmic or offset unit, not a multiple of one (a value in it '
            f"is not that many units); give the value as a plain number or in a multiplicative unit, "
            f"{describe_dimension(dimension)}"
        )
    return quantity


#: SI factors of the units most scenario files use, so that reading them needs no
#: pint registry (whose import and set-up cost a large part of a second). Every
#: entry is checked against pint in the test suite; anything else goes to pint.
COMMON_UNITS: dict[tuple[str, str], float] = {
    **{(u, "length"): f for u, f in (("m", 1.0), ("mm", 1e-3), ("cm", 1e-2), ("um", 1e-6), ("km", 1e3))},
    **{(u, "time"): f for u, f in (("s", 1.0), ("ms", 1e-3), ("us", 1e-6))},
    **{(u, "modulus"): f for u, f in (("Pa", 1.0), ("kPa", 1e3), ("MPa", 1e6), ("GPa", 1e9))},
    **{(u, "density"): f for u, f in (("kg/m^3", 1.0), ("kg/m**3", 1.0))},
    **{(u, "stiffness"): f for u, f in (("N/m", 1.0), ("kN/m", 1e3), ("N/mm", 1e3), ("MN/m", 1e6))},
    **{(u, "force_per_length"): f for u, f in (("N/m", 1.0), ("kN/m", 1e3), ("N/mm", 1e3))},
    **{(u, "force"): f for u, f in (("N", 1.0), ("kN", 1e3), ("mN", 1e-3))},
    **{(u, "acceleration"): f for u, f in (("m/s^2", 1.0), ("m/s**2", 1.0), ("g", STANDARD_GRAVITY))},
    **{(u, "area"): f for u, f in (("m^2", 1.0), ("mm^2", 1e-6))},
    **{(u, "second_moment"): f for u, f in (("m^4", 1.0),)},
    ("N*m/rad", "rotational_stiffness"): 1.0,
    **{(u, "stress"): f for u, f in (("Pa", 1.0), ("kPa", 1e3), ("MPa", 1e6), ("GPa", 1e9))},
    **{(u, "acceleration_psd"): f for u, f in (("g^2/Hz", STANDARD_GRAVITY**2), ("(m/s^2)^2/Hz", 1.0))},
    ("N^2/Hz", "force_psd"): 1.0,
    **{(u, "frequency"): f for u, f in (("Hz", 1.0), ("kHz", 1e3))},
}
_FACTORS: dict[tuple[str, str], float] = {}


def _unit_factor(unit: str, dimension: str, shown: str) -> float:
    """SI factor of ``unit`` for ``dimension`` (table, then cache, then pint)."""
    key = (unit, dimension)
    hit = COMMON_UNITS.get(key)
    if hit is None:
        hit = _FACTORS.get(key)
    if hit is None:
        hit = _quantity_to_si(_parse_unit(unit, dimension, shown), shown, dimension)
        hit = float(f"{hit:.15g}")  # pint's products leave round-off in decimal factors: "1 mm^4" is 1e-12 m^4
        if len(_FACTORS) < 1024:
            _FACTORS[key] = hit
    return hit


def _convert(value: Any, dimension: str) -> float:
    dim = _dimension(dimension)
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        kind = type(value).__name__
        if isinstance(value, bool):
            kind = "a boolean"
        elif isinstance(value, (list, tuple)):
            kind = "a list"
        elif isinstance(value, dict):
            kind = "a table"
        raise _UnitProblem(
            f"expected a number or a string with units ({dim.si_unit or 'dimensionless'}), "
            f"got {kind} {value!r}"
        )
    if isinstance(value, str):
        text = value.strip()
        low = text.lower()
        if low in {"inf", "+inf", "infinity", "+infinity", "rigid"}:
            if dimension in _STIFFNESSES:
                return math.inf
            raise _UnitProblem(
                f'"{value}" is not allowed here: expected a finite value, {describe_dimension(dimension)}'
            )
        if low in {"nan", "+nan", "-nan"}:
            raise _UnitProblem(f'NaN is not a valid value (expected {describe_dimension(dimension)})')
        try:
            out = float(text)  # a number written as a string: SI
        except ValueError:
            m = _NUMBER_UNIT.match(text)
            if m is None:
                raise _UnitProblem(
                    f'cannot read "{value}": expected one number (a decimal point, no separators) followed by a '
                    f"unit, {describe_dimension(dimension)}"
                ) from None
            # "<number> <unit>": convert the unit alone, multiply in decimal (see scale_decimal)
            unit = m.group("unit")
            if unit.startswith("*"):  # "5*mm"
                unit = unit[1:].lstrip()
            elif unit.startswith("/"):  # "2/s"
                unit = "1" + unit
            factor = _unit_factor(unit, dimension, text)
            number = m.group("number")
            special = number.lower().lstrip("+-")
            if special == "nan":
                out = math.nan
            elif special.startswith("inf"):
                out = float(number)
            else:
                out = scale_decimal(number, factor)
    else:
        out = float(value)
    if math.isnan(out):
        raise _UnitProblem(f"NaN is not a valid value (expected {describe_dimension(dimension)})")
    if math.isinf(out) and dimension not in _STIFFNESSES:
        raise _UnitProblem(f"must be finite, got {value!r} (expected {describe_dimension(dimension)})")
    return out


def to_si(value: Any, dimension: str, key: str) -> float:
    """Return ``value`` in SI units as a float.

    Parameters
    ----------
    value : int, float or str
        A plain number (taken as SI) or a string with a unit, e.g. ``"0.229 mm"``,
        ``"15 g"`` (standard gravity, for accelerations), ``"1834 MPa"``.
    dimension : str
        One of :data:`DIMENSIONS`: ``"length"``, ``"stiffness"`` (N/m),
        ``"rotational_stiffness"`` (N m/rad), ``"modulus"`` (Pa), ``"density"``
        (kg/m^3), ``"area"``, ``"second_moment"``, ``"time"``, ``"acceleration"``,
        ``"force"``, ``"force_per_length"``, ``"stress"`` (Pa), the one-sided
        spectral densities ``"acceleration_psd"`` ((m/s^2)^2/Hz, ``"0.01 g^2/Hz"``),
        ``"force_psd"`` (N^2/Hz), ``"force_per_length_psd"`` ((N/m)^2/Hz), ``"dimensionless"``.
    key : str
        Dotted name of the field, used in error messages.

    Returns
    -------
    float
        The value in the SI unit of ``dimension``; ``inf`` only for stiffnesses
        given as ``inf`` or ``"inf"``.

    Raises
    ------
    ScenarioError
        For NaN, an infinite non-stiffness, an unreadable string or a unit of
        the wrong dimension; ``key`` is set and starts the message.

    Examples
    --------
    >>> to_si("15 g", "acceleration", "excitation.amplitude")
    147.09975
    >>> to_si("0.229 mm", "length", "contactors.0.gap")
    0.000229
    """
    try:
        return _convert(value, dimension)
    except _UnitProblem as exc:
        raise ScenarioError(f"{key}: {exc}", key=key) from None


def unit_scale(unit: str, dimension: str, key: str) -> float:
    """Factor that converts values in ``unit`` to the SI unit of ``dimension``.

    ``unit_scale("ms", "time", k)`` is 1e-3; ``unit_scale("g", "acceleration", k)``
    is 9.80665. Used for column headers such as ``time [ms]``.

    Parameters
    ----------
    unit : str
        A unit, e.g. ``"ms"`` or ``"N/mm"``.
    dimension : str
        One of :data:`DIMENSIONS`.
    key : str
        The field or column named in errors.

    Returns
    -------
    float

    Raises
    ------
    ScenarioError
        An unknown unit, or one of another dimension.
    """
    text = unit.strip()
    try:
        if not text:
            raise _UnitProblem(f"empty unit; expected {describe_dimension(dimension)}")
        out = _unit_factor(text, dimension, text)
    except _UnitProblem as exc:
        raise ScenarioError(f"{key}: {exc}", key=key) from None
    if not (math.isfinite(out) and out != 0.0):
        raise ScenarioError(f'{key}: unit "{unit}" has no finite, non-zero scale', key=key)
    return out
