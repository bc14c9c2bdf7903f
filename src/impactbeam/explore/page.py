"""The explorer's page: Bokeh sliders, figures and table served by Panel (:mod:`impactbeam.explore`)."""

from __future__ import annotations

import html
import io
import math
import time
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

from .._optional import require
from ..exceptions import ParameterError
from ..result.metrics import METRIC_DISPLAY
from ..scenario import Scenario
from .model import SLIDERS, ExplorerModel, Slider, _surface, contact_spans, curves, padded_range

__all__ = ["ExplorerPage", "build_app", "metrics_html", "serve", "status_html"]


def _fmt(value: Any, scale: float, unit: str) -> str:
    try:
        x = float(value)
    except (TypeError, ValueError):
        return "n/a"
    if not math.isfinite(x):
        return "n/a"
    return (f"{int(x)}" if unit == "" else f"{x * scale:.4f} {unit}").strip()


def metrics_html(model: ExplorerModel, out: dict[str, Any], update_ms: float | None) -> str:
    """The metrics table of the page; every value cell has the id ``m-<key>``."""
    from .._html import table

    rows = [(label, _fmt(out["metrics"].get(key), scale, unit), f"m-{key}")
            for key, label, scale, unit in METRIC_DISPLAY]
    rows.append(("max contact force", f"{float(np.nanmax(out['force_N'], initial=0.0)):.4f} N", "m-max_force"))
    for s in SLIDERS:
        if s.name in model.values:
            scale = model.amplitude_unit()[1] if s.name == "amplitude" else s.scale
            rows.append((model.label(s), f"{model.values[s.name] * scale:.6g}", f"v-{s.name}"))
    rows.append(("simulation and metrics", f"{out['seconds'] * 1e3:.1f} ms", "m-sim_ms"))
    rows.append(("sampling", f"{out.get('sample_seconds', 0.0) * 1e3:.1f} ms", "m-sample_ms"))
    if update_ms is not None:
        rows.append(("last update (server)", f"{update_ms:.1f} ms", "m-update_ms"))
    where = ("u at the first contactor, positive away from it" if model.base.contactors else
             "w at the first output point")
    return table(rows, caption=f"Metrics ({where})")


def status_html(out: dict[str, Any]) -> str:
    """The line under the sliders: what the run warned of (empty without a warning)."""
    return "".join(f"<p><b>Warning:</b> {html.escape(text)}</p>" for text in out["warnings"])


