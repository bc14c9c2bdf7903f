"""The live explorer: sliders for a scenario's main parameters, redrawn on change.

``impactbeam explore [SCENARIO] [--port N]`` serves a page on 127.0.0.1 with
sliders for the first contactor's gap, stiffness and position, the pulse
amplitude and duration, the modal damping of both states (paper eq. 9; when
the scenario gives one ratio per state) and the modes per state; a slider
writes its key only once moved, and the run's warnings show under the
sliders. Every change re-simulates (:func:`impactbeam.simulate`)
and redraws the response ``u`` at the first contactor (the metrics'
quantity) with the contactor's surface and the contact intervals shaded,
the contact force and the metrics table; a button downloads the scenario as
TOML. The figures, sliders and table are Bokeh models updated in place
(:class:`ExplorerPage`): one websocket message per change, the curves
decimated to about one point per pixel column with the extrema kept. A
slider step of Case 3 is redrawn 40-60 ms after the key press on 2 cores
(``benchmarks/bench_explore.py``).

The browser draws the page from the server's websocket: a page saved, or a
screenshot taken by a headless browser, without that live connection shows
empty panels. For a static figure of a run use ``impactbeam simulate
SCENARIO --plot FILE`` or :func:`impactbeam.plot.plot_result`.

:class:`ExplorerModel` has no web dependency (the tests check it against
:func:`impactbeam.simulate`); Panel is needed by :class:`ExplorerPage`,
:func:`build_app` and :func:`serve` only (the ``explore`` extra).
"""

from __future__ import annotations

from .model import SLIDERS, ExplorerModel, Slider, contact_spans, curves, envelope, envelope_index
from .page import ExplorerPage, build_app, serve

__all__ = ["SLIDERS", "ExplorerModel", "ExplorerPage", "Slider", "build_app", "contact_spans", "curves", "envelope",
           "envelope_index", "serve"]
