"""SimulationResult: the exact solution, its events, and sampled histories on request."""

from __future__ import annotations

import functools
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from ._atomic import atomic_path
from .beam import Beam, Contactor
from .exceptions import ParameterError, ResourceError

if TYPE_CHECKING:
    import xarray as xr

    from .solver.solution import Event, PiecewiseSolution

__all__ = [
    "SimulationResult", "write_result", "RESULT_SUFFIXES", "memory_limit", "check_memory", "output_bytes",
    "check_output_size",
]

RESULT_SUFFIXES = (".nc", ".csv", ".parquet")
_CHUNK = 65536  # samples evaluated per call of the compiled sampler
_REFERENCE = (
    "W. Xu and E. K. Ervin, Parameters affecting the transient response of an impacting beam, "
    "Shock and Vibration 20 (2013)"
)


def memory_limit() -> int:
    """Bytes a request may allocate for sampled histories.

    The smallest of: ``IMPACTBEAM_MEMORY_LIMIT`` (bytes, or a number with a
    ``K``, ``M`` or ``G`` suffix; default 4 GiB), half of the machine's
    physical memory, and 80 % of the process's address-space limit
    (``ulimit -v``) when one is set.
    """
    raw = os.environ.get("IMPACTBEAM_MEMORY_LIMIT", "").strip().upper()
    limit = 4 << 30
    if raw:
        mult = {"K": 1 << 10, "M": 1 << 20, "G": 1 << 30}.get(raw[-1:], 1)
        try:
            limit = int(float(raw.rstrip("KMGB") or "nan") * mult)
        except ValueError:
            raise ParameterError(f"IMPACTBEAM_MEMORY_LIMIT: not a size: {raw!r}") from None
    try:
        limit = min(limit, os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") // 2)
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        pass
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
        if soft != resource.RLIM_INFINITY:
            limit = min(limit, int(0.8 * soft))
    except (ImportError, OSError, ValueError):  # pragma: no cover - not POSIX
        pass
    return limit


def check_memory(nbytes: float, what: str, hint: str) -> None:
    """Raise ResourceError before allocating more than :func:`memory_limit`."""
    limit = memory_limit()
    if nbytes > limit:
        raise ResourceError(
            f"{what} would need {nbytes / 2**30:.3g} GiB, above the limit of {limit / 2**30:.3g} GiB; {hint} "
            "(or raise IMPACTBEAM_MEMORY_LIMIT)"
        )


def output_bytes(n_times: int, n_points: int, n_contactors: int, n_modes: int, *, modal: bool = True) -> int:
    """Estimated peak bytes of the sampled histories of a result and one copy of them.

    ``w, w_t`` at the points and the contactors, contact forces and states,
    and, with ``modal``, the modal coordinates and the seven energy series; the
    factor 2 covers the copy a Dataset or DataFrame makes.
    """
    per = 8 * (2 * (n_points + n_contactors) + 2 * n_contactors) + n_contactors
    if modal:
        per += 8 * (2 * n_modes + 4 + 7)
    return 2 * per * n_times


def check_output_size(n_times: int, n_points: int, n_contactors: int, n_modes: int, modal: bool = True) -> None:
    """Raise ResourceError, before any work, when :func:`output_bytes` exceeds :func:`memory_limit`."""
    check_memory(
        output_bytes(n_times, n_points, n_contactors, n_modes, modal=modal),
        f"sampling {n_times} output times at {n_points} points" + (f" with {n_modes} modal coordinates" if modal else ""),
        "use a larger solver.time_step, fewer output points or a shorter end_time",
    )


@dataclass(frozen=True, eq=False)
class SimulationResult:
    """Result of :func:`impactbeam.simulate`.

    The result holds the exact piecewise solution (``solution``); sampled
    histories are evaluated on first access, at the output times
    ``0, dt, 2 dt, ...`` (``solver.time_step``), and the metrics come from the
    exact solution, not from the samples.

    Attributes
    ----------
    solution : PiecewiseSolution
        Dense output: evaluate anywhere with :meth:`displacement` / :meth:`velocity`.
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
        ``input_work`` and ``dissipated`` (cumulative, trapezoid rule on the
        samples), ``total`` and ``residual``
        (``total(0) + input_work - dissipated - total``).
    eta, eta_t : ndarray, (n_t, n_state_modes)
        Modal coordinates in the basis of the state at each sample (``n_modes``
        modes, plus one attachment shape per contactor position with the
        shared Ritz basis, ``solver.basis = "enriched"``).
    status : int
        0 reached end_time; 1 stopped by the chattering guard (later samples NaN).
    message : str
    warnings : tuple of str
        What the solver is not sure of (also issued as ImpactBeamWarning).
    """

    solution: PiecewiseSolution = field(repr=False)
    points: np.ndarray
    beam: Beam = field(repr=False)
    contactors: tuple[Contactor, ...]
    n_modes: int
    time_step: float
    end_time: float
    scenario_name: str = "scenario"
    options: dict[str, Any] = field(default_factory=dict)
    rerun: Callable[[int], SimulationResult] | None = field(default=None, repr=False)
    tolerance: float = 2e-3
    scenario: Any = field(default=None, repr=False)

    # ------------------------------------------------------------------ from the solution
    @property
    def events(self) -> list[Event]:
        return self.solution.events

    @property
    def status(self) -> int:
        return self.solution.status

    @property
    def message(self) -> str:
        return self.solution.message

    @property
    def warnings(self) -> tuple[str, ...]:
        """The solver's warnings, and the convergence warning once :attr:`convergence` is known."""
        out = tuple(self.solution.warnings)
        conv = self.__dict__.get("_convergence")
        if conv is not None and not self.converged:
            from .solver.convergence import worst

            key, change = worst(conv)
            out += (
                f"not converged in the number of modes: with {self.n_modes} modes {key} still changes by "
                f"{change:.2g} (relative; solver.tolerance = {self.tolerance:g}); use more modes or "
                'solver.modes = "auto"',
            )
        return out

    # ------------------------------------------------------------------ convergence in the modes
    def set_convergence(self, changes: dict[str, float]) -> None:
        """Record the relative change of the metrics against a smaller mode count."""
        self.__dict__["_convergence"] = dict(changes)

    @property
    def convergence(self) -> dict[str, float] | None:
        """Relative change of each Table-2 metric against a run with fewer modes.

        For ``solver.modes = "auto"`` the change between the last two counts;
        for a fixed count ``n`` computed on first access by a second run with
        ``n - max(2, n // 4)`` modes (see :mod:`impactbeam.solver.convergence`).
        None when it cannot be computed (one mode).
        """
        if "_convergence" not in self.__dict__:
            from ._warnings import emit_user_level_warning as warn
            from .solver.convergence import coarser_count, relative_changes

            if self.rerun is None or self.n_modes <= 1:
                return None
            coarse = self.rerun(coarser_count(self.n_modes))
            self.set_convergence(relative_changes(self.metrics(impacts=False), coarse.metrics(impacts=False)))
            if not self.converged:
                warn(self.warnings[-1])
        return self.__dict__["_convergence"]

    @property
    def converged(self) -> bool:
        """True when every convergence metric changes by less than ``solver.tolerance``."""
        conv = self.convergence
        return conv is not None and max(conv.values()) < self.tolerance

    @property
    def energy_jumps(self) -> np.ndarray:
        """Change of mechanical energy at each switch [J] (zero for a lossless change of basis)."""
        return np.asarray(self.solution.energy_jumps)

    @property
    def success(self) -> bool:
        """True when the run reached its end time."""
        return self.status == 0

    def _repr_html_(self) -> str:
        """Compact summary for Jupyter: run, contactors, metrics, warnings."""
        from . import _html
        from .metrics import METRIC_DISPLAY

        m = self.metrics(impacts=False)
        rows = [(label, "n/a" if m.get(key) is None else f"{m[key] * scale:.5g} {unit}".strip())
                for key, label, scale, unit in METRIC_DISPLAY]
        run = [("scenario", self.scenario_name), ("status", self.message), ("modes per state", self.n_modes),
               ("events", len(self.events)), ("end time", f"{self.end_time * 1e3:.5g} ms")]
        cont = [(f"contactor {i}", f"{c.side} at {_html.mm(c.position)}, gap {_html.mm(c.gap)}, k = {c.stiffness:.4g} N/m")
                for i, c in enumerate(self.contactors)]
        parts = [_html.table(run, "run"), _html.table(rows, "metrics (exact, from the closed form)")]
        if cont:
            parts.insert(1, _html.table(cont, "contactors"))
        if self.warnings:
            parts.append(_html.table([("warning", w) for w in self.warnings], "warnings"))
        return _html.sections("SimulationResult", parts)

    # ------------------------------------------------------------------ sampled histories (lazy)
    @functools.cached_property
    def time(self) -> np.ndarray:
        n = int(math.floor(self.end_time / self.time_step * (1.0 + 1e-12))) + 1
        return np.arange(n) * self.time_step

    def _sampled(self, modal: bool) -> dict[str, np.ndarray]:
        t = self.time
        xs = np.concatenate([self.points, [c.position for c in self.contactors]])
        nm = self.solution.n_modes  # N, or N + attachment shapes in the shared Ritz basis
        check_output_size(t.size, self.points.size, len(self.contactors), nm, modal)
        out = {
            "w": np.empty((t.size, xs.size)), "w_t": np.empty((t.size, xs.size)),
            "engaged": np.empty((t.size, len(self.contactors)), dtype=bool),
        }
        if modal:
            out.update(eta=np.empty((t.size, nm)), eta_t=np.empty((t.size, nm)), energies=np.empty((t.size, 4)))
        for a in range(0, t.size, _CHUNK):
            b = min(a + _CHUNK, t.size)
            s = self.solution.sample(xs, t[a:b], modal=modal, energy=modal)
            out["w"][a:b] = s.w
            out["w_t"][a:b] = s.w_t
            out["engaged"][a:b] = s.engaged
            if modal:
                out["eta"][a:b] = s.eta
                out["eta_t"][a:b] = s.eta_t
                out["energies"][a:b] = s.energies
        return out

    @functools.cached_property
    def _grid(self) -> dict[str, np.ndarray]:
        return self._sampled(modal=False)

    @functools.cached_property
    def _modal_grid(self) -> dict[str, np.ndarray]:
        return self._sampled(modal=True)

    @property
    def w(self) -> np.ndarray:
        return self._grid["w"][:, : self.points.size]

    @property
    def w_t(self) -> np.ndarray:
        return self._grid["w_t"][:, : self.points.size]

    @property
    def w_contact(self) -> np.ndarray:
        return self._grid["w"][:, self.points.size :]

    @property
    def w_t_contact(self) -> np.ndarray:
        return self._grid["w_t"][:, self.points.size :]

    @property
    def engaged(self) -> np.ndarray:
        return self._grid["engaged"]

    @functools.cached_property
    def contact_force(self) -> np.ndarray:
        force = np.zeros((self.time.size, len(self.contactors)))
        for i, c in enumerate(self.contactors):
            g = c.gap - c.direction * self.w_contact[:, i]
            force[:, i] = np.where(self.engaged[:, i], c.stiffness * np.maximum(-g, 0.0), 0.0)
        force[np.isnan(self.w_contact).any(axis=1)] = np.nan
        return force

    @property
    def eta(self) -> np.ndarray:
        return self._modal_grid["eta"]

    @property
    def eta_t(self) -> np.ndarray:
        return self._modal_grid["eta_t"]

    @functools.cached_property
    def energy(self) -> dict[str, np.ndarray]:
        en = self._modal_grid["energies"]
        kinetic, modal_strain, load_power, damping_power = en.T
        contactor_energy = np.zeros(self.time.size)
        spring_at_zero_gap = np.zeros(self.time.size)
        for i, c in enumerate(self.contactors):
            wc = self.w_contact[:, i]
            g = c.gap - c.direction * wc
            on = self.engaged[:, i]
            contactor_energy += np.where(on, 0.5 * c.stiffness * g**2, 0.0)
            spring_at_zero_gap += np.where(on, 0.5 * c.stiffness * wc**2, 0.0)
        strain = modal_strain - spring_at_zero_gap
        total = kinetic + strain + contactor_energy
        dt = np.diff(self.time)

        def cumulative(p: np.ndarray) -> np.ndarray:
            return np.concatenate([[0.0], np.cumsum(0.5 * (p[1:] + p[:-1]) * dt)])

        input_work = cumulative(load_power)
        dissipated = cumulative(damping_power)
        return {
            "kinetic": kinetic, "strain": strain, "contactor": contactor_energy, "input_work": input_work,
            "dissipated": dissipated, "total": total, "residual": total[0] + input_work - dissipated - total,
        }

    # ------------------------------------------------------------------ dense output
    def _check_points(self, x: Any) -> np.ndarray:
        x = np.atleast_1d(np.asarray(x, dtype=float))
        L = self.beam.length
        bad = ~np.isfinite(x) | (x < 0.0) | (x > L * (1.0 + 1e-12))
        if bad.any():
            raise ParameterError(f"x: {x[bad][0]:g} m is off the beam [0, {L:g}] m")
        return x

    def displacement(self, x: Any, t: Any) -> np.ndarray:
        """Exact deflection ``w(x, t)`` [m] at any positions and times: array (n_x, n_t).

        Raises ParameterError for a point off the beam or a time outside
        ``[0, end_time]``; times after a chattering stop give NaN.
        """
        x = self._check_points(x)
        t = self.solution.check_times(t, self.end_time)
        return self.solution.sample(x, t).w.T

    def velocity(self, x: Any, t: Any) -> np.ndarray:
        """Exact velocity ``w_t(x, t)`` [m/s]: array (n_x, n_t); see :meth:`displacement`."""
        x = self._check_points(x)
        t = self.solution.check_times(t, self.end_time)
        return self.solution.sample(x, t).w_t.T

    # ------------------------------------------------------------------ derived
    def metrics(self, *, impacts: bool = True) -> dict[str, Any]:
        """Response metrics (keys of ``impactbeam simulate --json``); see :mod:`impactbeam.metrics`.

        Parameters
        ----------
        impacts : bool
            Include the per-impact table (``"impacts"``); sweeps leave it out.
        """
        from .metrics import compute_metrics

        return compute_metrics(self, impacts=impacts)

    @property
    def impacts(self):
        """The per-impact table as a :class:`pandas.DataFrame` (one row per contact interval).

        Columns: ``contactor``, ``start`` [s], ``end`` [s], ``duration`` [s],
        ``peak_force`` [N], ``impulse`` [N s]; exact (closed form), see
        :mod:`impactbeam.metrics`.
        """
        import pandas as pd

        cols = ["contactor", "start", "end", "duration", "peak_force", "impulse"]
        rows = self.metrics()["impacts"]
        df = pd.DataFrame(rows, columns=cols).astype({"end": float, "duration": float})
        df.attrs["units"] = {"start": "s", "end": "s", "duration": "s", "peak_force": "N", "impulse": "N s"}
        return df

    def to_xarray(self) -> xr.Dataset:
        """The result as a CF-style :class:`xarray.Dataset`, with units and its provenance.

        Every variable has ``units`` (UDUNITS) and ``long_name``; the states are
        CF flags (``flag_values``/``flag_meanings``); the global attributes hold
        ``Conventions``, ``title``, ``history``, ``source``, ``references`` (the
        paper), the scenario as TOML text (``scenario``), the metrics as JSON
        (``metrics``), the solver options, status, message and warnings.
        """
        import datetime

        import xarray as xr

        from . import __version__

        n_c = len(self.contactors)
        kind = np.array([1 if e.kind == "impact" else 0 for e in self.events], dtype=np.int8)
        flag = {"flag_values": np.array([0, 1], dtype=np.int8)}
        ds = xr.Dataset(
            {
                "w": (("time", "point"), self.w, {"units": "m", "long_name": "deflection w(x, t)"}),
                "w_t": (("time", "point"), self.w_t, {"units": "m s-1", "long_name": "velocity w_t(x, t)"}),
                "contact_force": (
                    ("time", "contactor"), self.contact_force, {"units": "N", "long_name": "contact force on the beam"}
                ),
                "engaged": (("time", "contactor"), self.engaged.astype(np.int8),
                            {"long_name": "contactor state", **flag, "flag_meanings": "free engaged"}),
                "w_contactor": (
                    ("time", "contactor"), self.w_contact, {"units": "m", "long_name": "deflection at the contactor"}
                ),
                "modal_displacement": (
                    ("time", "mode"), self.eta,
                    {"long_name": "modal displacement in the basis of the current state",
                     "comment": "mass-normalised modal coordinate: unit m kg^(1/2), which UDUNITS cannot express"},
                ),
                "modal_velocity": (
                    ("time", "mode"), self.eta_t,
                    {"long_name": "modal velocity", "comment": "unit m kg^(1/2) s^-1"},
                ),
                "event_time": (("event",), np.array([e.time for e in self.events], dtype=float),
                               {"units": "s", "long_name": "event time"}),
                "event_kind": (("event",), kind, {"long_name": "event kind", **flag,
                                                  "flag_meanings": "rebound impact"}),
                "event_contactor": (("event",), np.array([e.contactor for e in self.events], dtype=np.int32),
                                    {"long_name": "contactor of the event"}),
            },
            coords={
                "time": ("time", self.time, {"units": "s", "long_name": "time", "standard_name": "time"}),
                "point": ("point", self.points, {"units": "m", "long_name": "position along the beam"}),
                "contactor": ("contactor", np.arange(n_c, dtype=np.int32), {"long_name": "contactor index"}),
                "contactor_position": (
                    "contactor", np.array([c.position for c in self.contactors], dtype=float),
                    {"units": "m", "long_name": "contactor position"},
                ),
                "mode": ("mode", np.arange(1, self.solution.n_modes + 1, dtype=np.int32),
                         {"long_name": "mode number"}),
                "event": ("event", np.arange(len(self.events), dtype=np.int32), {"long_name": "event number"}),
            },
            attrs={
                "Conventions": "CF-1.10",
                "title": f"impactbeam simulation: {self.scenario_name}",
                "history": f"{datetime.datetime.now(datetime.timezone.utc).isoformat(timespec='seconds')}: "
                           f"impactbeam {__version__} simulate",
                "source": f"impactbeam {__version__}: exact piecewise modal solution (closed form between exact "
                          "events)",
                "references": _REFERENCE,
                "impactbeam_version": __version__,
                "status": self.status,
                "message": self.message,
                "warnings": "; ".join(self.warnings),
                "n_modes": self.n_modes,
                "sign_convention": "w from the rest position; contactor 'below' engaged while w(a) < -gap",
                "scenario": self.scenario.to_toml() if self.scenario is not None else "",
                "metrics": metrics_json(self.metrics()),
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
    from ._optional import require

    require({".nc": "h5netcdf", ".csv": "pandas", ".parquet": "pyarrow"}[suffix], "io", feature=f"writing {suffix}")
    path.parent.mkdir(parents=True, exist_ok=True)
    check_output_size(result.time.size, result.points.size, len(result.contactors), result.solution.n_modes)
    with atomic_path(path) as tmp:
        if suffix == ".nc":
            result.to_xarray().to_netcdf(tmp, engine="h5netcdf")
        elif suffix == ".csv":
            result.to_dataframe().to_csv(tmp, index=False)
        else:
            result.to_dataframe().to_parquet(tmp, index=False)
    return path
