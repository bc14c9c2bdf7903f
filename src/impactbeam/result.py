"""SimulationResult: sampled histories, exact dense output, events, energy account."""

from __future__ import annotations

import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ._atomic import atomic_path
from .beam import Beam, Contactor
from .exceptions import ParameterError

if TYPE_CHECKING:
    import xarray as xr

    from .solver.engine import Event, RawSolution

__all__ = ["SimulationResult", "write_result", "RESULT_SUFFIXES"]

RESULT_SUFFIXES = (".nc", ".csv", ".parquet")


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Result of :func:`impactbeam.simulate`.

    Attributes
    ----------
    time : ndarray, (n_t,), [s]
        Output times (multiples of ``solver.time_step``).
    points : ndarray, (n_p,), [m]
        Output positions.
    w, w_t : ndarray, (n_t, n_p), [m], [m/s]
        Deflection and velocity at the output points (exact at the samples).
    w_contact, w_t_contact : ndarray, (n_t, n_c)
        Deflection and velocity at each contactor.
    contact_force : ndarray, (n_t, n_c), [N]
        Force of each contactor on the beam (>= 0, pushing the beam away).
    engaged : ndarray of bool, (n_t, n_c)
        Contactor engaged at each sample.
    events : list of Event
        Every impact and rebound at its exact time.
    energy : dict of ndarray (n_t,), [J]
        ``kinetic``, ``strain`` (beam and end supports), ``contactor``,
        ``input_work`` and ``dissipated`` (cumulative), ``total``
        (kinetic + strain + contactor) and ``residual``
        (``total(0) + input_work - dissipated - total``: zero for the exact
        N-mode model except for the projections at events and the trapezoid
        rule of the cumulative integrals).
    eta, eta_t : ndarray, (n_t, n_modes)
        Modal coordinates in the basis of the state at each sample.
    status : int
        0 reached end_time; 1 stopped by the chattering guard.
    message : str
    """

    time: np.ndarray
    points: np.ndarray
    w: np.ndarray
    w_t: np.ndarray
    w_contact: np.ndarray
    w_t_contact: np.ndarray
    contact_force: np.ndarray
    engaged: np.ndarray
    events: list[Event]
    energy: dict[str, np.ndarray]
    eta: np.ndarray
    eta_t: np.ndarray
    status: int
    message: str
    beam: Beam
    contactors: tuple[Contactor, ...]
    n_modes: int
    energy_jumps: np.ndarray = field(repr=False)
    _raw: RawSolution = field(repr=False)
    scenario_name: str = "scenario"
    options: dict[str, Any] = field(default_factory=dict)

    @property
    def success(self) -> bool:
        """True when the run reached its end time."""
        return self.status == 0

    @classmethod
    def from_raw(cls, raw: RawSolution, beam: Beam, contactors, points, n_modes: int, name: str, options: dict) -> SimulationResult:
        n_t = raw.time.size
        n_c = len(contactors)
        engaged = np.zeros((n_t, n_c), dtype=bool)
        codes = raw.state_code
        for code, key in enumerate(raw.state_keys):
            rows = codes == code
            for c in key:
                engaged[rows, c] = True
        force = np.zeros((n_t, n_c))
        contactor_energy = np.zeros(n_t)
        spring_at_zero_gap = np.zeros(n_t)
        for i, c in enumerate(contactors):
            g = c.gap - c.direction * raw.w_contact[:, i]
            comp = np.where(engaged[:, i], np.maximum(-g, 0.0), 0.0)
            force[:, i] = c.stiffness * comp
            contactor_energy += np.where(engaged[:, i], 0.5 * c.stiffness * g**2, 0.0)
            spring_at_zero_gap += np.where(engaged[:, i], 0.5 * c.stiffness * raw.w_contact[:, i] ** 2, 0.0)
        invalid = codes < 0
        force[invalid] = np.nan
        kinetic = raw.kinetic
        strain = raw.modal_strain - spring_at_zero_gap
        total = kinetic + strain + contactor_energy
        dt = np.diff(raw.time)
        cum = lambda p: np.concatenate([[0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * dt)])  # noqa: E731
        input_work = cum(np.nan_to_num(raw.load_power))
        dissipated = cum(np.nan_to_num(raw.damping_power))
        residual = total[0] + input_work - dissipated - total
        for arr in (input_work, dissipated, residual):
            arr[invalid] = np.nan
        energy = {
            "kinetic": kinetic,
            "strain": strain,
            "contactor": np.where(invalid, np.nan, contactor_energy),
            "input_work": input_work,
            "dissipated": dissipated,
            "total": total,
            "residual": residual,
        }
        return cls(
            raw.time, np.asarray(points, dtype=float), raw.w, raw.w_t, raw.w_contact, raw.w_t_contact, force,
            engaged, list(raw.events), energy, raw.eta, raw.eta_t, raw.status, raw.message, beam,
            tuple(contactors), n_modes, np.asarray(raw.switch_energy_jumps), raw, name, options,
        )

    # ------------------------------------------------------------------ dense output
    def _dense(self, x, t, which: int) -> np.ndarray:
        x = np.atleast_1d(np.asarray(x, dtype=float))
        t = np.atleast_1d(np.asarray(t, dtype=float))
        segs = self._raw.segments
        starts = np.array([s.t0 for s in segs])
        idx = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(segs) - 1)
        out = np.full((x.size, t.size), np.nan)
        space = self._raw.space
        cache = self.__dict__.setdefault("_shape_cache", {})
        xkey = x.tobytes()
        for j in np.unique(idx):
            seg = segs[j]
            sel = (idx == j) & (t <= seg.t1 + 1e-15)
            if not sel.any():
                continue
            W = cache.get((seg.engaged, xkey))
            if W is None:
                W = space.state(seg.engaged).modes.shapes(x).T
                cache[(seg.engaged, xkey)] = W
            eta, deta = seg.solution.evaluate(t[sel] - seg.t0)
            out[:, sel] = W @ (eta if which == 0 else deta)
        return out

    def _scalar(self, x: float, lo: float, hi: float):
        """``(t0, f)`` with ``f(tau) -> (w(x), w_t(x))`` of the one segment covering [lo, hi], else None."""
        segs = self._raw.segments
        starts = np.array([s.t0 for s in segs])
        j = int(np.clip(np.searchsorted(starts, lo, side="right") - 1, 0, len(segs) - 1))
        seg = segs[j]
        if not (seg.t0 <= lo and hi <= seg.t1) or not hasattr(seg.solution, "projector"):
            return None
        W = self._raw.space.state(seg.engaged).modes.shapes([x])[:, 0]
        return seg.t0, seg.solution.projector(W)

    def displacement(self, x, t) -> np.ndarray:
        """Exact deflection ``w(x, t)`` [m] at any positions and times: array (n_x, n_t)."""
        return self._dense(x, t, 0)

    def velocity(self, x, t) -> np.ndarray:
        """Exact velocity ``w_t(x, t)`` [m/s]: array (n_x, n_t)."""
        return self._dense(x, t, 1)

    # ------------------------------------------------------------------ derived
    def metrics(self) -> dict[str, Any]:
        """Response metrics (keys of ``impactbeam simulate --json``); see :mod:`impactbeam.metrics`."""
        from .metrics import compute_metrics

        return compute_metrics(self)

    def to_xarray(self) -> xr.Dataset:
        """The result as a labelled :class:`xarray.Dataset` with units in the attributes."""
        import xarray as xr

        from . import __version__

        n_c = len(self.contactors)
        ds = xr.Dataset(
            {
                "w": (("time", "point"), self.w, {"units": "m", "long_name": "deflection"}),
                "w_t": (("time", "point"), self.w_t, {"units": "m/s", "long_name": "velocity"}),
                "contact_force": (
                    ("time", "contactor"), self.contact_force, {"units": "N", "long_name": "contact force"}
                ),
                "engaged": (("time", "contactor"), self.engaged, {"long_name": "contactor engaged"}),
                "w_contactor": (
                    ("time", "contactor"), self.w_contact, {"units": "m", "long_name": "deflection at contactor"}
                ),
                "modal_displacement": (
                    ("time", "mode"), self.eta,
                    {"units": "m kg^0.5", "long_name": "modal displacement (basis of the current state)"},
                ),
                "modal_velocity": (
                    ("time", "mode"), self.eta_t, {"units": "m kg^0.5/s", "long_name": "modal velocity"}
                ),
                "event_time": (("event",), np.array([e.time for e in self.events], dtype=float), {"units": "s"}),
                "event_kind": (("event",), np.array([e.kind for e in self.events], dtype=str)),
                "event_contactor": (("event",), np.array([e.contactor for e in self.events], dtype=int)),
            },
            coords={
                "time": ("time", self.time, {"units": "s", "long_name": "time"}),
                "point": ("point", self.points, {"units": "m", "long_name": "position along the beam"}),
                "contactor": ("contactor", np.arange(n_c)),
                "contactor_position": (
                    "contactor", np.array([c.position for c in self.contactors], dtype=float), {"units": "m"}
                ),
                "mode": ("mode", np.arange(1, self.eta.shape[1] + 1)),
            },
            attrs={
                "title": f"impactbeam simulation: {self.scenario_name}",
                "impactbeam_version": __version__,
                "status": self.status,
                "message": self.message,
                "n_modes": self.n_modes,
                "sign_convention": "w from the rest position; contactor 'below' engaged while w(a) < -gap",
                **{f"solver_{k}": v for k, v in self.options.items()},
            },
        )
        for name, arr in self.energy.items():
            ds[f"energy_{name}"] = ("time", arr, {"units": "J", "long_name": f"energy: {name.replace('_', ' ')}"})
        return ds

    def to_dataframe(self):
        """Wide table: time, w and w_t at each point, contact force per contactor, energies."""
        import pandas as pd

        cols: dict[str, np.ndarray] = {"time [s]": self.time}
        for j, x in enumerate(self.points):
            cols[f"w(x={x:.6g}) [m]"] = self.w[:, j]
        for j, x in enumerate(self.points):
            cols[f"w_t(x={x:.6g}) [m/s]"] = self.w_t[:, j]
        for i in range(len(self.contactors)):
            cols[f"contact_force_{i} [N]"] = self.contact_force[:, i]
            cols[f"engaged_{i}"] = self.engaged[:, i]
        for name, arr in self.energy.items():
            cols[f"energy_{name} [J]"] = arr
        return pd.DataFrame(cols)

    def plot(self, path: str | os.PathLike | None = None, **kwargs):
        """Response figure; see :func:`impactbeam.plot.plot_result`."""
        from .plot import plot_result

        return plot_result(self, path, **kwargs)


def _json_default(o: Any) -> Any:
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    raise TypeError(type(o))


def metrics_json(metrics: dict[str, Any]) -> str:
    """JSON text of a metrics dict (NaN and inf become null)."""

    def clean(v: Any) -> Any:
        if isinstance(v, dict):
            return {k: clean(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        if isinstance(v, (float, np.floating)):
            return float(v) if math.isfinite(v) else None
        if isinstance(v, np.integer):
            return int(v)
        return v

    return json.dumps(clean(metrics), indent=2, default=_json_default)


def write_result(result: SimulationResult, path: str | os.PathLike) -> Path:
    """Write the full result to ``.nc`` (netCDF4/HDF5), ``.csv`` or ``.parquet``, atomically."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in RESULT_SUFFIXES:
        raise ParameterError(f"--out: unsupported file type {suffix!r}; use one of {', '.join(RESULT_SUFFIXES)}")
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        if suffix == ".nc":
            ds = result.to_xarray()
            ds.attrs["metrics"] = metrics_json(result.metrics())
            ds.to_netcdf(tmp, engine="h5netcdf")
        elif suffix == ".csv":
            result.to_dataframe().to_csv(tmp, index=False)
        else:
            result.to_dataframe().to_parquet(tmp, index=False)
    return path
