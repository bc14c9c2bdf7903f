"""The study plan: the one-at-a-time parameter study around Case 3, the mode counts of the convergence study,
the extra runs on flexibility, and the closed forms the report compares with.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any
if TYPE_CHECKING:
    from ..scenario import Scenario
from .cases import case
from .data import PAPER_REFIT, REFERENCE_CASE, SPECIMEN, TABLE1

__all__ = [
    "CONVERGENCE_MODES",
    "FLEX_HEIGHTS",
    "FLEX_STIFFNESS",
    "N_FIGURES",
    "OPEN_ENGAGED_LIMIT",
    "PARAMETER_STUDY",
]


#: The one-at-a-time study around Case 3 (section 2, seven parameters).
#: name -> (label, scenario path(s), values [SI], display scale, display unit, xscale)
PARAMETER_STUDY: dict[str, dict[str, Any]] = {
    "height": {"label": "beam height h", "path": "beam.height", "unit": "mm", "scale": 1e3, "xscale": "linear",
               "values": [2.0e-3, 2.5e-3, 3.03e-3, 3.5e-3, 4.0e-3]},
    "modulus": {"label": "Young's modulus E", "path": "beam.youngs_modulus", "unit": "MPa", "scale": 1e-6,
                "xscale": "linear", "values": [1000e6, 1400e6, 1834e6, 2300e6, 2800e6]},
    "stiffness": {"label": "contact stiffness k", "path": "contactors.0.stiffness", "unit": "N/m", "scale": 1.0,
                  "xscale": "log", "values": [1000.0, 2000.0, 4030.0, 8000.0, 16000.0, 32000.0, 64000.0]},
    "location": {"label": "contact location a/L", "path": "contactors.0.position_ratio", "unit": "-", "scale": 1.0,
                 "xscale": "linear", "values": [0.2, 0.35, 0.484, 0.65, 0.8, 0.95, 1.0]},
    "damping": {"label": "damping ratio (free state; contact state scaled alike)", "path": "damping",
                "unit": "%", "scale": 100.0, "xscale": "log", "values": [0.00275, 0.0055, 0.011, 0.022, 0.044]},
    "duration": {"label": "pulse duration t1", "path": "excitation.duration", "unit": "ms", "scale": 1e3,
                 "xscale": "linear", "values": [5e-3, 10e-3, 15e-3, 20e-3, 30e-3, 45e-3, 60e-3]},
    "clearance": {"label": "clearance c", "path": "contactors.0.gap", "unit": "mm", "scale": 1e3, "xscale": "linear",
                  "values": [0.0, 0.102e-3, 0.229e-3, 0.432e-3, 0.686e-3, 1.0e-3]},
}
_BASE_VALUE = {"height": 3.03e-3, "modulus": 1834e6, "stiffness": 4030.0, "location": 0.484, "damping": 0.011,
               "duration": 15e-3, "clearance": 0.229e-3}
CONVERGENCE_MODES = (2, 4, 8, 16)
#: Figures the report draws: Figs. 4-8 analogues, Case 3 detail, Case 0 decay, convergence, one per parameter.
N_FIGURES = 8 + len(PARAMETER_STUDY)
#: Engaged-while-open time [s] above which a run is flagged in the report.
OPEN_ENGAGED_LIMIT = 5e-4
#: Extra runs for "the more flexible the structure, the more sensitive to k": h factors x k factors.
FLEX_HEIGHTS = (0.8, 1.2)
FLEX_STIFFNESS = (0.5, 2.0)


def _param_values(name: str, value: float) -> dict[str, Any]:
    spec = PARAMETER_STUDY[name]
    if name == "damping":
        ratio = SPECIMEN["damping_contact"] / SPECIMEN["damping_free"]
        return {"damping.free": value, "damping.contact": value * ratio}
    return {spec["path"]: value}


def _table1_scenarios() -> dict[int, Scenario]:
    """The Table 1 cases as run in the reproduction: no-contactor cases also record w at 0.4840 L."""
    out = {}
    for c in TABLE1:
        sc = case(c.number)
        if not sc.contactors:
            sc = sc.with_values({"output.point_ratios": [SPECIMEN["contact_position_ratio"], 1.0]})
        out[c.number] = sc
    return out


def _refit_variants(base: Scenario) -> dict[str, dict[str, Any]]:
    amp = base.excitation.amplitude
    k7 = PAPER_REFIT["contact_stiffness"]
    return {
        "raw parameters (Case 3)": {},
        "k = 7000 N/m": {"contactors.0.stiffness": k7},
        "pulse +20 %": {"excitation.amplitude": PAPER_REFIT["pulse_factor"] * amp},
        "k = 7000 N/m and pulse +20 %": {"contactors.0.stiffness": k7,
                                         "excitation.amplitude": PAPER_REFIT["pulse_factor"] * amp},
    }


def _flex_values(hf: float, kf: float) -> dict[str, float]:
    return {"beam.height": hf * SPECIMEN["height"], "contactors.0.stiffness": kf * SPECIMEN["contact_stiffness"]}


def _all_scenarios() -> list[Scenario]:
    """Every scenario :func:`reproduce` runs, in order (duplicates included)."""
    scs = _table1_scenarios()
    out = list(scs.values())
    out += [scs[n].with_values({"solver.modes": m}) for n in (12, 3) for m in CONVERGENCE_MODES]
    base = scs[REFERENCE_CASE]
    out += [base.with_values(_param_values(name, v)) for name, spec in PARAMETER_STUDY.items() for v in spec["values"]]
    out += [base.with_values(_flex_values(hf, kf)) for hf in FLEX_HEIGHTS for kf in (*FLEX_STIFFNESS, 1.0)]
    out += [base.with_values(v) if v else base for v in _refit_variants(base).values()]
    return out


def _closed_form_cantilever(beam: Any, n: int) -> list[float]:
    """Clamped-free Euler-Bernoulli frequencies [Hz] from cos(bL) cosh(bL) = -1 (independent check)."""
    from scipy.optimize import brentq

    roots = []
    for i in range(1, n + 1):
        guess = (2 * i - 1) * math.pi / 2
        roots.append(brentq(lambda z: math.cos(z) * math.cosh(z) + 1.0, guess - 0.5, guess + 0.5) if i < 6 else guess)
    L = beam.length
    c = math.sqrt(beam.bending_stiffness / beam.mass_per_length)
    return [z**2 / (2 * math.pi * L**2) * c for z in roots]


def _quasi_static_deflection(beam: Any, x: float, q: float) -> float:
    """Static deflection of a uniformly loaded cantilever at x: q x^2 (6L^2 - 4Lx + x^2) / (24 EI)."""
    L = beam.length
    return q * x**2 * (6 * L**2 - 4 * L * x + x**2) / (24 * beam.bending_stiffness)
