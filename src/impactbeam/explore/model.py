"""The explorer's state and what it draws, without any web dependency (:mod:`impactbeam.explore`)."""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._warnings import WarningLog
from ..result.metrics import contact_intervals
from ..scenario import Scenario, parse_scenario
from ..units import STANDARD_GRAVITY

__all__ = ["SLIDERS", "ExplorerModel", "Slider", "contact_spans", "curves", "envelope", "envelope_index",
           "padded_range"]

G = STANDARD_GRAVITY  # [m/s^2], for base accelerations shown in g


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
        pulse controls without a half-sine pulse, no damping controls unless
        ``damping.model = "modal"`` with one ratio per state: per-mode ratios,
        free-mode and Rayleigh damping are kept as the scenario gives them).
        Only a value moved from its start is written into the scenario.
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
        d = sc.damping
        if d.model == "modal" and not isinstance(d.free, tuple) and not isinstance(d.contact, tuple):
            v["damping_free"] = float(d.free)
            v["damping_contact"] = float(d.contact)
        v["modes"] = int(sc.solver.modes)
        self.values = v
        self._start = dict(v)

    # ------------------------------------------------------------------ ranges

    def amplitude_unit(self) -> tuple[str, float]:
        """Display unit and scale of the pulse amplitude (g for base accelerations)."""
        kind = self.base.excitation.kind
        return {"base_acceleration": ("g", 1 / G), "point_force": ("N", 1.0), "distributed_force": ("N/m", 1.0)}.get(
            kind, ("", 1.0)
        )

    def label(self, slider: Slider) -> str:
        """The label of a control with its display unit (the amplitude's says ``excitation.scale`` when not 1).

        Parameters
        ----------
        slider : Slider
            One of :data:`SLIDERS`.
        """
        if slider.name != "amplitude":
            return slider.label
        scale = self.base.excitation.scale
        times = "" if scale == 1.0 else f", times excitation.scale = {scale:g}"
        return f"pulse amplitude [{self.amplitude_unit()[0]}{times}]"

    def bounds(self, name: str) -> tuple[float, float]:
        """SI range of a control around its starting value.

        Parameters
        ----------
        name : str
            A key of :attr:`values`.
        """
        x0 = self._start[name]
        if name == "gap":
            return 0.0, max(4 * x0, 1e-3)
        if name == "position_ratio":
            return min(0.05, x0), 1.0
        if name in ("damping_free", "damping_contact"):
            return 0.0, max(0.1, 3 * x0)
        if name == "modes":
            return 1, max(30, int(x0))
        if x0 > 0:
            return x0 / 10, x0 * 10
        if x0 < 0:  # a load pointing the other way keeps its sign
            return x0 * 10, x0 / 10
        return 0.0, 1.0

    # ------------------------------------------------------------------ model

    def scenario(self) -> Scenario:
        """The base scenario with the current values, re-validated.

        Raises
        ------
        ParameterError
            A value the scenario rejects (the message names the key).
        """
        data = copy.deepcopy(self.base.data)
        moved = {k: x for k, x in self.values.items() if x != self._start[k]}
        where = {"gap": ("contactors", 0, "gap"), "stiffness": ("contactors", 0, "stiffness"),
                 "position_ratio": ("contactors", 0, "position_ratio"), "amplitude": ("excitation", "amplitude"),
                 "duration": ("excitation", "duration"), "damping_free": ("damping", "free"),
                 "damping_contact": ("damping", "contact"), "modes": ("solver", "modes")}
        for name, value in moved.items():
            *path, key = where[name]
            node = data
            for part in path:
                node = node.setdefault(part, {}) if isinstance(part, str) else node[part]
            if name == "position_ratio":
                node.pop("position", None)
            node[key] = int(value) if name == "modes" else value
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
            ``metrics`` (:meth:`SimulationResult.metrics`); ``warnings``, what
            the run and its metrics warned of (as ``impactbeam simulate``
            prints it: a run stopped early, not converged, ...); ``seconds``,
            the wall time of the simulation and its metrics; ``sample_seconds``,
            that of sampling ``u`` and the force on the output grid.

        Notes
        -----
        Only the one plotted point is sampled, once: the force follows from
        the same samples (:meth:`~impactbeam.model.beam.Contactor.force`,
        ``max(k d + c d', 0)`` while engaged, with the dashpot a restitution
        stands for) instead of the result's full output grid of every point.
        """
        from ..simulation import simulate

        sc = self.scenario()
        t0 = time.perf_counter()
        with WarningLog() as log:
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
            force = c.force(samples.w[:, 0], samples.w_t[:, 0], float(res.solution.dashpots[0]))
            force = np.where(samples.engaged[:, 0], force, 0.0)
            force[np.isnan(u)] = np.nan
        else:
            u = np.asarray(res.displacement([sc.output_points[0]], t)).reshape(-1)
            force = np.zeros_like(t)
        t2 = time.perf_counter()
        surface = -sc.contactors[0].gap * 1e3 if sc.contactors else None
        return {"time_ms": t * 1e3, "u_mm": u * 1e3, "force_N": force, "metrics": metrics, "contacts_ms": contacts,
                "surface_mm": surface, "warnings": log.messages, "seconds": t1 - t0, "sample_seconds": t2 - t1}

    def toml(self) -> str:
        """The current scenario as TOML text (loads back to the same scenario)."""
        return self.scenario().to_toml()


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


