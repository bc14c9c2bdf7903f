"""Rigid contactors, ``stiffness = "inf"`` (issue 10 item 8).

A rigid prop pins its point in the contact state, so the contact-state modes
are those of the propped beam; checked against the closed form of
REFERENCES.md (clamped-pinned: tan(lambda) = tanh(lambda)). A transient
simulation with a rigid stop is refused with one line naming the key.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from test_cli_input import assert_one_error_line, run

import impactbeam as ib
from impactbeam.exceptions import ParameterError

PROP = """
[beam]
length = "109.20 mm"
width = "9.93 mm"
height = "3.03 mm"
youngs_modulus = "1834 MPa"
density = "951.98 kg/m^3"

[[contactors]]
position_ratio = 1.0
stiffness = "inf"
gap = 0

[solver]
modes = 6
end_time = 0.01
"""

# REFERENCES.md: lambda_n L of the clamped-free and clamped-pinned beams (10 digits)
CANTILEVER_1 = 1.875104069
CLAMPED_PINNED = (3.926602312, 7.068582745, 10.21017612, 13.35176878, 16.49336143)


@pytest.fixture()
def prop(tmp_path: Path) -> Path:
    p = tmp_path / "prop.toml"
    p.write_text(PROP)
    return p


def test_rigid_prop_modes_match_clamped_pinned(prop: Path) -> None:
    """Contact-state frequencies / free f1 = (lambda_n / 1.875104069)^2 of the closed forms.

    Tolerance 1e-8 relative: the references are given to 10 significant
    digits (a relative 5e-10 in lambda, 1e-9 in lambda^2), and the mode
    solver converges its roots to a few ulps; 1e-8 leaves a margin of 10
    over the references' rounding while failing any modelling error (a
    finite spring of 1e12 N/m would already shift f1 by ~1e-9 x 1e3).
    """
    sc = ib.load_scenario(prop)
    assert math.isinf(sc.contactors[0].stiffness) and sc.contactors[0].rigid
    ms = ib.modes(sc)
    assert ms.contact is not None and ms.contact.n_rigid == 0
    f1 = ms.free.frequencies_hz[0]
    for n, lam in enumerate(CLAMPED_PINNED):
        assert ms.contact.frequencies_hz[n] / f1 == pytest.approx((lam / CANTILEVER_1) ** 2, rel=1e-8)


def test_stiff_spring_approaches_the_rigid_prop(prop: Path) -> None:
    """k -> inf converges to the pinned limit from below, monotonically."""
    sc = ib.load_scenario(prop)
    rigid = ib.modes(sc).contact.frequencies_hz[0]
    prev = 0.0
    for k in (1e3, 1e5, 1e7, 1e9):
        f = ib.modes(sc.with_values({"contactors.0.stiffness": k})).contact.frequencies_hz[0]
        assert prev < f < rigid
        prev = f
    assert prev / rigid - 1 > -1e-5


def test_modes_command_with_rigid_prop(prop: Path) -> None:
    proc = run("modes", prop, "--json")
    assert proc.returncode == 0, proc.stderr
    d = json.loads(proc.stdout)
    ratio = d["contact"]["frequencies_hz"][0] / d["free"]["frequencies_hz"][0]
    assert ratio == pytest.approx((CLAMPED_PINNED[0] / CANTILEVER_1) ** 2, rel=1e-8)


def test_simulate_with_rigid_prop_exits_2(prop: Path, tmp_path: Path) -> None:
    out = tmp_path / "r.nc"
    line = assert_one_error_line(run("simulate", prop, "--out", out), 2, "contactors.0.stiffness", "finite stiffness")
    assert "N/m" in line
    assert not out.exists()
    with pytest.raises(ParameterError, match=r"^contactors\.0\.stiffness: "):
        ib.simulate(ib.load_scenario(prop))


@pytest.mark.parametrize(("value", "ok"), [("inf", True), ('"rigid"', True), ("0", False), ("-5", False)])
def test_contactor_stiffness_values(tmp_path: Path, value: str, ok: bool) -> None:
    p = tmp_path / "c.toml"
    p.write_text(PROP.replace('stiffness = "inf"', f"stiffness = {value}"))
    if ok:
        assert math.isinf(ib.load_scenario(p).contactors[0].stiffness)
    else:
        with pytest.raises(ParameterError, match=r"contactors\.0\.stiffness: must be positive"):
            ib.load_scenario(p)


def test_contactor_object_accepts_inf_and_refuses_zero() -> None:
    assert ib.Contactor(0.1, math.inf).rigid
    assert not ib.Contactor(0.1, 4030.0).rigid
    with pytest.raises(ParameterError, match="contactor.stiffness"):
        ib.Contactor(0.1, 0.0)
