"""Project warnings: one class, emitted at the user's line, reported by the command line.

Issue 10 item 6 and issue 11 item 7: inputs that are valid but very likely
mistakes get an ImpactBeamWarning (pointing at the caller's line, not at
impactbeam's internals); ``simulate`` prints each as ``warning: ...`` in its
summary and lists them under ``"warnings"`` in ``--json`` (always present).
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest
from test_cli_input import BEAM, EXAMPLES, assert_one_error_line, run

import impactbeam as ib
from impactbeam._warnings import WarningLog, emit_user_level_warning
from impactbeam.exceptions import ParameterError

CONTACTOR = '[[contactors]]\nposition_ratio = 0.484\nstiffness = 4030\ngap = 0.229e-3\nside = "above"\n'
PULSE = '[excitation]\nkind = "base_acceleration"\namplitude = "15 g"\nduration = "15 ms"\n'
SHORT = "[solver]\nmodes = 4\nend_time = 0.01\ntime_step = 1e-4\n"


def test_warning_class_is_exported_and_a_user_warning() -> None:
    assert issubclass(ib.ImpactBeamWarning, UserWarning)
    assert "ImpactBeamWarning" in ib.__all__


def test_emit_points_at_the_callers_line() -> None:
    with pytest.warns(ib.ImpactBeamWarning, match="hello") as rec:
        emit_user_level_warning("hello")
    assert rec[0].filename == __file__


# (scenario text, substring of the warning) -- issue 11 item 7
WARNED = [
    pytest.param(BEAM + SHORT + "[initial]\nmodal_displacement = [1e-4, 0, 0, 0, 0, 1e-6]\n",
                 "initial.modal_displacement: 6 entries but solver.modes = 4", id="modal-longer-than-modes"),
    pytest.param(BEAM + SHORT + PULSE + "start = 0.02\n",
                 "excitation.start: the excitation starts at 0.02 s, at or after solver.end_time = 0.01 s",
                 id="excitation-after-end"),
    pytest.param(BEAM.replace("length = 0.1092", 'length = "0.1092"') + SHORT + PULSE,
                 'beam.length: "0.1092" is a number written as a string without a unit; it is taken as SI (m). '
                 'Write it as a number (0.1092) or with its unit (e.g. "0.1092 m")',
                 id="numeric-string"),
    # the example unit is the key's (a stress was shown as "800 mm")
    pytest.param(BEAM.replace('youngs_modulus = 1834e6', 'youngs_modulus = "1834e6"') + SHORT + PULSE,
                 'or with its unit (e.g. "1834e6 Pa")', id="numeric-string-stress"),
    # an S-N curve whose reference point does no damage, a Goodman line below it (units left out, typically)
    pytest.param(BEAM + SHORT + PULSE + '[fatigue]\npoints = [0.0]\nsn_stress = "800 MPa"\nsn_cycles = 1e6\n'
                 'sn_exponent = 4\nendurance_limit = "900 MPa"\n',
                 "fatigue.endurance_limit: 9e+08 Pa is at or above sn_stress = 8e+08 Pa", id="endurance-above-sn"),
    pytest.param(BEAM + SHORT + PULSE + '[fatigue]\npoints = [0.0]\nsn_stress = "800 MPa"\nsn_cycles = 1e6\n'
                 'sn_exponent = 4\nmean_stress = "goodman"\nultimate_strength = "500 MPa"\n',
                 "fatigue.ultimate_strength: 5e+08 Pa is at or below sn_stress = 8e+08 Pa", id="ultimate-below-sn"),
    pytest.param(BEAM + SHORT + PULSE + '[fatigue]\npoints = [0.0]\nsn_stress = 800\nsn_cycles = 1e6\n'
                 'sn_exponent = 4\n',
                 'fatigue.sn_stress: 800 Pa is below 1e-6 of the beam\'s Young\'s modulus (1.834e+09 Pa); a plain '
                 'number is in Pa: give the unit ("800 MPa")', id="sn-stress-bare-number"),
    pytest.param(BEAM + PULSE + SHORT + "event_tolerance = 1e-6\n",
                 "solver.event_tolerance: 1e-06 s is more than 1e-3 of solver.time_step", id="event-tolerance"),
]


@pytest.mark.parametrize(("text", "needle"), WARNED)
def test_api_warns_at_the_users_line(tmp_path: Path, text: str, needle: str) -> None:
    p = tmp_path / "w.toml"
    p.write_text(text)
    with pytest.warns(ib.ImpactBeamWarning) as rec:
        ib.load_scenario(p)
    messages = [str(w.message) for w in rec]
    assert any(needle in m for m in messages), messages
    assert all(w.filename == __file__ for w in rec)  # the user's line, not impactbeam's


@pytest.mark.parametrize(("text", "needle"), WARNED)
def test_cli_reports_warnings_on_stderr_and_in_json(tmp_path: Path, text: str, needle: str) -> None:
    # beside the summary on the terminal, but on stderr: stdout stays the summary alone (issue 19)
    p = tmp_path / "w.toml"
    p.write_text(text)
    proc = run("simulate", p)
    assert proc.returncode == 0, proc.stderr
    assert any(line.startswith("warning: ") and needle in line for line in proc.stderr.splitlines()), proc.stderr
    assert "warning:" not in proc.stdout
    proc = run("simulate", p, "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert any(needle in w for w in out["warnings"]), out["warnings"]
    assert "max_response" in out  # the metrics are still there


def test_json_warnings_empty_when_none(tmp_path: Path) -> None:
    p = tmp_path / "ok.toml"
    p.write_text(BEAM + CONTACTOR + PULSE + SHORT)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ib.ImpactBeamWarning)
        ib.load_scenario(p)
    proc = run("simulate", p, "--json")
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["warnings"] == []
    proc = run("simulate", p)
    assert "warning:" not in proc.stdout + proc.stderr


def test_warning_log_keeps_other_warnings_and_dedupes() -> None:
    with pytest.warns(DeprecationWarning):
        with WarningLog() as log:
            for _ in range(3):
                emit_user_level_warning("same")
            warnings.warn("other", DeprecationWarning)
    assert log.messages == ["same"]


# (scenario text, substring of the one error line) -- issue 11 items 4 and 7
REFUSED = [
    pytest.param(BEAM + SHORT.replace("[solver]\n", "[solver]\nevent_tolerance = 1.0\n"),
                 "solver.event_tolerance: 1 s is not smaller than solver.time_step", id="event-tolerance-1s"),
    pytest.param(BEAM.replace("length = 0.1092", "length = 1e300"), "beam.length: 1e+300 gives a frequency scale",
                 id="length-1e300"),
    pytest.param(BEAM.replace("length = 0.1092", "length = 1e-300"), "beam.length: 1e-300 gives", id="length-1e-300"),
    pytest.param(BEAM.replace("height = 3.03e-3", "height = 1e300"), "beam.height: 1e+300 gives", id="height-1e300"),
    pytest.param(BEAM.replace("height = 3.03e-3", "height = 1e-300"), "beam.height: 1e-300 gives", id="height-1e-300"),
    pytest.param(BEAM.replace("width = 9.93e-3", "width = 1e-300"), "beam.width: 1e-300 gives", id="width-1e-300"),
    pytest.param(BEAM.replace("density = 951.98", "density = 1e300"), "beam.density: 1e+300 gives",
                 id="density-1e300"),
    pytest.param(BEAM.replace("youngs_modulus = 1834e6", 'youngs_modulus = "1e200 GPa"'),
                 "beam.youngs_modulus: '1e200 GPa' gives a bending stiffness", id="modulus-1e209-Pa"),
    pytest.param(BEAM + CONTACTOR.replace("stiffness = 4030", "stiffness = 1e300"),
                 'contactors.0.stiffness: 1e+300 N/m is ~1e298 times the beam\'s bending stiffness', id="k-1e300"),
    pytest.param(BEAM + CONTACTOR.replace("stiffness = 4030", "stiffness = 1e-300"),
                 "contactors.0.stiffness: 1e-300 N/m", id="k-1e-300"),
    # issue 20: a contactor where the support holds w = 0 can never act (it was a warning, and the
    # enriched basis then gave a growing deflection at the support): refused
    pytest.param(BEAM + SHORT + PULSE + '[[contactors]]\nposition = 0\nstiffness = 4030\ngap = 1e-4\n',
                 "contactors.0.position: 0 m is at the left end (clamped), where w = 0", id="contactor-at-clamped-end"),
]


@pytest.mark.parametrize(("text", "needle"), REFUSED)
def test_extreme_and_absurd_values_exit_2(tmp_path: Path, text: str, needle: str) -> None:
    """Exit 2, one line naming the key the user wrote (never a derived key such as beam.second_moment)."""
    p = tmp_path / "bad.toml"
    p.write_text(text)
    for command in ("simulate", "modes"):
        line = assert_one_error_line(run(command, p), 2, needle)
        assert "second_moment" not in line and "area" not in line.split(":")[1]
    with pytest.raises(ParameterError, match=needle.split(":")[0].replace(".", r"\.")):
        ib.load_scenario(p)


def test_magnitude_limits_accept_a_micro_beam(tmp_path: Path) -> None:
    """A MEMS cantilever (200 um x 2 um x 0.5 um silicon) is far inside the limits."""
    p = tmp_path / "mems.toml"
    p.write_text('[beam]\nlength = "200 um"\nwidth = "2 um"\nheight = "0.5 um"\nyoungs_modulus = "169 GPa"\n'
                 'density = 2330\n[[contactors]]\nposition_ratio = 1.0\nstiffness = 0.1\ngap = "50 nm"\n')
    sc = ib.load_scenario(p)
    assert sc.beam.length == pytest.approx(2e-4)


def test_cli_overrides_in_si_do_not_warn(tmp_path: Path) -> None:
    """--time-step 1e-4 is documented as seconds: no unit-less-string warning."""
    proc = run("simulate", EXAMPLES / "case03.toml", "--time-step", "1e-4", "--end-time", "0.01", "--json")
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["warnings"] == []


def test_commands_that_do_not_report_warnings_print_them_on_stderr() -> None:
    """handle_errors prints the ImpactBeamWarnings a command did not take (sweep, reproduce) on stderr."""
    import click
    from click.testing import CliRunner

    from impactbeam.cli import handle_errors, take_warnings

    @click.command()
    @click.option("--take", is_flag=True)
    @handle_errors
    def cmd(take: bool) -> None:
        emit_user_level_warning("solver.modes: a word")
        if take:
            click.echo(f"took {take_warnings()}")
        click.echo("done")

    res = CliRunner().invoke(cmd, [])
    assert res.exit_code == 0 and res.stdout == "done\n"
    assert res.stderr == "warning: solver.modes: a word\n"
    res = CliRunner().invoke(cmd, ["--take"])
    assert res.stdout == "took ['solver.modes: a word']\ndone\n" and res.stderr == ""


def test_one_mode_says_it_has_no_convergence_estimate(tmp_path: Path) -> None:
    # a 1-mode run has no coarser run to compare with: its estimate is None, and that is said, not silent
    p = tmp_path / "one.toml"
    p.write_text(BEAM + CONTACTOR + PULSE + SHORT.replace("modes = 4", "modes = 1"))
    res = ib.simulate(ib.load_scenario(p))
    with pytest.warns(ib.ImpactBeamWarning, match="no convergence estimate with 1 mode per state") as rec:
        assert res.convergence is None
    assert len(rec) == 1 and rec[0].filename == __file__
    assert not res.converged and res.impact_convergence is None
    with warnings.catch_warnings():
        warnings.simplefilter("error", ib.ImpactBeamWarning)
        assert res.convergence is None  # said once, not at every access
    assert any("no convergence estimate" in w for w in res.warnings)
    out = json.loads(run("simulate", p, "--json").stdout)
    assert out["convergence"] is None and out["modes"] == 1
    assert [w for w in out["warnings"] if "no convergence estimate" in w]
    two = ib.simulate(ib.load_scenario(p).with_values({"solver.modes": 2}))
    assert two.convergence is not None  # compared with 1 mode
