"""Random systems through both paths: the compiled engine against the independent ``solve_ivp`` path.

Systems are drawn with fixed seeds over what a scenario offers: the
specimen with any supports (clamped, pinned, free, sliding, finite springs),
a point mass, an interior spring, a stepped section, Timoshenko theory, one
to three contactors anywhere (a two-sided pair at one position), gaps 0 to
0.3 mm, stiffnesses 1/3 to 1e4 times 3 EI / L^3, dashpots and restitution,
modal, Rayleigh and free-mode damping, a base acceleration or a point force
(half-sine, step, harmonic), an initial velocity or rotation, a preload, 4 to
16 modes of the default or the paper's basis. Each runs 20 ms.

Both paths must give the same events (kinds and contactors), event times
within ``T_EVENT`` and metrics within ``R_METRIC`` (:func:`test_engine.compare`,
whose module docstring gives those tolerances), and the deflection
histories at the contactors and the right end within ``R_HISTORY`` of the
largest one. The seeds are the draws among the first 120 that impact
without the engine's warnings (a chattering stop, a projection that moves a
stop's deflection by more than 5 %) and pass; the others part where the
rules allow it: a zero-gap stop grazed less deeply than the engine's touch
tolerance (1e-12 L, which the `solve_ivp` path does not have), a maximum so
flat that its time is not defined to 1e-10 s, or a warned chatter.
Measured over these seeds: event times within 1.6e-11 s, histories within 2.2e-9.
This generator found the `solve_ivp` path's handling of rows left on the
wrong side of a switch, of touching rows and of rows a round-off below 0.
"""

from __future__ import annotations

import random

import numpy as np
import pytest

import impactbeam as ib

from test_engine import compare, problem
from test_fe_random_systems import spaced_ratio

_L, _W, _H, _E, _RHO = 0.1092, 9.93e-3, 3.03e-3, 1834e6, 951.98
_SUPPORTS = ["clamped", "pinned", "free", "sliding", {"translational": 1e3, "rotational": 0.0},
             {"translational": "inf", "rotational": 50.0}]
R_HISTORY = 2e-8  # 9 times the largest measured (2.2e-9): DOP853 at rtol 1e-10 over a dozen impacts


def random_system(seed: int) -> dict:
    """A scenario mapping drawn from ``seed`` (module docstring)."""
    rng = random.Random(seed)
    k_ref = 3 * _E * _W * _H**3 / 12 / _L**3
    left = rng.choice(["clamped", "clamped", "pinned", _SUPPORTS[4], _SUPPORTS[5]])
    right = rng.choice(_SUPPORTS)
    d: dict = {"beam": {"length": _L, "width": _W, "height": _H, "youngs_modulus": _E, "density": _RHO},
               "supports": {"left": left, "right": right}}
    if rng.random() < 0.3:
        d["masses"] = [{"position_ratio": round(rng.uniform(0.3, 1.0), 3), "mass": rng.choice([1e-4, 1e-3, 5e-3]),
                        **({"rotary_inertia": 1e-9} if rng.random() < 0.5 else {})}]
    if rng.random() < 0.2:
        d["springs"] = [{"position": round(rng.uniform(0.2, 0.9) * _L, 5),
                         "translational": k_ref * rng.choice([0.1, 1, 10])}]
    if rng.random() < 0.2:
        d["beam"]["sections"] = [{"length": 0.04, "height": 4e-3}, {"length": _L - 0.04}]
    contactors: list[dict] = []
    used: list[float] = []
    for _ in range(rng.choice([1, 1, 2, 3])):
        r = spaced_ratio(rng, used)
        c = {"position_ratio": r, "stiffness": k_ref * 10 ** rng.uniform(-0.5, 4.0),
             "gap": rng.choice([0.0, 1e-5, 1e-4, 3e-4]), "side": rng.choice(["above", "below"])}
        u = rng.random()
        if u < 0.2:
            c["damping"] = k_ref * 10 ** rng.uniform(-3, -1)
        elif u < 0.35:
            c["restitution"] = rng.choice([0.3, 0.7, 0.95])
        contactors.append(c)
    d["contactors"] = contactors
    u = rng.random()
    if u < 0.6:
        d["damping"] = {"free": rng.choice([0.0, 0.005, 0.02, 0.3, 1.0]),
                        "contact": rng.choice([0.0, 0.01, 0.05, 0.8, 2.0])}
    elif u < 0.8:
        d["damping"] = {"model": "rayleigh", "alpha": rng.choice([0.0, 5.0, 50.0]),
                        "beta": rng.choice([0.0, 1e-5, 1e-4])}
    else:
        d["damping"] = {"model": "free_modes", "free": rng.choice([0.0, 0.01, 0.05])}
    kind = rng.choice(["base_acceleration", "point_force"])
    shape = rng.choice(["half_sine", "step", "harmonic"])
    ex: dict = {"kind": kind, "shape": shape}
    ex["amplitude"] = ((rng.choice([1, 5, 15]) * 9.81 if kind == "base_acceleration" else rng.choice([0.01, 0.05, 0.2]))
                       * rng.choice([1, -1]))
    if kind == "point_force":
        ex["position"] = round(rng.uniform(0.1, 1.0) * _L, 5)
    if shape == "half_sine":
        ex["duration"] = rng.choice([0.002, 0.005, 0.015])
    if shape == "harmonic":
        ex["frequency"] = rng.choice([40.0, 90.0, 300.0])
    d["excitation"] = ex
    u = rng.random()
    if u < 0.15:
        d["initial"] = {"velocity": rng.choice([-0.2, 0.1])}
    elif u < 0.25:
        d["initial"] = {"angular_velocity": -2.0, "pivot": 0.0}
    if rng.random() < 0.15:
        d["preload"] = {"kind": "base_acceleration", "amplitude": rng.choice([-9.81, 9.81])}
    if rng.random() < 0.15:
        d["beam"]["theory"] = "timoshenko"
        d["beam"]["poisson_ratio"] = 0.35
    if rng.random() < 0.2:
        pair = dict(contactors[0])
        pair["side"] = "below" if contactors[0]["side"] == "above" else "above"
        contactors.append(pair)
    if rng.random() < 0.1:
        d["preload"] = {"kind": "point_force", "amplitude": rng.choice([-0.05, 0.05]),
                        "position": round(rng.uniform(0.2, 1.0) * _L, 5)}
    if rng.random() < 0.5:
        ex["amplitude"] *= 5
    d["solver"] = {"modes": rng.choice([4, 6, 10, 16]), "time_step": 1e-5, "end_time": 0.02}
    if rng.random() < 0.3:
        d["solver"]["basis"] = "paper"
    return d


