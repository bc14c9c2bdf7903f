"""A simulation against a measured deflection: the model driven by the measured base acceleration, the paper's
section-4 quantities side by side, and their overlay plot.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal
import numpy as np

from .._optional import require
from ..result.metrics import response_point
from ..exceptions import ParameterError, SimulationError
if TYPE_CHECKING:
    from ..model.loading import Excitation
    from ..result import SimulationResult
    from ..scenario import Scenario
from .inversion import _crossings
from .records import Record, _require

__all__ = [
    "Comparison",
    "FEATURES",
    "compare",
    "drive_with_trace",
    "prepare_run",
    "record_point",
    "response_features",
]


def drive_with_trace(scenario: Scenario, trace: Record, *, hold: Literal["constant", "linear"] = "linear") -> Scenario:
    """The scenario driven by a measured base-acceleration trace (paper Fig. 3).

    Parameters
    ----------
    scenario : Scenario
    trace : Record
        Base acceleration [m/s^2] against time [s] on the clock of the
        deflection record (the model starts at t = 0; samples before 0 are
        ignored by the solver).
    hold : {"constant", "linear"}
        Between samples: constant steps (the paper's discretisation) or
        linear (first-order hold). The solver integrates either exactly.

    Returns
    -------
    Scenario
        A copy whose ``excitation`` is
        ``Excitation(kind="base_acceleration", shape="table", times=trace.time,
        values=trace.values, hold=hold, start=0, scale=s)``, ``s`` being the
        scenario's ``excitation.scale`` (1 by default). Its ``data`` still
        describes the original excitation: :func:`impactbeam.fit.fit` keeps
        the trace separately and writes it next to a fitted scenario.
    """
    from ..model.loading import Excitation

    _require(trace, "acceleration", "a base-acceleration excitation")
    if hold not in ("constant", "linear"):
        raise ParameterError(f"hold: must be 'constant' or 'linear', got {hold!r}")
    scale = scenario.excitation.scale if scenario.excitation.kind != "none" else 1.0
    exc = Excitation(
        kind="base_acceleration", shape="table", times=trace.time, values=trace.values, hold=hold,
        start=0.0, scale=scale,
    )
    return dataclasses.replace(scenario, excitation=exc)


def record_point(scenario: Scenario, point: float | None = None) -> float:
    """Where a deflection record is taken [m]: ``point``, else the first contactor, else the first output point.

    Parameters
    ----------
    scenario : Scenario
    point : float, optional, [m]
        Where the record was taken, if known.
    """
    if point is not None:
        x = float(point)
        if not 0 <= x <= scenario.beam.length * (1 + 1e-12):
            raise ParameterError(f"point: {x:g} m is off the beam (length {scenario.beam.length:g} m)")
        return x
    if scenario.contactors:
        return float(scenario.contactors[0].position)
    return float(scenario.output_points[0])


#: The section-4 comparison quantities: key -> (label, unit scale, unit).
FEATURES: dict[str, tuple[str, float, str]] = {
    "first_peak": ("first major peak", 1e3, "mm"),
    "first_peak_time": ("  at time", 1e3, "ms"),
    "first_negative_peak": ("first negative peak", 1e3, "mm"),
    "first_negative_peak_time": ("  at time", 1e3, "ms"),
    "first_contact_duration": ("first contact duration", 1e3, "ms"),
    "negative_period": ("period around first negative peak", 1e3, "ms"),
}


def _vertex(t: np.ndarray, u: np.ndarray, k: int, *, drop: float = 0.05, max_side: int = 25) -> tuple[float, float]:
    """Maximum of ``u`` near sample ``k``: least-squares parabola through the samples around ``k``
    that lie within ``drop * |u[k]|`` of it (at most ``max_side`` on each side), which averages
    the noise of a measured peak; the sample itself when no parabola fits."""
    peak = u[k]
    thr = peak - drop * abs(peak)
    i = k
    while i > 0 and k - i < max_side and u[i - 1] >= thr:
        i -= 1
    j = k
    while j < u.size - 1 and j - k < max_side and u[j + 1] >= thr:
        j += 1
    if k - i < 1 or j - k < 1:
        i, j = max(k - 1, 0), min(k + 1, u.size - 1)
    if j - i < 2:
        return float(t[k]), float(peak)
    x = t[i : j + 1] - t[k]
    a, b, c = np.polyfit(x, u[i : j + 1], 2)
    if not a < 0:
        return float(t[k]), float(peak)
    xv = -b / (2 * a)
    if not x[0] <= xv <= x[-1]:
        return float(t[k]), float(peak)
    return float(t[k] + xv), float(c - b * b / (4 * a))


def response_features(
    time: np.ndarray, u: np.ndarray, *, gap: float | None = None, major: float = 0.8
) -> dict[str, float | None]:
    """The section-4 quantities of a response ``u`` (positive away from the contactor).

    Parameters
    ----------
    time : ndarray, [s]
        Uniform sample times.
    u : ndarray, [m]
        ``u = -w`` for a contactor above, ``w`` otherwise.
    gap : float or None, [m]
        Contactor clearance; contact is ``u < -gap``. None without contactor.
    major : float
        A peak is "major" when it reaches this fraction of ``max u``.

    Returns
    -------
    dict
        ``first_peak`` [m] and ``first_peak_time`` [s]: the first local
        maximum reaching ``major * max(u)`` (paper 4.1/4.2 "first major
        peak"); ``first_negative_peak`` and its time: the minimum of the first
        excursion below zero after it ("first negative peak", "minimum
        deflection for the first contact state"); ``negative_period`` [s]: the
        time between the zero crossings bounding that excursion (the paper's
        "time period in the first negative peak", 4.1);
        ``first_contact_duration`` [s]: the first interval after the major
        peak with ``u < -gap`` (4.2). Extremes are refined by a parabola
        through three samples, crossings by linear interpolation. ``None``
        where undefined.
    """
    t = np.asarray(time, dtype=float)
    u = np.asarray(u, dtype=float)
    out: dict[str, float | None] = {k: None for k in FEATURES}
    umax = float(np.max(u))
    if not umax > 0:
        return out
    i0 = int(np.argmax(u >= major * umax))
    after = np.nonzero(u[i0:] < 0)[0]
    i_end = i0 + int(after[0]) if after.size else u.size
    kp = i0 + int(np.argmax(u[i0:i_end]))
    out["first_peak_time"], out["first_peak"] = _vertex(t, u, kp)
    if not after.size:
        return out
    n0 = i_end
    back = np.nonzero(u[n0:] >= 0)[0]
    n1 = n0 + int(back[0]) if back.size else u.size
    kn = n0 + int(np.argmin(u[n0:n1]))
    tv, mv = _vertex(t, -u, kn)
    out["first_negative_peak_time"], out["first_negative_peak"] = tv, -mv
    if back.size and n0 > 0:
        down = t[n0 - 1] + (t[n0] - t[n0 - 1]) * u[n0 - 1] / (u[n0 - 1] - u[n0])
        up = t[n1 - 1] + (t[n1] - t[n1 - 1]) * u[n1 - 1] / (u[n1 - 1] - u[n1])
        out["negative_period"] = float(up - down)
    if gap is not None:
        s = -u - gap
        for a, b, i, j in _crossings(t, s):
            if t[i] >= out["first_peak_time"]:  # type: ignore[operator]
                if j < u.size - 1 and i > 0:
                    out["first_contact_duration"] = b - a
                break
    return out


@dataclass(frozen=True, eq=False)
class Comparison:
    """Simulated and measured deflection histories side by side (paper section 4).

    Attributes
    ----------
    scenario : Scenario
        The scenario simulated (with the measured excitation, if given).
    result : SimulationResult
    measured : Record
        The measured deflection (restricted to t >= 0).
    simulated : Record
        The simulation at the measured times (exact, :meth:`SimulationResult.displacement`).
    point : float, [m]
        Where the deflection is compared.
    sign : float
        ``u = sign * w`` (-1 for a contactor above).
    features : dict
        ``{key: {"simulated", "measured", "difference_percent"}}`` for the keys of
        :data:`FEATURES`; the difference is ``(sim - meas) / |meas|`` in percent.
    rms_difference : float, [m]
        RMS of ``w_sim - w_meas`` at the measured times.
    nrmse : float or None
        ``rms_difference / rms(w_meas)``; None when the measured rms is 0.
    """

    scenario: Scenario
    result: SimulationResult = field(repr=False)
    measured: Record = field(repr=False)
    simulated: Record = field(repr=False)
    point: float
    sign: float
    features: dict[str, dict[str, float | None]]
    rms_difference: float
    nrmse: float | None

    def to_dict(self) -> dict[str, Any]:
        """Plain-Python summary (for JSON)."""
        return {
            "point": self.point,
            "sign": self.sign,
            "features": self.features,
            "units": {k: "s" if k.endswith(("_time", "duration", "period")) else "m" for k in FEATURES},
            "rms_difference": self.rms_difference,
            "nrmse": self.nrmse,
            "n_samples": int(self.measured.time.size),
        }

    def table(self) -> str:
        """The quantities side by side, as text."""
        rows = [("quantity", "simulated", "measured", "difference")]
        for key, (label, scale, unit) in FEATURES.items():
            f = self.features[key]
            fmt = lambda v: "n/a" if v is None else f"{v * scale:.4f}"  # noqa: E731
            d = f["difference_percent"]
            rows.append((f"{label} [{unit}]", fmt(f["simulated"]), fmt(f["measured"]),
                         "n/a" if d is None else f"{d:+.2f} %"))
        rel = "n/a (measured rms is 0)" if self.nrmse is None else f"{self.nrmse * 100:.1f} % of rms"
        rows.append(("rms difference [mm]", f"{self.rms_difference * 1e3:.4f}", "", rel))
        widths = [max(len(r[j]) for r in rows) for j in range(4)]
        lines = [
            f"Comparison at x = {self.point * 1e3:.4g} mm (u = {'-w' if self.sign < 0 else 'w'}, "
            f"positive away from the contactor), {self.measured.time.size} samples"
        ]
        for r in rows:
            lines.append("  ".join([r[0].ljust(widths[0])] + [c.rjust(w) for c, w in zip(r[1:], widths[1:])]))
        return "\n".join(lines)

    def plot(self, path: str | Path | None = None, *, ax: Any = None) -> Any:
        """Overlay of the measured and simulated deflection (mm) against time.

        Returns the ``(figure, axes, lines)`` of matplotlib; with ``path`` the
        figure is also saved (atomically) there.

        Parameters
        ----------
        path : str or path-like, optional
            Also write the figure there.
        ax : matplotlib Axes, optional
            Draw here (default: a new figure).
        """
        if ax is None:
            plt = require("matplotlib.pyplot", "plot")

            fig, ax = plt.subplots(figsize=(8, 4.5))
        else:
            fig = ax.figure
        tm = self.measured.time
        lines = [
            ax.plot(tm, self.measured.values * 1e3, ".", ms=2.5, color="0.35", label="measured")[0],
        ]
        res = self.result
        t = res.time[res.time <= tm[-1]]
        ws = res.displacement([self.point], t)[0]
        lines.append(ax.plot(t, ws * 1e3, "-", lw=1.2, color="C3", label="simulated")[0])
        for c in self.scenario.contactors[:1]:
            lines.append(ax.axhline(c.direction * c.gap * 1e3, ls="--", lw=0.8, color="C0", label="contactor surface"))
        ax.set_xlabel("time [s]")
        ax.set_ylabel(f"deflection w at x = {self.point * 1e3:.4g} mm [mm]")
        ax.legend(loc="best", fontsize="small")
        ax.grid(True, lw=0.3)
        if path is not None:
            from ..plot.figure import save_figure

            save_figure(fig, path, dpi=130, bbox_inches="tight")
        return fig, ax, lines


def prepare_run(
    scenario: Scenario,
    measured: Record,
    excitation: Record | Excitation | None,
    hold: Literal["constant", "linear"],
    window: tuple[float | None, float | None] | None,
) -> tuple[Scenario, Record]:
    """The scenario set up to run over a measured deflection record, and the record's part used.

    Parameters
    ----------
    scenario : Scenario
    measured : Record
        A deflection record.
    excitation : Record, Excitation or None
        A measured base-acceleration trace or an excitation replacing the scenario's.
    hold : {"constant", "linear"}
        How a measured trace is held between samples.
    window : (start, stop) or None, [s]
        The part of the record to use (samples before t = 0 are dropped).

    Returns
    -------
    scenario : Scenario
        Ending at the record's last sample.
    record : Record
    """
    from ..model.loading import Excitation

    _require(measured, "deflection", "a comparison")
    meas = measured
    if window is not None:
        meas = meas.window(*window)
    if meas.time[0] < 0:
        meas = meas.window(0.0, None)
    sc = scenario
    if isinstance(excitation, Record):
        sc = drive_with_trace(sc, excitation, hold=hold)
    elif isinstance(excitation, Excitation):
        sc = dataclasses.replace(sc, excitation=excitation)
    elif excitation is not None:
        raise ParameterError(f"excitation: expected a Record or an Excitation, got {type(excitation).__name__}")
    t_end = float(meas.time[-1])
    if t_end <= 0:
        raise ParameterError(f"{measured.label}: no samples after t = 0")
    sc = dataclasses.replace(sc, solver=dataclasses.replace(sc.solver, end_time=t_end))
    _warn_implausible(sc, meas)
    return sc, meas


def _warn_implausible(scenario: Scenario, record: Record) -> None:
    """Warn of a deflection record whose units look wrong for the beam: a peak over half its length, or a
    sampling below twice its first free frequency (mm read as m, ms read as s, under unit-less headers)."""
    from .._warnings import emit_user_level_warning
    from ..modal import mode_set

    length = scenario.beam.length
    peak = float(np.max(np.abs(record.values)))
    if peak > 0.5 * length:
        emit_user_level_warning(
            f"{record.label}: its largest deflection, {peak:.4g} m, is more than half the beam's length "
            f"({length:.4g} m): is its unit right (a header without one is read in m)?"
        )
    ms = mode_set(scenario.beam, (), 4)
    elastic = ms.frequencies_hz[ms.n_rigid:]
    if elastic.size and record.sample_rate < 2.0 * elastic[0]:
        emit_user_level_warning(
            f"{record.label}: sampled at {record.sample_rate:.4g} Hz, below twice the beam's first frequency "
            f"({elastic[0]:.4g} Hz): the record cannot follow the response (is its time unit right? a header "
            "without one is read in s)"
        )


def compare(
    scenario: Scenario,
    measured: Record,
    *,
    excitation: Record | Excitation | None = None,
    hold: Literal["constant", "linear"] = "linear",
    point: float | None = None,
    window: tuple[float | None, float | None] | None = None,
) -> Comparison:
    """Simulate ``scenario`` and compare it with a measured deflection (paper section 4).

    Parameters
    ----------
    scenario : Scenario
    measured : Record
        Deflection ``w`` [m] at ``point`` against time [s] (the model's clock:
        t = 0 when the simulation starts).
    excitation : Record or Excitation, optional
        A measured base-acceleration trace (:func:`drive_with_trace`, with
        ``hold``) or any excitation, replacing the scenario's.
    hold : {"constant", "linear"}
        How a trace is held between samples.
    point : float, optional, [m]
        Default: the first contactor's position, else the first output point.
    window : (start, stop), optional, [s]
        Compare only this part of the record.

    Returns
    -------
    Comparison

    Notes
    -----
    The simulation runs to the last measured time and is evaluated exactly
    at the measured times. The quantities (:func:`response_features`) are
    computed the same way on both: on the measured samples and on the exact
    solution scanned at 8 samples per period of its highest frequency
    (:func:`~impactbeam.result.timegrid.scan_times`), not on the output grid:
    they do not depend on ``solver.time_step``.
    """
    from ..result.timegrid import scan_times
    from ..simulation import simulate

    sc, meas = prepare_run(scenario, measured, excitation, hold, window)
    x = record_point(sc, point)
    result = simulate(sc)
    if not result.success:
        raise SimulationError(f"compare: the simulation stopped early: {result.message}")
    w_sim = result.displacement([x], meas.time)[0]
    sim_rec = Record(meas.time, w_sim, name="simulated deflection", quantity="deflection")
    sign = response_point(sc.contactors, sc.output_points)[1]
    # contact is told from the deflection at the contactor: elsewhere the contact features are undefined
    at_stop = bool(sc.contactors) and math.isclose(x, sc.contactors[0].position, rel_tol=0.0,
                                                   abs_tol=1e-9 * sc.beam.length)
    gap = sc.contactors[0].gap if at_stop else None
    fm = response_features(meas.time, sign * meas.values, gap=gap)
    tg = scan_times(result, float(meas.time[0]), float(meas.time[-1]), breaks=False)  # the span of the record
    fs = response_features(tg, sign * result.displacement([x], tg)[0], gap=gap)
    feats: dict[str, dict[str, float | None]] = {}
    for k in FEATURES:
        s, m = fs[k], fm[k]
        d = None if (s is None or m is None or m == 0) else 100.0 * (s - m) / abs(m)
        feats[k] = {"simulated": s, "measured": m, "difference_percent": d}
    diff = w_sim - meas.values
    rms = float(np.sqrt(np.mean(diff**2)))
    rms_m = float(np.sqrt(np.mean(meas.values**2)))
    if float(np.ptp(meas.values)) <= 1e-12 * max(float(np.max(np.abs(meas.values))), 1e-300):
        from .._warnings import emit_user_level_warning

        emit_user_level_warning(
            f"{meas.label}: the measured deflection is constant ({float(meas.values[0]):.6g} m) over the "
            "compared window; the measured features are undefined and the comparison says little"
        )
    return Comparison(
        scenario=sc, result=result, measured=meas, simulated=sim_rec, point=x, sign=sign,
        features=feats, rms_difference=rms, nrmse=rms / rms_m if rms_m > 0 else None,
    )
