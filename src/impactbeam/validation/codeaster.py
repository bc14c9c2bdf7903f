"""code_aster's validation tests of this problem class: SDLX400, SDNL32 and SDNL104.

The scenarios are written here as mappings (the files of
``examples/validation/`` hold the same, checked by the tests), and each case
compares impactbeam with the test's published values
(:mod:`.references`). Tolerances and why:

* SDLX400 (analytical frequencies of the Euler-Bernoulli beam, four digits):
  code_aster's PRECISION of its Euler-Bernoulli run (sdlx400a), 1e-3 to 5e-3;
  impactbeam's modes are exact, so the difference is the references' rounding.
* SDNL32 (the VPCS tip deflections, three digits): 5e-5 m, 1 % of the peak
  deflection. code_aster's PRECISIONs (1e-3 to 1.5e-2 relative) are tuned to
  its own 10-element run, tighter than the references' own rounding (up to
  5e-6 m, 0.7 % at 12 ms for k = 18000 N/m), so they do not apply to a
  converged solver. The converged finite-element model of the test suite
  (Euler-Bernoulli, exact in time, free-mode damping of 1 %) lies within
  3.3e-5 m of the table, the largest difference at 3 ms for k = 18000 N/m,
  where code_aster's own result differs by as much (its PRECISION there is 1 %).
* SDNL104 (a 10-element Newmark run, dt = 1e-4 s): code_aster's own bands for
  its modal runs against it, 8 % (deflection) and 4 % (velocity) for five
  modes, 2 % for its runs with a static mode, which impactbeam's converged
  deflection must meet; its converged velocity gets 4 %, because the
  reference velocity itself carries an error of a few % (its mesh and time
  step: see the validation manual).
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from .core import Check, case_result, register, sample
from .references import SDLX400, SDNL32, SDNL104

__all__ = ["sdlx400_data", "sdnl32_data", "sdnl104_data", "SDNL32_TOLERANCE"]

#: Absolute tolerance of the SDNL32 tip deflections [m] (module notes).
SDNL32_TOLERANCE = 5e-5
_SDNL32_BASIS = "5e-5 m = 1 % of the peak; the references have 3 digits"
_L32 = 0.783
_R104 = 0.1


def _vpcs_beam() -> dict[str, Any]:
    """The beam of SDLX400 and SDNL32 (VPCS): L = 0.783 m, 14 mm square, E = 6.7e10 Pa, rho = 2400 kg/m^3."""
    return {"length": _L32, "width": "14 mm", "height": "14 mm", "youngs_modulus": 6.7e10, "density": 2400.0}


def sdlx400_data() -> dict[str, Any]:
    """SDLX400 as a scenario: the pinned-free beam with the tip spring as a contactor of zero gap.

    The free state is case 1 of the test (free end), the contact state case 2
    (elastic support k = 18000 N/m), as ``impactbeam modes`` prints them.
    """
    return {
        "name": "sdlx400",
        "description": "code_aster SDLX400: pinned-free beam, without and with a tip spring k = 18000 N/m",
        "beam": _vpcs_beam(),
        "supports": {"left": "pinned", "right": "free"},
        "contactors": [{"position": _L32, "stiffness": 18000.0, "gap": 0.0, "side": "below"}],
        "solver": {"modes": 6},
    }


def sdnl32_data(stiffness: float) -> dict[str, Any]:
    """SDNL32 as a scenario: released with a rigid rotation of -3.8 rad/s about the pin onto a one-sided tip spring.

    Parameters
    ----------
    stiffness : float, [N/m]
        18000 (case 1) or 45000 (case 2).
    """
    return {
        "name": f"sdnl32_k{stiffness:.0f}",
        "description": f"code_aster SDNL32 (VPCS): pinned beam swung onto a one-sided tip spring k = {stiffness:.0f} N/m",
        "beam": _vpcs_beam(),
        "supports": {"left": "pinned", "right": "free"},
        "contactors": [{"position": _L32, "stiffness": float(stiffness), "gap": 0.0, "side": "below"}],
        "damping": {"model": "free_modes", "free": 0.01},
        "initial": {"angular_velocity": "-3.8 rad/s", "pivot": 0.0},
        "solver": {"modes": 10, "end_time": "13 ms"},
        "output": {"points": [_L32]},
    }


def sdnl104_data(modes: int = 5, basis: str = "paper") -> dict[str, Any]:
    """SDNL104 as a scenario: a cantilever pushed by a constant tip force onto a stiff stop 0.1 mm below its tip.

    Parameters
    ----------
    modes : int
        ``solver.modes``.
    basis : {"paper", "enriched"}
        ``solver.basis``.
    """
    return {
        "name": "sdnl104",
        "description": "code_aster SDNL104: clamped beam, tip force -1000 N from t = 0, stop k = 1e8 N/m, gap 0.1 mm",
        "beam": {"length": 1.0, "area": math.pi * _R104**2, "second_moment": math.pi * _R104**4 / 4.0,
                 "youngs_modulus": 1e10, "density": 1e6},
        "supports": {"left": "clamped", "right": "free"},
        "contactors": [{"position": 1.0, "stiffness": 1e8, "gap": 1e-4, "side": "below"}],
        "excitation": {"kind": "point_force", "shape": "step", "amplitude": -1000.0, "position": 1.0},
        "solver": {"modes": modes, "basis": basis, "end_time": 0.16},
        "output": {"points": [1.0]},
    }


def _sdlx400_checks(free: np.ndarray | None = None, spring: np.ndarray | None = None) -> list[Check]:
    out = []
    for state, values, offset in (("free end", free, 1), ("tip spring", spring, 0)):
        for i, ref in enumerate(SDLX400["free" if state == "free end" else "spring"]):
            res = None if values is None else float(values[i + offset])
            out.append(Check(f"{state}, {ref.label} [Hz]", "Hz", ref.reference, res, ref.precision, "relative",
                             "code_aster PRECISION (sdlx400a)", ref.code_aster))
    return out


@register("SDLX400", "Pinned-free beam: frequencies without and with a tip spring", "SDLX400",
          lambda: _sdlx400_checks())
def run_sdlx400() -> Any:
    """SDLX400: the free and contact states' frequencies against the analytical ones."""
    from ..modal import scenario_modes
    from ..scenario import parse_scenario

    t0 = time.perf_counter()
    sm = scenario_modes(parse_scenario(sdlx400_data()))
    assert sm.contact is not None
    checks = _sdlx400_checks(sm.free.frequencies_hz, sm.contact.frequencies_hz)
    series = {"free": sm.free.frequencies_hz[1:6], "spring": sm.contact.frequencies_hz[:6]}
    return case_result("SDLX400", "Pinned-free beam: frequencies without and with a tip spring", "SDLX400", checks,
                       series, time.perf_counter() - t0)


