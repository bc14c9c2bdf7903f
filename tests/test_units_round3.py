"""Units found wanting by an independent hunt through every input (each test fails on the code before it).

* Logarithmic and offset units (dB, octave, decade, degC) were multiplied as if they were multiples of a
  unit: ``excitation.scale = "0 dB"`` removed the load (0 dB is a factor 1) and "6 dB" scaled it by
  6 x 1.2589 = 7.55. They are refused now, naming the key.
* ``IMPACTBEAM_MEMORY_LIMIT=4GB`` was read as 4 bytes (its last letter, B, taken as the multiplier).
* A damping ratio of 1 or more written as a bare number (``free = 1.1`` meaning 1.1 %) ran overdamped in
  silence; it is warned about, with the spelling of a percentage.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

import impactbeam as ib

CASE3 = Path(__file__).resolve().parents[1] / "examples" / "case03.toml"


@pytest.mark.parametrize("value", ["0 dB", "6 dB", "-6 dB", "3 octave", "2 decade", "20 degC"])
def test_a_logarithmic_or_offset_unit_is_refused_naming_the_key(value):
    sc = ib.load_scenario(CASE3)
    with pytest.raises(ib.ScenarioError, match=r"^excitation\.scale: .* logarithmic or offset unit"):
        sc.with_values({"excitation.scale": value})
    assert sc.with_values({"excitation.scale": "50 %"}).excitation.scale == 0.5  # a multiple of a unit still reads


@pytest.mark.parametrize("text,gib", [("4G", 4.0), ("4GB", 4.0), ("4 GiB", 4.0), ("4gb", 4.0), ("512MB", 0.5),
                                      ("1073741824", 1.0), ("1073741824B", 1.0)])
def test_a_memory_limit_reads_its_unit(monkeypatch, text, gib):
    from impactbeam import _memory

    monkeypatch.setenv("IMPACTBEAM_MEMORY_LIMIT", text)
    assert _memory._size("IMPACTBEAM_MEMORY_LIMIT", 1.0) == gib * 2**30


@pytest.mark.parametrize("text", ["4 GB of it", "G", "-4G", "0"])
def test_a_memory_limit_that_is_no_size_is_refused(monkeypatch, text):
    from impactbeam import _memory

    monkeypatch.setenv("IMPACTBEAM_MEMORY_LIMIT", text)
    with pytest.raises(ib.ParameterError, match="^IMPACTBEAM_MEMORY_LIMIT: not a positive size"):
        _memory._size("IMPACTBEAM_MEMORY_LIMIT", 1.0)


def test_a_damping_ratio_of_one_or_more_as_a_bare_number_is_warned_about():
    sc = ib.load_scenario(CASE3)
    with pytest.warns(ib.ImpactBeamWarning, match=r'damping\.free: 1\.1 is read as a ratio, 110 % of critical.*'
                                                  r'write "1\.1 %" or 0\.011'):
        sc.with_values({"damping.free": 1.1})
    with pytest.warns(ib.ImpactBeamWarning, match=r"damping\.contact: 2 is read as a ratio"):
        sc.with_values({"damping.contact": [0.01, 2]})
    with warnings.catch_warnings():  # a percentage written as one, and ratios below 1, say nothing
        warnings.simplefilter("error")
        sc.with_values({"damping.free": "110 %", "damping.contact": 0.5})


def test_the_linear_frf_reads_frequencies_with_units():
    # ib.linear_frf(sc, ["60 Hz"]) raised a bare ValueError: strings with units are read as everywhere else
    import numpy as np

    sc = ib.load_scenario(Path(__file__).resolve().parents[1] / "examples" / "periodic" / "specimen_harmonic.toml")
    # "3600 rpm" is 60 Hz to the unit factor's 15 digits (1/60 rounded): 2e-15 of the frequency, 4e-14 here
    np.testing.assert_allclose(ib.linear_frf(sc, ["60 Hz", "3600 rpm"]), ib.linear_frf(sc, [60.0, 60.0]), rtol=1e-12)
    with pytest.raises(ib.ParameterError, match=r"frequencies \(value 1\)"):
        ib.linear_frf(sc, ["60 mm"])


def test_a_selection_of_a_ratio_takes_a_percentage():
    # plot --sel "damping.free=2 %" was refused (a dimensionless coordinate had no dimension to read it in)
    from impactbeam.plot.sweep import _in_si

    assert _in_si("2 %", "damping.free", "1") == pytest.approx(0.02, rel=1e-15)
    assert _in_si("2 %", "excitation.scale", "") == pytest.approx(0.02, rel=1e-15)
    with pytest.raises(ib.ParameterError, match=r"--sel damping\.free"):
        _in_si("2 mm", "damping.free", "1")


def test_a_random_history_too_long_for_memory_names_the_end_time():
    # the refusal named excitation.duration, a key a random load refuses; the history's length is set by
    # solver.end_time (from excitation.start)
    sc = ib.parse_scenario({
        "beam": {"length": 0.1092, "width": 9.93e-3, "height": 3.03e-3, "youngs_modulus": 1834e6, "density": 951.98},
        "excitation": {"kind": "base_acceleration", "shape": "random", "seed": 1,
                       "psd": [["10 Hz", "0.01 g^2/Hz"], ["1000 Hz", "0.01 g^2/Hz"]]},
        "solver": {"modes": 2, "end_time": 1.0}})
    with pytest.raises(ib.ParameterError, match=r"^excitation\.sample_rate: .*\(from excitation\.start to "
                                                r"solver\.end_time.*shorter history \(solver\.end_time\)"):
        sc.with_values({"solver.end_time": 1e6, "solver.time_step": 1.0})
