"""The live explorer: its model against ``ib.simulate``, and the page in a real browser.

The browser test starts ``python -m impactbeam explore`` on a free port,
drives headless Chromium (the system package) with Playwright, moves the gap
slider with the keyboard and checks that the first-impact time shown changes
and equals ``ib.simulate`` for the gap the page shows. It is skipped, saying
why, when Panel, Playwright or Chromium is missing. It prints the time from
key press to redraw as the test driver sees it (with its own round trips);
``benchmarks/bench_explore.py`` measures the latency inside the page.
"""

from __future__ import annotations

import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

import impactbeam as ib

ROOT = Path(__file__).resolve().parents[1]
CASE3 = ROOT / "examples" / "case03.toml"
CHROMIUM = shutil.which("chromium") or ("/usr/bin/chromium" if Path("/usr/bin/chromium").exists() else None)
ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
        "--disable-component-update", "--disable-sync"]


def test_model_matches_simulate_and_round_trips_toml(tmp_path: Path) -> None:
    from impactbeam.explore import ExplorerModel

    sc = ib.load_scenario(CASE3)
    model = ExplorerModel(sc)
    assert model.values["gap"] == pytest.approx(0.229e-3, rel=1e-12)
    model.values["gap"] = 0.300e-3
    model.values["modes"] = 6
    out = model.run()
    ref = ib.simulate(sc.with_values({"contactors.0.gap": 0.300e-3, "solver.modes": 6})).metrics()
    # same scenario, same deterministic solver: equal to round-off
    assert out["metrics"]["first_impact_time"] == pytest.approx(ref["first_impact_time"], rel=1e-12)
    assert out["metrics"]["max_response"] == pytest.approx(ref["max_response"], rel=1e-12)
    # u is -w at a contactor above: its sampled peak is the metric max_response, which is
    # located between samples. A peak missed by at most dt/2 = 5 us on the first mode
    # (about 70 Hz) is low by at most (omega dt / 2)^2 / 2 = 2.4e-6 of it; a sign error
    # would be off by far more.
    peak = out["u_mm"].max() / (ref["max_response"] * 1e3)
    assert 1 - 3e-6 < peak <= 1 + 1e-12
    path = tmp_path / "saved.toml"
    path.write_text(model.toml())
    again = ib.load_scenario(path)
    assert again.contactors[0].gap == pytest.approx(0.300e-3, rel=1e-15) and again.solver.modes == 6


def _with(base: Path, edit) -> ib.Scenario:
    import copy

    data = copy.deepcopy(ib.load_scenario(base).data)
    edit(data)
    return ib.parse_scenario(data, base_dir=base.parent)


@pytest.mark.filterwarnings("ignore:Stopped at")
def test_the_explorer_shows_what_simulate_gives_for_any_damping_and_stop() -> None:
    # Found by a hunt: the explorer replaced per-mode damping ratios by the first one (max penetration 5 % off
    # on the first draw), could not open a free-mode damping scenario (it wrote damping.contact, which that model
    # refuses), drew a restitution stop's force without its dashpot (0.64 N where the force is 1.72 N), and showed
    # a run stopped early as complete. Now only a moved slider is written, the force is Contactor.force with the
    # run's dashpot, and the run's warnings are returned (the page shows them under the sliders).
    import numpy as np

    from impactbeam.explore import ExplorerModel

    def perm(d):
        d["damping"].update(free=[0.011, 0.10], contact=[0.02, 0.10])

    def stop_early(d):
        d["solver"]["max_events"] = 6

    cases = [_with(CASE3, perm), ib.load_scenario(ROOT / "examples" / "validation" / "sdnl32_k18000.toml"),
             _with(CASE3, lambda d: d["contactors"][0].update(restitution=0.5)), _with(CASE3, stop_early)]
    for sc in cases:
        model = ExplorerModel(sc)
        assert not {"damping_free", "damping_contact"} & set(model.values) or sc.damping.model == "modal"
        out = model.run()
        res = ib.simulate(sc)
        ref = res.metrics()
        for key in ("max_response", "first_impact_time", "n_impacts", "max_penetration"):
            assert out["metrics"][key] == ref[key], (sc.name, key)
        if sc.contactors:  # the same force as the result's on the same grid (one rule, to round-off)
            force = res.contact_force[:, 0]
            ok = np.isfinite(force)
            np.testing.assert_allclose(out["force_N"][ok], force[ok], rtol=1e-12, atol=1e-12 * np.nanmax(force))
    assert any("Stopped at" in w for w in ExplorerModel(cases[3]).run()["warnings"])
    assert "damping_free" not in ExplorerModel(cases[0]).values


