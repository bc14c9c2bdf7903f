"""Tests of impactbeam.plot: handles, labels with units, atomic files, data drawn = data given."""

from __future__ import annotations

import numpy as np
import pytest

from pathlib import Path

import impactbeam as ib
from impactbeam import paper, plot

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.fixture(scope="module")
def case3():
    return ib.simulate(paper.case(3).with_values({"solver.end_time": 0.06}))


@pytest.fixture(scope="module")
def case12():
    return ib.simulate(paper.case(12).with_values({"solver.end_time": 0.05, "output.point_ratios": [0.484, 1.0]}))


def test_plot_result_draws_the_solution(case3, tmp_path):
    path = tmp_path / "r.png"
    h = plot.plot_result(case3, path, excitation=paper.case(3).excitation)
    ax_w, ax_f, ax_ex = h.axes
    x, y = h.lines[0].get_data()
    np.testing.assert_allclose(x, case3.time * 1e3)  # ms, as the metric summaries
    # u, the metrics' quantity: -w for the contactor above, in mm
    np.testing.assert_allclose(y, -case3.w_contact[:, 0] * 1e3)
    assert y.max() == pytest.approx(case3.metrics()["max_response"] * 1e3, rel=3e-6)  # sampled vs exact peak
    assert "[mm]" in ax_w.get_ylabel() and "[N]" in ax_f.get_ylabel() and "[ms]" in ax_f.get_xlabel()
    assert "[g]" in ax_ex.get_ylabel() and h.artists["excitation"].get_ydata().max() == pytest.approx(15.0, rel=1e-3)
    legend = h.artists["legend"]  # below the axes, never over the data
    fig = h.figure
    fig.canvas.draw()
    box = legend.get_window_extent()
    assert all(box.y1 <= a.get_window_extent().y0 + 1 for a in h.axes)
    assert fig.get_figwidth() == pytest.approx(7.0)  # two journal columns
    n_impacts = sum(e.kind == "impact" for e in case3.events)
    assert len(h.artists["contact_spans"]) == n_impacts > 0
    assert len(h.artists["impacts"].get_xdata()) == n_impacts
    assert h.artists["surface"].get_ydata()[0] == pytest.approx(-0.229)  # u = -gap at the surface
    import matplotlib.image as mpimg

    img = mpimg.imread(path)
    assert img.shape[0] > 100 and np.std(img[..., :3]) > 0.01
    assert not list(tmp_path.glob(".*"))  # no temporary file left


def test_plot_result_single_column_both_quantities_vector(case3, tmp_path):
    h = plot.plot_result(case3, tmp_path / "r.svg", size="single", quantity="both")
    assert h.figure.get_figwidth() == pytest.approx(3.5)
    (u, w) = (line.get_ydata() for line in h.lines[:2])
    np.testing.assert_allclose(u, -w)  # contactor above: u = -w
    assert {line.get_label() for line in h.lines[:2]} == {"u", "w (from rest)"}
    text = (tmp_path / "r.svg").read_text()
    assert text.lstrip().startswith("<?xml") and "<svg" in text
    h.save(tmp_path / "r.pdf")
    assert (tmp_path / "r.pdf").read_bytes()[:5] == b"%PDF-"
    fonts = [t.get_fontsize() for a in h.axes for t in [a.xaxis.label, a.yaxis.label, *a.get_xticklabels()]]
    assert min(fonts) >= 8  # journal minimum at print size
    with pytest.raises(ib.ParameterError, match="size"):
        plot.plot_result(case3, size="quarter")


def test_plot_handles_display_as_figure_in_jupyter(case3):
    h = plot.plot_response(case3)
    bundle = h._repr_mimebundle_()
    assert bundle["image/png"][:8] == b"\x89PNG\r\n\x1a\n"
    assert len(repr(h)) < 100 and "array" not in repr(h)


def test_series_styles_differ_without_colour():
    styles = [ls for _, ls, _ in plot.SERIES_STYLES]
    assert len({str(s) for s in styles}) == len(styles)  # distinct dash patterns: grey-scale safe


def test_plot_result_on_given_axes(case3):
    from impactbeam.plot.figure import _new_figure

    fig, grid = _new_figure((4, 3))
    h = plot.plot_result(case3, ax=grid[0, 0])
    assert h.axes[0] is grid[0, 0] and len(h.axes) == 2  # twin axis for the force
    assert h.figure is fig


def test_plot_result_without_contactor(case12):
    h = plot.plot_result(case12)  # the result carries its scenario: response and excitation panels
    assert len(h.axes) == 2 and h.artists["contact_spans"] == []
    h = plot.plot_response(case12)  # no contactor: no "contactor surface" in the label
    assert "contactor" not in h.axes[0].get_ylabel() and "[mm]" in h.axes[0].get_ylabel()


