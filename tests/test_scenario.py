"""Scenario files: parsing, units, defaults, dotted paths, round trips and bad input.

The scenario layer is the project's input boundary (docs/scenario reference and the CLI contract):
every value a user writes must reach the data classes in SI, and every
mistake must come back as a ScenarioError that names the dotted key.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from impactbeam.model.beam import Contactor
from impactbeam.exceptions import ParameterError, ScenarioError
from impactbeam.scenario import (
    Scenario,
    dump_scenario,
    load_scenario,
    parse_scenario,
    read_table,
    scenario_paths,
    set_path,
)
from impactbeam.units import STANDARD_GRAVITY, to_si

from specimen import BEAM, CONTACTOR

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"

PULSE = """
[excitation]
kind = "base_acceleration"
amplitude = "15 g"
duration = "15 ms"
"""


# --------------------------------------------------------------------------- examples


@pytest.mark.parametrize(
    "path", sorted(p for p in EXAMPLES.glob("*.toml") if not p.name.startswith("sweep")), ids=lambda p: p.name
)
def test_every_example_parses(path: Path) -> None:
    # Reason: the examples document the format; each must load as shipped.
    sc = load_scenario(path)
    assert isinstance(sc, Scenario)
    assert sc.source == path.resolve()
    assert sc.base_dir == path.resolve().parent
    assert sc.beam.length == 0.10920


def test_example_set_is_complete() -> None:
    # Reason: the paper's Table 1 has Cases 0..13; one file each plus the specimen.
    names = {p.stem for p in EXAMPLES.glob("*.toml") if not p.name.startswith("sweep")}  # sweep files are not scenarios
    assert names == {"specimen"} | {f"case{n:02d}" for n in range(14)}


def test_specimen_values() -> None:
    # Reason: the specimen must carry the paper's numbers exactly (section 3, Table 1 Case 3);
    # decimal strings such as "3.03 mm" must give the same float as 3.03e-3.
    sc = load_scenario(EXAMPLES / "specimen.toml")
    b = sc.beam
    assert (b.length, b.width, b.height) == (0.10920, 9.93e-3, 3.03e-3)
    assert b.youngs_modulus == 1834e6 and b.density == 951.98
    assert b.left.name == "clamped" and b.right.name == "free"
    (c,) = sc.contactors
    assert c.position == 0.4840 * 0.10920
    assert (c.stiffness, c.gap, c.side) == (4030.0, 0.229e-3, "above")
    assert (sc.damping.free, sc.damping.contact) == (0.011, 0.02)
    ex = sc.excitation
    assert (ex.kind, ex.shape) == ("base_acceleration", "half_sine")
    assert ex.amplitude == 15 * STANDARD_GRAVITY and ex.duration == 0.015
    assert (sc.solver.modes, sc.solver.time_step, sc.solver.end_time) == (8, 1e-5, 0.2)
    assert sc.output_points == (c.position, 0.10920)
    assert sc.name == "specimen"


# Table 1 of Xu & Ervin (2013): case -> (amplitude [g], duration [ms], gap [mm] or None)
TABLE1 = {
    1: (9, 15, None), 2: (15, 15, 0.102), 3: (15, 15, 0.229), 4: (15, 10, 0.229),
    5: (15, 5, 0.229), 6: (10, 15, 0.229), 7: (5, 15, 0.229), 8: (12.5, 15, 0.229),
    9: (15, 15, 0.0), 10: (15, 15, 0.432), 11: (15, 15, 0.686), 12: (15, 15, None),
}


@pytest.mark.parametrize("case", sorted(TABLE1))
def test_table1_pulse_cases(case: int) -> None:
    # Reason: each case file must match its Table 1 row (amplitude, duration, gap).
    amp_g, dur_ms, gap_mm = TABLE1[case]
    sc = load_scenario(EXAMPLES / f"case{case:02d}.toml")
    assert sc.excitation.amplitude == pytest.approx(amp_g * STANDARD_GRAVITY, rel=1e-15)
    assert sc.excitation.duration == pytest.approx(dur_ms * 1e-3, rel=1e-15)
    if gap_mm is None:
        assert sc.contactors == ()
    else:
        (c,) = sc.contactors
        assert c.gap == pytest.approx(gap_mm * 1e-3, rel=1e-15, abs=0.0)
        assert c.position == pytest.approx(0.4840 * 0.10920, rel=1e-15)
        assert (c.stiffness, c.side) == (4030.0, "above")


@pytest.mark.parametrize("case", [0, 13])
def test_release_cases(case: int) -> None:
    # Reason: Cases 0/13 are a 2 mm tip release with no contactor and no load.
    sc = load_scenario(EXAMPLES / f"case{case:02d}.toml")
    assert sc.initial.tip_displacement == 2e-3
    assert sc.excitation.kind == "none" and not sc.excitation.active
    assert sc.contactors == () and sc.solver.end_time == 0.5


# --------------------------------------------------------------------------- units


@pytest.mark.parametrize(
    ("value", "dimension", "expected"),
    [
        ("0.229 mm", "length", 0.229e-3),
        ("15 g", "acceleration", 15 * 9.80665),
        ("0.5 g", "acceleration", 0.5 * 9.80665),
        ("9.81 m/s^2", "acceleration", 9.81),
        ("15 ms", "time", 0.015),
        ("10 us", "time", 1e-5),
        ("1834 MPa", "modulus", 1834e6),
        ("4030 N/m", "stiffness", 4030.0),
        ("1 kN/mm", "stiffness", 1e6),
        ("50 N m/rad", "rotational_stiffness", 50.0),
        ("951.98 kg/m^3", "density", 951.98),
        ("30 mm^2", "area", 30e-6),
        ("2 N", "force", 2.0),
        ("3 N/m", "force_per_length", 3.0),
        ("1.1 %", "dimensionless", 0.011),
        ("inf", "stiffness", math.inf),
        ("infinity", "rotational_stiffness", math.inf),
        (0.25, "length", 0.25),
        (3, "time", 3.0),
        ("0.5", "length", 0.5),
    ],
)
def test_to_si(value: object, dimension: str, expected: float) -> None:
    # Reason: unit strings must reach SI exactly (g is standard gravity, not gram);
    # equality is exact because decimal strings are scaled in decimal arithmetic.
    assert to_si(value, dimension, "k") == expected


@pytest.mark.parametrize(
    ("value", "dimension", "match"),
    [
        ("15 kg", "acceleration", r'^excitation\.amplitude: "15 kg" is a mass, expected an acceleration \(m/s\^2\)$'),
        ("15 g", "force", r"is a mass, expected a force \(N\)"),
        ("nan", "length", "NaN"),
        (float("nan"), "length", "NaN"),
        ("nan mm", "length", "NaN"),
        ("inf", "length", "finite"),
        (math.inf, "time", "finite"),
        ("15 gee", "acceleration", "cannot read"),
        ("mm", "length", "expected one number"),
        (True, "length", "expected a number"),
        ([1.0], "length", "got a list"),
        # one number and a unit: a decimal comma, a thousands separator or arithmetic was read as another
        # number ("0,229 mm" as 0, "1 000 um" as 0, "2 m + 1 m" as 4 m, "1.5.3 mm" as 0.45 mm)
        ("0,229 mm", "length", "expected one number"),
        ("1 000 um", "length", '"000 um" is not a unit'),
        ("2 m + 1 m", "length", "is not a unit"),
        ("15 g + 1 g", "acceleration", "is not a unit"),
        ("1.5.3 mm", "length", "expected one number"),
        # an angle where the dimension has none (pint takes the radian as dimensionless): "0.5 deg" was a
        # position ratio of 0.0087, "1e6 cycles" a count of 6.28e6, "100 %" an angle of 1 rad
        ("0.5 deg", "dimensionless", "has an angle in its unit"),
        ("1e6 cycles", "dimensionless", "has an angle in its unit"),
        ("1 rpm", "rate", "has an angle in its unit"),
        ("100 %", "angle", "has no angle in its unit"),
        ("1 1/s", "angular_velocity", "has no angle in its unit"),
    ],
)
def test_to_si_rejects(value: object, dimension: str, match: str) -> None:
    # Reason: a wrong dimension, NaN or nonsense must be an error naming the key, never a number.
    with pytest.raises(ScenarioError, match=match) as info:
        to_si(value, dimension, "excitation.amplitude")
    assert info.value.key == "excitation.amplitude"
    assert str(info.value).startswith("excitation.amplitude: ")


# --------------------------------------------------------------------------- parsing


def test_unit_strings_in_a_file(tmp_path: Path) -> None:
    # Reason: every field accepts unit strings; the parsed objects hold SI.
    text = """
