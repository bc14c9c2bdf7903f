"""SIGINT stops a long bifurcation diagram cleanly: exit 130, one line, no file written."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.faults

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "periodic" / "specimen_harmonic.toml"
CLI = [sys.executable, "-c", "import sys; from impactbeam.cli import main; sys.argv[0] = 'impactbeam'; main()"]


def test_bifurcation_stops_on_sigint(tmp_path):
    out, png = tmp_path / "d.nc", tmp_path / "d.png"
    # 4000 values of 2000 periods each take minutes
    proc = subprocess.Popen(
        [*CLI, "bifurcation", str(EXAMPLE), "--parameter", "excitation.frequency", "--range", "30", "90", "4000",
         "--settle-periods", "2000", "--out", str(out), "--plot", str(png), "--json"],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True,
        env={**os.environ, "MPLBACKEND": "Agg"},
    )
    time.sleep(8.0)
    assert proc.poll() is None, proc.communicate()
    t0 = time.monotonic()
    os.killpg(proc.pid, signal.SIGINT)
    stdout, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err[-2000:]
    assert time.monotonic() - t0 < 5.0
    assert "Traceback" not in err and "interrupted" in err
    assert stdout == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == []
