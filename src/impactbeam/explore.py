"""The live explorer: sliders for a scenario's main parameters, redrawn on change.

``impactbeam explore [SCENARIO] [--port N]`` serves a page on 127.0.0.1 with
sliders for the gap, contact stiffness and position of the first contactor,
the pulse amplitude and duration, the modal damping of the free and contact
states (paper eq. 9) and the number of modes per state. Every change
re-simulates the scenario with :func:`impactbeam.simulate` and redraws the
response ``u`` at the first contactor (the quantity of the metrics), the
contact force, and the metrics table, with the time the update took. A
button downloads the current scenario as TOML.

Panel (on the Bokeh server) is used: the figures are Bokeh plots whose data
sources are replaced in place, so an update sends only the new arrays over
the open websocket; with the compiled event loop a Case 3 update takes a few
milliseconds of simulation and a few tens of milliseconds in all.

The model part (:class:`ExplorerModel`) has no web dependency and is what
the tests check against :func:`impactbeam.simulate`; Panel is needed only
by :func:`build_app` and :func:`serve` (the ``explore`` extra).
"""

from __future__ import annotations

import copy
import io
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._optional import require
from .exceptions import ParameterError
from .metrics import METRIC_DISPLAY
from .scenario import Scenario, parse_scenario

__all__ = ["SLIDERS", "ExplorerModel", "Slider", "build_app", "serve"]

G = 9.80665  # standard gravity [m/s^2], for base accelerations shown in g


@dataclass(frozen=True)
class Slider:
    """One explorer control: ``name`` (key of :attr:`ExplorerModel.values`), label, display scale."""

    name: str
    label: str
    scale: float  # display value = SI value * scale
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
        """SI range of a control around its starting value."""
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
        """Simulate the current scenario.

        Returns
        -------
        dict
            ``time_ms``; ``u_mm``, the metric deflection ``u`` [mm] at the first
            contactor (``-w`` above, ``w`` below) or ``w`` at the first output
            point; ``force_N``, the first contactor's force (zeros without
            one); ``metrics`` (:meth:`SimulationResult.metrics`); ``seconds``,
            the wall time of the simulation.
        """
        from .solver import simulate

        sc = self.scenario()
        t0 = time.perf_counter()
        res = simulate(sc)
        seconds = time.perf_counter() - t0
        t = np.asarray(res.time)
        if sc.contactors:
            c = sc.contactors[0]
            sign = -1.0 if c.side == "above" else 1.0
            x = c.position
        else:
            sign, x = 1.0, sc.output_points[0]
        u = sign * np.asarray(res.displacement([x], t)).reshape(-1)
        force = getattr(res, "contact_force", None)
        force = np.asarray(force)[:, 0] if force is not None and np.ndim(force) == 2 and np.shape(force)[1] else np.zeros_like(t)
        return {"time_ms": t * 1e3, "u_mm": u * 1e3, "force_N": force, "metrics": res.metrics(), "seconds": seconds}

    def toml(self) -> str:
        """The current scenario as TOML text (loads back to the same scenario)."""
        import tomli_w

        from .scenario import _normalise

        return tomli_w.dumps(_normalise(self.scenario().data))


# --------------------------------------------------------------------------- page


def envelope(t: np.ndarray, y: np.ndarray, bins: int = 1500) -> tuple[np.ndarray, np.ndarray]:
    """Decimate a curve for drawing: the first, minimum and maximum sample of each of ``bins`` buckets.

    A screen-wide plot cannot show more than about one point per pixel
    column; keeping each bucket's extremes keeps every peak (the impacts) that
    plain sub-sampling would cut. Curves of up to ``3 * bins`` samples are
    returned unchanged.
    """
    n = t.size
    if n <= 3 * bins:
        return t, y
    k = n // bins  # samples per bucket; the last bucket takes the remainder
    body = y[: k * bins].reshape(bins, k)
    starts = np.arange(bins) * k
    tail = np.arange(k * bins, n)
    keep = [starts, starts + body.argmin(axis=1), starts + body.argmax(axis=1), tail[:1], [n - 1]]
    if tail.size:
        keep += [[tail[np.argmin(y[tail])]], [tail[np.argmax(y[tail])]]]
    idx = np.unique(np.concatenate([np.asarray(i, dtype=int) for i in keep]))
    return t[idx], y[idx]


def _curves(out: dict[str, Any]) -> dict[str, np.ndarray]:
    tu, u = envelope(out["time_ms"], out["u_mm"])
    tf, f = envelope(out["time_ms"], out["force_N"])
    return {"tu": tu, "u": u, "tf": tf, "f": f}



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
    rows.append(("max contact force", f"{float(np.max(out['force_N'], initial=0.0)):.4f} N", "m-max_force"))
    for s in SLIDERS:
        if s.name in model.values:
            unit, scale = model.amplitude_unit() if s.name == "amplitude" else ("", s.scale)
            label = f"pulse amplitude [{unit}]" if s.name == "amplitude" else s.label
            rows.append((label, f"{model.values[s.name] * scale:.6g}", f"v-{s.name}"))
    rows.append(("simulation", f"{out['seconds'] * 1e3:.1f} ms", "m-sim_ms"))
    if update_ms is not None:
        rows.append(("last update (server)", f"{update_ms:.1f} ms", "m-update_ms"))
    return table(rows, caption="Metrics (u at the first contactor, positive away from it)")


