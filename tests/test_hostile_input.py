"""Misleading messages and silent acceptances of issue 11 (items 4, 5, 7 and 8), input side.

Each row: the input, the exit status and a substring of the one ``error:``
line (or of the warning), run through the real console script as a user
would. Items 4 and 7 (extreme magnitudes, warnings) are in test_warnings.py;
item 5 (identify on a constant record) in test_identify_short.py.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from test_cli_input import BEAM, EXAMPLES, assert_one_error_line, run

import impactbeam as ib
from impactbeam.exceptions import ScenarioError

TRACE_SCENARIO = BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "t.csv"\n'


# (arguments; {file name: content}; exit status; substring of the error line; substring it must NOT contain)
CASES = [
    pytest.param(["simulate", ""], {}, 2, "the path is empty", "directory", id="empty-scenario-path"),
    pytest.param(["modes", ""], {}, 2, "the path is empty", "directory", id="empty-scenario-path-modes"),
    pytest.param(["simulate", str(EXAMPLES / "case03.toml"), "--out", "{tmp}"], {}, 2,
                 "is a directory; give a file name in it", "unsupported file type", id="out-is-a-directory"),
    pytest.param(["simulate", str(EXAMPLES / "case03.toml"), "--out", "{tmp}/sub/"], {}, 2,
                 "is a directory", "unsupported file type", id="out-ends-with-slash"),
    pytest.param(["simulate", str(EXAMPLES / "case03.toml"), "--plot", "{tmp}"], {}, 2,
                 "--plot", "unsupported file type", id="plot-is-a-directory"),
    pytest.param(["simulate", "{tmp}/s.toml"], {"s.toml": TRACE_SCENARIO, "t.csv": "acceleration (g)\n0\n1\n2\n"}, 2,
                 "only one column", "unit", id="one-column-trace-with-unit"),
    pytest.param(["simulate", "{tmp}/s.toml"], {"s.toml": TRACE_SCENARIO, "t.csv": "0\n1\n2\n"}, 2,
                 "only one column", "unit", id="one-column-trace"),
    pytest.param(["simulate", "{tmp}/s.toml"], {"s.toml": TRACE_SCENARIO, "t.csv": "time (kg),acceleration (g)\n0,0\n1,1\n"},
                 2, 'column 1 (\'time\'), unit "kg"', None, id="trace-time-in-kg"),
]


@pytest.mark.parametrize(("args", "files", "status", "needle", "absent"), CASES)
def test_input_gets_one_precise_line(tmp_path: Path, args: list[str], files: dict[str, str], status: int,
                                     needle: str, absent: str | None) -> None:
    (tmp_path / "sub").mkdir()
    for name, content in files.items():
        (tmp_path / name).write_text(content)
    line = assert_one_error_line(run(*[a.format(tmp=tmp_path) for a in args]), status, needle)
    if absent is not None:
        assert absent not in line


def test_load_scenario_empty_path() -> None:
    with pytest.raises(ScenarioError, match="the path is empty"):
        ib.load_scenario("")


def test_simulate_given_a_path_says_to_load_it() -> None:
    for arg in ("case03.toml", EXAMPLES / "case03.toml"):
        with pytest.raises(TypeError, match=r"load_scenario"):
            ib.simulate(arg)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="expected a Scenario"):
        ib.simulate({"beam": {}})  # type: ignore[arg-type]


@pytest.mark.parametrize("level", [0.0, 1e-4], ids=["zero", "constant"])
def test_compare_against_a_constant_record(tmp_path: Path, level: float) -> None:
    """No "inf %": the relative rms is n/a (null) when the record's rms is 0, and a constant record is warned about."""
    t = np.arange(100) / 2000.0
    p = tmp_path / "flat.csv"
    p.write_text("time,deflection\n" + "\n".join(f"{float(a)!r},{level!r}" for a in t))
    proc = run("compare", EXAMPLES / "case03.toml", p)
    assert proc.returncode == 0, proc.stderr
    assert "inf" not in proc.stdout and "nan" not in proc.stdout.lower()
    assert any(line.startswith("warning: ") and "constant" in line for line in proc.stderr.splitlines())
    d = json.loads(run("compare", EXAMPLES / "case03.toml", p, "--json").stdout)
    assert any("constant" in w for w in d["warnings"])
    if level == 0.0:
        assert d["nrmse"] is None and "n/a" in proc.stdout
    else:
        assert d["nrmse"] is not None and math.isfinite(d["nrmse"])
