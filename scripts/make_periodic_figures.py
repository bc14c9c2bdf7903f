"""Figures of docs/periodic.md: the specimen against its stop under harmonic base excitation.

Run from the repository root: ``python scripts/make_periodic_figures.py`` (about a minute;
the map runs on a local Dask cluster and is kept in out/periodic_map.zarr, resumable).
Writes docs/figures/periodic_*.png and prints the numbers quoted in the text.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np  # noqa: E402

import impactbeam as ib  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
FIG = ROOT / "docs" / "figures"
G = 9.80665


def main() -> None:
    (ROOT / "out").mkdir(exist_ok=True)
    warnings.simplefilter("ignore", ib.ImpactBeamWarning)
    sc = ib.load_scenario(ROOT / "examples" / "periodic" / "specimen_harmonic.toml")
    f = np.linspace(25.0, 90.0, 261)
    d = ib.bifurcation(sc, "excitation.frequency", f, sweep="both")
    d.plot(FIG / "periodic_frequency.png")
    fr = ib.frequency_response(sc, f, sweep="both")
    fr.plot(FIG / "periodic_frf.png", contactor=sc.contactors[0])
    a = ib.bifurcation(sc.with_values({"excitation.frequency": 55.0}), "excitation.amplitude",
                       np.linspace(4.5 * G, 6.5 * G, 201), sweep="both")
    a.plot(FIG / "periodic_amplitude.png", x_scale=1 / G, xlabel="base acceleration amplitude [g]")
    ds = ib.bifurcation_map(sc, ("excitation.frequency", np.linspace(30.0, 90.0, 121)),
                            ("excitation.amplitude", np.linspace(0.5 * G, 4.0 * G, 36)),
                            ROOT / "out" / "periodic_map.zarr", settle_periods=100, record_periods=20)
    from impactbeam.plot.periodic import plot_map

    plot_map(ds, FIG / "periodic_map.png")
    for diagram in (d, a):
        prev = None
        for p in diagram.points:
            key = (p.direction, p.state.period, round(p.state.impacts_per_period, 2))
            if key != prev:
                print(f"{diagram.parameter} = {p.value:.4g}: {key}")
            prev = key
    ss = ib.steady_state(sc)
    st = ib.impact_statistics(ss)
    print("60 Hz:", ss.period, ss.impacts_per_period, st.contactors[0])


if __name__ == "__main__":
    main()
