"""Write the SYNTHETIC "measured" records of this folder with the impactbeam simulator.

Nothing here was measured: the records are simulations of the paper's
specimen (Xu & Ervin 2013) with known "true" parameters, sampled as a
high-speed camera (2 kHz) and a table accelerometer (10 kHz) would, with
seeded noise added, so the identification workflow in README.md can be
checked against the truth:

* free_decay.csv: release from a 2 mm tip deflection (Table 1, Case 0),
  deflection at the tip, 0.5 s at 2 kHz, noise 5 um rms;
  truth: E = 1900 MPa (the scenario files say 1834 MPa), damping 1.1 %.
* base_acceleration.csv: the shaker table's acceleration, a distorted
  half-sine of nominal 15 g, 15 ms like the paper's Fig. 3 (skewed, with an
  undershoot and ringing), 0.06 s at 10 kHz, noise 1 % of 15 g. The
  accelerometer reads 10 % low: the true base acceleration is 1.10 x the
  noise-free trace.
* deflection.csv: Case 3 (contactor above at 0.4840 L, gap 0.229 mm) driven
  by the true base acceleration, with E = 1900 MPa and a "true" contact
  stiffness k = 5200 N/m; deflection w at the contactor, 0.2 s at 2 kHz,
  noise 5 um rms.

Run from anywhere: ``python examples/measured/make_synthetic.py``.
Deterministic (seeded); rewrites the three CSV files atomically.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

import impactbeam as ib
from impactbeam.experiment import Record, drive_with_trace

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent
G = 9.80665

#: The hidden truth of the synthetic experiment.
TRUTH = {
    "youngs_modulus": 1900e6,  # Pa
    "damping_free": 0.011,
    "damping_contact": 0.02,
    "contact_stiffness": 5200.0,  # N/m
    "trace_scale": 1.10,  # true base acceleration / recorded trace
}
CAMERA_RATE = 2000.0  # Hz
ACCEL_RATE = 10000.0  # Hz
DEFLECTION_NOISE = 5e-6  # m rms
ACCEL_NOISE = 0.01 * 15 * G  # m/s^2 rms
SEED = 20130501


def shaker_pulse(t: np.ndarray, amplitude: float = 15 * G, duration: float = 0.015, delay: float = 0.002) -> np.ndarray:
    """A distorted half-sine like the paper's Fig. 3 (what the shaker delivers, not the ideal pulse)."""
    tau = (t - delay) / duration
    a = np.zeros_like(t)
    m = (tau >= 0) & (tau <= 1)
    a[m] = amplitude * np.sin(np.pi * tau[m]) ** 1.3 * (1 + 0.18 * (0.5 - tau[m]))  # skewed, peaks early
    m = (tau > 1) & (tau <= 1.8)
    a[m] = -0.12 * amplitude * np.sin(np.pi * (tau[m] - 1) / 0.8)  # undershoot
    m = tau > 1.8
    s = t[m] - (delay + 1.8 * duration)
    a[m] = 0.03 * amplitude * np.exp(-s / 0.01) * np.sin(2 * np.pi * 120 * s)  # table ringing
    return a


def _write(path: Path, header: list[str], columns: str, rows: list[str]) -> None:
    text = "\n".join([*(f"# {h}" for h in header), columns, *rows]) + "\n"
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(text)
    os.replace(tmp, path)


def main() -> None:
    rng = np.random.default_rng(SEED)
    label = "SYNTHETIC data made by impactbeam (examples/measured/make_synthetic.py), not a measurement."

    # 1. free decay (Case 0)
    sc0 = ib.load_scenario(EXAMPLES / "case00.toml").with_values(
        {"beam.youngs_modulus": TRUTH["youngs_modulus"], "damping.free": TRUTH["damping_free"], "solver.end_time": 0.5}
    )
    res0 = ib.simulate(sc0)
    t = np.arange(1000) / CAMERA_RATE
    w = res0.displacement([sc0.beam.length], t)[0] + rng.normal(0.0, DEFLECTION_NOISE, t.size)
    _write(
        HERE / "free_decay.csv",
        [label, "Release from a 2 mm tip deflection (Case 0); deflection w at the tip, 2 kHz camera, 5 um noise.",
         "Truth: E = 1900 MPa, damping ratio 1.1 %."],
        "time [s],deflection [mm]",
        [f"{ti:.4f},{wi * 1e3:.5f}" for ti, wi in zip(t, w)],
    )

    # 2. base acceleration trace (Fig. 3-like)
    ta = np.arange(600) / ACCEL_RATE
    clean = shaker_pulse(ta)
    measured = clean + rng.normal(0.0, ACCEL_NOISE, ta.size)
    _write(
        HERE / "base_acceleration.csv",
        [label, "Shaker table acceleration: distorted half-sine, nominal 15 g, 15 ms; 10 kHz, noise 1 % of 15 g.",
         "Truth: the accelerometer reads 10 % low (true base acceleration = 1.10 x this trace without noise)."],
        "time [s],acceleration [g]",
        [f"{ti:.4f},{ai / G:.5f}" for ti, ai in zip(ta, measured)],
    )

    # 3. Case 3 response to the true base acceleration
    sc3 = ib.load_scenario(EXAMPLES / "case03.toml").with_values(
        {
            "beam.youngs_modulus": TRUTH["youngs_modulus"],
            "contactors.0.stiffness": TRUTH["contact_stiffness"],
            "damping.free": TRUTH["damping_free"],
            "damping.contact": TRUTH["damping_contact"],
            "excitation.scale": TRUTH["trace_scale"],
            "solver.end_time": 0.2,
        }
    )
    sc3 = drive_with_trace(sc3, Record(ta, clean, name="acceleration", quantity="acceleration"), hold="linear")
    res3 = ib.simulate(sc3)
    t = np.arange(400) / CAMERA_RATE
    x = sc3.contactors[0].position
    w = res3.displacement([x], t)[0] + rng.normal(0.0, DEFLECTION_NOISE, t.size)
    _write(
        HERE / "deflection.csv",
        [label, "Case 3 (contactor above at 0.4840 L, gap 0.229 mm) driven by the shaker trace;",
         "deflection w at the contactor (positive towards the contactor), 2 kHz camera, 5 um noise.",
         "Truth: E = 1900 MPa, k = 5200 N/m, base acceleration = 1.10 x base_acceleration.csv."],
        "time [s],deflection [mm]",
        [f"{ti:.4f},{wi * 1e3:.5f}" for ti, wi in zip(t, w)],
    )
    print(f"wrote {', '.join(p for p in ('free_decay.csv', 'base_acceleration.csv', 'deflection.csv'))} in {HERE}")


if __name__ == "__main__":
    main()