def test_surface_distance_is_gap_function(case3, case12):
    c = case3.contactors[0]
    np.testing.assert_allclose(plot.surface_distance(case3), c.gap - case3.w_contact[:, 0])
    np.testing.assert_allclose(plot.surface_distance(case12), -case12.w[:, 0])
    np.testing.assert_allclose(plot.surface_distance(case12, side="below"), case12.w[:, 0])


def test_plot_response_dense_point(case12):
    """A point that is not an output point is evaluated exactly; the tip equals the stored column."""
    x_mid = 0.03
    h = plot.plot_response(case12, quantity="w", x=x_mid)
    _, y = h.lines[0].get_data()
    np.testing.assert_allclose(y, case12.displacement([x_mid], case12.time)[0] * 1e3)
    h2 = plot.plot_response([case12], quantity="w", x=0.1092, labels=["tip"])
    np.testing.assert_allclose(h2.lines[0].get_data()[1], case12.w[:, 1] * 1e3)


def test_plot_response_reference_and_errors(case3):
    h = plot.plot_response([case3, case3], labels=["a", "b"], reference=[(1.0e-3, "ref")], time_window=(0.0, 0.02))
    assert len(h.lines) == 2 and h.artists["reference"][0].get_ydata()[0] == pytest.approx(1.0)
    assert h.lines[0].get_data()[0].max() <= 20.0  # ms
    assert h.lines[0].get_linestyle() != h.lines[1].get_linestyle()
    with pytest.raises(ib.ParameterError, match="labels"):
        plot.plot_response([case3], labels=["a", "b"])
    with pytest.raises(ib.ParameterError, match="quantity"):
        plot.plot_response(case3, quantity="v")


def test_plot_excitation_in_g():
    ex = paper.case(3).excitation
    h = plot.plot_excitation([ex], labels=["15 g"])
    t, y = h.lines[0].get_data()
    assert y.max() == pytest.approx(15.0, rel=1e-3)  # half-sine peak in g, sampled at 50 us
    assert "[g]" in h.axes[0].get_ylabel() and "[ms]" in h.axes[0].get_xlabel()
    assert t.max() == pytest.approx(30.0)  # 0.03 s in ms


def test_plot_parameter_study_and_convergence(tmp_path):
    h = plot.plot_parameter_study([1, 2, 3], {"a": [1.0, np.nan, 3.0], "b": [3, 2, 1]},
                                  metric_labels={"a": "a [mm]"}, parameter_label="p [N/m]", baseline=2,
                                  path=tmp_path / "s.png")
    assert len(h.axes) == 2 and h.axes[0].get_ylabel() == "a [mm]"
    assert len(h.lines[0].get_xdata()) == 2  # NaN left out
    assert (tmp_path / "s.png").stat().st_size > 0
    with pytest.raises(ib.ParameterError, match="metrics.a"):
        plot.plot_parameter_study([1, 2], {"a": [1.0]})
    h = plot.plot_convergence([2, 4, 8], {"x": [1.1, 1.01, 1.0]})
    np.testing.assert_allclose(h.lines[0].get_ydata(), [10.0, 1.0])


def test_save_figure_rejects_unknown_suffix(case3, tmp_path):
    h = plot.plot_response(case3)
    with pytest.raises(ib.ParameterError, match="unsupported"):
        plot.save_figure(h.figure, tmp_path / "x.doc")
    with pytest.raises(OSError):
        plot.save_figure(h.figure, tmp_path / "missing" / "x.png")


def test_result_plot_forwards(case3, tmp_path):
    h = case3.plot(tmp_path / "f.png")
    assert isinstance(h, plot.PlotHandles) and (tmp_path / "f.png").is_file()


@pytest.mark.parametrize(
    ("name", "units", "label", "scale"),
    [
        ("contactors.0.gap", "m", "gap [mm]", 1e3),
        ("contactors.1.stiffness", "N/m", "stiffness (contactor 1) [N/m]", 1.0),
        ("excitation.duration", "s", "pulse duration [ms]", 1e3),
        ("max_response", "m", "max response [mm]", 1e3),
        ("n_impacts", "1", "n impacts", 1.0),
        ("damping.free", None, "damping ratio, free state", 1.0),
    ],
)
def test_sweep_axis_labels_are_readable(name, units, label, scale):
    from impactbeam.plot.style import display_label

    assert display_label(name, units) == (label, scale)


