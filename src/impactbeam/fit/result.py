"""The outcome of a fit: fitted values with their uncertainties, the fitted scenario and its files."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from .._io import write_text
from ..exceptions import ParameterError

if TYPE_CHECKING:
    from ..experiment import Record

__all__ = ["FitResult"]


@dataclass(frozen=True, eq=False)
class FitResult:
    """Outcome of :func:`fit`.

    Attributes
    ----------
    paths : tuple of str
        The fitted dotted paths.
    initial, values : dict of str -> float
        Starting and fitted values (SI).
    stderr : dict of str -> float or None
        Standard errors from the covariance of the fit (``J^T J``)^-1 scaled by
        the reduced chi-square (so they reflect the actual residual noise);
        None when the covariance could not be estimated.
    ci95 : dict of str -> (float, float) or None
        ``value -/+ t_{0.975, dof} * stderr`` (linearised 95 % interval).
    conf_intervals : dict or None
        lmfit's profile-likelihood intervals (``conf_interval=True``):
        ``{path: {"lower95", "upper95", ...}}``.
    correlation : ndarray, (n, n)
        Correlation matrix of the fitted parameters (NaN when unknown).
    bounds : dict of str -> (float, float)
        Bounds used (user's or defaults).
    rms_residual : float, [m]
        RMS of ``w_sim - w_meas`` at the fitted values.
    initial_rms_residual : float, [m]
        The same at the starting values.
    nrmse : float
        ``rms_residual / rms(w_meas)``; NaN when the record's rms is 0.
    nfev : int
        Simulations run.
    success : bool
    message : str
    scenario : Scenario
        The fitted scenario (with the measured excitation, if any).
    measured : Record
        The record fitted (windowed, t >= 0).
    point : float, [m]
    residual : ndarray
        ``w_sim - w_meas`` at the fitted values.
    """

    paths: tuple[str, ...]
    initial: dict[str, float]
    values: dict[str, float]
    stderr: dict[str, float | None]
    ci95: dict[str, tuple[float, float] | None]
    conf_intervals: dict[str, dict[str, float]] | None
    correlation: np.ndarray = field(repr=False)
    bounds: dict[str, tuple[float, float]] = field(repr=False)
    rms_residual: float = math.nan
    initial_rms_residual: float = math.nan
    nrmse: float = math.nan
    nfev: int = 0
    success: bool = False
    message: str = ""
    scenario: Any = field(default=None, repr=False)
    measured: Record | None = field(default=None, repr=False)
    point: float = math.nan
    residual: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    _data: dict[str, Any] = field(default_factory=dict, repr=False)
    _override: bool = field(default=False, repr=False)  # the excitation replaced the scenario's (a trace or an object)

    def to_dict(self) -> dict[str, Any]:
        """Plain-Python summary (for JSON)."""
        params = {}
        for p in self.paths:
            params[p] = {
                "value": self.values[p],
                "initial": self.initial[p],
                "stderr": self.stderr[p],
                "ci95": list(self.ci95[p]) if self.ci95[p] is not None else None,
                "lower": self.bounds[p][0],
                "upper": self.bounds[p][1],
            }
            if self.conf_intervals and p in self.conf_intervals:
                params[p]["conf_interval"] = self.conf_intervals[p]
        return {
            "params": params,
            "rms_residual": self.rms_residual,
            "initial_rms_residual": self.initial_rms_residual,
            "nrmse": self.nrmse,
            "nfev": self.nfev,
            "success": self.success,
            "message": self.message,
            "n_samples": int(self.residual.size),
            "point": self.point,
            "correlation": self.correlation.tolist(),
        }

    def report(self) -> str:
        """A text report: one row per parameter, the residuals and the status."""
        rows = [("parameter", "initial", "fitted", "std error", "95 % interval", "bounds")]
        for p in self.paths:
            se = self.stderr[p]
            ci = self.ci95[p]
            lo, hi = self.bounds[p]
            rows.append((
                p,
                f"{self.initial[p]:.6g}",
                f"{self.values[p]:.6g}",
                "n/a" if se is None else f"{se:.3g} ({100 * se / abs(self.values[p]):.2g} %)" if self.values[p] else f"{se:.3g}",
                "n/a" if ci is None else f"[{ci[0]:.6g}, {ci[1]:.6g}]",
                f"[{lo:g}, {hi:g}]",
            ))
        widths = [max(len(r[j]) for r in rows) for j in range(len(rows[0]))]
        lines = [f"Least-squares fit of {len(self.paths)} parameter{'s' if len(self.paths) > 1 else ''} "
                 f"to {self.residual.size} samples at x = {self.point * 1e3:.4g} mm"]
        lines += ["  " + "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() for r in rows]
        lines.append(
            f"  rms residual {self.rms_residual * 1e3:.4g} mm ("
            f"{f'{100 * self.nrmse:.2f} % of the rms record' if math.isfinite(self.nrmse) else 'record rms is 0'}; "
            f"{self.initial_rms_residual * 1e3:.4g} mm at the start), {self.nfev} simulations"
        )
        if len(self.paths) > 1 and np.all(np.isfinite(self.correlation)):
            pairs = [
                f"{self.paths[i]} ~ {self.paths[j]}: {self.correlation[i, j]:+.2f}"
                for i in range(len(self.paths)) for j in range(i + 1, len(self.paths))
            ]
            lines.append("  correlation " + "; ".join(pairs))
        lines.append(f"  status: {'converged' if self.success else 'NOT converged'} ({self.message})")
        return "\n".join(lines)

    def scenario_data(self, out: str | Path | None = None) -> dict[str, Any]:
        """The fitted scenario as a raw mapping (TOML schema).

        Parameters
        ----------
        out : str or path-like, optional
            Where the scenario will be written: with a measured trace (or any
            sampled excitation) the excitation then refers to ``<out
            stem>_excitation.csv`` (see :meth:`write_scenario`).

        Returns
        -------
        dict
        """
        from ..scenario import set_path

        data = self._data
        if self._override:  # the fitted excitation (its start, scale ...), not the scenario's
            name = f"{Path(out).stem}_excitation.csv" if out is not None else "excitation.csv"
            data = set_path(data, "excitation", excitation_data(self.scenario.excitation, name))
        return data

    def write_scenario(self, path: str | Path) -> list[Path]:
        """Write the fitted scenario as TOML (atomically); returns the files written.

        With a measured excitation trace, the trace is written beside it as
        ``<stem>_excitation.csv`` (``time [s],base_acceleration [m/s^2]``) and
        the scenario refers to it, so ``load_scenario(path)`` reproduces the fit.

        Parameters
        ----------
        path : str or path-like
            The ``.toml`` file to write.

        Returns
        -------
        list of Path
        """
        from ..scenario import dump_scenario

        target = Path(path)
        if not target.parent.is_dir():
            raise ParameterError(f'--out: directory "{target.parent}" does not exist')
        written = []
        ex = self.scenario.excitation
        if self._override and ex.times is not None:  # the samples of the fitted excitation
            csv_path = target.with_name(f"{target.stem}_excitation.csv")
            from ..model.loading import UNITS

            unit = UNITS[ex.kind]
            lines = ["# excitation used by the fit (impactbeam fit)", f"time [s],{ex.kind} [{unit}]"]
            lines += [f"{t!r},{v!r}" for t, v in zip(ex.times.tolist(), ex.values.tolist())]
            write_text(csv_path, "\n".join(lines) + "\n")
            written.append(csv_path)
        data = self.scenario_data(target)
        comment = f"fitted by impactbeam fit: {', '.join(f'{p} = {self.values[p]:.6g}' for p in self.paths)}"
        desc = data.get("description")
        from ..scenario import set_path

        data = set_path(data, "description", f"{desc} ({comment})" if desc else comment)
        dump_scenario(data, target)
        written.append(target)
        return written


def excitation_data(ex: Any, file: str) -> dict[str, Any]:
    """An excitation object as a scenario's ``[excitation]`` table (SI numbers); a sampled one refers to ``file``.

    Parameters
    ----------
    ex : Excitation
    file : str
        The file its samples are written to (a table or a random load).
    """
    sampled = ex.shape in ("table", "random")
    raw: dict[str, Any] = {"kind": ex.kind, "shape": "table" if sampled else ex.shape}
    if ex.kind == "point_force":
        raw["position"] = ex.position
    keys = {"half_sine": ("amplitude", "duration"), "step": ("amplitude",),
            "harmonic": ("amplitude", "frequency", "phase")}.get(ex.shape, ())
    raw.update({k: float(getattr(ex, k)) for k in keys})
    if sampled:
        raw.update(file=file, hold="linear" if ex.shape == "random" else ex.hold)
    if ex.start:
        raw["start"] = float(ex.start)
    if ex.scale != 1.0:
        raw["scale"] = float(ex.scale)
    return raw

