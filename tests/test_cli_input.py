"""The command line's handling of bad input (the scenario contract: bad input exits 2 naming the key).

The real console script is run in a subprocess, as a user would run it: bad
input must exit with status 2 and print exactly one line on stderr,
``error: ...`` naming the key, never a traceback, and leave no output file.
Every error here is raised while the scenario is parsed, before any solver
code runs, so these tests do not depend on modes()/simulate() results.
"""

from __future__ import annotations

import json
import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from impactbeam._io import to_jsonable
from specimen import BEAM

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _command() -> list[str]:
    """The installed console script next to this interpreter, else ``python -m impactbeam.cli``."""
    script = shutil.which("impactbeam", path=str(Path(sys.executable).parent))
    return [script] if script else [sys.executable, "-m", "impactbeam.cli"]


def run(*args: str | Path, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*_command(), *map(str, args)], capture_output=True, text=True, cwd=cwd, timeout=120
    )


def assert_one_error_line(proc: subprocess.CompletedProcess[str], status: int, *needles: str) -> str:
    assert proc.returncode == status, (proc.returncode, proc.stdout, proc.stderr)
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("error: ")
    for needle in needles:
        assert needle in lines[0], lines[0]
    assert proc.stdout == ""
    return lines[0]


# (scenario text, extra files, text the error line must contain)
BAD = [
    pytest.param(BEAM.replace("length = 0.1092", "length = -0.1"), {}, "beam.length", id="negative-length"),
    pytest.param(BEAM.replace("length = 0.1092", "lenght = 0.1092"), {},
                 'unknown key "beam.lenght" (did you mean "beam.length"?)', id="unknown-key"),
    pytest.param(BEAM + "[[contactors]]\nposition = 0.2\nstiffness = 4030\n", {},
                 "contactors.0.position: 0.2 m is off the beam", id="contactor-off-beam"),
    pytest.param(BEAM + "[[contactors]]\nposition = 0.05\nstiffness = 4030\ngap = -1e-4\n", {},
                 "contactors.0.gap", id="negative-gap"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\namplitude = "nan"\nduration = 0.01\n', {},
                 "excitation.amplitude", id="nan"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\namplitude = "15 kg"\nduration = 0.01\n', {},
                 "excitation.amplitude", id="wrong-unit"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "gone.csv"\n', {},
                 "excitation.file", id="missing-trace"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "t.csv"\n',
                 {"t.csv": "time [ms],acceleration [g]\n0,0\n1,nan\n"}, "excitation.file", id="nan-in-trace"),
    pytest.param(BEAM + "[solver]\ntime_step = 0\n", {}, "solver.time_step", id="zero-time-step"),
    pytest.param("[beam]\nlength = 1\nwidth =\n", {}, "invalid TOML", id="toml-syntax"),
]


@pytest.mark.parametrize("command", ["simulate", "modes"])
@pytest.mark.parametrize(("text", "files", "needle"), BAD)
def test_bad_scenario_exits_2(
    tmp_path: Path, scenario_file, command: str, text: str, files: dict[str, str], needle: str
) -> None:
    # Reason: the contract for bad input: status 2, one clear line naming the key, no
    # traceback, and (simulate --out) no output file left behind.
    for name, content in files.items():
        (tmp_path / name).write_text(content, encoding="utf-8")
    scenario = scenario_file(text, "bad.toml")
    out = tmp_path / "result.nc"
    extra = ["--out", str(out), "--json"] if command == "simulate" else ["--json"]
    proc = run(command, scenario, *extra)
    assert_one_error_line(proc, 2, needle)
    assert not out.exists()


@pytest.mark.parametrize("command", ["simulate", "modes"])
def test_missing_scenario_file(tmp_path: Path, command: str) -> None:
    # Reason: a wrong path is bad input too (exit 2, one line naming the file).
    proc = run(command, tmp_path / "nope.toml")
    assert_one_error_line(proc, 2, "nope.toml", "not found")


def test_unsupported_out_suffix_checked_before_simulating(tmp_path: Path) -> None:
    # Reason: a typo in --out must not cost a whole simulation; rejected up front.
    out = tmp_path / "result.txt"
    proc = run("simulate", EXAMPLES / "case03.toml", "--out", out)
    assert_one_error_line(proc, 2, "--out", ".txt")
    assert not out.exists()


def test_out_directory_must_exist(tmp_path: Path) -> None:
    # Reason: same as above, for a missing directory.
    proc = run("simulate", EXAMPLES / "case03.toml", "--out", tmp_path / "no" / "r.nc")
    assert_one_error_line(proc, 2, "--out", "does not exist")


@pytest.mark.parametrize(
    ("option", "value", "needle"),
    [("--modes", "0", "solver.modes"), ("--time-step", "-1e-5", "solver.time_step"),
     ("--end-time", "5 kg", "solver.end_time")],
)
def test_bad_overrides(tmp_path: Path, option: str, value: str, needle: str) -> None:
    # Reason: command-line overrides go through Scenario.with_values and are validated
    # like file values, before the solver runs.
    out = tmp_path / "r.nc"
    proc = run("simulate", EXAMPLES / "case03.toml", option, value, "--out", out)
    assert_one_error_line(proc, 2, needle)
    assert not out.exists()


