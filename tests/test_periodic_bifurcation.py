"""Bifurcation diagrams (API and command line) and per-impact statistics."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import tomllib

import numpy as np
import pytest
from click.testing import CliRunner

import impactbeam as ib
from impactbeam.cli import main
from impactbeam.exceptions import ParameterError, ScenarioError
from impactbeam.periodic.bifurcation import bifurcation
from impactbeam.periodic.impact_stats import impact_statistics
from impactbeam.periodic.strobe import steady_state
from impactbeam.scenario import parse_scenario

SCENARIO = """
name = "harmonic"
[beam]
length = 0.10920
width = 9.93e-3
height = 3.03e-3
youngs_modulus = "1834 MPa"
density = "951.98 kg/m^3"
[supports]
left = "clamped"
right = "free"
[[contactors]]
position_ratio = 0.4840
stiffness = "4030 N/m"
gap = "0.1 mm"
side = "above"
[damping]
free = 0.011
contact = 0.02
[excitation]
kind = "base_acceleration"
shape = "harmonic"
amplitude = "2 g"
frequency = "60 Hz"
[solver]
modes = 8
"""


@pytest.fixture
def scenario_file(tmp_path: Path) -> Path:
    p = tmp_path / "harmonic.toml"
    p.write_text(SCENARIO)
    return p


def _invoke(*args: str):
    return CliRunner().invoke(main, list(args), catch_exceptions=False)


def test_json_contract(scenario_file):
    r = _invoke("bifurcation", str(scenario_file), "--parameter", "excitation.frequency",
                "--values", "50 Hz,60,70", "--sweep", "both", "--record-periods", "12", "--json")
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    assert out["parameter"] == "excitation.frequency"
    assert [(p["value"], p["direction"]) for p in out["points"]] == [
        (50.0, "up"), (60.0, "up"), (70.0, "up"), (70.0, "down"), (60.0, "down"), (50.0, "down")]
    for p in out["points"]:
        assert set(p) == {"value", "direction", "period", "impacts_per_period", "strobe", "max", "min"}
        assert len(p["strobe"]) == 12
        assert p["min"] <= min(p["strobe"]) <= max(p["strobe"]) <= p["max"]
    assert "warnings" in out


def test_dataset_and_plot(scenario_file, tmp_path):
    xr = pytest.importorskip("xarray")
    nc, png = tmp_path / "d.nc", tmp_path / "d.png"
    r = _invoke("bifurcation", str(scenario_file), "--parameter", "contactors.0.gap", "--range", "0.1 mm",
                "0.3 mm", "3", "--record-periods", "8", "--settle-periods", "50", "--out", str(nc), "--plot", str(png))
    assert r.exit_code == 0, r.output
    with xr.open_dataset(nc) as ds:
        assert ds["strobe"].dims == ("value", "sample")
        assert ds.sizes["sample"] == 8
        np.testing.assert_allclose(ds["value"].values, [1e-4, 2e-4, 3e-4], rtol=1e-12)
        assert ds["strobe"].attrs["units"] == "m"
        # its provenance, as a simulation's file has (it had none): version, scenario, when and how
        assert ds.attrs["impactbeam_version"] == ib.__version__ and ds.attrs["Conventions"] == "CF-1.10"
        assert ib.parse_scenario(tomllib.loads(ds.attrs["scenario"])).contactors[0].position > 0
        assert "impactbeam" in ds.attrs["history"] and "bifurcation" in ds.attrs["history"]
    assert png.stat().st_size > 1000


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--parameter", "excitation.frequency", "--values", "3 mm"], "excitation.frequency"),
        (["--parameter", "excitation.bogus", "--values", "1"], "excitation.bogus"),
        (["--parameter", "excitation.frequency", "--values", "50", "--range", "1", "2", "3"], "--values"),
        (["--parameter", "excitation.frequency", "--values", "50", "--record-periods", "1"], "--record-periods"),
        (["--parameter", "excitation.frequency", "--range", "40", "50", "x"], "--range"),
        (["--parameter", "excitation.frequency", "--values", "50", "--out", "x.csv"], "--out"),
        (["--parameter", "excitation.frequency", "--values", "50,-3"], "excitation.frequency"),
    ],
)
def test_bad_input_exit_2(scenario_file, args, needle):
    r = _invoke("bifurcation", str(scenario_file), *args)
    assert r.exit_code == 2
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:") and needle in lines[0]


def test_continuation_carries_the_state(scenario_file):
    """Sweeping one value up then down: the down run continues the up run's steady state seamlessly."""
    sc = ib.load_scenario(scenario_file)
    d = bifurcation(sc, "excitation.frequency", [60.0], sweep="both", settle_periods=150, record_periods=10)
    up, down = (p.state for p in d.points)
    assert up.period == down.period == 1
    # tolerance: both records lie on the same orbit, converged to 1e-10 of the amplitude after 150 periods
    np.testing.assert_allclose(down.strobe, up.strobe, rtol=0, atol=1e-8 * up.max)


def test_from_rest_differs_from_continuation_only_by_the_start(scenario_file):
    sc = ib.load_scenario(scenario_file)
    with pytest.warns(ib.ImpactBeamWarning, match="no period"):  # 20 periods do not settle: said so
        a = bifurcation(sc, "excitation.amplitude", ["1.5 g", "2 g"], from_rest=True, settle_periods=20,
                        record_periods=4, max_settle_periods=20)
    with pytest.warns(ib.ImpactBeamWarning, match="no period"):
        b = steady_state(sc.with_values({"excitation.amplitude": "2 g"}), settle_periods=20, record_periods=4,
                         max_settle_periods=20)
    # from rest, the second value is exactly the single run from rest (same bits)
    np.testing.assert_array_equal(a.points[1].state.strobe, b.strobe)


def test_auto_modes_chosen_once_and_carried(scenario_file):
    """solver.modes = "auto": the first run chooses the count; extensions and continuation keep it.

    Both need the modal state of a previous run, which only a fixed count has: an extended steady state
    and a continued diagram used to stop with an error about a ``start`` the user never gave.
    """
    sc = ib.load_scenario(scenario_file).with_values({"solver.modes": "auto"})
    # 5 settle + 4 recorded periods do not settle at 60 Hz: the run is extended from its final state
    with pytest.warns(ib.ImpactBeamWarning, match="no period"):
        ss = steady_state(sc, settle_periods=5, record_periods=4, max_settle_periods=20)
    assert ss.settled_after == 14
    chosen = ss.result.n_modes
    with pytest.warns(ib.ImpactBeamWarning, match="no period"):
        fixed = steady_state(sc.with_values({"solver.modes": chosen}), settle_periods=5, record_periods=4,
                             max_settle_periods=20)
    np.testing.assert_array_equal(ss.strobe, fixed.strobe)  # the same runs: the same bits
    with pytest.warns(ib.ImpactBeamWarning) as record:
        d = bifurcation(sc, "excitation.frequency", [59.0, 60.0], settle_periods=5, record_periods=4,
                        max_settle_periods=5)
    assert not any("modal basis" in str(w.message) for w in record)  # continued, not restarted from rest
    assert [p.state.result.n_modes for p in d.points] == [chosen, chosen]
    with pytest.raises(ParameterError, match="start_state"):
        steady_state(sc, start_state=ss.result.final_state())


def test_api_errors(scenario_file):
    sc = ib.load_scenario(scenario_file)
    with pytest.raises(ParameterError, match="sweep"):
        bifurcation(sc, "excitation.frequency", [50.0], sweep="sideways")  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="no values"):
        bifurcation(sc, "excitation.frequency", [])
    with pytest.raises(ScenarioError, match="contactors.0.gap"):
        bifurcation(sc, "contactors.0.gap", ["1 s"])


def test_impact_statistics_against_mechanics(scenario_file):
    """Mean contact force from the static balance; work in contact from the peak force."""
    sc = ib.load_scenario(scenario_file).with_values({"damping.contact": 0.011})
    ss = steady_state(sc, settle_periods=150, record_periods=20)
    assert ss.period == 1
    st = impact_statistics(ss)
    c0 = st.contactors[0]
    assert c0["n_impacts"] == 20
    assert c0["impacts_per_forcing_period"] == pytest.approx(1.0, abs=1e-12)
    assert 0.0 < c0["restitution_mean"] < 1.0
    c = sc.contactors[0]
    lo, hi = ss.window
    # 1) averaged over a period the base load has zero mean, so the mean deflection at the contactor is
    #    the static deflection under the mean contact force: <w(a)> = -<F> a^3 / (3 EI) (cantilever). The
    #    shared basis holds the static shape of a load at a, so the stiffness side is exact. The damping
    #    side is not: modal damping is diagonal in each state's own modes, so the damping matrix changes
    #    at every switch and its mean force over a period is not zero. That error is proportional to the
    #    damping (measured 1e-4 with 0.011/0.02, 5e-6 with 0.011 in both states, 2e-7 with 0.002).
    mean_w = ss.result.solution.integral(c.position, lo, hi) / (hi - lo)
    flex = c.position**3 / (3 * sc.beam.bending_stiffness)
    # tolerance: 2e-5 relative, four times the damping effect measured at 0.011 in both states
    assert c0["force_mean"] == pytest.approx(-mean_w / flex, rel=2e-5)
    # 2) the contactor is an undamped spring: over one contact the work F v done on it is zero, so
    #    int |F v| dt = 2 * (peak force)^2 / (2 k) per impact (one compression, one release)
    imps = [r for r in st.impacts if r["contactor"] == 0]
    t_contact = sum(r["end"] - r["start"] for r in imps)
    work = sum(r["peak_force"] ** 2 / c.stiffness for r in imps)
    # tolerance: Gauss-Legendre on each smooth side of the deepest compression (located to 1e-12 L) is
    # exact to round-off for the closed form: 1e-9 relative
    assert c0["work_rate"] * t_contact == pytest.approx(work, rel=1e-9)
    # 3) mean force = impulse per period times impacts per period / T
    assert c0["force_mean"] == pytest.approx(c0["impulse_mean"] * ss.frequency, rel=1e-12)
    assert c0["force_rms"] >= c0["force_mean"]
    assert math.isfinite(c0["peak_force_mean"]) and c0["peak_force_mean"] > c0["force_rms"]


