"""One reader of delimited data: scenario traces and measured records honour the same unit headers.

Issue: a trace with the header ``time (ms),acceleration (g)`` was read as
seconds and m/s^2 (parentheses were not recognised by the trace reader),
while the record reader applied them. Both now go through
``impactbeam._io``; these tests check the units reach the simulation.
"""

from __future__ import annotations

import math
from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest

import impactbeam as ib
from impactbeam import experiment as ex
from impactbeam.exceptions import ParameterError
from impactbeam.units import STANDARD_GRAVITY
from specimen import BEAM, CONTACTOR

SCENARIO = BEAM + CONTACTOR + """
[excitation]
kind = "base_acceleration"
shape = "table"
file = "{file}"
hold = "linear"

[solver]
modes = 6
end_time = 0.06
time_step = 1e-4
"""

# A 15 g, 15 ms half-sine pulse written every 0.5 ms (written numbers, exact decimals).
MS = [Decimal(i) / 2 for i in range(41)]
G = [Decimal(f"{15 * math.sin(math.pi * float(t) / 15):.6f}") if t <= 15 else Decimal(0) for t in MS]


def _write_traces(tmp_path: Path, header_si: str, header_user: str) -> tuple[Path, Path]:
    si = tmp_path / "si.csv"
    user = tmp_path / "user.csv"
    # SI file: the exact decimal products (ms * 0.001, g * 9.80665), so that a
    # reader that scales in decimal gives bit-identical floats.
    si.write_text(header_si + "\n" + "\n".join(
        f"{t * Decimal('0.001')},{a * Decimal(repr(STANDARD_GRAVITY))}" for t, a in zip(MS, G)) + "\n")
    user.write_text(header_user + "\n" + "\n".join(f"{t},{a}" for t, a in zip(MS, G)) + "\n")
    return si, user


@pytest.mark.parametrize("header", ["time (ms),acceleration (g)", "time [ms],acceleration [g]"])
def test_trace_in_ms_and_g_simulates_like_si(tmp_path: Path, header: str) -> None:
    """Same trace in ms/g and in SI: the same simulation, metrics equal to 1e-12 relative.

    The tolerance is round-off only: the two files hold the same numbers
    (decimal scaling gives identical floats), so any difference would mean
    the header was ignored (then the response is ~1e3 x 1e-1 different, not 1e-12).
    """
    si, user = _write_traces(tmp_path, "time (s),acceleration (m/s^2)", header)
    (tmp_path / "si.toml").write_text(SCENARIO.format(file="si.csv"))
    (tmp_path / "user.toml").write_text(SCENARIO.format(file="user.csv"))
    a = ib.load_scenario(tmp_path / "si.toml")
    b = ib.load_scenario(tmp_path / "user.toml")
    np.testing.assert_array_equal(a.excitation.times, b.excitation.times)
    np.testing.assert_array_equal(a.excitation.values, b.excitation.values)
    assert b.excitation.times[1] == 0.0005 and b.excitation.values.max() == pytest.approx(15 * STANDARD_GRAVITY, rel=1e-6)
    ma = ib.simulate(a).metrics()
    mb = ib.simulate(b).metrics()
    assert ma["max_penetration"] > 1e-5  # the pulse drives the beam into the stop: a real response
    for key, va in ma.items():
        vb = mb[key]
        if isinstance(va, float) and math.isfinite(va):
            assert vb == pytest.approx(va, rel=1e-12, abs=1e-300), key
        else:
            assert vb == va, key


@pytest.mark.parametrize("unit", ["[mm/(s^2)]", "(mm/(s^2))", "[mm/s^2]"])
def test_a_unit_with_parentheses_in_a_header_is_honoured(tmp_path: Path, unit: str) -> None:
    # "acc [mm/(s^2)]" did not match the header pattern: the whole cell became the column's name and the
    # values were read as m/s^2, 1000 times too large, in silence
    (tmp_path / "t.csv").write_text(f"time [ms],acc {unit}\n0,0\n1,1500\n2,0\n")
    (tmp_path / "s.toml").write_text(SCENARIO.format(file="t.csv"))
    ex = ib.load_scenario(tmp_path / "s.toml").excitation
    assert list(ex.times) == [0.0, 0.001, 0.002] and list(ex.values) == [0.0, 1.5, 0.0]


def test_trace_and_record_read_the_same_numbers(tmp_path: Path) -> None:
    """The scenario trace and load_record give identical SI arrays from one file."""
    user = _write_traces(tmp_path, "time,acceleration", "time (ms),acceleration (g)")[1]
    (tmp_path / "user.toml").write_text(SCENARIO.format(file="user.csv"))
    sc = ib.load_scenario(tmp_path / "user.toml")
    rec = ex.load_record(user, resample=False)
    assert rec.quantity == "acceleration"
    np.testing.assert_array_equal(rec.time, sc.excitation.times)
    np.testing.assert_array_equal(rec.values, sc.excitation.values)


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("time (kg),acceleration (g)\n0,0\n1,1\n", ['user.csv', "column 1", '"kg"', "a mass"]),
        ("time (ms),acceleration (mm)\n0,0\n1,1\n", ['user.csv', "column 2", '"mm"', "a length"]),
        ("time (ms),acceleration (bananas)\n0,0\n1,1\n", ["column 2", "bananas"]),
        ("acceleration (g)\n0\n1\n", ["only one column", "needs two"]),
        ("0\n1\n2\n", ["only one column"]),
    ],
    ids=["time-in-kg", "accel-in-mm", "unknown-unit", "one-column-header", "one-column"],
)
def test_bad_trace_header(tmp_path: Path, text: str, expected: list[str]) -> None:
    (tmp_path / "user.csv").write_text(text)
    (tmp_path / "user.toml").write_text(SCENARIO.format(file="user.csv"))
    with pytest.raises(ParameterError) as info:
        ib.load_scenario(tmp_path / "user.toml")
    msg = str(info.value)
    assert msg.startswith("excitation.file: ")
    for part in expected:
        assert part in msg, msg
    if "one column" in expected[0]:
        assert "unit" not in msg  # about the missing column, not about units


def test_record_unit_error_names_file_column_and_unit(tmp_path: Path) -> None:
    p = tmp_path / "r.csv"
    p.write_text("time (kg),deflection (mm)\n" + "\n".join(f"{i},{i}" for i in range(10)) + "\n")
    with pytest.raises(ParameterError) as info:
        ex.load_record(p)
    msg = str(info.value)
    assert "r.csv" in msg and "column 1" in msg and '"kg"' in msg


def test_blank_separated_header_keeps_name_and_unit_together(tmp_path: Path) -> None:
    """``time (ms)  acceleration (g)`` separated by blanks: two columns, units applied."""
    p = tmp_path / "blank.txt"
    p.write_text("time (ms)   acceleration (g)\n0 0\n0.5 1\n1.0 2\n")
    (tmp_path / "b.toml").write_text(SCENARIO.format(file="blank.txt"))
    sc = ib.load_scenario(tmp_path / "b.toml")
    assert list(sc.excitation.times) == [0.0, 0.0005, 0.001]
    assert sc.excitation.values[2] == 2 * STANDARD_GRAVITY