def test_result_in_a_notebook_is_a_compact_summary():
    # repr without arrays; an HTML table of run, contactors, exact metrics and warnings
    import impactbeam as ib

    from pathlib import Path

    res = ib.simulate(ib.load_scenario(Path(__file__).resolve().parents[1] / "examples" / "case03.toml"))
    assert len(repr(res)) < 600
    html = res._repr_html_()
    assert "max response" in html and "1.0172 mm" in html and "contactor 0" in html
    assert list(res.impacts.columns) == ["contactor", "start", "end", "duration", "peak_force", "impulse"]
    assert len(res.impacts) == 12


# --------------------------------------------------------------------------- the metrics figure


def test_plot_metrics_marks_each_metric_at_its_value(tmp_path):
    # The figure of docs/metrics.md: every mark sits where the metric says (exact values, in mm and ms),
    # the durations span the intervals of the events, and the force panel marks the impact table.
    res = ib.simulate(ib.load_scenario(EXAMPLES / "case03.toml"))
    m = res.metrics()
    h = plot.plot_metrics(res, tmp_path / "m.png")
    a = h.artists
    assert a["max_response"].get_xdata()[0] == pytest.approx(m["t_max"] * 1e3)
    assert a["max_response"].get_ydata()[0] == pytest.approx(m["max_response"] * 1e3)
    assert a["t_max"].get_xdata()[0] == pytest.approx(m["t_max"] * 1e3)
    assert a["first_impact_time"].get_xdata()[0] == pytest.approx(m["first_impact_time"] * 1e3)
    assert a["min_response"].get_ydata()[0] == pytest.approx(m["min_response"] * 1e3)
    assert a["surface"].get_ydata()[0] == pytest.approx(-0.229)  # u = -gap
    (f0, _), (f1, _) = a["free_duration"].xyann, a["free_duration"].xy
    assert f1 - f0 == pytest.approx(m["free_duration"] * 1e3)
    (c0, _), (c1, _) = a["contact_duration"].xyann, a["contact_duration"].xy
    assert c1 - c0 == pytest.approx(m["contact_duration"] * 1e3) and c0 == pytest.approx(m["first_impact_time"] * 1e3)
    (_, top), (_, deep) = a["max_penetration"].xyann, a["max_penetration"].xy
    assert top - deep == pytest.approx(m["max_penetration"] * 1e3)
    row = m["impacts"][0]
    assert a["peak_force"].get_ydata()[0] == pytest.approx(row["peak_force"])
    assert a["start"].get_xdata()[0] == pytest.approx(row["start"] * 1e3)
    assert a["end"].get_xdata()[0] == pytest.approx(row["end"] * 1e3)
    # the shaded impulse integrates (trapezoid on the 10 us grid) to the exact impulse within 1e-3:
    # the force is smooth inside a contact and vanishes at its ends
    verts = a["impulse"].get_paths()[0].vertices
    inside = (res.time >= row["start"]) & (res.time <= row["end"])
    f, t = res.contact_force[inside, 0], res.time[inside]
    area = float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(t)))
    assert area == pytest.approx(row["impulse"], rel=1e-3) and verts[:, 1].max() <= row["peak_force"] * (1 + 1e-9)
    assert h.figure.get_figwidth() == pytest.approx(7.0)
    assert str(m["n_impacts"]) in a["n_impacts"].get_text()
    assert (tmp_path / "m.png").stat().st_size > 0


def test_plot_metrics_needs_a_contact_after_the_peak(case12):
    with pytest.raises(ib.ParameterError, match="no contactor"):
        plot.plot_metrics(case12)
    sc = ib.load_scenario(EXAMPLES / "case03.toml").with_values({"solver.end_time": 0.015})  # stops before any impact
    with pytest.raises(ib.ParameterError, match="contact_duration is null"):
        plot.plot_metrics(ib.simulate(sc))


# --------------------------------------------------------------------------- periodic motion


def _no_pyplot_figures() -> int:
    import matplotlib.pyplot as plt

    return len(plt.get_fignums())


@pytest.fixture(scope="module", params=["below", "above"])
def harmonic_diagram(request):
    # the specimen against its 0.1 mm stop on either side, three forcing frequencies around the
    # impacting resonance (short settling: the figure, not the orbit, is under test)
    import warnings

    sc = ib.load_scenario(EXAMPLES / "periodic" / "specimen_harmonic.toml").with_values(
        {"contactors.0.side": request.param})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ib.ImpactBeamWarning)  # short settling: periods may not be found
        d = ib.bifurcation(sc, "excitation.frequency", [55.0, 60.0, 72.0], sweep="both", settle_periods=30,
                           record_periods=4)
    return sc, d