def _sdnl32_checks(results: dict[float, np.ndarray] | None = None) -> list[Check]:
    out = []
    for k, rows in SDNL32.items():
        for i, ref in enumerate(rows):
            res = None if results is None else float(results[k][i])
            out.append(Check(f"k = {k:.0f} N/m, w(L) at {ref.label}", "m", ref.reference, res, SDNL32_TOLERANCE,
                             "absolute", _SDNL32_BASIS, ref.code_aster))
    return out


@register("SDNL32", "Pinned beam swung onto a one-sided tip spring (VPCS)", "SDNL32", lambda: _sdnl32_checks())
def run_sdnl32() -> Any:
    """SDNL32: the tip deflection at 1 ... 12 ms for both stiffnesses."""
    from ..scenario import parse_scenario
    from ..simulation import simulate

    t0 = time.perf_counter()
    at = np.arange(1, 13) * 1e-3
    dense = np.linspace(0.0, 0.013, 261)
    values, series = {}, {"t": dense}
    for k in SDNL32:
        res = simulate(parse_scenario(sdnl32_data(k)))
        values[k] = sample(res, _L32, at)
        series[f"k{k:.0f}"] = sample(res, _L32, dense)
    return case_result("SDNL32", "Pinned beam swung onto a one-sided tip spring (VPCS)", "SDNL32",
                       _sdnl32_checks(values), series, time.perf_counter() - t0)


_SDNL104_RUNS = (
    # (label, modes, basis, deflection tolerance, velocity tolerance, basis of the tolerances, judged)
    ("5 modes, paper basis", 5, "paper", 8e-2, 4e-2, "code_aster PRECISION of its 5-mode run (sdnl104c TRAN4)", True),
    ("5 modes, enriched basis", 5, "enriched", None, None, "informative: the shared basis at 5 modes", False),
    ("8 modes, enriched basis", 8, "enriched", None, None, "informative: the shared basis at 8 modes", False),
    # converged: the tip velocity at 0.1566 s converges slowly in the modes (40 modes of the shared basis were
    # 0.85 % from 120 modes, their Table-2 estimate converged all the same); 80 and 120 modes agree to 0.06 %
    ("converged (120 modes), paper basis", 120, "paper", 2e-2, 4e-2,
     "code_aster PRECISION with a static mode (2 %); 4 % on the velocity (the reference's own error)", True),
    ("converged (120 modes), enriched basis", 120, "enriched", 2e-2, 4e-2,
     "code_aster PRECISION with a static mode (2 %); 4 % on the velocity (the reference's own error)", True),
)


def _sdnl104_checks(results: dict[str, tuple[float, float]] | None = None) -> list[Check]:
    (tw, tv), (rw, rv) = SDNL104["times"], SDNL104["reference"]  # type: ignore[misc]
    ca = {5: (SDNL104["five_modes"].reference, SDNL104["five_modes_velocity"].reference)}  # type: ignore[attr-defined]
    out = []
    for label, modes, _, tol_w, tol_v, why, judged in _SDNL104_RUNS:
        w, v = (None, None) if results is None else results[label]
        kind = "relative" if judged else "info"
        other = ca.get(modes, (None, None)) if "paper" in label else (None, None)
        out.append(Check(f"{label}: w(L) at {tw} s", "m", rw, w, tol_w, kind, why, other[0]))
        out.append(Check(f"{label}: w_t(L) at {tv} s", "m/s", rv, v, tol_v, kind, why, other[1]))
    return out


@register("SDNL104", "Cantilever pushed onto a stiff stop: 5-mode runs and the converged value", "SDNL104",
          lambda: _sdnl104_checks())
def run_sdnl104() -> Any:
    """SDNL104: tip deflection at 0.1315 s and velocity at 0.1566 s, 5 modes and converged."""
    from ..scenario import parse_scenario
    from ..simulation import simulate

    t0 = time.perf_counter()
    tw, tv = SDNL104["times"]  # type: ignore[misc]
    dense = np.linspace(0.0, 0.16, 801)
    results, series = {}, {"t": dense}
    for label, modes, basis, *_ in _SDNL104_RUNS:
        res = simulate(parse_scenario(sdnl104_data(modes, basis)))
        results[label] = (float(sample(res, 1.0, [tw])[0]), float(np.asarray(res.velocity([1.0], [tv]))[0, 0]))
        series[label] = sample(res, 1.0, dense)
    return case_result("SDNL104", "Cantilever pushed onto a stiff stop: 5-mode runs and the converged value", "SDNL104",
                       _sdnl104_checks(results), series, time.perf_counter() - t0)