[beam]
length = "109.2 mm"
width = "9.93 mm"
height = "3.03 mm"
youngs_modulus = "1.834 GPa"
density = "0.95198 g/cm^3"

[supports]
left = { translational = "inf", rotational = "200 N m/rad" }

[[contactors]]
position = "52.85 mm"
stiffness = "4.03 N/mm"
gap = "0.229 mm"

[excitation]
kind = "base_acceleration"
amplitude = "15 g"
duration = "15 ms"
start = "1 ms"

[solver]
time_step = "10 us"
end_time = "50 ms"
"""
    sc = parse_scenario(tomllib.loads(text))
    assert sc.beam.length == 0.1092 and sc.beam.height == 3.03e-3
    assert sc.beam.youngs_modulus == 1834e6
    assert sc.beam.density == pytest.approx(951.98, rel=1e-14)
    assert sc.beam.left.translational == math.inf and sc.beam.left.rotational == 200.0
    assert sc.beam.right.name == "free"
    c = sc.contactors[0]
    assert (c.position, c.stiffness, c.gap) == (52.85e-3, 4030.0, 0.229e-3)
    assert sc.excitation.amplitude == 15 * 9.80665
    assert (sc.excitation.duration, sc.excitation.start) == (0.015, 0.001)
    assert (sc.solver.time_step, sc.solver.end_time) == (1e-5, 0.05)


def test_defaults() -> None:
    # Reason: examples/README.md and the scenario reference promise these defaults.
    sc = parse_scenario(tomllib.loads(BEAM + '[[contactors]]\nposition = 0.05\nstiffness = 1e3\n'))
    assert sc.beam.left.name == "clamped" and sc.beam.right.name == "free"
    c = sc.contactors[0]
    assert (c.gap, c.side) == (0.0, "below")
    assert (sc.damping.free, sc.damping.contact) == (0.0, 0.0)
    assert sc.excitation.kind == "none" and not sc.excitation.active
    assert sc.initial.at_rest
    assert sc.solver.modes == 8 and sc.solver.time_step == 1e-5 and sc.solver.end_time == 0.2
    assert sc.output_points == (0.05, 0.1092)
    assert sc.name == "scenario"


def test_default_output_points_deduplicated() -> None:
    # Reason: two contactors at one point (a tube between two baffle faces) and one at
    # the tip give each point once, in order.
    data = tomllib.loads(
        BEAM
        + "[[contactors]]\nposition = 0.05\nstiffness = 1e3\nside = \"below\"\n"
        + "[[contactors]]\nposition = 0.05\nstiffness = 1e3\nside = \"above\"\n"
        + "[[contactors]]\nposition_ratio = 1.0\nstiffness = 1e3\n"
    )
    sc = parse_scenario(data)
    assert sc.output_points == (0.05, 0.1092)


def test_one_support_side_given() -> None:
    # Reason: a missing side keeps its default even when [supports] exists.
    sc = parse_scenario(tomllib.loads(BEAM + '[supports]\nright = "pinned"\n'))
    assert sc.beam.left.name == "clamped" and sc.beam.right.name == "pinned"
    sc = parse_scenario(tomllib.loads(BEAM + "[supports]\nright = { translational = 10 }\n"))
    assert (sc.beam.right.translational, sc.beam.right.rotational) == (10.0, 0.0)


def test_area_and_second_moment() -> None:
    # Reason: a general cross-section is given by A and I instead of b x h.
    text = "[beam]\nlength = 1\narea = 1e-4\nsecond_moment = 1e-9\nyoungs_modulus = 2e11\ndensity = 7800\n"
    sc = parse_scenario(tomllib.loads(text))
    assert (sc.beam.area, sc.beam.second_moment, sc.beam.width) == (1e-4, 1e-9, None)


def test_position_ratio_and_output_ratios() -> None:
    # Reason: ratios are fractions of the length: position = ratio * L.
    text = BEAM + CONTACTOR + "[output]\npoint_ratios = [0.25, 1.0]\n"
    sc = parse_scenario(tomllib.loads(text))
    assert sc.contactors[0].position == 0.4840 * 0.1092
    assert sc.output_points == (0.25 * 0.1092, 0.1092)


def test_point_force_and_lists(tmp_path: Path) -> None:
    # Reason: the kind sets the amplitude's unit; damping and modal lists are per mode.
    text = BEAM + """
