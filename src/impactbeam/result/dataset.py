"""A simulation result as a CF-style :class:`xarray.Dataset` with its provenance (``to_xarray``, netCDF files)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from .._io import json_text

__all__ = ["result_dataset", "result_attrs", "provenance"]

_REFERENCE = (
    "W. Xu and E. K. Ervin, Parameters affecting the transient response of an impacting beam, "
    "Shock and Vibration 20 (2013)"
)


def provenance(title: str, command: str, source: str) -> dict[str, str]:
    """The CF attributes every file of results carries: what made it, when, with which version.

    Parameters
    ----------
    title : str
    command : str
        The command or function that made it (``"simulate"``, ``"bifurcation"``).
    source : str
        The method, after ``"impactbeam <version>: "``.
    """
    import datetime

    from .. import __version__

    return {
        "Conventions": "CF-1.10",
        "title": title,
        "history": f"{datetime.datetime.now(datetime.timezone.utc).isoformat(timespec='seconds')}: "
                   f"impactbeam {__version__} {command}",
        "source": f"impactbeam {__version__}: {source}",
        "references": _REFERENCE,
        "impactbeam_version": __version__,
    }


def result_attrs(result: Any, report: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The attributes of a result's files (netCDF, Parquet): provenance, scenario, metrics, solver settings.

    Parameters
    ----------
    result : SimulationResult
    report : mapping, optional
        The metrics as a command reported them (with convergence, impact
        statistics, fatigue, seed) and, under ``"warnings"``, every warning
        it gave: the ``metrics`` and ``warnings`` attributes then hold these
        instead of ``result.metrics()`` and the run's own warnings.
    """
    metrics = result.metrics() if report is None else {k: v for k, v in report.items() if k != "warnings"}
    warned = result.warnings if report is None else report.get("warnings", result.warnings)
    return {
        **provenance(f"impactbeam simulation: {result.scenario_name}", "simulate",
                     "exact piecewise modal solution (closed form between exact events)"),
        "status": result.status,
        "message": result.message,
        "warnings": "; ".join(warned),
        "n_modes": result.n_modes,
        "sign_convention": "w from the rest position; contactor 'below' engaged while w(a) < -gap",
        "scenario": result.scenario.to_toml() if result.scenario is not None else "",
        "metrics": json_text(metrics, indent=2),
        **{f"solver_{k}": v for k, v in result.options.items()},
    }


def result_dataset(result: Any) -> Any:
    """The dataset of :meth:`impactbeam.result.SimulationResult.to_xarray`.

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    xarray.Dataset
    """
    import xarray as xr

    n_c = len(result.contactors)
    kind = np.array([1 if e.kind == "impact" else 0 for e in result.events], dtype=np.int8)
    flag = {"flag_values": np.array([0, 1], dtype=np.int8)}
    ds = xr.Dataset(
        {
            "w": (("time", "point"), result.w, {"units": "m", "long_name": "deflection w(x, t)"}),
            "w_t": (("time", "point"), result.w_t, {"units": "m s-1", "long_name": "velocity w_t(x, t)"}),
            "contact_force": (
                ("time", "contactor"), result.contact_force, {"units": "N", "long_name": "contact force on the beam"}
            ),
            "engaged": (("time", "contactor"), result.engaged.astype(np.int8),
                        {"long_name": "contactor state", **flag, "flag_meanings": "free engaged"}),
            "w_contactor": (
                ("time", "contactor"), result.w_contact, {"units": "m", "long_name": "deflection at the contactor"}
            ),
            "modal_displacement": (
                ("time", "mode"), result.eta,
                {"long_name": "modal displacement in the basis of the current state",
                 "comment": "mass-normalised modal coordinate: unit m kg^(1/2), which UDUNITS cannot express"},
            ),
            "modal_velocity": (
                ("time", "mode"), result.eta_t,
                {"long_name": "modal velocity", "comment": "unit m kg^(1/2) s^-1"},
            ),
            "event_time": (("event",), np.array([e.time for e in result.events], dtype=float),
                           {"units": "s", "long_name": "event time"}),
            "event_kind": (("event",), kind, {"long_name": "event kind", **flag,
                                              "flag_meanings": "rebound impact"}),
            "event_contactor": (("event",), np.array([e.contactor for e in result.events], dtype=np.int32),
                                {"long_name": "contactor of the event"}),
        },
        coords={
            "time": ("time", result.time, {"units": "s", "long_name": "time", "standard_name": "time"}),
            "point": ("point", result.points, {"units": "m", "long_name": "position along the beam"}),
            "contactor": ("contactor", np.arange(n_c, dtype=np.int32), {"long_name": "contactor index"}),
            "contactor_position": (
                "contactor", np.array([c.position for c in result.contactors], dtype=float),
                {"units": "m", "long_name": "contactor position"},
            ),
            "mode": ("mode", np.arange(1, result.solution.n_modes + 1, dtype=np.int32),
                     {"long_name": "mode number"}),
            "event": ("event", np.arange(len(result.events), dtype=np.int32), {"long_name": "event number"}),
        },
        attrs=result_attrs(result),
    )
    for name, arr in result.energy.items():
        ds[f"energy_{name}"] = ("time", arr, {"units": "J", "long_name": f"energy: {name.replace('_', ' ')}"})
    fields = result._field_grid  # the same arrays as the CSV and Parquet tables
    if "moment" in fields:
        ds["bending_moment"] = (("time", "point"), fields["moment"],
                                {"units": "N m", "long_name": "bending moment EI w''"})
    if "stress" in fields:
        ds["bending_stress"] = (("time", "point"), fields["stress"],
                                {"units": "Pa", "long_name": "outer-fibre bending stress M c / I"})
    return ds
