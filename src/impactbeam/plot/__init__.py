"""Matplotlib figures, sized and styled for journals: every figure the package draws.

Every function takes an optional ``ax=`` (or ``axes=``), never touches the
global pyplot state when it creates its own figure (a bare
:class:`matplotlib.figure.Figure` on the Agg canvas, whatever the user's
backend), labels its axes with units and returns a :class:`PlotHandles`,
which Jupyter displays as the figure. Functions given ``path`` write the
figure atomically; the format follows the suffix (``.png``, ``.pdf``,
``.svg`` ...).

Conventions, for figures that go into a paper:

* widths of one journal column (``size="single"``, 3.5 in) or two
  (``"double"``, 7 in), fonts of 8 pt (9 pt titles) at print size;
* time in ms and deflections in mm, as in the metrics summaries;
* the response as ``u``, the quantity of the metrics (``u = -w`` for a
  contactor above the beam, ``w`` below: positive away from the contactor),
  or ``w`` or both, always labelled;
* series that differ in line style as well as colour (the Okabe-Ito
  palette), so they survive grey-scale printing and colour-blindness;
* legends outside the data area of figures drawn here.

The modules: :mod:`.response` (results), :mod:`.metrics` (the metrics marked on a
response), :mod:`.study` (parameter and
convergence studies), :mod:`.modes` (mode shapes), :mod:`.sweep` (sweep
results), :mod:`.periodic` (bifurcation diagrams, frequency response, maps),
:mod:`.style` (the journal style), :mod:`.figure` (figure objects, saving).
Importing this package does not import matplotlib; drawing does. Nothing
below the drivers imports it: the core never needs matplotlib.
"""

from __future__ import annotations

from .figure import PlotHandles, save_figure
from .metrics import plot_metrics
from .modes import plot_modes
from .periodic import plot_bifurcation, plot_frequency_response, plot_map
from .random import plot_impact_histogram, plot_input_psd, plot_rainflow_histogram, plot_random, plot_response_psd
from .response import plot_excitation, plot_response, plot_result, surface_distance
from .study import plot_convergence, plot_convergence_study, plot_parameter_study
from .style import SERIES_STYLES, STYLE, figure_size, rc_context
from .sweep import plot_sweep, select_cases

__all__ = [
    "PlotHandles",
    "SERIES_STYLES",
    "STYLE",
    "figure_size",
    "plot_bifurcation",
    "plot_convergence",
    "plot_convergence_study",
    "plot_excitation",
    "plot_frequency_response",
    "plot_impact_histogram",
    "plot_input_psd",
    "plot_map",
    "plot_metrics",
    "plot_modes",
    "plot_parameter_study",
    "plot_rainflow_histogram",
    "plot_random",
    "plot_response_psd",
    "plot_response",
    "plot_result",
    "plot_sweep",
    "rc_context",
    "save_figure",
    "select_cases",
    "surface_distance",
]
