"""The report's figures: the analogues of the paper's Figs. 4-8, Case 3 in detail, the free decay, convergence and the parameter study."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any
import numpy as np
from .data import G, SECTION4, SPECIMEN, TABLE1
from .plan import CONVERGENCE_MODES, PARAMETER_STUDY, _BASE_VALUE

__all__ = ["case3_detail"]


def case3_detail(result: Any) -> Any:
    """The report's Case 3 detail: ``u = -w`` at the contact point, contacts, impacts and the contact force.

    ``u`` is the metrics' quantity (positive away from the contactor, which
    is above the beam in the paper's set-up), and the time axis runs past
    the last rebound of the run, so every contact is in the figure.

    Parameters
    ----------
    result : SimulationResult
        Case 3.

    Returns
    -------
    PlotHandles
    """
    from .. import plot as P
    from ..result.metrics import contact_intervals

    t_end = result.solution.t_end
    last_end = max((min(b, t_end) for _, b in contact_intervals(result, 0)), default=t_end)
    h = P.plot_result(result, quantity="u", title="Case 3: u = -w at the contact point (positive away from the "
                                                   "contactor), contact intervals and force")
    h.axes[0].set_xlim(0.0, min(t_end, last_end + 0.005) * 1e3)  # ms, past the last rebound
    return h


def _figures(data: dict[str, Any], fig_dir: Path, tick: Callable[[str], None]) -> dict[str, Path]:
    from .. import plot as P
    from ..plot.figure import _new_figure
    from ..plot.style import _outside_legend

    res = data["results"]
    scs = data["scenarios"]
    figs: dict[str, Path] = {}

    def save(name: str, handles: Any) -> None:
        path = fig_dir / f"{name}.png"
        fig = getattr(handles, "figure", handles)
        P.save_figure(fig, path, dpi=200)
        P.save_figure(fig, path.with_suffix(".pdf"))  # vector copy for papers
        figs[name] = path
        tick(f"figure {name}")

    window = (0.0, 0.2)
    # Fig. 4: pulse duration
    with P.rc_context():
        fig, grid = _new_figure((7.0, 5.2), 2, 1, height_ratios=[1.0, 2.0])
    group = (3, 4, 5)
    P.plot_excitation([scs[n].excitation for n in group], ax=grid[0, 0], end_time=0.03,
                      labels=[f"Case {n}: {TABLE1[n].label}" for n in group])
    grid[0, 0].set_title("(a) excitation (ideal half-sine pulses)")
    h = P.plot_response([res[n] for n in group], ax=grid[1, 0], labels=[f"Case {n}" for n in group],
                        time_window=window, title="(b) response at the contact point 0.4840 L")
    save("fig4_pulse_duration", h)
    # Fig. 5: pulse amplitude
    group = (7, 6, 8, 3)
    h = P.plot_response([res[n] for n in group], labels=[f"Case {n}: {TABLE1[n].amplitude / G:g} g" for n in group],
                        time_window=window, title="Response with changing pulse amplitude (Fig. 5 analogue)")
    save("fig5_pulse_amplitude", h)
    # Fig. 6: gap
    group = (9, 2, 3, 10, 11)
    h = P.plot_response([res[n] for n in group],
                        labels=[f"Case {n}: gap {TABLE1[n].gap * 1e3:.3f} mm" for n in group],
                        time_window=window, title="Response with changing gap size (Fig. 6 analogue)")
    save("fig6_gap_size", h)
    # Fig. 7: Case 12
    s12 = SECTION4[12]
    h = P.plot_response(res[12], labels=["Case 12 (this model, ideal pulse)"], time_window=window,
                        reference=[(s12["simulated"]["first_peak"], "paper: simulated first peak 1.08 mm"),
                                   (s12["measured"]["first_peak"], "paper: measured first peak 1.24 mm"),
                                   (s12["measured"]["first_negative_peak"], "paper: measured first negative peak -1.15 mm")],
                        title="Case 12, no contactor: deflection at 0.4840 L (Fig. 7 analogue)")
    save("fig7_case12", h)
    # Fig. 8: Case 3
    s3 = SECTION4[3]
    h = P.plot_response(res[3], labels=["Case 3 (this model, ideal pulse)"], time_window=window,
                        reference=[(s3["simulated"]["first_peak"], "paper: simulated first peak 1.237 mm"),
                                   (s3["measured"]["first_peak"], "paper: measured first peak 1.469 mm"),
                                   (s3["measured"]["min_response"], "paper: measured first-contact minimum -0.0828 mm")],
                        title="Case 3, reference case: deflection from the contactor surface (Fig. 8 analogue)")
    save("fig8_case3", h)
    save("case3_detail", case3_detail(res[3]))
    # Case 0 free decay
    h = P.plot_response([res[0]], quantity="w", x=scs[0].beam.length, labels=["Case 0: tip"],
                        title="Case 0: free decay after release from a 2 mm tip deflection")
    P.plot_response([res[0]], quantity="w", x=SPECIMEN["contact_position_ratio"] * scs[0].beam.length,
                    ax=h.axes[0], labels=["Case 0: contact point 0.4840 L"])
    h.axes[0].get_lines()[-1].set(color="#0072B2", ls="--")
    for leg in list(h.figure.legends):
        leg.remove()
    _outside_legend(h.figure, h.axes[0])
    save("case0_free_decay", h)
    # convergence
    conv = data["convergence"]
    with P.rc_context():
        fig, grid = _new_figure((7.0, 3.4), 1, 2)
    P.plot_convergence(CONVERGENCE_MODES, {
        "Case 12 first peak": [conv[12][m].max_response for m in CONVERGENCE_MODES],
        "Case 12 first negative peak": [conv[12][m].min_response for m in CONVERGENCE_MODES],
    }, ax=grid[0, 0], title="no contactor (Case 12)")
    P.plot_convergence(CONVERGENCE_MODES, {
        "Case 3 first peak": [conv[3][m].max_response for m in CONVERGENCE_MODES],
        "Case 3 contact duration": [conv[3][m].contact_duration for m in CONVERGENCE_MODES],
        "Case 3 first-contact minimum": [conv[3][m].min_response for m in CONVERGENCE_MODES],
    }, ax=grid[0, 1], title="with contactor (Case 3)")
    save("convergence", fig)
    # parameter studies: one figure per parameter
    for name, rows in data["study"].items():
        spec = PARAMETER_STUDY[name]
        xs = [v * spec["scale"] for v, _ in rows]
        mets = {
            "max_response": [m.max_response * 1e3 for _, m in rows],
            "n_impacts": [m.n_impacts for _, m in rows],
            "total_contact_time": [m.total_contact_time * 1e3 for _, m in rows],
            "cycle_time": [m.cycle_time * 1e3 for _, m in rows],
        }
        h = P.plot_parameter_study(
            xs, mets, parameter_label=f"{spec['label']} [{spec['unit']}]",
            metric_labels={"max_response": "max response d [mm]", "n_impacts": "impacts in 0.2 s [-]",
                           "total_contact_time": "total contact time [ms]", "cycle_time": "cycle time [ms]"},
            baseline=_BASE_VALUE[name] * spec["scale"], xscale=spec["xscale"],
            title=f"One-at-a-time study around Case 3: {spec['label']}")
        reb = [m.rebound_response * 1e3 for _, m in rows]
        ok = np.isfinite(reb)
        h.axes[0].lines[0].set_label("max response")
        h.axes[0].plot(np.asarray(xs)[ok], np.asarray(reb)[ok], marker="s", ms=3, ls="--", color="#0072B2",
                       label="rebound response")
        _outside_legend(h.figure, h.axes[0])
        save(f"study_{name}", h)
    return figs
