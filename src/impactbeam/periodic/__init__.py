"""Steady states under harmonic forcing: strobe sampling, bifurcation diagrams, frequency response, impacts.

* :mod:`~impactbeam.periodic.strobe`: Poincaré sampling once per forcing period, period detection;
* :mod:`~impactbeam.periodic.bifurcation`: diagrams over any scenario key, continued up and down;
* :mod:`~impactbeam.periodic.frf`: frequency-response curves and the linear modal FRF;
* :mod:`~impactbeam.periodic.impact_stats`: per-impact statistics over a steady state.
"""