[damping]
free = [0.01, "2 %"]
contact = 0.03
[excitation]
kind = "point_force"
shape = "step"
amplitude = "2 N"
position_ratio = 1.0
[initial]
modal_displacement = [1e-4, 0]
modal_velocity = [0, 0.5]
"""
    sc = parse_scenario(tomllib.loads(text))
    assert sc.damping.free == (0.01, 0.02) and sc.damping.contact == 0.03
    assert (sc.excitation.kind, sc.excitation.amplitude, sc.excitation.position) == ("point_force", 2.0, 0.1092)
    assert sc.initial.modal_displacement == (1e-4, 0.0) and sc.initial.modal_velocity == (0.0, 0.5)


def test_name_and_description(tmp_path: Path, scenario_file) -> None:
    # Reason: the name is the file stem unless the file gives one.
    sc = load_scenario(scenario_file(BEAM, "my_case.toml"))
    assert sc.name == "my_case" and sc.description is None
    sc = load_scenario(scenario_file('name = "x"\ndescription = "d"\n' + BEAM, "other.toml"))
    assert sc.name == "x" and sc.description == "d"


# --------------------------------------------------------------------------- trace tables


def test_table_excitation_with_units(tmp_path: Path, scenario_file) -> None:
    # Reason: header units convert the trace to SI; the file is relative to the scenario.
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "trace.csv").write_text(
        "# shaker record\ntime [ms],acceleration [g]\n0,0\n0.5,1.5\n\n1.0,3\n", encoding="utf-8"
    )
    text = BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "data/trace.csv"\nhold = "linear"\n'
    sc = load_scenario(scenario_file(text))
    ex = sc.excitation
    np.testing.assert_array_equal(ex.times, [0.0, 0.5e-3, 1e-3])
    np.testing.assert_array_equal(ex.values, [0.0, 1.5 * 9.80665, 3 * 9.80665])
    assert ex.hold == "linear"


def test_read_table_without_header_is_si(tmp_path: Path) -> None:
    # Reason: a bare two-column file is SI; semicolons and blanks are accepted separators.
    for sep in (",", ";", " "):
        p = tmp_path / "t.csv"
        p.write_text(f"0{sep}1\n0.001{sep}2\n", encoding="utf-8")
        t, v = read_table(p, value_dimension="force", key="excitation.file")
        np.testing.assert_array_equal(t, [0.0, 0.001])
        np.testing.assert_array_equal(v, [1.0, 2.0])


# --------------------------------------------------------------------------- dotted paths


def test_set_path_copies_and_creates() -> None:
    # Reason: set_path must never modify its input and may create absent schema tables.
    data = {"beam": {"length": 1.0}}
    new = set_path(data, "damping.contact", 0.02)
    assert new == {"beam": {"length": 1.0}, "damping": {"contact": 0.02}}
    assert data == {"beam": {"length": 1.0}}


def test_set_path_list_index_and_numpy() -> None:
    # Reason: sweeps pass numpy scalars and address contactors by index.
    data = tomllib.loads(BEAM + CONTACTOR)
    new = set_path(data, "contactors.0.gap", np.float64(4.32e-4))
    assert new["contactors"][0]["gap"] == 4.32e-4 and type(new["contactors"][0]["gap"]) is float
    assert data["contactors"][0]["gap"] == 0.229e-3


def test_set_path_alternatives_and_presets() -> None:
    # Reason: position replaces position_ratio; a preset support expands to springs.
    data = tomllib.loads(BEAM + CONTACTOR)
    new = set_path(data, "contactors.0.position", 0.03)
    assert "position_ratio" not in new["contactors"][0] and new["contactors"][0]["position"] == 0.03
    new = set_path(data, "supports.left.rotational", 100.0)
    assert new["supports"]["left"] == {"translational": math.inf, "rotational": 100.0}
    assert parse_scenario(new).beam.left.rotational == 100.0
    new = set_path(new, "supports.left.rotational", None)  # None removes a key
    assert new["supports"]["left"] == {"translational": math.inf}


def test_a_shortened_key_is_completed_where_keys_are_read_alone() -> None:
    # a sweep's or a bifurcation's parameter is checked against the whole schema: "excitation.freq" was
    # answered with "excitation.file", the closest by letters
    from impactbeam.scenario import path_dimension

    with pytest.raises(ScenarioError, match=r'did you mean "excitation\.frequency"'):
        path_dimension("excitation.freq")


@pytest.mark.parametrize(
    ("path", "match"),
    [
        ("beam.lenght", r'unknown key "beam.lenght" \(did you mean "beam.length"\?\)'),
        # a shortened key: the key it begins, not the closest by letters ("excitation.file")
        ("excitation.freq", r'unknown key "excitation.freq" \(did you mean "excitation.frequency"\?\)'),
        ("contactors.3.gap", "out of range"),
        ("contactors.x.gap", "not an index"),
        ("beam.length.0", "single value"),
        ("solver", None),  # a whole table is settable
        ("", "invalid path"),
    ],
)
def test_set_path_errors(path: str, match: str | None) -> None:
    # Reason: a sweep over a misspelt parameter must fail up front, naming it.
    data = tomllib.loads(BEAM + CONTACTOR)
    if match is None:
        set_path(data, path, {"modes": 4})
        return
    with pytest.raises(ScenarioError, match=match) as info:
        set_path(data, path, 1.0)
    assert info.value.key == path


def test_scenario_paths() -> None:
    # Reason: every schema path is listed (absent ones too), with present list indices.
    paths = scenario_paths(tomllib.loads(BEAM + CONTACTOR))
    for p in ("beam.length", "contactors.0.gap", "damping.contact", "supports.left.rotational",
              "excitation.file", "output.point_ratios", "solver.modes", "initial.tip_displacement"):
        assert p in paths
    assert "contactors.1.gap" not in paths


def test_with_values_revalidates() -> None:
    # Reason: with_values is how sweeps build cases; values are re-parsed with units
    # and bad ones are caught with the dotted key.
    sc = load_scenario(EXAMPLES / "case03.toml")
    sc2 = sc.with_values({"contactors.0.gap": "0.432 mm", "solver.modes": 12})
    assert sc2.contactors[0].gap == 0.432e-3 and sc2.solver.modes == 12
    assert sc.contactors[0].gap == 0.229e-3  # the original is unchanged
    assert sc2.source == sc.source and sc2.name == sc.name
    with pytest.raises(ScenarioError, match=r"^contactors\.0\.gap: ") as info:
        sc.with_values({"contactors.0.gap": -1e-4})
    assert info.value.key == "contactors.0.gap"


def test_dump_round_trip(tmp_path: Path) -> None:
    # Reason: a dumped scenario (including inf and numpy values) reloads to the same objects.
    sc = load_scenario(EXAMPLES / "specimen.toml").with_values(
        {"supports.right.translational": np.float64(1e3), "damping.free": np.array([0.01, 0.02])}
    )
    out = tmp_path / "dumped.toml"
    dump_scenario(sc.data, out)
    back = load_scenario(out)
    assert back.beam == sc.beam and back.contactors == sc.contactors
    assert back.damping == sc.damping and back.solver == sc.solver
    assert back.output_points == sc.output_points
    assert back.excitation.amplitude == sc.excitation.amplitude
    assert back.data == sc.data
    assert [p.name for p in tmp_path.iterdir()] == ["dumped.toml"]  # no temporary file left


def test_data_is_a_private_copy() -> None:
    # Reason: mutating the input mapping after parsing must not change the scenario.
    raw = tomllib.loads(BEAM + CONTACTOR)
    sc = parse_scenario(raw)
    raw["contactors"][0]["gap"] = 1.0
    assert sc.data["contactors"][0]["gap"] == 0.229e-3


# --------------------------------------------------------------------------- bad input

# (toml text, extra files, key expected at the start of the message / in the message)
BAD = [
    pytest.param(BEAM.replace("length = 0.1092", "length = -0.1092"), {}, "beam.length", id="negative-length"),
    pytest.param(BEAM.replace("length = 0.1092", "length = nan"), {}, "beam.length", id="nan-number"),
    pytest.param(BEAM.replace("length = 0.1092", 'length = "nan"'), {}, "beam.length", id="nan-string"),
    pytest.param(BEAM.replace("length = 0.1092", 'length = "0.1 kg"'), {}, "beam.length", id="length-in-kg"),
    pytest.param(BEAM.replace("length = 0.1092", 'length = "long"'), {}, "beam.length", id="length-not-number"),
    pytest.param(BEAM.replace("length = 0.1092\n", ""), {}, "beam.length", id="length-missing"),
    pytest.param(BEAM.replace("length = 0.1092", "lenght = 0.1092"), {}, "beam.lenght", id="unknown-key"),
    pytest.param(BEAM + "area = 1e-5\n", {}, "beam.area", id="width-and-area"),
    pytest.param(BEAM.replace("height = 3.03e-3\n", ""), {}, "beam.height", id="height-missing"),
    pytest.param("[beem]\nlength = 1\n", {}, "beem", id="unknown-table"),
    pytest.param("beam = 3\n", {}, "beam", id="beam-not-table"),
    pytest.param(BEAM + '[supports]\nleft = "fixed"\n', {}, "supports.left", id="bad-preset"),
    pytest.param(BEAM + "[supports]\nleft = { translational = -1 }\n", {}, "supports.left.translational",
                 id="negative-spring"),
    pytest.param(BEAM + "[supports]\nleft = { rotation = 1 }\n", {}, "supports.left.rotation", id="support-key"),
    pytest.param(BEAM + '[[contactors]]\nposition = "200 mm"\nstiffness = 4030\n', {},
                 "contactors.0.position", id="contactor-off-beam"),
    pytest.param(BEAM + "[[contactors]]\nposition = -0.01\nstiffness = 4030\n", {},
                 "contactors.0.position", id="contactor-negative-position"),
    pytest.param(BEAM + "[[contactors]]\nposition_ratio = 1.2\nstiffness = 4030\n", {},
                 "contactors.0.position_ratio", id="ratio-above-1"),
    pytest.param(BEAM + "[[contactors]]\nposition = 0.05\nposition_ratio = 0.5\nstiffness = 4030\n", {},
                 "contactors.0.position", id="position-and-ratio"),
    pytest.param(BEAM + "[[contactors]]\nstiffness = 4030\n", {}, "contactors.0.position", id="no-position"),
    pytest.param(BEAM + "[[contactors]]\nposition = 0.05\n", {}, "contactors.0.stiffness", id="no-stiffness"),
    pytest.param(BEAM + "[[contactors]]\nposition = 0.05\nstiffness = 0\n", {}, "contactors.0.stiffness",
                 id="zero-stiffness"),
    pytest.param(BEAM + "[[contactors]]\nposition = 0.05\nstiffness = 4030\ngap = -1e-4\n", {},
                 "contactors.0.gap", id="negative-gap"),
    pytest.param(BEAM + '[[contactors]]\nposition = 0.05\nstiffness = 4030\nside = "left"\n', {},
                 "contactors.0.side", id="bad-side"),
    pytest.param(BEAM + "[[contactors]]\nposition = 0.05\nstiffness = 4030\ngapp = 0\n", {},
                 "contactors.0.gapp", id="contactor-unknown-key"),
    pytest.param(BEAM + "[contactors]\nposition = 0.05\n", {}, "contactors", id="contactors-not-array"),
    pytest.param(BEAM + "[damping]\nfree = -0.01\n", {}, "damping.free", id="negative-damping"),
    pytest.param(BEAM + "[damping]\ncontact = [0.01, -0.02]\n", {}, "damping.contact.1", id="negative-damping-list"),
    pytest.param(BEAM + "[damping]\nfree = []\n", {}, "damping.free", id="empty-damping"),
    pytest.param(BEAM + '[excitation]\nkind = "shake"\n', {}, "excitation.kind", id="bad-kind"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\nduration = 0.01\n', {},
                 "excitation.amplitude", id="no-amplitude"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\namplitude = "15 g"\n', {},
                 "excitation.duration", id="no-duration"),
    pytest.param(BEAM + PULSE.replace('"15 g"', '"15 kg"'), {}, "excitation.amplitude", id="wrong-dimension"),
    pytest.param(BEAM + PULSE.replace('"15 ms"', '"-15 ms"'), {}, "excitation.duration", id="negative-duration"),
    pytest.param(BEAM + PULSE + 'position = 0.05\n', {}, "excitation.position", id="position-not-used"),
    pytest.param(BEAM + '[excitation]\nkind = "point_force"\nshape = "step"\namplitude = 1\n', {},
                 "excitation.position", id="point-force-no-position"),
    pytest.param(BEAM + '[excitation]\nkind = "none"\namplitude = 1\n', {}, "excitation.amplitude",
                 id="amplitude-without-kind"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "missing.csv"\n',
                 {}, "excitation.file", id="missing-trace"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "t.csv"\n',
                 {"t.csv": "0,0\n0.001,nan\n"}, "excitation.file", id="nan-in-trace"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "t.csv"\n',
                 {"t.csv": "0,0\n0.002,1\n0.001,2\n"}, "excitation.file", id="non-increasing-trace"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "t.csv"\n',
                 {"t.csv": "0,0\n0.001,1\n0.001,2\n"}, "excitation.file", id="repeated-time-trace"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "t.csv"\n',
                 {"t.csv": "time,value\n0,0\n"}, "excitation.file", id="one-row-trace"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "t.csv"\n',
                 {"t.csv": "0,0\n0.001,abc\n"}, "excitation.file", id="non-numeric-trace"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "t.csv"\n',
                 {"t.csv": "0,1.2x\n0.001,1\n0.002,2\n"}, "excitation.file", id="bad-first-row-not-a-header"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "t.csv"\n',
                 {"t.csv": "0,0,1\n0.001,1,2\n"}, "excitation.file", id="three-columns"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "t.csv"\n',
                 {"t.csv": "time [ms],acceleration [kg]\n0,0\n1,1\n"}, "excitation.file",
                 id="trace-header-wrong-unit"),
    pytest.param(BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "t.csv"\n'
                 'amplitude = "1 g"\n', {"t.csv": "0,0\n1,1\n"}, "excitation.amplitude", id="table-amplitude"),
    pytest.param(BEAM + "[initial]\nposition = 0.05\n", {}, "initial.position", id="position-without-tip"),
    pytest.param(BEAM + "[initial]\nmodal_velocity = 1.0\n", {}, "initial.modal_velocity", id="modal-not-list"),
    pytest.param(BEAM + "[solver]\ntime_step = 0\n", {}, "solver.time_step", id="zero-time-step"),
    pytest.param(BEAM + "[solver]\ntime_step = -1e-5\n", {}, "solver.time_step", id="negative-time-step"),
    pytest.param(BEAM + "[solver]\nmodes = 2.5\n", {}, "solver.modes", id="fractional-modes"),
    pytest.param(BEAM + '[solver]\nmodes = "8"\n', {}, "solver.modes", id="string-modes"),
    pytest.param(BEAM + "[solver]\nmodes = 0\n", {}, "solver.modes", id="zero-modes"),
    pytest.param(BEAM + "[solver]\nend_time = 1e-6\n", {}, "solver.time_step", id="step-beyond-end"),
    pytest.param(BEAM + "[output]\npoints = [0.05, 0.2]\n", {}, "output.points.1", id="point-off-beam"),
    pytest.param(BEAM + "[output]\npoints = [0.05, 0.05]\n", {}, "output.points.1", id="point-twice"),
    pytest.param(BEAM + "[output]\npoints = 0.05\n", {}, "output.points", id="points-not-list"),
    pytest.param("name = 3\n" + BEAM, {}, "name", id="name-not-string"),
]


@pytest.mark.parametrize(("text", "files", "key"), BAD)
def test_bad_input(tmp_path: Path, scenario_file, text: str, files: dict[str, str], key: str) -> None:
    # Reason: bad input is reported naming the key, never a
    # traceback or a silent default. ScenarioError is a ParameterError and a ValueError.
    for name, content in files.items():
        (tmp_path / name).write_text(content, encoding="utf-8")
    path = scenario_file(text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    message = str(info.value)
    assert key in message
    assert "\n" not in message
    assert info.value.key is not None and info.value.key.startswith(key.split(".")[0])
    assert isinstance(info.value, ParameterError) and isinstance(info.value, ValueError)


def test_unknown_key_suggestion(tmp_path: Path, scenario_file) -> None:
    # Reason: the message format other tools and users rely on.
    with pytest.raises(ScenarioError) as info:
        load_scenario(scenario_file(BEAM.replace("length", "lenght")))
    assert str(info.value) == 'unknown key "beam.lenght" (did you mean "beam.length"?)'
    assert info.value.key == "beam.lenght"


def test_off_beam_message(tmp_path: Path, scenario_file) -> None:
    # Reason: the exact form promised in the brief and in examples/README.md.
    with pytest.raises(ScenarioError) as info:
        load_scenario(scenario_file(BEAM + "[[contactors]]\nposition = 0.2\nstiffness = 4030\n"))
    assert str(info.value) == "contactors.0.position: 0.2 m is off the beam (length 0.1092 m)"


def test_trace_error_names_file_and_line(tmp_path: Path, scenario_file) -> None:
    # Reason: a user must find the bad row in a long measured trace.
    (tmp_path / "t.csv").write_text("time,value\n0,0\n0.001,1\n0.0005,2\n", encoding="utf-8")
    text = BEAM + '[excitation]\nkind = "base_acceleration"\nshape = "table"\nfile = "t.csv"\n'
    with pytest.raises(ScenarioError, match=r'^excitation\.file: "t\.csv" line 4, column 1 \(time\): time 0\.0005 s'):
        load_scenario(scenario_file(text))


def test_parameter_error_from_data_class_is_relabelled() -> None:
    # Reason: a ParameterError raised inside a data class must come out led by the dotted key.
    # Contactor itself rejects a zero stiffness ("contactor.stiffness: ..."); "inf" (a rigid
    # prop) is accepted since rigid contactors have contact-state modes (see test_rigid.py).
    with pytest.raises(ParameterError):
        Contactor(0.05, 0.0)
    assert Contactor(0.05, math.inf).rigid
    data = tomllib.loads(BEAM + '[[contactors]]\nposition = 0.05\nstiffness = 0\n')
    with pytest.raises(ScenarioError, match=r"^contactors\.0\.stiffness: ") as info:
        parse_scenario(data)
    assert info.value.key == "contactors.0.stiffness"


def test_toml_syntax_error(tmp_path: Path, scenario_file) -> None:
    # Reason: a syntax error names the file and the parser's line.
    with pytest.raises(ScenarioError, match=r'bad\.toml.*invalid TOML.*line 3'):
        load_scenario(scenario_file("[beam]\nlength = 1\nwidth =\n", "bad.toml"))


def test_missing_scenario_file(tmp_path: Path) -> None:
    # Reason: a wrong path is a ScenarioError (exit 2 at the command line), not OSError.
    with pytest.raises(ScenarioError, match="file not found"):
        load_scenario(tmp_path / "nope.toml")


def test_common_unit_table_agrees_with_pint():
    # the table that spares the pint import must say what pint says, to the last bit
    from impactbeam import units

    for (unit, dimension), factor in units.COMMON_UNITS.items():
        q = units._parse_unit(unit, dimension, unit)
        assert units._quantity_to_si(q, unit, dimension) == factor, (unit, dimension)


@pytest.mark.parametrize(("value", "dimension", "si"), [
    # a cycle is 2 pi rad where frequencies meet angles (the rule of frequencies: Hz counts cycles)
    ("1 N^2/(rad/s)", "force_psd", 2 * math.pi),  # S(f) = 2 pi S(omega); was read as 1 N^2/Hz
    ("1 (m/s^2)^2/(rad/s)", "acceleration_psd", 2 * math.pi),
    ("1 Hz", "angular_velocity", 2 * math.pi),  # was 1 rad/s, while "1 cycle/s" gave 2 pi
    ("1 cycle/s", "angular_velocity", 2 * math.pi),
    ("60 rpm", "angular_velocity", 2 * math.pi),
    ("90 deg", "angle", math.pi / 2),
    ("5 N*m", "rotational_stiffness", 5.0),  # its radian may be left out
    ("5 N*m/deg", "rotational_stiffness", 5.0 * 180 / math.pi),
    ("85 %", "dimensionless", 0.85),
    ("2/s", "rate", 2.0),
    ("5*mm", "length", 5e-3),
    ("1 mm^4", "second_moment", 1e-12),  # pint's factor is 1.0000000000000002e-12: rounded to its decimal
])
def test_to_si_keeps_the_angles_in_units(value: str, dimension: str, si: float) -> None:
    assert to_si(value, dimension, "k") == pytest.approx(si, rel=1e-15)


@pytest.mark.parametrize(
    ("values", "key"),
    [
        ({"beam.theory": "timoshenko"}, "beam.poisson_ratio"),  # a Timoshenko beam needs it
        ({"beam.theory": "rayleigh"}, "beam.theory"),
        ({"beam.shear_coefficient": 0.85}, "beam.shear_coefficient"),
    ],
)
def test_beam_theory_is_euler_bernoulli_or_refused_by_name(values: dict, key: str) -> None:
    # Reason: a theory or a Timoshenko key must never be ignored (the beam would silently stay
    # Euler-Bernoulli): unknown theories and shear keys on an Euler-Bernoulli beam are refused
    sc = parse_scenario(tomllib.loads(BEAM))
    assert sc.with_values({"beam.theory": "euler-bernoulli"}).beam == sc.beam
    with pytest.raises(ScenarioError) as err:
        sc.with_values(values)
    assert err.value.key == key and str(err.value).startswith(key)
