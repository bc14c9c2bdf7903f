"""Parameter sweeps (issue 4): sweep files, Dask execution, Zarr results that resume.

The independent references here are the simulator itself on the same
scenario (a stored metric must equal ``ib.simulate(...).metrics()`` bit for
bit: same code, same inputs, one BLAS thread, so no tolerance), an
uninterrupted run of the same sweep (``xr.testing.assert_identical``), and the
defining properties of the sampling designs (Latin hypercube and Sobol
stratification, the bounds and moments of the distributions).

Cases are kept short (Case 3 with end_time 0.05 s, ~15 ms each) except in the
kill test, which needs a run long enough to be interrupted midway.
"""

from __future__ import annotations

import math
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import tomli_w
from click.testing import CliRunner

import impactbeam as ib
from impactbeam.exceptions import ScenarioError
from impactbeam.result.metrics import METRIC_UNITS
from impactbeam.sweeps import (
    load_sweep,
    parse_sweep,
    plot_sweep,
    run_batch,
    run_sweep,
    sweep,
)
from impactbeam.sweeps.batches import _chunk_shape, _make_batch, _regions

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CASE3 = EXAMPLES / "case03.toml"
BIN = Path(sys.executable).parent

GRID = f"""
base = "{CASE3.as_posix()}"
design = "grid"
[parameters."contactors.0.gap"]
values = ["0.1 mm", 0.229e-3, 0.4e-3]
[parameters."excitation.duration"]
range = [5e-3, 20e-3, 4]
[parameters."solver.end_time"]
values = [0.05]
[outputs]
metrics = "all"
histories = {{ points = [0.052853, 0.1092], time_step = 1e-3 }}
"""

SCALARS = tuple(METRIC_UNITS)


def _cli() -> list[str]:
    """The installed ``impactbeam`` script, else the command group through this interpreter."""
    script = shutil.which("impactbeam", path=str(BIN))
    if script:
        return [script]
    return [sys.executable, "-m", "impactbeam"]


def _group():
    import click

    from impactbeam.cli.cmd_sweep import plot_command, sweep_command

    return click.Group(commands={c.name: c for c in (sweep_command, plot_command)})


def _write(tmp: Path, name: str, text: str) -> Path:
    p = tmp / name
    p.write_text(text)
    return p


def _same(stored: float, expected) -> bool:
    """Bit-equal, NaN standing for a metric that is None."""
    if expected is None:
        return math.isnan(stored)
    return stored == float(expected)


@pytest.fixture(scope="module")
def grid_run(tmp_path_factory):
    """The small grid run in this process (workers=0): the reference for several tests."""
    tmp = tmp_path_factory.mktemp("grid")
    path = _write(tmp, "grid.toml", GRID)
    run = run_sweep(path, tmp / "grid.zarr", workers=0, batch_size=4, progress=False)
    return path, tmp / "grid.zarr", run


# --------------------------------------------------------------------------- results


def test_grid_layout_units_and_status(grid_run):
    path, out, run = grid_run
    ds = run.dataset
    assert ds.sizes["contactors.0.gap"] == 3 and ds.sizes["excitation.duration"] == 4
    assert ds["max_response"].dims == ("contactors.0.gap", "excitation.duration", "solver.end_time")
    # "0.1 mm" converted to SI; the range inclusive of both ends (np.linspace)
    np.testing.assert_array_equal(ds["contactors.0.gap"].values, [1e-4, 0.229e-3, 0.4e-3])
    np.testing.assert_array_equal(ds["excitation.duration"].values, np.linspace(5e-3, 20e-3, 4))
    assert ds["contactors.0.gap"].attrs["units"] == "m"
    assert ds["excitation.duration"].attrs["units"] == "s"
    for m in SCALARS:
        assert ds[m].attrs["units"] == METRIC_UNITS[m]
    assert (ds["status"].values == 0).all()
    assert (ds["message"].values == "").all()
    assert run.computed == 12 and run.skipped == 0 and run.failed == 0
    assert ds.attrs["sweep_hash"] == load_sweep(path).hash