def test_frequency_response_draws_the_surface_on_the_contactors_side(harmonic_diagram):
    # The caller's bug of issue 19: a stop below has its surface at w = -gap, not +gap. Through the
    # command's own figure function (impactbeam bifurcation --frf).
    import warnings

    from impactbeam.cli.cmd_bifurcation import frf_figure

    sc, d = harmonic_diagram
    c = sc.contactors[0]
    before = _no_pyplot_figures()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ib.ImpactBeamWarning)  # short settling: periods may not be found
        h = frf_figure(sc, d)
    y = h.artists["surface"].get_ydata()[0]
    assert y == pytest.approx((-0.1 if c.side == "below" else 0.1))  # mm
    assert np.sign(y) == (-1.0 if c.side == "below" else 1.0)
    assert "-gap" in h.artists["surface"].get_label() if c.side == "below" else "+gap" in h.artists["surface"].get_label()
    assert _no_pyplot_figures() == before  # a bare figure, pyplot untouched
    assert h.figure.get_figwidth() == pytest.approx(7.0)


def test_frequency_response_axis_holds_the_impacting_branch_not_the_linear_peak():
    # Evidence for the scale: the linear FRF of the specimen peaks at ~3.5 mm near 57 Hz while the
    # impacting branch stays within ~1.7 mm; the axis is set by the simulated extremes (and the surface).
    from types import SimpleNamespace

    f = np.linspace(50.0, 64.0, 15)
    lin = 1e-3 / (np.abs(f - 57.0) + 0.3)  # a sharp linear peak, 3.3 mm
    fr = SimpleNamespace(frequency=np.concatenate([f, f[::-1]]), direction=np.array(["up"] * 15 + ["down"] * 15),
                         max=np.full(30, 0.4e-3), min=np.full(30, -0.6e-3), linear=np.concatenate([lin, lin[::-1]]),
                         point=0.0529, linear_curve=(np.empty(0), np.empty(0)))  # no fine grid: the swept values
    h = plot.plot_frequency_response(fr)
    lo, hi = h.axes[0].get_ylim()
    assert -0.8 < lo < -0.6 and 0.4 < hi < 0.6  # mm: the extremes with a margin
    assert "off scale" in h.artists["linear_peak"].get_text() and "3.33" in h.artists["linear_peak"].get_text()
    assert h.artists["surface"] is None


def test_bifurcation_figure_is_journal_styled_with_the_impact_markers_in_the_legend():
    from types import SimpleNamespace

    def point(value, direction, period, ipp):
        state = SimpleNamespace(strobe=np.array([1e-4, 2e-4]), period=period, impacts_per_period=ipp)
        return SimpleNamespace(value=value, direction=direction, state=state)

    d = SimpleNamespace(parameter="excitation.frequency", unit="Hz",
                        points=[point(50.0, "up", 1, 1.0), point(51.0, "up", 0, 1.5),
                                point(51.0, "down", 2, 2.0), point(50.0, "down", 1, 1.0)])
    before = _no_pyplot_figures()
    h = plot.plot_bifurcation(d)
    assert _no_pyplot_figures() == before
    labels = [t.get_text() for t in h.artists["legend"].get_texts()]
    assert "impacts per response period, up" in labels and "impacts per response period, down" in labels
    assert "no period found: impacts per forcing period, up" in labels
    assert h.figure.get_figwidth() == pytest.approx(7.0)
    assert h.axes[1].get_xlabel() == "forcing frequency [Hz]"
    sizes = {t.get_fontsize() for a in h.axes for t in (a.xaxis.label, a.yaxis.label, *a.get_yticklabels())}
    assert min(sizes) >= 8  # journal fonts at print size


def test_paper_case3_detail_shows_u_and_every_contact():
    # issue 19: the report's detail figure plots u = -w and must say so; its axis ran to 80 ms, before
    # the last of Case 3's 12 contacts
    from impactbeam.paper.figures import case3_detail
    from impactbeam.result.metrics import contact_intervals

    res = ib.simulate(paper.case(3))
    h = case3_detail(res)
    ax = h.axes[0]
    assert "u = -w" in " ".join(a.get_title() for a in h.axes) and ax.get_ylabel().endswith("u [mm]")
    np.testing.assert_allclose(h.lines[0].get_ydata(), -res.w_contact[:, 0] * 1e3)  # u = -w (contactor above)
    last_end = contact_intervals(res, 0)[-1][1]
    assert len(contact_intervals(res, 0)) == 12 and ax.get_xlim()[1] >= last_end * 1e3
