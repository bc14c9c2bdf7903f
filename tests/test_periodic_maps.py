"""Two-parameter maps of the steady state: in process, on Dask, resumed."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

import impactbeam as ib
from impactbeam.exceptions import ParameterError
from impactbeam.periodic.bifurcation import bifurcation
from impactbeam.periodic.maps import bifurcation_map

pytest.importorskip("zarr")
xr = pytest.importorskip("xarray")

EXAMPLE = __import__("pathlib").Path(__file__).resolve().parents[1] / "examples" / "periodic" / "specimen_harmonic.toml"
X = ("excitation.frequency", [40.0, 42.0, 60.0, 80.0])
Y = ("excitation.amplitude", ["1 g", "2 g"])
KW = dict(settle_periods=60, record_periods=8)


def test_rows_are_bifurcation_sweeps_and_resume(tmp_path):
    sc = ib.load_scenario(EXAMPLE)
    out = tmp_path / "m.zarr"
    ds = bifurcation_map(sc, X, Y, out, workers=0, **KW)
    assert ds["period"].dims == ("y", "x") and ds["strobe"].dims == ("y", "x", "sample")
    assert ds["done"].values.all()
    # its provenance, as a sweep store's: the version, the scenario (it reloads to the same one), the tolerance
    assert ds.attrs["impactbeam_version"] == ib.__version__ and ds.attrs["tolerance"] > 0
    assert ib.parse_scenario(tomllib.loads(ds.attrs["scenario"])).to_toml() == sc.to_toml()
    # each row is exactly the continuation sweep along x at that y (same bits)
    row = bifurcation(sc.with_values({"excitation.amplitude": "2 g"}), *X, **KW)
    np.testing.assert_array_equal(ds["strobe"].values[1], np.stack([p.state.strobe for p in row.points]))
    assert list(ds["period"].values[1]) == [p.state.period for p in row.points]
    # forget row 0: a second call recomputes it and leaves row 1 as it was
    strobe0 = ds["strobe"].values[0].copy()
    xr.Dataset({"done": ("y", np.array([False]))}).to_zarr(str(out), region={"y": slice(0, 1)}, consolidated=False)
    xr.Dataset({"strobe": (("y", "x", "sample"), np.zeros((1, 4, 8)))}).to_zarr(
        str(out), region={"y": slice(1, 2), "x": slice(None), "sample": slice(None)}, consolidated=False)
    again = bifurcation_map(sc, X, Y, out, workers=0, **KW)
    np.testing.assert_array_equal(again["strobe"].values[0], strobe0)
    assert not again["strobe"].values[1].any()  # done rows are not recomputed
    with pytest.raises(ParameterError, match="another map"):
        bifurcation_map(sc, X, ("excitation.amplitude", ["1 g"]), out, workers=0, **KW)


@pytest.mark.slow
def test_dask_gives_the_same_bits(tmp_path):
    sc = ib.load_scenario(EXAMPLE)
    a = bifurcation_map(sc, X, Y, tmp_path / "a.zarr", workers=0, **KW)
    b = bifurcation_map(sc, X, Y, tmp_path / "b.zarr", workers=1, **KW)
    np.testing.assert_array_equal(a["strobe"].values, b["strobe"].values)
    np.testing.assert_array_equal(a["period"].values, b["period"].values)


def test_bad_input(tmp_path):
    sc = ib.load_scenario(EXAMPLE)
    with pytest.raises(ParameterError, match="sweep"):
        bifurcation_map(sc, X, Y, tmp_path / "m.zarr", sweep="both")
    with pytest.raises(ParameterError, match="excitation.amplitude"):
        bifurcation_map(sc, X, ("excitation.amplitude", ["3 mm"]), tmp_path / "m.zarr")
    assert not (tmp_path / "m.zarr").exists()  # nothing written on bad input


def test_the_record_lengths_the_maps_page_quotes():
    # docs/periodic.md: "a map records 20 periods by default, so it shows periods up to 10, where
    # ib.bifurcation records 50" (a row equals ib.bifurcation's only with the same record)
    import inspect

    from impactbeam.periodic.bifurcation import bifurcation
    from impactbeam.periodic.maps import bifurcation_map

    assert inspect.signature(bifurcation_map).parameters["record_periods"].default == 20
    assert inspect.signature(bifurcation).parameters["record_periods"].default == 50