def test_shipped_example_is_the_test_scenario():
    """examples/periodic/specimen_harmonic.toml is the scenario these tests and the guide use."""
    path = Path(__file__).resolve().parents[1] / "examples" / "periodic" / "specimen_harmonic.toml"
    a, b = ib.load_scenario(path), parse_scenario(__import__("tomllib").loads(SCENARIO))
    assert a.beam == b.beam and a.contactors == b.contactors and a.damping == b.damping
    assert (a.excitation.shape, a.excitation.frequency, a.excitation.amplitude) == ("harmonic", 60.0, 2 * 9.80665)


def test_frf_figure_and_refusal(scenario_file, tmp_path):
    png = tmp_path / "frf.png"
    r = _invoke("bifurcation", str(scenario_file), "--parameter", "excitation.frequency", "--values", "50,60",
                "--record-periods", "4", "--settle-periods", "20", "--frf", str(png))
    assert r.exit_code == 0 and png.stat().st_size > 1000
    r = _invoke("bifurcation", str(scenario_file), "--parameter", "contactors.0.gap", "--values", "1e-4",
                "--frf", str(tmp_path / "x.png"))
    assert r.exit_code == 2 and "--frf" in r.stderr
    assert not (tmp_path / "x.png").exists()


def test_up_and_down_sweeps_find_coexisting_orbits(scenario_file):
    """Hysteresis: at 32.5 Hz the up sweep is on a two-impact orbit, the down sweep on a one-impact orbit.

    Each orbit is a genuine steady state: continued alone for another 150 periods it stays where it is.
    """
    sc = ib.load_scenario(scenario_file)
    d = bifurcation(sc, "excitation.frequency", np.arange(27.0, 35.01, 0.5), sweep="both")
    at = {p.direction: p.state for p in d.points if p.value == 32.5}
    assert (at["up"].period, at["up"].impacts_per_period) == (1, 2.0)
    assert (at["down"].period, at["down"].impacts_per_period) == (1, 1.0)
    one = sc.with_values({"excitation.frequency": 32.5})
    for s in at.values():
        again = steady_state(one, start_state=s.result.final_state())
        assert again.impacts_per_period == s.impacts_per_period
        # tolerance: both records are on the converged orbit (period mismatch < 1e-8 of the range)
        np.testing.assert_allclose(again.strobe, s.strobe, rtol=0, atol=1e-7 * s.max)
    # two different orbits: their Poincare points are far apart (1.0e-4 m and -0.8e-4 m)
    assert abs(at["up"].strobe[0] - at["down"].strobe[0]) > 0.5 * at["up"].max


def test_each_point_is_the_single_run_from_the_previous_state(scenario_file):
    """The diagram's extremes are searched on a second thread while the next value runs: every point is still,
    to the bit, what one steady-state run from the previous point's final state gives (strobe, period,
    extremes, extensions), impacting and free values, up and down."""
    sc = ib.load_scenario(scenario_file)
    values = [31.0, 32.5, 45.0, 57.0, 100.0]
    with pytest.warns(ib.ImpactBeamWarning):  # some values do not settle in 30 periods: said so, also below
        d = bifurcation(sc, "excitation.frequency", values, sweep="both", settle_periods=30, record_periods=10)
    assert len(d.points) == 2 * len(values)
    state = None
    for p in d.points:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ib.ImpactBeamWarning)
            one = steady_state(sc.with_values({"excitation.frequency": p.value}), settle_periods=30,
                               record_periods=10, start_state=state)
        s = p.state
        assert (s.period, s.settled_after, s.impacts_per_period) == (one.period, one.settled_after,
                                                                      one.impacts_per_period)
        np.testing.assert_array_equal(s.strobe, one.strobe)
        assert (s.max, s.min) == (one.max, one.min)
        state = one.result.final_state()
    assert any(p.state.impacts_per_period > 0 for p in d.points)
    assert any(p.state.settled_after == 0 for p in d.points)  # a value run from its linear steady state