SEEDS = [7, 11, 12, 13, 17, 19, 24, 32, 34, 41, 43, 44, 64, 67, 73, 88, 96, 101]


@pytest.mark.slow
@pytest.mark.parametrize("seed", SEEDS)
def test_random_system_exact_and_ivp_agree(seed):
    sc = ib.parse_scenario(random_system(seed))
    points = [c.position for c in sc.contactors] + [sc.beam.length]
    args = problem(beam=sc.beam, contactors=sc.contactors, damping=sc.damping, excitation=sc.excitation,
                   initial=sc.initial, options=sc.solver, points=points, preload=sc.preload)
    ex, iv = compare(args)
    # the seeds are runs without a warning, but that their paper-basis projections change the energy (12, 44
    # and 64: 59 %, 25 % and 30 % of it; seed 64 has 6 impacts where 40 modes give 68): both paths say so alike
    energy = "changed the model's energy"
    assert ex.events and not [w for w in ex.warnings if energy not in w]
    assert [energy in w for w in ex.warnings] == [energy in w for w in iv.warnings]
    t = np.linspace(0.0, sc.solver.end_time, 2001)
    w_ex, w_iv = ex.displacement(points, t), iv.displacement(points, t)
    assert np.max(np.abs(w_ex - w_iv)) <= R_HISTORY * np.max(np.abs(w_iv))


def rayleigh_dashpot_system(seed: int) -> dict:
    """:func:`random_system` with Rayleigh damping (``beta`` 3e-5 to 3e-4 s), a dashpot at every stop, 12-24 modes.

    The over-damped high coordinates then crowd their slow rates near
    ``1/beta`` in every engaged state (solver/blocks.py pairs them apart);
    zero gaps become 1e-5 m (the grazes of a zero gap part the two paths
    by the engine's touch tolerance, module docstring), restitution is
    dropped (a dashpot is given), and the run is 10 ms (solve_ivp integrates
    the fast rates, ``beta omega^2`` of the highest coordinates, with steps
    that small).
    """
    rng = random.Random(1000 + seed)
    d = random_system(seed)
    d["damping"] = {"model": "rayleigh", "alpha": rng.choice([0.0, 5.0]), "beta": rng.choice([3e-5, 1e-4, 3e-4])}
    for c in d["contactors"]:
        c.pop("restitution", None)
        c["damping"] = rng.choice([0.05, 0.5, 2.0])
        if c["gap"] == 0.0:
            c["gap"] = 1e-5
    d["solver"].update(modes=rng.choice([12, 16, 24]), end_time=0.01)
    return d


@pytest.mark.slow
@pytest.mark.parametrize("seed", [7, 9, 12, 14, 17])
def test_rayleigh_beta_with_dashpots_exact_and_ivp_agree(seed):
    # Seeds 7 and 17 were refused before the blocks paired real rates 10 % apart (17 of the first 40 draws
    # were; all 40 run now, and the first 19 have the same events as solve_ivp, times within 1.7e-12 s); 9, 12
    # and 14 ran before too. Same tolerances as above (test_engine.compare). Left out: draws that part where
    # the rules allow it, a maximum so flat that its time is not defined to 1e-10 s (seed 6: 4e-9 s apart, the
    # values 1.7e-10 apart) and responses so small (3.5e-8 m, 8.5e-11 m: seeds 5 and 11) that the extremes'
    # absolute tolerance is more than 1e-7 of them.
    sc = ib.parse_scenario(rayleigh_dashpot_system(seed))
    args = problem(beam=sc.beam, contactors=sc.contactors, damping=sc.damping, excitation=sc.excitation,
                   initial=sc.initial, options=sc.solver, points=[c.position for c in sc.contactors] + [sc.beam.length],
                   preload=sc.preload)
    compare(args)


def test_ivp_extremum_survives_a_round_off_slope_at_a_grid_point():
    # Seed 48 at 128 modes (the count solver.modes = "auto" reached for it): a contact's deepest compression lies
    # at a segment's end, where the dense output's slope is 1.7e-18 on the search grid and -1.7e-18 at the single
    # point; Brent's bracket then had no sign change and the solve_ivp path stopped with SciPy's ValueError.
    d = random_system(48)
    d["solver"].update(modes=128, end_time=1e-4)
    sc = ib.parse_scenario(d)
    ivp = ib.simulate(sc, method="ivp").metrics()
    exact = ib.simulate(sc).metrics()
    assert ivp["n_impacts"] == exact["n_impacts"]  # the same events (24 here)
    # tolerance: 24 impacts in 0.1 ms at 128 modes, DOP853 at rtol 1e-10 (measured 4e-7)
    assert ivp["max_penetration"] == pytest.approx(exact["max_penetration"], rel=1e-5)
