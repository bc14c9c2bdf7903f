"""Least-squares fits of scenario parameters to a measured deflection history.

The paper (section 4.2) closes its comparison by hand: "with k being 7000 N/m
and increasing the pulse by 20 %, the amplitude difference is about 6 %".
:func:`fit` does this systematically: chosen scenario parameters, named by
their dotted paths (``contactors.0.stiffness``, ``excitation.scale``,
``damping.free``, ``beam.youngs_modulus``), are adjusted by lmfit so that the
simulated deflection at the measured times matches the record in the least
squares sense, within bounds, with standard errors and confidence intervals.
"""

from __future__ import annotations

from .least_squares import fit
from .parameters import current_value, parse_bounds
from .result import FitResult

__all__ = ["FitResult", "fit", "current_value", "parse_bounds"]