class ExplorerPage:
    """One browser session's page: sliders, figures, metrics table and save button.

    Parameters
    ----------
    scenario : Scenario
        The scenario the page starts from.

    Attributes
    ----------
    model : ExplorerModel
        The current values and their simulation.
    source : bokeh.models.ColumnDataSource
        The plotted columns ``t``, ``u``, ``f`` (:func:`curves`), replaced on
        every change.
    contacts : bokeh.models.ColumnDataSource
        The shaded contact intervals (:func:`contact_spans`).
    surface : bokeh.models.Span
        The first contactor's surface, ``u = -gap`` (hidden without one).
    force_line : bokeh.models.GlyphRenderer
        The contact force, a solid line.
    sliders : dict of str to bokeh.models.Slider
        The controls by :attr:`Slider.name`.
    table : bokeh.models.Div
        The metrics table (:func:`metrics_html`).
    prepared : set of tuple
        The sets of values :meth:`prepare_modes` has run.
    layout : panel.Row
        The page, for :func:`panel.serve`.

    Notes
    -----
    The controls, figures and table are Bokeh models, and a slider's
    ``value_throttled`` (sent once per key press or at the end of a drag) is
    watched with a Bokeh callback: it runs while the server applies the
    change, so the update leaves before the server acknowledges the change.
    Panel lays the page out, serves it and provides the download button; its
    own widgets would add a 50 ms debounce and a scheduling round before the
    callback. A change re-simulates (:meth:`ExplorerModel.run`), decimates
    the curves once, and sends the new columns, the two y ranges (computed
    here, so the page does not auto-range and send them back) and the table
    in one websocket message (:func:`panel.io.unlocked`).
    """

    def __init__(self, scenario: Scenario) -> None:
        pn = require("panel", "explore", feature="impactbeam explore")
        plotting = require("bokeh.plotting", "explore", feature="impactbeam explore")
        models = require("bokeh.models", "explore", feature="impactbeam explore")

        self.model = ExplorerModel(scenario)
        out = self.model.run()
        c = curves(out)
        self.source = models.ColumnDataSource(c)
        t_end = float(out["time_ms"][-1])
        self.x_range = models.Range1d(0.0, t_end, reset_start=0.0, reset_end=t_end)
        u_lo, u_hi = padded_range(np.append(c["u"], _surface(out)))  # the curve and the surface
        self.u_range = models.Range1d(u_lo, u_hi)
        self.f_range = models.Range1d(*padded_range(c["f"]))
        self.contacts = models.ColumnDataSource(contact_spans(out, u_lo, u_hi))
        kw = {"height": 260, "sizing_mode": "stretch_width", "tools": "pan,wheel_zoom,box_zoom,reset,save",
              "x_range": self.x_range, "x_axis_label": "time [ms]", "min_border_left": 70}
        title = ("Response u at the first contactor (shaded: in contact; dashed: its surface, u = -gap)"
                 if out["surface_mm"] is not None else "Deflection w at the first output point")
        f_u = plotting.figure(title=title, y_axis_label="u [mm]" if scenario.contactors else "w [mm]",
                              y_range=self.u_range, **kw)
        f_u.quad(left="left", right="right", bottom="bottom", top="top", source=self.contacts, fill_color="#000000",
                 fill_alpha=0.12, line_alpha=0.0)
        self.surface = models.Span(location=out["surface_mm"] or 0.0, dimension="width", line_color="#555555",
                                   line_dash="dashed", line_width=1, visible=out["surface_mm"] is not None)
        f_u.add_layout(self.surface)
        f_u.line("t", "u", source=self.source, line_width=1.5, color="#0072B2")
        f_f = plotting.figure(title="Contact force", y_axis_label="force [N]", y_range=self.f_range, **kw)
        self.force_line = f_f.line("t", "f", source=self.source, line_width=1.5, color="#D55E00")
        self.table = models.Div(text=metrics_html(self.model, out, None), css_classes=["ib-metrics"],
                                sizing_mode="stretch_width")
        self.status = models.Div(text=status_html(out), css_classes=["ib-status"], width=300)
        self.sliders = {s.name: self._slider(models, s) for s in SLIDERS if s.name in self.model.values}
        self.prepared: set[tuple[Any, ...]] = set()  # mode counts prepared by prepare_modes
        style = "color" if "color" in pn.widgets.FileDownload.param else "button_type"  # renamed in Panel 1.9
        save = pn.widgets.FileDownload(
            callback=lambda: io.BytesIO(self.model.toml().encode()),
            filename=f"{scenario.name}-explored.toml",
            label="Save scenario as TOML",
            css_classes=["ib-save"],
            **{style: "primary"},
        )
        title = f"## impactbeam explorer: {scenario.description or scenario.name}"
        controls = pn.Column(*self.sliders.values(), save, self.status, width=320)
        self.layout = pn.Row(controls, pn.Column(pn.pane.Markdown(title), f_u, f_f, self.table,
                                                 sizing_mode="stretch_width"),
                             sizing_mode="stretch_width")

    def _slider(self, models: Any, s: Slider) -> Any:
        """The Bokeh slider of one control, in display units, watching ``value_throttled``."""
        model = self.model
        scale = model.amplitude_unit()[1] if s.name == "amplitude" else s.scale
        label = model.label(s)
        lo, hi = model.bounds(s.name)
        if s.integer:
            w = models.Slider(title=label, start=int(lo), end=int(hi), value=int(model.values[s.name]), step=1,
                              format="0")
        else:
            step = s.step if s.name != "amplitude" else max(abs(model.values[s.name] * scale) / 100, 1e-6)
            decimals = max(0, -math.floor(math.log10(step)))
            w = models.Slider(title=label, start=lo * scale, end=hi * scale, value=model.values[s.name] * scale,
                              step=step, format="0" + ("." + "0" * decimals if decimals else ""))
        w.css_classes = [f"ib-{s.name}"]
        w.sizing_mode = "stretch_width"
        w.on_change("value_throttled", lambda attr, old, new: self.set_value(s.name, new))
        return w

    def set_value(self, name: str, shown: float) -> bool:
        """Apply a control's new value (in display units): re-simulate and redraw.

        Parameters
        ----------
        name : str
            The control (:attr:`Slider.name`).
        shown : float
            Its value as the slider shows it (mm, ms, g, %, ...).

        Returns
        -------
        bool
            False when the scenario rejects the value: the old one is kept and
            the reason is shown under the sliders.
        """
        from panel.io import unlocked

        t0 = time.perf_counter()
        s = next(x for x in SLIDERS if x.name == name)
        scale = self.model.amplitude_unit()[1] if name == "amplitude" else s.scale
        old = self.model.values[name]
        self.model.values[name] = int(shown) if s.integer else float(shown) / scale
        try:
            out = self.model.run()
        except ParameterError as exc:
            self.model.values[name] = old
            self.status.text = f"<b>Not applied:</b> {html.escape(str(exc))}"
            self.sliders[name].value = int(old) if s.integer else old * scale  # back to the value in force
            return False
        c = curves(out)
        u_lo, u_hi = padded_range(np.append(c["u"], _surface(out)))
        f_lo, f_hi = padded_range(c["f"])
        with unlocked():  # one message for the whole change
            self.source.data = c
            self.contacts.data = contact_spans(out, u_lo, u_hi)
            if out["surface_mm"] is not None:
                self.surface.location = out["surface_mm"]
            self.u_range.update(start=u_lo, end=u_hi, reset_start=u_lo, reset_end=u_hi)
            self.f_range.update(start=f_lo, end=f_hi, reset_start=f_lo, reset_end=f_hi)
            self.table.text = metrics_html(self.model, out, (time.perf_counter() - t0) * 1e3)
            said = status_html(out)
            if self.status.text != said:
                self.status.text = said
        if name == "modes":
            self._schedule_neighbours()
        return True

    def _schedule_neighbours(self) -> None:
        """Prepare the mode counts one step away, each in its own later tick of the server."""
        doc = self.table.document
        if doc is None or doc.session_context is None:
            return
        n = int(self.model.values["modes"])
        lo, hi = self.model.bounds("modes")
        for count in (n + 1, n - 1):
            if lo <= count <= hi:
                doc.add_timeout_callback(lambda count=count: self.prepare_modes(count), 0)

    def prepare_modes(self, count: int) -> bool:
        """Run the current scenario with ``count`` modes once, so that its mode sets are cached.

        The first run at a new number of modes computes the modes of every
        contact state (about 35 ms at 30 modes, against 2 ms for a run that
        finds them cached); the page does it for the counts next to the
        current one after each change of the modes slider, between the
        user's changes, so that stepping through the counts finds them ready.

        Parameters
        ----------
        count : int
            Number of modes per state.

        Returns
        -------
        bool
            True if it ran, False if these modes were prepared already or the
            scenario rejects them.
        """
        from ..simulation import simulate

        values = dict(self.model.values, modes=int(count))
        key = tuple(sorted(values.items()))
        if key in self.prepared:
            return False
        self.prepared.add(key)
        probe = ExplorerModel(self.model.base)
        probe.values = values
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # the run the user asks for reports them
                simulate(probe.scenario())
        except ParameterError:
            return False
        return True