def test_random_cases_equal_simulate_exactly(grid_run):
    """For cases picked at random, the stored values are those of ib.simulate (bit-equal)."""
    path, out, _ = grid_run
    spec = load_sweep(path)
    ds = xr.open_zarr(out, consolidated=False).load()  # what is on disk
    rng = np.random.default_rng(20240604)
    for flat in rng.choice(spec.n_cases, size=3, replace=False):
        idx = np.unravel_index(int(flat), spec.shape)
        point = {d: ds[d].values[i] for d, i in zip(spec.dims, idx)}
        # the scenario from the stored coordinates, built independently of the sweep's batches
        sc = ib.load_scenario(CASE3).with_values({k: float(v) for k, v in point.items()})
        res = ib.simulate(sc)
        expected = res.metrics()
        case = ds.sel(point)
        for m in SCALARS:
            assert _same(float(case[m]), expected[m]), (m, point)
        t = ds["time"].values
        inside = t <= sc.solver.end_time  # NaN after the case's end_time
        w = res.displacement([0.052853, 0.1092], t[inside]).T
        np.testing.assert_array_equal(case["w"].values[inside], w)
        assert np.isnan(case["w"].values[~inside]).all()


def test_each_cases_warnings_are_stored_with_it(tmp_path):
    """The warnings of a case were issued in the process that ran it (lost on a Dask worker, and on resume)."""
    text = f"""
base = "{CASE3.as_posix()}"
[parameters."contactors.0.stiffness"]
values = [4030, 1e5]
[parameters."solver.basis"]
values = ["paper"]
[parameters."solver.end_time"]
values = [0.05]
[outputs]
metrics = ["n_impacts"]
"""
    path = _write(tmp_path, "warn.toml", text)
    run = run_sweep(path, tmp_path / "warn.zarr", workers=0, progress=False)
    ds = run.dataset.squeeze()
    soft, stiff = (str(v) for v in ds["warnings"].values)
    alone = ib.simulate(ib.load_scenario(CASE3).with_values(
        {"contactors.0.stiffness": 1e5, "solver.basis": "paper", "solver.end_time": 0.05}))
    assert soft == "" and stiff.splitlines() == list(alone.warnings) and "changed the model's energy" in stiff
    out = subprocess.run([*_cli(), "sweep", str(path), "--out", str(tmp_path / "again.zarr"), "--workers", "0",
                          "--no-progress"], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0 and "1 with warnings (see the warnings variable)" in out.stderr, out.stderr


def test_a_swept_start_redraws_a_random_record(tmp_path):
    """A random load's record lasts end_time - start, drawn when the scenario is read; a swept start moved the
    start-0 record instead (at start 0.1 s: 15 impacts stored where the scenario alone has 20)."""
    base = CASE3.read_text().split("[excitation]")[0] + (
        '[excitation]\nkind = "base_acceleration"\nshape = "random"\n'
        'psd = [["10 Hz", "0.01 g^2/Hz"], ["500 Hz", "0.01 g^2/Hz"]]\nseed = 7\n'
        "[solver]\nmodes = 4\ntime_step = 1e-4\nend_time = 0.3\n")
    base = base.replace('gap = "0.229 mm"', 'gap = "0.05 mm"')
    _write(tmp_path, "rand.toml", base)
    text = 'base = "rand.toml"\n[parameters."excitation.start"]\nvalues = [0.0, 0.1]\n' \
           '[outputs]\nmetrics = ["max_response", "n_impacts"]\n'
    ds = run_sweep(_write(tmp_path, "s.toml", text), None, workers=0, progress=False).dataset
    for start in (0.0, 0.1):
        alone = ib.simulate(ib.load_scenario(tmp_path / "rand.toml").with_values({"excitation.start": start})).metrics()
        case = ds.sel({"excitation.start": start})
        assert int(case["n_impacts"]) == alone["n_impacts"] and float(case["max_response"]) == alone["max_response"]


def test_failed_case_is_recorded_and_the_sweep_goes_on(tmp_path):
    """A contactor at 0.06 m lies off a 0.05 m beam: only that combination fails."""
    text = f"""
base = "{CASE3.as_posix()}"
[parameters."beam.length"]
values = [0.1092, 0.05]
[parameters."contactors.0.position"]
values = [0.03, 0.06]
[parameters."solver.end_time"]
values = [0.02]
[outputs]
metrics = ["max_response", "n_impacts"]
"""
    path = _write(tmp_path, "fail.toml", text)
    run = run_sweep(path, None, workers=0, progress=False)
    ds = run.dataset
    bad = {"beam.length": 0.05, "contactors.0.position": 0.06, "solver.end_time": 0.02}
    assert int(ds["status"].sel(bad)) == -1
    assert "off the beam" in str(ds["message"].sel(bad).values)
    assert math.isnan(float(ds["max_response"].sel(bad)))
    assert int((ds["status"] == 0).sum()) == 3 and run.failed == 1
    assert list(ds.data_vars) == ["max_response", "n_impacts", "status", "message", "warnings"]
    with pytest.raises(ScenarioError, match="off the beam"):
        sweep(path, None, workers=0, progress=False, on_error="raise")


def test_auto_modes_are_stored_per_case(tmp_path):
    """With solver.modes = "auto" each case's count is provenance: stored as ``modes``, as simulate chooses it."""
    base = tomllib.loads(CASE3.read_text())
    base["solver"].update(modes="auto", end_time=0.03)
    scen = tmp_path / "auto.toml"
    scen.write_bytes(tomli_w.dumps(base).encode())
    text = f"""
base = "{scen.as_posix()}"
[parameters."contactors.0.gap"]
values = ["0.1 mm", "0.3 mm"]
[parameters."contactors.0.stiffness"]
values = [4030.0, 1e6]
[outputs]
metrics = ["max_response", "n_impacts"]
"""
    ds = run_sweep(_write(tmp_path, "auto_sweep.toml", text), None, workers=0, progress=False).dataset
    sc = ib.load_scenario(scen)
    for gap in ds["contactors.0.gap"].values:
        for k in ds["contactors.0.stiffness"].values:
            want = ib.simulate(sc.with_values({"contactors.0.gap": float(gap), "contactors.0.stiffness": float(k)}))
            assert int(ds["modes"].sel({"contactors.0.gap": gap, "contactors.0.stiffness": k})) == want.n_modes
    assert int(ds["modes"].max()) > int(ds["modes"].min())  # the stiff stop needs more modes: not a constant
    fixed = run_sweep(_write(tmp_path, "fixed.toml", text.replace(scen.as_posix(), CASE3.as_posix())), None,
                      workers=0, progress=False).dataset
    assert "modes" not in fixed  # a fixed count is in the scenario already


def test_batches_group_cases_that_share_the_modes(tmp_path):
    """Geometry parameters get chunk 1, so a batch holds one geometry; its cases hit the mode cache."""
    text = f"""
base = "{CASE3.as_posix()}"
[parameters."beam.height"]
values = [3.0e-3, 3.03e-3]
[parameters."contactors.0.gap"]
range = [0.1e-3, 0.3e-3, 5]
[parameters."solver.end_time"]
values = [0.01]
"""
    spec = load_sweep(_write(tmp_path, "geo.toml", text))
    chunk = _chunk_shape(spec, 4)
    assert chunk == (1, 3, 1)  # 5 gaps in two equal-ish batches (3 + 2), one height each
    regions = list(_regions(spec.shape, chunk))
    assert len(regions) == 4  # 2 heights x 2 gap batches
    from impactbeam.modal.modeset import _cached
    from impactbeam.solver.ritz import _cached_basis  # the shared basis of solver.basis = "enriched"

    from impactbeam.solver import engine

    _cached.cache_clear()
    _cached_basis.cache_clear()
    engine._CACHE.clear()  # the packed states of a problem, keyed without the gaps
    run_batch(_make_batch(spec, regions[0], "record"))
    misses_after_one_batch = _cached.cache_info().misses + _cached_basis.cache_info().misses
    assert len(engine._CACHE) == 1
    run_batch(_make_batch(spec, regions[1], "record"))  # same height, other gaps: modes reused
    info, basis_info = _cached.cache_info(), _cached_basis.cache_info()
    assert info.misses + basis_info.misses == misses_after_one_batch  # no mode set computed again
    assert len(engine._CACHE) == 1  # one packed problem served both batches


# --------------------------------------------------------------------------- sampled designs


def _sampled(design: str, seed: int, n: int = 64) -> str:
    return f"""
base = "{CASE3.as_posix()}"
design = "{design}"
samples = {n}
seed = {seed}
[parameters."contactors.0.gap"]
distribution = "uniform"
low = "0.1 mm"
high = "0.3 mm"
[parameters."excitation.duration"]
distribution = "normal"
mean = "15 ms"
std = "1 ms"
[parameters."contactors.0.stiffness"]
distribution = "lognormal"
mean = 4030
std = 400
"""


@pytest.mark.parametrize("design", ["lhs", "sobol", "random"])
def test_sampled_designs_reproducible_and_in_bounds(design):
    n = 256
    a = parse_sweep(tomllib.loads(_sampled(design, 7, n))).sample_values()
    b = parse_sweep(tomllib.loads(_sampled(design, 7, n))).sample_values()
    c = parse_sweep(tomllib.loads(_sampled(design, 8, n))).sample_values()
    np.testing.assert_array_equal(a, b)  # same seed, same cases
    assert not np.array_equal(a, c)
    gap, dur, k = a.T
    assert gap.min() >= 1e-4 and gap.max() <= 3e-4 and k.min() > 0
    u = (gap - 1e-4) / 2e-4
    if design in ("lhs", "sobol"):
        # stratification: every one of the n equal strata holds exactly one point
        # (LHS by construction; scrambled Sobol with n = 2^m is a (0, m, 1)-net per axis)
        assert sorted(np.floor(u * n).astype(int)) == list(range(n))
    # moments: Monte Carlo error bound 5 sigma/sqrt(n) (stratified designs do far better)
    tol = 5 / math.sqrt(n)
    assert abs(dur.mean() - 15e-3) < tol * 1e-3
    assert abs(k.mean() - 4030) < tol * 400
    assert abs(k.std() - 400) < 400 * 0.25  # std of the value itself, not of its log


def test_sampled_sweep_uses_case_dimension(tmp_path):
    # an inline base keeps the file self-contained and short (end_time 0.05)
    base = ib.load_scenario(CASE3).with_values({"solver.end_time": 0.05}).data
    data = tomllib.loads(_sampled("lhs", 3, 4))
    data["base"] = base
    data["outputs"] = {"metrics": ["max_response", "first_impact_time"]}
    path = tmp_path / "lhs_inline.toml"
    path.write_text(tomli_w.dumps(data))
    ds = sweep(path, tmp_path / "lhs.zarr", workers=0, progress=False).load()
    spec = load_sweep(path)
    assert ds["max_response"].dims == ("case",)
    np.testing.assert_array_equal(ds["case"].values, np.arange(4))
    np.testing.assert_array_equal(ds["contactors.0.gap"].values, spec.sample_values()[:, 0])
    assert ds.attrs["seed"] == 3 and ds.attrs["design"] == "lhs"
    i = 2
    values = {p: float(ds[p].values[i]) for p in spec.paths}
    expected = ib.simulate(ib.load_scenario(CASE3).with_values({"solver.end_time": 0.05, **values})).metrics()
    for m in ("max_response", "first_impact_time"):
        assert _same(float(ds[m].values[i]), expected[m])


# --------------------------------------------------------------------------- bad input


BAD = {
    "unknown path": ('[parameters."contactors.0.gapp"]\nvalues = [1e-4]\n', 'contactors.0.gapp'),
    "empty range": ('[parameters."contactors.0.gap"]\nrange = [1e-4, 2e-4, 0]\n', "empty range"),
    "negative count": ('[parameters."contactors.0.gap"]\nrange = [1e-4, 2e-4, -3]\n', "positive integer"),
    "negative samples": (
        'design = "lhs"\nsamples = -5\n[parameters."contactors.0.gap"]\ndistribution = "uniform"\nlow = 0\nhigh = 1e-4\n',
        "samples: must be a positive integer",
    ),
    "bad distribution": (
        'design = "lhs"\nsamples = 8\n[parameters."contactors.0.gap"]\ndistribution = "gauss"\nmean = 1e-4\nstd = 1e-5\n',
        'unknown "gauss"',
    ),
    "uniform low >= high": (
        'design = "sobol"\nsamples = 8\n[parameters."contactors.0.gap"]\ndistribution = "uniform"\nlow = 2e-4\nhigh = 1e-4\n',
        "low must be < high",
    ),
    "invalid value": ('[parameters."contactors.0.gap"]\nvalues = [1e-4, -1e-4]\n', "contactors.0.gap"),
    "unknown design": ('design = "factorial"\n[parameters."contactors.0.gap"]\nvalues = [1e-4]\n', "unknown design"),
    "empty values": ('[parameters."contactors.0.gap"]\nvalues = []\n', "the list is empty"),
}


@pytest.mark.parametrize("name", list(BAD))
def test_bad_sweep_files_exit_2_with_one_line(tmp_path, name):
    body, needle = BAD[name]
    path = _write(tmp_path, "bad.toml", f'base = "{CASE3.as_posix()}"\n' + body)
    out = tmp_path / "bad.zarr"
    result = CliRunner().invoke(_group(), ["sweep", str(path), "--out", str(out), "--workers", "0"])
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: bad.toml: "), lines
    assert needle in lines[0]
    assert not out.exists()  # nothing half-written


def test_bad_sweep_file_in_a_real_process(tmp_path):
    path = _write(tmp_path, "bad.toml", f'base = "{CASE3.as_posix()}"\n' + BAD["unknown path"][0])
    proc = subprocess.run([*_cli(), "sweep", str(path), "--out", str(tmp_path / "x.zarr")],
                          capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and 'did you mean "contactors.0.gap"' in lines[0], lines


def test_refuses_to_resume_a_different_sweep(grid_run, tmp_path):
    _, out, _ = grid_run
    other = _write(tmp_path, "other.toml", GRID.replace("0.4e-3", "0.5e-3"))
    result = CliRunner().invoke(_group(), ["sweep", str(other), "--out", str(out), "--workers", "0"])
    assert result.exit_code == 2
    assert "different sweep" in result.stderr and len(result.stderr.strip().splitlines()) == 1
    junk = tmp_path / "junk"
    junk.mkdir()
    (junk / "file.txt").write_text("x")
    result = CliRunner().invoke(_group(), ["sweep", str(other), "--out", str(junk), "--workers", "0"])
    assert result.exit_code == 2 and "not a sweep result" in result.stderr


# --------------------------------------------------------------------------- plot


def test_plot_line_and_heat_map(grid_run, tmp_path):
    _, out, run = grid_run
    runner = CliRunner()
    png = tmp_path / "line.png"
    r = runner.invoke(_group(), ["plot", str(out), "--x", "excitation.duration", "--metric", "first_impact_time",
                                 "--out", str(png)])
    assert r.exit_code == 0, r.output
    assert png.stat().st_size > 1000 and "note: contactors.0.gap = 0.0001" in r.stderr
    png2 = tmp_path / "map.png"
    r = runner.invoke(_group(), ["plot", str(out), "--x", "excitation.duration", "--y", "contactors.0.gap",
                                 "--metric", "first_impact_time", "--out", str(png2)])
    assert r.exit_code == 0 and png2.stat().st_size > 1000
    r = runner.invoke(_group(), ["plot", str(out), "--x", "excitation.duration", "--metric", "max_response",
                                 "--sel", "contactors.0.gap=0.3e-3", "--out", str(png)])
    assert r.exit_code == 2 and "not one of its values" in r.stderr
    r = runner.invoke(_group(), ["plot", str(out), "--x", "beam.height", "--metric", "max_response"])
    assert r.exit_code == 2 and "not a parameter" in r.stderr
    # a value with its unit, as every other option takes it ("expected a number" before)
    r = runner.invoke(_group(), ["plot", str(out), "--x", "excitation.duration", "--metric", "max_response",
                                 "--sel", "contactors.0.gap=0.229 mm", "--out", str(png)])
    assert r.exit_code == 0, r.output
    r = runner.invoke(_group(), ["plot", str(out), "--x", "excitation.duration", "--metric", "max_response",
                                 "--sel", "contactors.0.gap=0.229 kg", "--out", str(png)])
    assert r.exit_code == 2 and "--sel contactors.0.gap" in r.stderr and "a mass" in r.stderr
    # the per-case warnings are text, no metric: refused as such (it was a traceback), and not offered
    r = runner.invoke(_group(), ["plot", str(out), "--x", "excitation.duration", "--metric", "warnings"])
    assert r.exit_code == 2 and "is not in the results" in r.stderr and "Traceback" not in r.output
    offered = r.stderr.split("(use ")[1]
    assert "warnings" not in offered and "message" not in offered and "max_response" in offered

    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    line = plot_sweep(run.dataset, "excitation.duration", "first_impact_time", sel={"contactors.0.gap": 0.229e-3}, ax=ax)
    np.testing.assert_allclose(  # shown in ms, as the summaries
        line.get_ydata(), run.dataset["first_impact_time"].sel({"contactors.0.gap": 0.229e-3}).values[:, 0] * 1e3,
        rtol=1e-15,
    )
    np.testing.assert_allclose(line.get_xdata(), run.dataset["excitation.duration"].values * 1e3, rtol=1e-15)
    assert ax.get_ylabel() == "first impact time [ms]" and ax.get_xlabel() == "pulse duration [ms]"
    plt.close(fig)


def test_plot_selects_a_choice_parameter(tmp_path):
    """--sel on a string parameter (contactors.0.side) ended in a traceback (a NumPy string dtype cast)."""
    import matplotlib.pyplot as plt

    text = (f'base = "{CASE3.as_posix()}"\n[parameters."contactors.0.gap"]\nvalues = ["0.1 mm", "0.3 mm"]\n'
            '[parameters."contactors.0.side"]\nvalues = ["above", "below"]\n[parameters."solver.end_time"]\n'
            'values = [0.03]\n[outputs]\nmetrics = ["max_response"]\n')
    run = run_sweep(_write(tmp_path, "c.toml", text), None, workers=0, progress=False)
    fig, ax = plt.subplots()
    line = plot_sweep(run.dataset, "contactors.0.gap", "max_response", sel={"contactors.0.side": "below"}, ax=ax)
    want = run.dataset["max_response"].sel({"contactors.0.side": "below"}).values.ravel() * 1e3
    np.testing.assert_allclose(line.get_ydata(), want, rtol=1e-15)
    plt.close(fig)


# --------------------------------------------------------------------------- Dask


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _stop(procs: list[subprocess.Popen]) -> None:
    for p in procs:
        if p.poll() is None:
            p.send_signal(signal.SIGTERM)
    for p in procs:
        try:
            p.wait(timeout=20)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


@pytest.mark.dask
def test_sweep_on_a_running_dask_scheduler(grid_run, tmp_path):
    """A real `dask scheduler` and two `dask worker` processes on 127.0.0.1 run the grid."""
    from distributed import Client

    path, ref_out, _ = grid_run
    dask = str(BIN / "dask")
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    env = {**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}
    procs = [subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)]
    try:
        for i in range(2):
            procs.append(subprocess.Popen(
                [dask, "worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard",
                 "--host", "127.0.0.1", "--name", f"w{i}"],
                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=tmp_path,
            ))
        with Client(address, timeout="30s") as client:
            client.wait_for_workers(2, timeout=60)
            assert len(client.scheduler_info()["workers"]) == 2
        out = tmp_path / "remote.zarr"
        proc = subprocess.run([*_cli(), "sweep", str(path), "--out", str(out), "--scheduler", address,
                               "--batch-size", "2", "--no-progress"],
                              capture_output=True, text=True, timeout=120, env=env)
        assert proc.returncode == 0, proc.stderr
        assert "12 computed" in proc.stderr
        got = xr.open_zarr(out, consolidated=False).load()
        ref = xr.open_zarr(ref_out, consolidated=False).load()
        xr.testing.assert_identical(got, ref)  # distributed == in-process, other batch layout
    finally:
        _stop(procs[1:])
        _stop(procs[:1])
    assert all(p.returncode is not None for p in procs)


KILL = f"""
base = "{CASE3.as_posix()}"
[parameters."contactors.0.gap"]
range = [0.0, 0.4e-3, 6]
[parameters."excitation.duration"]
range = [5e-3, 20e-3, 6]
[outputs]
metrics = "all"
"""
N_KILL = 36


@pytest.mark.slow
@pytest.mark.dask
def test_killed_sweep_resumes_to_the_uninterrupted_result(tmp_path):
    """SIGTERM midway, rerun: only the missing cases run and the file equals an uninterrupted run's.

    36 Case-3 cases of 0.2 s (~40 ms each) on one local worker, 2 cases per batch.
    """
    path = _write(tmp_path, "kill.toml", KILL)
    out = tmp_path / "kill.zarr"
    cmd = [*_cli(), "sweep", str(path), "--out", str(out), "--workers", "1", "--batch-size", "2", "--no-progress"]
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 90
    chunks = out / "status" / "c"
    while time.monotonic() < deadline and proc.poll() is None:
        if chunks.exists() and sum(1 for f in chunks.rglob("*") if f.is_file()) >= 3:
            proc.send_signal(signal.SIGTERM)
            break
        time.sleep(0.02)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert "run the same command again" in err

    status = xr.open_zarr(out, consolidated=False)["status"].values
    done = int((status != -2).sum())
    assert 0 < done < N_KILL, done  # really midway
    before = {f: (f.stat().st_mtime_ns, f.read_bytes()) for f in chunks.rglob("*") if f.is_file()}

    rerun = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert rerun.returncode == 0, rerun.stderr
    assert f"{N_KILL - done} computed, {done} already done" in rerun.stderr
    for f, (mtime, data) in before.items():  # finished batches were not rewritten
        assert f.stat().st_mtime_ns == mtime and f.read_bytes() == data

    reference = sweep(path, tmp_path / "ref.zarr", workers=0, batch_size=5, progress=False).load()
    resumed = xr.open_zarr(out, consolidated=False).load()
    xr.testing.assert_identical(resumed, reference)
    assert (resumed["status"].values == 0).all()

    again = subprocess.run(cmd, capture_output=True, text=True, timeout=120)  # complete: nothing to do
    assert again.returncode == 0 and f"0 computed, {N_KILL} already done" in again.stderr


def test_one_writer_per_store(tmp_path):
    """A second sweep on a store that another process is writing is refused, naming the holder."""
    import json as _json
    import socket

    path = _write(tmp_path, "grid.toml", GRID)
    out = tmp_path / "g.zarr"
    lock = tmp_path / "g.zarr.lock"
    # a live holder (this test's parent process) on this host
    lock.write_text(_json.dumps({"pid": os.getppid(), "host": socket.gethostname(), "started": 0}))
    with pytest.raises(ib.ParameterError, match=r"being written by another sweep \(pid \d+ on host"):
        run_sweep(path, out, workers=0, progress=False)
    assert not out.exists()
    # a stale lock (its process is gone) is taken over, and released at the end
    lock.write_text(_json.dumps({"pid": 2**22 + 12345, "host": socket.gethostname(), "started": 0}))
    run = run_sweep(path, out, workers=0, progress=False)
    assert run.computed == 12 and not lock.exists()


def test_a_changed_trace_file_is_another_sweep(tmp_path):
    """The hash covered the base scenario's data, which names the trace file but holds none of its numbers: a
    store made with one trace was resumed ("0 computed, 4 already done") after the trace changed."""
    from impactbeam.exceptions import ParameterError

    (tmp_path / "pulse.csv").write_text("t,a\n0,0\n0.005,100\n0.01,0\n")
    base = CASE3.read_text().split("[excitation]")[0] + (
        '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "pulse.csv"\n'
        "[solver]\nmodes = 4\nend_time = 0.02\n")
    _write(tmp_path, "b.toml", base)

    def refused_after(sweep_file, trace, amplitude):
        """The sweep run, ``trace`` rewritten with another amplitude, the same sweep refused on its store."""
        store = tmp_path / f"{sweep_file.stem}.zarr"
        run_sweep(sweep_file, store, workers=0, progress=False)
        (tmp_path / trace).write_text(f"t,a\n0,0\n0.005,{amplitude}\n0.01,0\n")
        with pytest.raises(ParameterError, match="holds the results of a different sweep"):
            run_sweep(sweep_file, store, workers=0, progress=False)

    refused_after(_write(tmp_path, "s.toml", 'base = "b.toml"\n[parameters."excitation.scale"]\n'
                         'values = [1.0, 2.0]\n[outputs]\nmetrics = ["max_response"]\n'), "pulse.csv", 300)
    # a trace named as a swept value: its numbers too (a store mixed the old and the new file's cases)
    (tmp_path / "other.csv").write_text("t,a\n0,0\n0.005,50\n0.01,0\n")
    refused_after(_write(tmp_path, "f.toml", 'base = "b.toml"\n[parameters."excitation.file"]\n'
                         'values = ["pulse.csv", "other.csv"]\n[outputs]\nmetrics = ["max_response"]\n'), "other.csv", 25)


def test_an_interrupt_before_the_first_case_says_nothing_was_written():
    # a sweep or an ensemble interrupted before its store existed said "0 of 0 cases are in m2.zarr"
    from impactbeam.sweeps import SweepInterrupted

    early = SweepInterrupted(signal.SIGINT)
    assert early.summary("cases", "m2.zarr") == "interrupted before the first of the cases ran: nothing was written"
    later = SweepInterrupted(signal.SIGTERM, 3, 36)
    assert later.summary("seeds", "rnd") == ("interrupted: 3 of 36 seeds are in rnd; run the same command again to "
                                             "finish")


@pytest.mark.dask
def test_a_scheduler_out_of_reach_leaves_no_store(tmp_path):
    """Exit 2 naming --scheduler, and no store: one was left with every case "not yet run" (after 10 s)."""
    path = _write(tmp_path, "far.toml", KILL)
    out = tmp_path / "far.zarr"
    proc = subprocess.run([*_cli(), "sweep", str(path), "--out", str(out), "--scheduler", "tcp://127.0.0.1:9",
                           "--no-progress"], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2 and proc.stderr.startswith("error: --scheduler: cannot connect"), proc.stderr
    assert not out.exists()


def test_a_rigid_stop_swept_is_a_failed_case_not_a_traceback(tmp_path):
    # "inf" (a rigid stop: modes only, simulate refuses it) as a swept stiffness ended in a traceback from the
    # sweep's hash (JSON has no infinity); it is now a case that fails with its message, the others run
    path = _write(tmp_path, "inf.toml", f'base = "{CASE3.as_posix()}"\n[parameters."contactors.0.stiffness"]\n'
                  'values = ["4030 N/m", "inf"]\n[outputs]\nmetrics = ["max_response"]\n')
    run = run_sweep(path, tmp_path / "inf.zarr", workers=0, progress=False)
    assert run.computed == 2 and run.failed == 1
    ds = run.dataset
    assert "cannot be simulated" in str(ds["message"].values[1]) and np.isfinite(ds["max_response"].values[0])
