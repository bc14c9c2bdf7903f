"""Finite-element references for the dissipation targets: contactor dashpots, Rayleigh and free-mode damping.

Used ONLY by the test-suite; like :mod:`fe_reference` it imports nothing from
``impactbeam`` (the scenarios below are plain mappings that the tests hand to
``impactbeam.parse_scenario``), so agreement is evidence.

The cases
---------
The paper's specimen (Xu & Ervin 2013, Table 1: ABS cantilever, L = 109.2 mm,
9.93 x 3.03 mm, E = 1834 MPa, rho = 951.98 kg/m^3), its contactor at
0.4840 L above the beam with the 0.229 mm gap of Case 3, and the Case 3 pulse
(15 g, 15 ms half-sine base acceleration along +w), run for 0.1 s, with

* a soft stop, k = 4030 N/m (Case 3), and a stiff stop, k = 1e5 N/m;
* one of three dissipations:

  - ``dashpot``: an undamped beam and a dashpot in parallel with the stop,
    c = 1.0 N s/m (soft) or 4.0 N s/m (stiff): the force is ``k d + c d'``
    while it is positive, the contact ends when it reaches 0. In the engaged
    state's FE modes (80 elements) the dashpot gives the two modes that hold
    the stop's strain energy the ratios ``c W(a)^2 / (2 omega)`` = 3.7 % and
    12.6 % (soft: 108 and 445 Hz) or 5.7 % and 11.2 % (stiff: 1157 and 2415 Hz).
    (With c = 5 N s/m the stiff stop has, near 33 ms, a cluster of contacts
    of a few mN while the beam leaves exactly as fast as the dashpot relaxes,
    ``d' = -k d / c``, whose count depends on the mesh; c = 4 N s/m has none);
  - ``rayleigh``: ``C = alpha M + beta K`` of each state (K with the engaged
    stop), alpha = 13.5 1/s, beta = 6e-6 s: 1.95 %, 0.97 %, 1.99 % on the
    free state's first three modes (57.0, 357.0, 999.7 Hz);
  - ``free_modes``: the free state's modal damping matrix with 1.5 % on every
    mode, kept unchanged while the stop is engaged (code_aster's convention).

How the reference is computed and converged
-------------------------------------------
:func:`fe_reference.fe_transient_exact`: Hermite-cubic elements, the model
integrated EXACTLY in time between events (matrix exponential of each state's
first-order system, events by Brent's method on the exact solution), so the
only discretisation is the mesh. Each case is run on 80 and 160 elements
(a node at the contactor); the cached values are the 160-element ones, and
the differences between the two meshes are cached with them as the
reference's own convergence (``convergence``). The output grid (2 us) only
samples the result; it does not change it (checked: 1e-14 s on event times
between 1 and 2 us grids).

Cached (``tests/data/fe_dissipation.json`` and ``fe_dissipation_w.npz``),
per case: the scenario, the events (time, kind, contactor), the contact
intervals, the largest contact force of every contact interval (located on
the exact solution) and the first one, the deflection at the contactor on a
20 us grid, the energy the dashpots dissipated, and the convergence measures.
Regenerate with ``python tests/fe_dissipation.py`` (about 15 minutes).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

import fe_reference as fr

DATA = Path(__file__).resolve().parent / "data"
JSON_FILE = DATA / "fe_dissipation.json"
HISTORY_FILE = DATA / "fe_dissipation_w.npz"

#: The specimen, SI.
LENGTH, WIDTH, HEIGHT, MODULUS, DENSITY = 0.1092, 9.93e-3, 3.03e-3, 1834e6, 951.98
POSITION_RATIO, GAP = 0.4840, 0.229e-3
PULSE = {"amplitude": 15 * 9.80665, "duration": 0.015}
END_TIME = 0.1
#: Stops: stiffness [N/m] and the dashpot of the ``dashpot`` cases [N s/m].
STOPS = {"soft": (4030.0, 1.0), "stiff": (1e5, 4.0)}
RAYLEIGH = (13.5, 6e-6)
FREE_MODES = 0.015
MESHES = (80, 160)
GRID = 2e-6
HISTORY_STEP = 2e-5

CASES = [f"{model}_{stop}" for model in ("dashpot", "rayleigh", "free_modes") for stop in STOPS]


def scenario(name: str) -> dict[str, Any]:
    """The case as an impactbeam scenario mapping (for ``impactbeam.parse_scenario``)."""
    model, stop = name.rsplit("_", 1)
    k, c = STOPS[stop]
    contactor: dict[str, Any] = {"position_ratio": POSITION_RATIO, "stiffness": k, "gap": GAP, "side": "above"}
    if model == "dashpot":
        contactor["damping"] = c
        damping: dict[str, Any] = {"model": "modal", "free": 0.0, "contact": 0.0}
    elif model == "rayleigh":
        damping = {"model": "rayleigh", "alpha": RAYLEIGH[0], "beta": RAYLEIGH[1]}
    else:
        damping = {"model": "free_modes", "free": FREE_MODES}
    return {
        "name": name,
        "beam": {"length": LENGTH, "width": WIDTH, "height": HEIGHT, "youngs_modulus": MODULUS, "density": DENSITY},
        "supports": {"left": "clamped", "right": "free"},
        "contactors": [contactor],
        "damping": damping,
        "excitation": {"kind": "base_acceleration", "shape": "half_sine", "amplitude": PULSE["amplitude"],
                       "duration": PULSE["duration"]},
        "solver": {"end_time": END_TIME},
        "output": {"point_ratios": [POSITION_RATIO, 1.0]},
    }


def fe_run(name: str, n_elements: int, dt: float = GRID) -> fr.ExactResult:
    """The exact-in-time FE run of a case on ``n_elements`` elements."""
    model, stop = name.rsplit("_", 1)
    k, c = STOPS[stop]
    EI = MODULUS * WIDTH * HEIGHT**3 / 12.0
    rhoA = DENSITY * WIDTH * HEIGHT
    damping = {"dashpot": {"model": "modal"},
               "rayleigh": {"model": "rayleigh", "alpha": RAYLEIGH[0], "beta": RAYLEIGH[1]},
               "free_modes": {"model": "free_modes", "free": FREE_MODES}}[model]
    a = POSITION_RATIO * LENGTH
    contactor = {"position": a, "stiffness": k, "gap": GAP, "side": "above", "damping": c if model == "dashpot" else 0.0}
    return fr.fe_transient_exact(
        LENGTH, EI, rhoA, left=(math.inf, math.inf), right=(0.0, 0.0), contactors=[contactor],
        load={"kind": "base_acceleration", "shape": "half_sine", **PULSE}, damping=damping,
        dt=dt, t_end=END_TIME, n_elements=n_elements, output_x=[a, LENGTH],
    )


def summarise(r: fr.ExactResult) -> dict[str, Any]:
    """What the tests compare: events, contact intervals, peak forces, the deflection history at the contactor."""
    starts = [t for t, kind, _ in r.events if kind == "impact"]
    ends = [t for t, kind, _ in r.events if kind == "rebound"]
    step = int(round(HISTORY_STEP / (r.t[1] - r.t[0])))
    return {
        "events": [[float(t), kind, int(i)] for t, kind, i in r.events],
        "n_impacts": len(starts),
        "contact_start": [float(t) for t in starts],
        "contact_end": [float(t) for t in ends],
        "peak_force": [[float(t), float(F)] for t, F, _ in r.peaks],
        "first_peak_force": float(r.peaks[0][1]) if r.peaks else None,
        "dashpot_energy": float(r.dashpot[-1]),
        "w_contactor": r.w[::step, 0].copy(),
        "event_residual": float(r.event_residual),
    }


def _convergence(coarse: dict[str, Any], fine: dict[str, Any]) -> dict[str, Any]:
    """Differences between two meshes: the reference's own error estimate."""
    te_c = np.array([e[0] for e in coarse["events"]])
    te_f = np.array([e[0] for e in fine["events"]])
    n = min(te_c.size, te_f.size)
    w_peak = float(np.max(np.abs(fine["w_contactor"])))
    return {
        "meshes": list(MESHES),
        "impact_count_change": fine["n_impacts"] - coarse["n_impacts"],
        "event_time_change": float(np.max(np.abs(te_c[:n] - te_f[:n]), initial=0.0)),
        "first_peak_force_change": abs(fine["first_peak_force"] - coarse["first_peak_force"]) / fine["first_peak_force"],
        "deflection_change": float(np.max(np.abs(fine["w_contactor"] - coarse["w_contactor"]))) / w_peak,
    }


