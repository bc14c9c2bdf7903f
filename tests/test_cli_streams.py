"""Output streams of the commands: results on stdout, warnings on stderr (and in ``--json``'s "warnings").

A table on stdout is what scripts read (``impactbeam bifurcation ... > table.txt``); a warning line
among its rows breaks them and is lost in the file. Every command prints its ImpactBeamWarnings on
stderr as ``warning: ...`` lines, once, when it ends; with ``--json`` they are the "warnings" list of
the JSON instead, and stdout is the JSON alone. Run as subprocesses, as a user runs them.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import impactbeam as ib

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


def _run(*args: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.run([sys.executable, "-m", "impactbeam", *args], capture_output=True, text=True, env=env,
                          timeout=600)
    assert proc.returncode == 0, proc.stderr
    return proc


def _warning_lines(text: str) -> list[str]:
    return [ln for ln in text.splitlines() if ln.startswith("warning:")]


#: Two forcing frequencies in the specimen's window without a period (docs/periodic.md), with short
#: settling so that no period is found: each value warns.
BIFURCATION = [str(EXAMPLES / "periodic" / "specimen_harmonic.toml"), "--parameter", "excitation.frequency",
               "--values", "64 Hz,64.25 Hz", "--settle-periods", "4", "--record-periods", "4"]


def test_bifurcation_table_on_stdout_warnings_on_stderr():
    proc = _run("bifurcation", *BIFURCATION)
    out = proc.stdout.splitlines()
    assert out[0].startswith("bifurcation over excitation.frequency") and len(out) == 2 + 2  # title, header, 2 rows
    assert not _warning_lines(proc.stdout)
    warned = _warning_lines(proc.stderr)
    assert len(warned) == 2 and all("no period" in ln for ln in warned), proc.stderr


def test_bifurcation_json_carries_the_warnings_and_nothing_else_on_stdout():
    proc = _run("bifurcation", *BIFURCATION, "--json")
    data = json.loads(proc.stdout)  # stdout is the JSON alone
    assert len(data["warnings"]) == 2 and all("no period" in w for w in data["warnings"])
    assert not _warning_lines(proc.stderr)  # reported once, in the JSON


@pytest.fixture(scope="module")
def warning_scenario(tmp_path_factory) -> Path:
    # The zero-gap Case 9 with the paper's basis and 2 modes: the projection at the switches moves the
    # contactor by more than 5 % of its deflection, and the run says so (an ImpactBeamWarning).
    sc = ib.load_scenario(EXAMPLES / "case09.toml").with_values({"solver.basis": "paper", "solver.modes": 2})
    path = tmp_path_factory.mktemp("streams") / "case09_2modes.toml"
    path.write_text(sc.to_toml())
    return path


def test_simulate_summary_on_stdout_warnings_on_stderr(warning_scenario):
    proc = _run("simulate", str(warning_scenario))
    assert proc.stdout.startswith("Simulation of") and not _warning_lines(proc.stdout)
    assert any("too stiff for this number of modes" in ln for ln in _warning_lines(proc.stderr)), proc.stderr
    proc = _run("simulate", str(warning_scenario), "--json")
    data = json.loads(proc.stdout)
    assert any("too stiff for this number of modes" in w for w in data["warnings"])
    assert not _warning_lines(proc.stderr)


def test_progress_into_a_pipe_is_whole_lines_before_the_warnings():
    # A bar redrawn with carriage returns ran into the first warning line of a CI log (the run took
    # more than the 2 s before progress shows): into a pipe, progress is whole lines, and the
    # warnings come after the last one, each on its own line.
    code = (
        "import time, warnings\n"
        "from impactbeam.cli._group import handle_errors, progress_bar\n"
        "from impactbeam.exceptions import ImpactBeamWarning\n"
        "@handle_errors\n"
        "def command():\n"
        "    with progress_bar(1.0, desc='simulate', unit='s', after=0.0) as report:\n"
        "        report(0.25); warnings.warn('too stiff', ImpactBeamWarning); time.sleep(0.05); report(1.0)\n"
        "command()\n"
    )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr
    err = proc.stderr.decode()
    assert "\r" not in err
    lines = err.splitlines()
    assert lines[0].startswith("simulate:  25% (0.25/1 s)"), err
    assert lines[-2].startswith("simulate: 100% (1/1 s)"), err
    assert lines[-1] == "warning: too stiff", err


def test_a_sweep_into_a_pipe_reports_progress_in_whole_lines(tmp_path):
    # The sweep, the paper's reproduction and the commands share one progress rule
    # (impactbeam._warnings.Progress): into a pipe, lines without carriage returns.
    spec = tmp_path / "s.toml"
    spec.write_text(f'base = "{(EXAMPLES / "case03.toml").as_posix()}"\ndesign = "grid"\n'
                    '[parameters."contactors.0.gap"]\nvalues = [0.0, 1e-4]\n[outputs]\nmetrics = ["max_response"]\n')
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.run([sys.executable, "-m", "impactbeam", "sweep", str(spec), "--out", str(tmp_path / "o.zarr"),
                           "--workers", "0"], capture_output=True, env=env, timeout=600)  # bytes: "\r" kept
    err = proc.stderr.decode()
    assert proc.returncode == 0, err
    assert "\r" not in err
    lines = [ln for ln in err.splitlines() if ln.startswith("sweep:")]
    assert lines and lines[-1].startswith("sweep: 100% (2/2 case)"), err


def test_a_closed_progress_shows_nothing_more(capsys, monkeypatch):
    # The convergence estimate's runs reported to the simulation's bar after it had closed: a line
    # "simulate: 81%" came after the run had ended. A closed Progress ignores late reports.
    import impactbeam._warnings as w
    from impactbeam._warnings import Progress

    monkeypatch.setattr(w, "LINE_EVERY", 0.0)  # every report is a line
    with Progress(1.0, desc="simulate", unit="s", after=0.0) as report:
        report(0.5)
    report(0.75)
    err = capsys.readouterr().err.splitlines()
    assert [ln.split(" after")[0] for ln in err] == ["simulate:  50% (0.5/1 s)", "simulate:  50% (0.5/1 s)"]


def test_the_convergence_estimate_reports_its_own_runs():
    # The estimate repeats the run at two coarser counts; the command line shows that as its own
    # progress ("convergence estimate"), not on the simulation's bar.
    sc = ib.load_scenario(EXAMPLES / "case03.toml")
    seen: list[float] = []
    res = ib.simulate(sc, progress=seen.append)
    n_run = len(seen)
    conv = res.estimate_convergence(seen.append)
    assert conv == ib.simulate(sc).convergence
    est = seen[n_run:]
    assert len(est) >= 2 and est[-1] == 2.0 and all(b >= a for a, b in zip(est, est[1:]))
    assert res.estimate_convergence(seen.append) is conv and len(seen) == n_run + len(est)  # computed once


# the script's quick exit (impactbeam.cli.console_main ends the process with os._exit)


def test_console_exit_keeps_status_and_output(tmp_path):
    """The script's quick exit: stdout complete through a pipe, exit status 0, 2 (bad input) kept."""
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    cli = [sys.executable, "-m", "impactbeam"]

    def run(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run([*cli, *args], capture_output=True, text=True, env=env, timeout=300)

    ok = run("simulate", str(EXAMPLES / "case03.toml"), "--json", "--end-time", "0.02")
    assert ok.returncode == 0, ok.stderr
    assert json.loads(ok.stdout)["n_impacts"] >= 0  # the whole JSON arrived
    bad = run("simulate", str(tmp_path / "missing.toml"))
    assert bad.returncode == 2 and bad.stderr.startswith("error:")
    version = run("--version")
    assert version.returncode == 0 and "impactbeam" in version.stdout


def test_large_output_through_a_pipe_is_complete(tmp_path):
    """More than a pipe's buffer of output (a CSV written to stdout would be): flushed before the exit."""
    code = ("import sys\nsys.argv = ['impactbeam', '--help']\nfrom impactbeam.cli import console_main\n"
            "print('x' * 200000)\nconsole_main()\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0
    assert out.stdout.startswith("x" * 200000) and "Usage" in out.stdout