def test_the_explorer_controls_keep_the_scenarios_own_values(tmp_path: Path) -> None:
    # a negative amplitude keeps its sign in the slider's range, a contactor near the root its own position, the
    # amplitude's label says excitation.scale, and a saved scenario naming a trace file loads from anywhere
    from impactbeam.explore import SLIDERS, ExplorerModel

    sc = _with(CASE3, lambda d: (d["excitation"].update(amplitude="-15 g", scale=2.0),
                                 d["contactors"][0].update(position_ratio=0.02)))
    model = ExplorerModel(sc)
    lo, hi = model.bounds("amplitude")
    assert lo < model.values["amplitude"] < hi < 0
    assert model.bounds("position_ratio")[0] <= 0.02
    label = model.label(next(s for s in SLIDERS if s.name == "amplitude"))
    assert label == "pulse amplitude [g, times excitation.scale = 2]"

    def traced(d):
        for key in ("amplitude", "duration"):
            d["excitation"].pop(key, None)
        d["excitation"].update(shape="table", file="measured/base_acceleration.csv")

    table = _with(CASE3, traced)
    path = tmp_path / "saved.toml"
    path.write_text(ExplorerModel(table).toml())
    assert ib.load_scenario(path).excitation.values.tolist() == table.excitation.values.tolist()


def test_envelope_keeps_the_extremes() -> None:
    import numpy as np

    from impactbeam.explore import envelope

    t = np.linspace(0.0, 1.0, 20001)
    y = np.sin(2 * np.pi * 37 * t) * np.exp(-t) + (np.abs(t - 0.61803) < 2e-5) * 5.0  # a one-sample spike
    tt, yy = envelope(t, y, bins=500)
    assert tt.size <= 3 * 500 + 1 and np.all(np.diff(tt) > 0)
    assert yy.max() == y.max() and yy.min() == y.min()  # the spike and the trough survive exactly
    assert tt[0] == t[0] and tt[-1] == t[-1]