def build_app(scenario: Scenario) -> Any:
    """The explorer page for ``scenario`` as a Panel layout (needs the ``explore`` extra).

    Parameters
    ----------
    scenario : Scenario
        The starting point of the sliders.
    """
    return ExplorerPage(scenario).layout


def serve(scenario: Scenario, *, port: int = 5006, show: bool = False,
          announce: Callable[[str], None] | None = None) -> Any:
    """Serve the explorer on ``http://127.0.0.1:port`` until interrupted (blocks).

    Each browser session gets its own page built by :func:`build_app`.

    Parameters
    ----------
    scenario : Scenario
        The starting point of the sliders.
    port : int
        Port on 127.0.0.1 (0: any free port).
    show : bool
        Open a browser.
    announce : callable, optional
        ``announce(text)`` with the address, once the scenario has run (a
        scenario that cannot run is refused before anything is served).
    """
    pn = require("panel", "explore", feature="impactbeam explore")
    if not (0 <= int(port) <= 65535):
        raise ParameterError(f"--port: must be 0-65535, got {port}")
    ExplorerModel(scenario).run()  # a scenario that cannot run is refused here, not on every page load
    if announce is not None:
        announce(f"impactbeam explorer on http://127.0.0.1:{port}/ (Ctrl-C to stop)")
    return pn.serve(
        {"/": lambda: build_app(scenario)}, port=int(port), address="127.0.0.1",
        allow_websocket_origin=[f"127.0.0.1:{port}", f"localhost:{port}"], show=show,
        title="impactbeam explorer", threaded=False,
    )