def build_app(scenario: Scenario) -> Any:
    """The explorer page for ``scenario`` as a Panel layout (needs the ``explore`` extra)."""
    pn = require("panel", "explore", feature="impactbeam explore")
    plotting = require("bokeh.plotting", "explore", feature="impactbeam explore")
    models = require("bokeh.models", "explore", feature="impactbeam explore")

    model = ExplorerModel(scenario)
    out = model.run()
    c = _curves(out)
    src_u = models.ColumnDataSource({"t": c["tu"], "y": c["u"]})
    src_f = models.ColumnDataSource({"t": c["tf"], "y": c["f"]})
    kw = {"height": 260, "sizing_mode": "stretch_width", "tools": "pan,wheel_zoom,box_zoom,reset,save"}
    f_u = plotting.figure(title="Response u at the first contactor", x_axis_label="time [ms]", y_axis_label="u [mm]", **kw)
    f_u.line("t", "y", source=src_u, line_width=1.5, color="#0072B2")
    f_f = plotting.figure(title="Contact force", x_axis_label="time [ms]", y_axis_label="force [N]", x_range=f_u.x_range, **kw)
    f_f.line("t", "y", source=src_f, line_width=1.5, color="#D55E00", line_dash="dashed")
    table_pane = pn.pane.HTML(metrics_html(model, out, None), css_classes=["ib-metrics"], sizing_mode="stretch_width")
    status = pn.pane.Markdown("", css_classes=["ib-status"])

    widgets = []
    for s in SLIDERS:
        if s.name not in model.values:
            continue
        scale = model.amplitude_unit()[1] if s.name == "amplitude" else s.scale
        label = f"pulse amplitude [{model.amplitude_unit()[0]}]" if s.name == "amplitude" else s.label
        lo, hi = model.bounds(s.name)
        if s.integer:
            w = pn.widgets.IntSlider(name=label, start=int(lo), end=int(hi), value=int(model.values[s.name]), step=1)
        else:
            step = s.step if s.name != "amplitude" else max(abs(model.values[s.name] * scale) / 100, 1e-6)
            decimals = max(0, -math.floor(math.log10(step)))
            w = pn.widgets.FloatSlider(
                name=label, start=lo * scale, end=hi * scale, value=model.values[s.name] * scale, step=step,
                format="0" + ("." + "0" * decimals if decimals else ""),
            )
        w.css_classes = [f"ib-{s.name}"]

        def on_change(event: Any, s: Slider = s, scale: float = scale) -> None:
            t0 = time.perf_counter()
            old = model.values[s.name]
            model.values[s.name] = int(event.new) if s.integer else float(event.new) / scale
            try:
                new = model.run()
            except ParameterError as exc:
                model.values[s.name] = old
                status.object = f"**Not applied:** {exc}"
                return
            c = _curves(new)
            src_u.data = {"t": c["tu"], "y": c["u"]}
            src_f.data = {"t": c["tf"], "y": c["f"]}
            table_pane.object = metrics_html(model, new, (time.perf_counter() - t0) * 1e3)
            status.object = ""

        w.param.watch(on_change, "value_throttled")
        widgets.append(w)

    save = pn.widgets.FileDownload(
        callback=lambda: io.BytesIO(model.toml().encode()),
        filename=f"{scenario.name}-explored.toml",
        label="Save scenario as TOML",
        button_type="primary",
        css_classes=["ib-save"],
    )
    title = f"## impactbeam explorer: {scenario.description or scenario.name}"
    controls = pn.Column(*widgets, save, status, width=320)
    return pn.Row(controls, pn.Column(pn.pane.Markdown(title), pn.pane.Bokeh(f_u), pn.pane.Bokeh(f_f), table_pane,
                                      sizing_mode="stretch_width"), sizing_mode="stretch_width")


def serve(scenario: Scenario, *, port: int = 5006, show: bool = False) -> Any:
    """Serve the explorer on ``http://127.0.0.1:port`` until interrupted (blocks).

    Each browser session gets its own page built by :func:`build_app`.
    """
    pn = require("panel", "explore", feature="impactbeam explore")
    if not (0 <= int(port) <= 65535):
        raise ParameterError(f"--port: must be 0-65535, got {port}")
    return pn.serve(
        {"/": lambda: build_app(scenario)}, port=int(port), address="127.0.0.1",
        allow_websocket_origin=[f"127.0.0.1:{port}", f"localhost:{port}"], show=show,
        title="impactbeam explorer", threaded=False,
    )