def test_page_update_sends_the_new_run() -> None:
    pytest.importorskip("panel", reason="the explore extra (panel) is not installed")
    import numpy as np

    from impactbeam.explore import ExplorerPage, envelope_index

    sc = ib.load_scenario(CASE3)
    page = ExplorerPage(sc)
    assert page.set_value("gap", 0.300)  # the slider shows mm
    ref = ib.simulate(sc.with_values({"contactors.0.gap": 0.300e-3}))
    u = -ref.displacement([sc.contactors[0].position], ref.time)[0] * 1e3  # u = -w above, mm
    force = ref.contact_force[:, 0]
    idx = envelope_index([u, force])
    data = page.source.data
    assert data["t"].dtype == np.float32 and 1000 < data["t"].size < 7000
    # the plotted columns are the result's own samples (float32), extremes included
    np.testing.assert_allclose(data["t"], ref.time[idx] * 1e3, rtol=1e-6)
    np.testing.assert_allclose(data["u"], u[idx], rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(data["f"], force[idx], rtol=1e-6, atol=1e-9)
    assert data["u"].max() == np.float32(u.max()) and data["f"].max() == np.float32(force.max())
    assert page.u_range.start < u.min() and page.u_range.end > u.max()
    shown = re.search(r'id="m-first_impact_time">([^<]*)<', page.table.text).group(1)
    assert _seconds(shown) == pytest.approx(ref.metrics()["first_impact_time"], abs=0.51e-7)

    # a value the scenario rejects is not applied, and the slider goes back
    assert not page.set_value("modes", 0)
    assert "Not applied" in page.status.text and "solver.modes" in page.status.text
    assert page.model.values["modes"] == 8 and page.sliders["modes"].value == 8
    assert page.set_value("modes", 6) and page.status.text == ""
    assert page.prepare_modes(7) and not page.prepare_modes(7)  # once per set of values


_CHANGED = """([sel, old]) => {
    const find = (root) => {
        const hit = root.querySelector(sel);
        if (hit) return hit;
        for (const node of root.querySelectorAll("*")) {
            if (node.shadowRoot) { const r = find(node.shadowRoot); if (r) return r; }
        }
        return null;
    };
    const e = find(document);
    return e !== null && e.textContent !== old;
}"""


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _seconds(text: str) -> float:
    value, unit = text.split()
    return float(value) * {"ms": 1e-3, "s": 1.0}[unit]


@pytest.mark.timeout(300)
def test_explorer_in_headless_chromium(tmp_path: Path) -> None:
    pytest.importorskip("panel", reason="the explore extra (panel) is not installed")
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (pip install playwright)")
    if CHROMIUM is None:
        pytest.skip("no Chromium browser: apt-get install chromium (the browser test needs it)")
    port = _free_port()
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    server = subprocess.Popen(
        [sys.executable, "-m", "impactbeam", "explore", str(CASE3), "--port", str(port)],
        cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )
    try:
        with sync_api.sync_playwright() as pw:
            ctx = pw.chromium.launch_persistent_context(
                tempfile.mkdtemp(dir=tmp_path), executable_path=CHROMIUM, headless=True, args=ARGS,
                viewport={"width": 1300, "height": 1000}, accept_downloads=True,
            )
            page = ctx.new_page()
            deadline = time.monotonic() + 120
            while True:  # the server needs a moment to start and compile
                try:
                    page.goto(f"http://127.0.0.1:{port}/", timeout=10_000)
                    break
                except sync_api.Error:
                    assert server.poll() is None, server.stdout.read()
                    assert time.monotonic() < deadline, "explorer did not start"
                    time.sleep(1)
            first = page.locator("#m-first_impact_time")
            first.wait_for(timeout=120_000)
            before = first.inner_text()
            gap_before = float(page.locator("#v-gap").inner_text())
            assert gap_before == pytest.approx(0.229, rel=1e-9)

            handle = page.locator(".ib-gap .noUi-handle").first
            handle.focus()
            latencies = []
            for _ in range(5):  # one step of 0.001 mm at a time: the latency of one change
                old = first.inner_text()
                t0 = time.perf_counter()
                page.keyboard.press("ArrowRight")
                # polled in the page at every animation frame (Panel renders into shadow roots)
                page.wait_for_function(_CHANGED, arg=["#m-first_impact_time", old], polling="raf", timeout=30_000)
                latencies.append(time.perf_counter() - t0)
            latency = sorted(latencies)[2]
            for _ in range(15):  # 15 more steps at once
                page.keyboard.press("ArrowRight")
            time.sleep(1.5)  # let the updates settle on the last value
            gap_mm = float(page.locator("#v-gap").inner_text())
            shown = _seconds(first.inner_text())
            assert gap_mm > gap_before
            assert first.inner_text() != before

            sc = ib.load_scenario(CASE3)
            ref = ib.simulate(sc.with_values({"contactors.0.gap": gap_mm * 1e-3})).metrics()["first_impact_time"]
            # the page prints 4 decimals of ms: agreement to its rounding (5e-8 s)
            assert shown == pytest.approx(ref, abs=0.51e-7), (gap_mm, shown, ref)
            update_ms = float(page.locator("#m-update_ms").inner_text().split()[0])
            print(f"\nexplorer: gap {gap_before} -> {gap_mm} mm, first impact {before} -> {first.inner_text()}; "
                  f"server update {update_ms:.1f} ms, key press to redraw seen by the driver (median of 5) {latency * 1e3:.0f} ms, all {[round(x * 1e3) for x in latencies]}")

            with page.expect_download() as info:  # the save button
                page.locator(".ib-save button").first.click()
            saved = tmp_path / "saved.toml"
            info.value.save_as(saved)
            assert ib.load_scenario(saved).contactors[0].gap == pytest.approx(gap_mm * 1e-3, rel=1e-9)
            ctx.close()
    finally:
        server.terminate()
        try:
            server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            server.kill()


def test_page_shows_the_surface_and_shades_the_contacts() -> None:
    # issue 19: the response plot shows the stop's surface (u = -gap) and the contact intervals,
    # both following the sliders; the force is a solid line
    pytest.importorskip("panel", reason="the explore extra (panel) is not installed")
    from impactbeam.explore import ExplorerPage
    from impactbeam.result.metrics import contact_intervals

    sc = ib.load_scenario(CASE3)
    page = ExplorerPage(sc)
    assert page.surface.visible and page.surface.location == pytest.approx(-0.229)
    spans = page.contacts.data
    ref = contact_intervals(ib.simulate(sc), 0)
    assert len(spans["left"]) == len(ref) == 12
    assert spans["left"] == pytest.approx([a * 1e3 for a, _ in ref]) and spans["right"] == pytest.approx(
        [b * 1e3 for _, b in ref])
    assert all(b == page.u_range.start for b in spans["bottom"]) and all(t == page.u_range.end for t in spans["top"])
    assert page.u_range.start < -0.229 < page.u_range.end
    assert page.force_line.glyph.line_dash == []  # solid
    assert page.set_value("gap", 0.300)
    assert page.surface.location == pytest.approx(-0.300)
    ref = contact_intervals(ib.simulate(sc.with_values({"contactors.0.gap": 0.300e-3})), 0)
    assert page.contacts.data["left"] == pytest.approx([a * 1e3 for a, _ in ref])


def test_page_without_contactor_has_no_surface() -> None:
    pytest.importorskip("panel", reason="the explore extra (panel) is not installed")
    from impactbeam.explore import ExplorerPage

    page = ExplorerPage(ib.load_scenario(ROOT / "examples" / "case12.toml"))
    assert not page.surface.visible and page.contacts.data["left"] == []
