"""SimulationResult: the exact solution, its events, and sampled histories on request."""

from __future__ import annotations

import functools
import os
from dataclasses import dataclass, field
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from .._memory import check_output_size, sample_count
from ..model.beam import Beam, Contactor
from ..exceptions import ParameterError
from .timegrid import cumulative_power

if TYPE_CHECKING:
    import xarray as xr

    from ..solver.solution import Event, ModalState, PiecewiseSolution

__all__ = ["SimulationResult", "STRESS_METRIC_UNITS"]

#: Units of the metrics that ``[output] fields = ["stress"]`` adds to :meth:`SimulationResult.metrics`.
STRESS_METRIC_UNITS = {"max_bending_stress": "Pa", "max_bending_stress_time": "s", "max_bending_stress_position": "m"}

_CHUNK = 65536  # samples evaluated per call of the compiled sampler


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
    beam : Beam
    contactors : tuple of Contactor
    n_modes : int
        Modes per state used.
    time_step, end_time : float, [s]
        Output step and end of the run (``solver.time_step``, ``solver.end_time``).
    scenario_name : str
    options : dict
        The solver options of the run (stored in result files).
    rerun : callable, optional
        ``rerun(n_modes)`` repeats the run with another mode count (for :attr:`convergence`).
    tolerance : float
        Relative change above which the result is flagged as not converged.
    scenario : Scenario, optional
        The scenario of the run (its TOML text goes into result files).
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
        ``input_work``, ``dissipated`` and ``dashpots`` (cumulative, integrated
        on the exact solution: the same at any output step), ``total`` and
        ``residual`` (``total(0) + input_work - dissipated - dashpots - total``).
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
        from ..solver.convergence import NO_ESTIMATE, unconverged_message

        out = tuple(self.solution.warnings)
        conv = self.__dict__.get("_convergence")
        if conv is None and "_convergence" in self.__dict__:
            out += (NO_ESTIMATE,)
        if conv is not None and not self.converged:
            out += (unconverged_message(self.n_modes, conv, self.tolerance, self.unseen_flexibility),)
        return out

    # ------------------------------------------------------------------ convergence in the modes
    def set_convergence(self, changes: dict[str, float], peak_forces: Any = None, counts: tuple[int, ...] = ()) -> None:
        """Record the error estimate of the metrics (and of the impacts' peak forces) from runs with fewer modes.

        Parameters
        ----------
        changes : dict of str -> float
            Metric name -> estimated relative error (see :attr:`convergence`).
        peak_forces : array_like, (n_impacts,), optional
            Estimated relative error of each impact's peak force (see :attr:`impact_convergence`).
        counts : tuple of int
            The mode counts the estimate compared with.
        """
        self.__dict__["_convergence"] = dict(changes)
        self.__dict__["_impact_convergence"] = None if peak_forces is None else np.asarray(peak_forces, dtype=float)
        self.__dict__["_convergence_counts"] = tuple(int(c) for c in counts)

    def estimate_convergence(self, progress: Callable[[float], None] | None = None) -> dict[str, float] | None:
        """:attr:`convergence`, computed now if it is not yet (the run again at two smaller counts).

        Parameters
        ----------
        progress : callable, optional
            Called with the re-runs done (:func:`~impactbeam.solver.convergence.estimate_by_reruns`).
        """
        if "_convergence" not in self.__dict__:
            from .._warnings import emit_user_level_warning as warn
            from ..solver.convergence import estimate_by_reruns, length_scale

            if self.rerun is None or self.n_modes <= 1:
                if self.rerun is not None:  # one mode: nothing coarser to compare with, said, not silent
                    self.__dict__["_convergence"] = None
                    warn(self.warnings[-1])
                return None
            self.set_convergence(*estimate_by_reruns(self.metrics(), self.rerun, self.n_modes, self.end_time,
                                                     progress, length_scale(self.contactors)))
            if not self.converged:
                warn(self.warnings[-1])
        return self.__dict__["_convergence"]

    @property
    def convergence(self) -> dict[str, float] | None:
        """Estimated relative error of each Table-2 metric (modal truncation).

        The largest change against two runs with fewer modes (about ``n / 2``
        and ``3 n / 4``: :func:`~impactbeam.solver.convergence.coarser_counts`,
        :attr:`convergence_counts`), computed on first access (with
        ``solver.modes = "auto"``, during the search); what it guarantees and
        where it does not: :mod:`impactbeam.solver.convergence`.
        None when it cannot be computed (one mode, said in :attr:`warnings`; a result without a re-run).
        """
        return self.estimate_convergence()

    @property
    def impact_convergence(self) -> np.ndarray | None:
        """Estimated relative error of each impact's peak force, one per row of :attr:`impacts`.

        1 for an impact that has no overlapping impact in a coarser run (it
        may not exist in the converged answer); see :attr:`convergence`.
        """
        if self.convergence is None:
            return None
        return self.__dict__.get("_impact_convergence")

    @property
    def convergence_counts(self) -> tuple[int, ...]:
        """The mode counts the estimate of :attr:`convergence` compared with."""
        self.convergence  # noqa: B018 - computes it
        return self.__dict__.get("_convergence_counts", ())

    @property
    def converged(self) -> bool:
        """True when every Table-2 metric's estimated error is below ``solver.tolerance``, the estimate seeing
        every contactor (:attr:`unseen_flexibility` None)."""
        conv = self.convergence
        return conv is not None and max(conv.values()) < self.tolerance and self.unseen_flexibility is None

    @property
    def unseen_flexibility(self) -> tuple[int, float] | None:
        """A contactor the retained modes do not reach, and the share of its flexibility outside them
        (:func:`~impactbeam.solver.convergence.unseen_flexibility`); None when they reach every contactor."""
        if "_unseen" not in self.__dict__:
            from ..solver.convergence import unseen_flexibility

            sol = self.solution
            space = sol.packed.space if hasattr(sol, "packed") else getattr(getattr(sol, "ref", None), "space", None)
            self.__dict__["_unseen"] = None if space is None else unseen_flexibility(space, self.n_modes)
        return self.__dict__["_unseen"]

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
        from .. import _html
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
        return np.arange(sample_count(self.end_time, self.time_step)) * self.time_step

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
            out.update(eta=np.empty((t.size, nm)), eta_t=np.empty((t.size, nm)), energies=np.empty((t.size, 5)))
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
        dash = self.solution.dashpots
        for i, c in enumerate(self.contactors):
            f = c.force(self.w_contact[:, i], self.w_t_contact[:, i], dash[i])
            force[:, i] = np.where(self.engaged[:, i], f, 0.0)
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
        kinetic, modal_strain = en[:, 0], en[:, 1]
        contactor_energy = np.zeros(self.time.size)
        spring_at_zero_gap = np.zeros(self.time.size)
        for i, c in enumerate(self.contactors):
            wc = self.w_contact[:, i]
            g = c.gap - c.direction * wc
            on = self.engaged[:, i]
            contactor_energy += np.where(on, 0.5 * c.stiffness * g**2, 0.0)
            spring_at_zero_gap += np.where(on, 0.5 * c.stiffness * wc**2, 0.0)
        contactor_energy[np.isnan(kinetic)] = np.nan  # after a stop by the chattering guard, as every sample
        strain = modal_strain - spring_at_zero_gap
        total = kinetic + strain + contactor_energy
        input_work, dissipated, dashpot_work = cumulative_power(self, self.time).T  # exact, not the output grid's
        t_rel, lost = self.solution.release_losses()
        at_release = np.cumsum(np.bincount(np.searchsorted(self.time, t_rel, side="left"), weights=lost,
                                           minlength=self.time.size + 1)[: self.time.size])
        dashpots = dashpot_work + at_release
        return {
            "kinetic": kinetic, "strain": strain, "contactor": contactor_energy, "input_work": input_work,
            "dissipated": dissipated, "dashpots": dashpots, "total": total,
            "residual": total[0] + input_work - dissipated - dashpots - total,
        }

    # ------------------------------------------------------------------ dense output
    def check_points(self, x: Any) -> np.ndarray:
        """Positions as a float array; ParameterError for a point off the beam.

        Parameters
        ----------
        x : float or array_like, [m]

        Returns
        -------
        ndarray, [m]
        """
        x = _one_dimensional("x", x)
        L = self.beam.length
        bad = ~np.isfinite(x) | (x < 0.0) | (x > L * (1.0 + 1e-12))
        if bad.any():
            raise ParameterError(f"x: {x[bad][0]:g} m is off the beam [0, {L:g}] m")
        return x

    def displacement(self, x: Any, t: Any) -> np.ndarray:
        """Exact deflection ``w(x, t)`` [m] at any positions and times: array (n_x, n_t).

        Parameters
        ----------
        x : float or array_like, [m]
            Positions on the beam.
        t : float or array_like, [s]
            Times in ``[0, end_time]``.

        Returns
        -------
        ndarray, (n_x, n_t), [m]
            Times after a chattering stop give NaN.

        Raises
        ------
        ParameterError
            A point off the beam or a time outside ``[0, end_time]``.
        """
        x = self.check_points(x)
        t = self.solution.check_times(_one_dimensional("t", t), self.end_time)
        return self.solution.sample(x, t).w.T

    def velocity(self, x: Any, t: Any) -> np.ndarray:
        """Exact velocity ``w_t(x, t)`` [m/s]: array (n_x, n_t).

        Parameters
        ----------
        x : float or array_like, [m]
            Positions on the beam.
        t : float or array_like, [s]
            Times in ``[0, end_time]``.

        Returns
        -------
        ndarray, (n_x, n_t), [m/s]
            See :meth:`displacement` for NaN and errors.
        """
        x = self.check_points(x)
        t = self.solution.check_times(_one_dimensional("t", t), self.end_time)
        return self.solution.sample(x, t).w_t.T

    def bending_moment(self, points: Any, times: Any, *, static_correction: bool = True) -> np.ndarray:
        """Bending moment ``EI w''`` [N m] at any positions and times: array (n_x, n_t).

        Parameters
        ----------
        points : float or array_like, [m]
            Positions on the beam.
        times : float or array_like, [s]
            Times in ``[0, end_time]``.
        static_correction : bool
            The mode-acceleration method (default); see :mod:`impactbeam.result.stress`.

        Returns
        -------
        ndarray, (n_x, n_t), [N m]
        """
        from .stress import bending_moment

        self._require_exact("bending_moment")
        return bending_moment(self, points, times, static_correction=static_correction)

    def bending_stress(self, points: Any, times: Any, *, static_correction: bool = True) -> np.ndarray:
        """Outer-fibre bending stress ``M c / I`` [Pa] at any positions and times: array (n_x, n_t).

        Parameters
        ----------
        points : float or array_like, [m]
            Positions on the beam.
        times : float or array_like, [s]
            Times in ``[0, end_time]``.
        static_correction : bool
            As for :meth:`bending_moment`.

        Returns
        -------
        ndarray, (n_x, n_t), [Pa]
        """
        from .stress import bending_stress

        self._require_exact("bending_stress")
        return bending_stress(self, points, times, static_correction=static_correction)

    def _require_exact(self, what: str) -> None:
        """ParameterError for a moment or stress of a ``method = "ivp"`` run (its solution has no state space)."""
        if self.options.get("method", "exact") != "exact":
            raise ParameterError(
                f'{what}: moments and stresses come from the exact solution; this result was computed with '
                f'method = "{self.options.get("method")}" (the reference path): run simulate(..., method="exact")'
            )

    @functools.cached_property
    def _field_grid(self) -> dict[str, np.ndarray]:
        """The ``[output] fields`` beyond w and w_t on the output grid: ``moment`` [N m], ``stress`` [Pa], (n_t, n_p)."""
        out = {}
        if "moment" in self.fields:
            out["moment"] = self.bending_moment(self.points, self.time).T
        if "stress" in self.fields:
            out["stress"] = self.bending_stress(self.points, self.time).T
        return out

    def final_state(self) -> ModalState:
        """The modal state at the end of the run, to start another from (``simulate(..., start=)``).

        Returns
        -------
        ModalState
            At ``solution.t_end``, in the free state's basis. Only for the exact method.
        """
        from ..solver.solution import basis_signature

        if not hasattr(self.solution, "modal_state"):
            raise ParameterError('final_state: only a run with method = "exact" has a modal state to continue from')
        basis = basis_signature(self.beam, self.contactors, self.n_modes, self.options.get("basis", "enriched"),
                                self.solution.excitation)
        return self.solution.modal_state(self.solution.t_end, basis)

    # ------------------------------------------------------------------ derived
    def metrics(self, *, impacts: bool = True) -> dict[str, Any]:
        """Response metrics (keys of ``impactbeam simulate --json``); see :mod:`impactbeam.result.metrics`.

        Parameters
        ----------
        impacts : bool
            Include the per-impact table (``"impacts"``); sweeps leave it out.
        """
        from .metrics import compute_metrics, warn_unresolved

        out = compute_metrics(self, impacts=impacts)
        warn_unresolved(self, out)
        if "stress" in self.fields:
            self._require_exact("max_bending_stress")
            from .stress import max_bending_stress

            value, when, where = max_bending_stress(self)
            out.update(max_bending_stress=value, max_bending_stress_time=when, max_bending_stress_position=where)
        return out

    @property
    def fields(self) -> tuple[str, ...]:
        """The fields of result files asked for by the scenario's ``[output] fields`` (canonical names)."""
        return tuple(getattr(self.scenario, "output_fields", ()) or ())

    @property
    def impacts(self):
        """The per-impact table as a :class:`pandas.DataFrame` (one row per contact interval).

        Columns: ``contactor``, ``start`` [s], ``end`` [s], ``duration`` [s],
        ``peak_force`` [N], ``impulse`` [N s]; exact (closed form), see
        :mod:`impactbeam.result.metrics`.
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
        from .dataset import result_dataset

        return result_dataset(self)

    def to_dataframe(self):
        """Wide table: time, w and w_t at each point, contact force per contactor, energies, and the
        bending moment ``M`` and stress ``sigma`` at each point when ``[output] fields`` asks for them."""
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
        for name, (label, unit) in (("moment", ("M", "N m")), ("stress", ("sigma", "Pa"))):
            for j, x in enumerate(self.points if name in self._field_grid else ()):
                cols[f"{label}(x={x:.6g}) [{unit}]"] = self._field_grid[name][:, j]
        return pd.DataFrame(cols)

    def plot(self, path: str | os.PathLike | None = None, **kwargs):
        """Response figure; see :func:`impactbeam.plot.plot_result`.

        Parameters
        ----------
        path : str or path-like, optional
            Also save the figure there (format from the suffix).
        **kwargs
            Passed to :func:`impactbeam.plot.plot_result`.

        Returns
        -------
        PlotHandles
        """
        from ..plot.response import plot_result

        return plot_result(self, path, **kwargs)


def _one_dimensional(name: str, values: Any) -> np.ndarray:
    """``values`` as a 1-D float array; ParameterError naming ``name`` for a 2-D array or a non-number."""
    try:
        arr = np.atleast_1d(np.asarray(values, dtype=float))
    except (TypeError, ValueError):
        raise ParameterError(f"{name}: expected numbers, got {type(values).__name__}") from None
    if arr.ndim != 1:
        raise ParameterError(f"{name}: expected a number or a 1-D sequence, got an array of shape {arr.shape}")
    return arr