def test_modes_bad_count() -> None:
    # Reason: --count must be positive; same one-line error.
    proc = run("modes", EXAMPLES / "specimen.toml", "--count", "0")
    assert_one_error_line(proc, 2, "--count")


@pytest.mark.parametrize(
    ("args", "needles"),
    [(["simulate", "CASE3", "--bogus"], ["impactbeam simulate", "--bogus"]),
     (["random", "CASE3", "--seeds", "x"], ["impactbeam random", "--seeds", "'x'"]),
     (["bogus"], ["No such command", "'bogus'"]),
     (["simulate"], ["impactbeam simulate", "SCENARIO"]),
     (["--bogus"], ["--bogus"])],
    ids=["unknown-option", "option-type", "unknown-command", "missing-argument", "group-option"],
)
def test_usage_errors_are_one_line(args: list[str], needles: list[str]) -> None:
    # Reason: a mistyped option or command is bad input like a bad scenario value: status 2 and one
    # line naming the option (click's own display takes three: usage, hint, error).
    proc = run(*[str(EXAMPLES / "case03.toml") if a == "CASE3" else a for a in args])
    assert_one_error_line(proc, 2, *needles)


def test_a_bare_command_shows_the_help() -> None:
    # Reason: no command at all is not an error line: the help, as click shows it (on stderr with click >= 8.2).
    proc = run()
    assert "Usage: impactbeam" in proc.stdout + proc.stderr and "error:" not in proc.stderr
    assert "simulate" in proc.stdout + proc.stderr


def test_help_and_info() -> None:
    # Reason: the entry point is installed and the cheap commands work without a scenario.
    proc = run("--help")
    assert proc.returncode == 0 and "simulate" in proc.stdout and "modes" in proc.stdout
    proc = run("info")
    assert proc.returncode == 0, proc.stderr
    for name in ("impactbeam", "python", "numpy", "scipy", "xarray", "pint"):
        assert name in proc.stdout


def test_to_jsonable() -> None:
    # Reason: --json output must be strict JSON: NaN/inf/None -> null, numpy -> Python.
    data = {"a": np.float64(1.5), "b": math.nan, "c": None, "d": np.int64(3),
            "e": [{"time": np.float32(0.5), "kind": "impact", "contactor": np.int64(0)}],
            "f": np.array([1.0, np.inf]), "g": (1, 2)}
    text = json.dumps(to_jsonable(data), allow_nan=False)
    assert json.loads(text) == {"a": 1.5, "b": None, "c": None, "d": 3,
                                "e": [{"time": 0.5, "kind": "impact", "contactor": 0}],
                                "f": [1.0, None], "g": [1, 2]}


def test_result_file_holds_what_the_command_reported(tmp_path: Path) -> None:
    # Reason: a result file carries its provenance: the metrics as --json gave them (the convergence
    # estimate, the impact statistics) and every warning of the command, not only the run's own.
    # Case 3 on the paper's basis with 2 modes warns twice: the projections' energy (the run's own
    # warning) and the convergence estimate's (a re-run's, given by the command).
    scenario = tmp_path / "paper.toml"
    text = (EXAMPLES / "case03.toml").read_text(encoding="utf-8")
    scenario.write_text(text.replace("[solver]", '[solver]\nbasis = "paper"', 1), encoding="utf-8")
    xr = pytest.importorskip("xarray")
    pytest.importorskip("h5netcdf")
    out = tmp_path / "r.nc"
    proc = run("simulate", scenario, "--modes", "2", "--json", "--out", out)
    assert proc.returncode == 0, proc.stderr
    reported = json.loads(proc.stdout)
    assert any("not converged in the number of modes" in w for w in reported["warnings"])
    with xr.open_dataset(out) as ds:
        stored = json.loads(ds.attrs["metrics"])
        warned = ds.attrs["warnings"]
    assert stored["convergence"] == reported["convergence"]
    assert stored["impact_statistics"] == reported["impact_statistics"]
    assert stored["n_impacts"] == reported["n_impacts"] and stored["modes"] == 2
    assert warned == "; ".join(reported["warnings"])


def test_a_load_that_never_acts_reports_zero_not_minus_zero(tmp_path: Path) -> None:
    # max_response was printed "-0.0" in the JSON of a run whose load never acts
    scenario = tmp_path / "still.toml"
    text = (EXAMPLES / "case03.toml").read_text(encoding="utf-8")
    scenario.write_text(text.replace('amplitude = "15 g"', 'amplitude = "0 g"'), encoding="utf-8")
    proc = run("simulate", scenario, "--json", "--end-time", "0.01")
    assert proc.returncode == 0, proc.stderr
    assert '"max_response": 0.0' in proc.stdout and "-0.0" not in proc.stdout
