"""The live explorer: sliders for a scenario's main parameters, redrawn on change.

``impactbeam explore [SCENARIO] [--port N]`` serves a page on 127.0.0.1 with
sliders for the first contactor's gap, stiffness and position, the pulse
amplitude and duration, the modal damping of both states (paper eq. 9) and
the modes per state. Every change re-simulates (:func:`impactbeam.simulate`)
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

import copy
import html
import io
import math
import time
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._optional import require
from .exceptions import ParameterError
from .result.metrics import METRIC_DISPLAY, contact_intervals
from .scenario import Scenario, parse_scenario

__all__ = ["SLIDERS", "ExplorerModel", "ExplorerPage", "Slider", "build_app", "contact_spans", "curves", "envelope",
           "envelope_index", "serve"]

G = 9.80665  # standard gravity [m/s^2], for base accelerations shown in g


@dataclass(frozen=True)
class Slider:
    """One explorer control.

    Attributes
    ----------
    name : str
        Key of :attr:`ExplorerModel.values`.
    label : str
        Shown beside the slider, with the display unit.
    scale : float
        Display value = SI value * scale.
    step : float
        Slider step, in display units.
    integer : bool
        Whole numbers only (the mode count).
    """

    name: str
    label: str
    scale: float
    step: float
    integer: bool = False


#: The controls, in page order. Display units are those of the paper (mm, ms, g, %).
SLIDERS: tuple[Slider, ...] = (
    Slider("gap", "gap [mm]", 1e3, 0.001),
    Slider("stiffness", "contact stiffness [N/m]", 1.0, 10.0),
    Slider("position_ratio", "contact position a/L [-]", 1.0, 0.001),
    Slider("amplitude", "pulse amplitude", 1.0, 0.1),
    Slider("duration", "pulse duration [ms]", 1e3, 0.1),
    Slider("damping_free", "damping, free state [%]", 100.0, 0.05),
    Slider("damping_contact", "damping, contact state [%]", 100.0, 0.05),
    Slider("modes", "modes per state", 1.0, 1.0, integer=True),
)


def _first_ratio(value: Any) -> float:
    return float(value[0] if isinstance(value, (tuple, list)) else value)


@dataclass
class ExplorerModel:
    """The explorer's state: a base scenario and the slider values (SI) applied to it.

    Parameters
    ----------
    base : Scenario
        The scenario the page starts from.

    Attributes
    ----------
    values : dict of str to float
        Current values in SI units (``modes`` an integer) of the controls
        that apply to ``base`` (no contactor controls without a contactor, no
        pulse controls without a half-sine pulse).
    """

    base: Scenario
    values: dict[str, float] = field(init=False)

    def __post_init__(self) -> None:
        sc = self.base
        v: dict[str, float] = {}
        if sc.contactors:
            c = sc.contactors[0]
            v["gap"] = float(c.gap)
            v["stiffness"] = float(c.stiffness)
            v["position_ratio"] = float(c.position / sc.beam.length)
        ex = sc.excitation
        if ex.kind != "none" and ex.shape == "half_sine":
            v["amplitude"] = float(ex.amplitude)
            v["duration"] = float(ex.duration)
        v["damping_free"] = _first_ratio(sc.damping.free)
        v["damping_contact"] = _first_ratio(sc.damping.contact)
        v["modes"] = int(sc.solver.modes)
        self.values = v

    # ------------------------------------------------------------------ ranges

    def amplitude_unit(self) -> tuple[str, float]:
        """Display unit and scale of the pulse amplitude (g for base accelerations)."""
        kind = self.base.excitation.kind
        return {"base_acceleration": ("g", 1 / G), "point_force": ("N", 1.0), "distributed_force": ("N/m", 1.0)}.get(
            kind, ("", 1.0)
        )

    def bounds(self, name: str) -> tuple[float, float]:
        """SI range of a control around its starting value.

        Parameters
        ----------
        name : str
            A key of :attr:`values`.
        """
        x0 = self.values[name]
        if name == "gap":
            return 0.0, max(4 * x0, 1e-3)
        if name == "position_ratio":
            return 0.05, 1.0
        if name in ("damping_free", "damping_contact"):
            return 0.0, max(0.1, 3 * x0)
        if name == "modes":
            return 1, max(30, int(x0))
        lo, hi = (x0 / 10, x0 * 10) if x0 > 0 else (0.0, 1.0)
        return lo, hi

    # ------------------------------------------------------------------ model

    def scenario(self) -> Scenario:
        """The base scenario with the current values, re-validated.

        Raises
        ------
        ParameterError
            A value the scenario rejects (the message names the key).
        """
        data = copy.deepcopy(self.base.data)
        v = self.values
        if "gap" in v:
            c = data["contactors"][0]
            c.pop("position", None)
            c.update(gap=v["gap"], stiffness=v["stiffness"], position_ratio=v["position_ratio"])
        if "amplitude" in v:
            data["excitation"].update(amplitude=v["amplitude"], duration=v["duration"])
        data.setdefault("damping", {}).update(free=v["damping_free"], contact=v["damping_contact"])
        data.setdefault("solver", {})["modes"] = int(v["modes"])
        return parse_scenario(data, base_dir=self.base.base_dir, source=self.base.source, name=self.base.name)

    def run(self) -> dict[str, Any]:
        """Simulate the current scenario and sample the plotted quantity once.

        Returns
        -------
        dict
            ``time_ms``; ``u_mm``, the metric deflection ``u`` [mm] at the first
            contactor (``-w`` above, ``w`` below) or ``w`` at the first output
            point; ``force_N``, the first contactor's force (zeros without
            one); ``contacts_ms``, its contact intervals (start, end) [ms];
            ``surface_mm``, its surface ``u = -gap`` [mm] (None without one);
            ``metrics`` (:meth:`SimulationResult.metrics`); ``seconds``,
            the wall time of the simulation and its metrics; ``sample_seconds``,
            that of sampling ``u`` and the force on the output grid.

        Notes
        -----
        Only the one plotted point is sampled, once: the force follows from
        the same samples (``k max(-(gap + u), 0)`` while engaged) instead of
        the result's full output grid of every point.
        """
        from .simulation import simulate

        sc = self.scenario()
        t0 = time.perf_counter()
        res = simulate(sc)
        metrics = res.metrics()
        t1 = time.perf_counter()
        t = np.asarray(res.time)
        contacts: list[tuple[float, float]] = []
        if sc.contactors:
            c = sc.contactors[0]
            contacts = [(a * 1e3, min(b, float(t[-1])) * 1e3) for a, b in contact_intervals(res, 0)]
            samples = res.solution.sample(np.array([c.position]), t)
            u = -c.direction * samples.w[:, 0]  # -w above, w below: the opening is gap + u
            engaged = samples.engaged[:, 0]
            force = np.where(engaged, c.stiffness * np.maximum(-(c.gap + u), 0.0), 0.0)
            force[np.isnan(u)] = np.nan
        else:
            u = np.asarray(res.displacement([sc.output_points[0]], t)).reshape(-1)
            force = np.zeros_like(t)
        t2 = time.perf_counter()
        surface = -sc.contactors[0].gap * 1e3 if sc.contactors else None
        return {"time_ms": t * 1e3, "u_mm": u * 1e3, "force_N": force, "metrics": metrics, "contacts_ms": contacts,
                "surface_mm": surface, "seconds": t1 - t0, "sample_seconds": t2 - t1}

    def toml(self) -> str:
        """The current scenario as TOML text (loads back to the same scenario)."""
        return self.scenario().to_toml()


# --------------------------------------------------------------------------- page


def envelope_index(ys: list[np.ndarray], bins: int = 1000) -> np.ndarray:
    """Indices that keep the shape of curves sampled on one grid: each bucket's first, minimum and maximum.

    Parameters
    ----------
    ys : list of ndarray
        Curves of the same length ``n`` on the same grid.
    bins : int
        Number of buckets. A screen-wide plot cannot show more than about one
        point per pixel column; keeping each bucket's extremes keeps every
        peak (the impacts) that plain sub-sampling would cut.

    Returns
    -------
    ndarray of int
        Sorted distinct indices, the first and last sample included: at most
        ``(1 + 2 len(ys)) (bins + 1) + 1`` of them. Curves of up to
        ``3 * bins`` samples keep every index.
    """
    n = ys[0].size
    if n <= 3 * bins:
        return np.arange(n)
    k = n // bins  # samples per bucket; the last bucket takes the remainder
    starts = np.arange(bins) * k
    tail = np.arange(k * bins, n)
    keep = [starts, tail[:1], np.array([n - 1])]
    for y in ys:
        body = y[: k * bins].reshape(bins, k)
        keep += [starts + body.argmin(axis=1), starts + body.argmax(axis=1)]
        if tail.size:
            keep += [tail[[np.argmin(y[tail]), np.argmax(y[tail])]]]
    return np.unique(np.concatenate(keep))


def envelope(t: np.ndarray, y: np.ndarray, bins: int = 1000) -> tuple[np.ndarray, np.ndarray]:
    """Decimate one curve for drawing; see :func:`envelope_index`.

    Parameters
    ----------
    t, y : ndarray
        Times and the values at them.
    bins : int
        Buckets; each keeps its minimum and maximum.
    """
    idx = envelope_index([y], bins)
    return t[idx], y[idx]


def curves(out: dict[str, Any], bins: int = 1000) -> dict[str, np.ndarray]:
    """The plotted columns of a :meth:`ExplorerModel.run` output, decimated on one shared time axis.

    Parameters
    ----------
    out : dict
        From :meth:`ExplorerModel.run`.
    bins : int
        Buckets of :func:`envelope_index`, about one per pixel column.

    Returns
    -------
    dict
        ``t`` [ms], ``u`` [mm] and ``f`` [N] at the samples that
        :func:`envelope_index` keeps for either curve, as float32 (finer than
        the page can show; half the bytes of float64 on the websocket).
    """
    idx = envelope_index([out["u_mm"], out["force_N"]], bins)
    return {k: np.asarray(out[src][idx], dtype=np.float32)
            for k, src in (("t", "time_ms"), ("u", "u_mm"), ("f", "force_N"))}


def padded_range(y: np.ndarray, pad: float = 0.05) -> tuple[float, float]:
    """Axis limits around the finite values of ``y`` with a margin (``(-1, 1)`` without any)."""
    finite = y[np.isfinite(y)]
    if not finite.size:
        return -1.0, 1.0
    lo, hi = float(finite.min()), float(finite.max())
    span = hi - lo if hi > lo else max(abs(hi), 1.0)
    return lo - pad * span, hi + pad * span


def _surface(out: dict[str, Any]) -> list[float]:
    return [] if out["surface_mm"] is None else [out["surface_mm"]]


def contact_spans(out: dict[str, Any], bottom: float, top: float) -> dict[str, list[float]]:
    """The shaded contact intervals of a :meth:`ExplorerModel.run` output: columns of Bokeh quads [ms, mm].

    Parameters
    ----------
    out : dict
        From :meth:`ExplorerModel.run`.
    bottom, top : float, [mm]
        The height of the shading (the response axis' limits).
    """
    spans = out["contacts_ms"]
    return {"left": [a for a, _ in spans], "right": [b for _, b in spans],
            "bottom": [bottom] * len(spans), "top": [top] * len(spans)}


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
    from ._html import table

    rows = [(label, _fmt(out["metrics"].get(key), scale, unit), f"m-{key}")
            for key, label, scale, unit in METRIC_DISPLAY]
    rows.append(("max contact force", f"{float(np.nanmax(out['force_N'], initial=0.0)):.4f} N", "m-max_force"))
    for s in SLIDERS:
        if s.name in model.values:
            unit, scale = model.amplitude_unit() if s.name == "amplitude" else ("", s.scale)
            label = f"pulse amplitude [{unit}]" if s.name == "amplitude" else s.label
            rows.append((label, f"{model.values[s.name] * scale:.6g}", f"v-{s.name}"))
    rows.append(("simulation and metrics", f"{out['seconds'] * 1e3:.1f} ms", "m-sim_ms"))
    rows.append(("sampling", f"{out.get('sample_seconds', 0.0) * 1e3:.1f} ms", "m-sample_ms"))
    if update_ms is not None:
        rows.append(("last update (server)", f"{update_ms:.1f} ms", "m-update_ms"))
    return table(rows, caption="Metrics (u at the first contactor, positive away from it)")


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
        title = "Response u at the first contactor" + (
            " (shaded: in contact; dashed: its surface, u = -gap)" if out["surface_mm"] is not None else "")
        f_u = plotting.figure(title=title, y_axis_label="u [mm]", y_range=self.u_range, **kw)
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
        self.status = models.Div(text="", css_classes=["ib-status"], width=300)
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
        unit, scale = model.amplitude_unit() if s.name == "amplitude" else ("", s.scale)
        label = f"pulse amplitude [{unit}]" if s.name == "amplitude" else s.label
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
            if self.status.text:
                self.status.text = ""
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
        from .simulation import simulate

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


def serve(scenario: Scenario, *, port: int = 5006, show: bool = False) -> Any:
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
    """
    pn = require("panel", "explore", feature="impactbeam explore")
    if not (0 <= int(port) <= 65535):
        raise ParameterError(f"--port: must be 0-65535, got {port}")
    return pn.serve(
        {"/": lambda: build_app(scenario)}, port=int(port), address="127.0.0.1",
        allow_websocket_origin=[f"127.0.0.1:{port}", f"localhost:{port}"], show=show,
        title="impactbeam explorer", threaded=False,
    )
