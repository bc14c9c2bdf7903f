"""Exact modal analysis of a beam in one state (paper section 2, eqs. 2-7 and 12).

The one face of the method's heart: what the solver, the Ritz basis, the
stresses and the drivers need of the modes goes through these names.

* :class:`ModeSet`, :func:`mode_set`: the mass-normalised modes of the beam
  with a set of engaged springs (:mod:`.modeset`), from the exact segments
  of an Euler-Bernoulli beam (:mod:`.euler`) or a Timoshenko beam
  (:mod:`.timoshenko`), every root bracketed by the Wittrick-Williams count
  and refined by Brent's method (:mod:`.roots`);
* :func:`scenario_modes`, :func:`modes`: the free and contact states of a scenario;
* :func:`count_below`: the number of natural frequencies below a frequency;
* :func:`static_state`, :func:`static_moment`: the exact static solver of any
  supported beam (:mod:`.static`); :func:`static_coefficients`: the
  polynomials of the uniform beam with end springs (:mod:`.uniform_static`).

This package imports only :mod:`impactbeam.model` and the foundation modules
(exceptions, validation); nothing of the solver or the layers above it.
"""

from __future__ import annotations

from .modeset import ModeSet, ScenarioModes, count_below, mode_set, modes, scenario_modes
from .static import static_moment, static_state
from .uniform_static import static_coefficients, static_polynomial

__all__ = [
    "ModeSet",
    "ScenarioModes",
    "count_below",
    "mode_set",
    "modes",
    "scenario_modes",
    "static_coefficients",
    "static_moment",
    "static_polynomial",
    "static_state",
]