def reference(name: str) -> dict[str, Any]:
    """The cached reference of a case (module notes); ``w_contactor`` on the grid ``t_history``."""
    meta = json.loads(JSON_FILE.read_text())
    out = dict(meta["cases"][name])
    with np.load(HISTORY_FILE) as data:
        out["w_contactor"] = data[name]
        out["t_history"] = np.arange(out["w_contactor"].size) * HISTORY_STEP
    out["scenario"] = scenario(name)
    return out


def generate(names: list[str] | None = None) -> None:
    """Run every case on both meshes and write the cache."""
    meta: dict[str, Any] = {"meshes": list(MESHES), "grid": GRID, "history_step": HISTORY_STEP, "cases": {}}
    histories: dict[str, np.ndarray] = {}
    if JSON_FILE.exists() and names:
        meta = json.loads(JSON_FILE.read_text())
        with np.load(HISTORY_FILE) as data:
            histories = {k: data[k] for k in data.files}
    for name in names or CASES:
        runs = [summarise(fe_run(name, n)) for n in MESHES]
        fine = runs[-1]
        histories[name] = fine.pop("w_contactor")
        fine["convergence"] = _convergence(runs[0], {**fine, "w_contactor": histories[name]})
        meta["cases"][name] = fine
        print(name, fine["n_impacts"], "impacts", json.dumps(fine["convergence"]), flush=True)
    DATA.mkdir(exist_ok=True)
    JSON_FILE.write_text(json.dumps(meta, indent=1) + "\n")
    np.savez_compressed(HISTORY_FILE, **histories)


if __name__ == "__main__":
    generate(sys.argv[1:] or None)
