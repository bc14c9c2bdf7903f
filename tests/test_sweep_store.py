"""Making a sweep's store beside its first batch, and the default batches.

A new store is made by a forked process while the sweep's own process runs
its first batch (:class:`impactbeam.sweeps.store.StoreMaker`). These tests
check what that must not change: the store's contents (compared with one
made in the process), the errors (the maker's exception reaches the caller,
its message intact) and an interrupt (nothing half-written is left).
"""

from __future__ import annotations

import sys
import time
import tomllib
from pathlib import Path

import pytest
import xarray as xr

from impactbeam.exceptions import ImpactBeamError
from impactbeam.sweeps import parse_sweep, run_sweep
from impactbeam.sweeps import store as store_mod
from impactbeam.sweeps.batches import _chunk_shape
from impactbeam.sweeps.spec import default_batch_size

CASE3 = Path(__file__).resolve().parents[1] / "examples" / "case03.toml"
FORK = sys.platform.startswith("linux")

GRID = f"""
base = "{CASE3.as_posix()}"
design = "grid"
[parameters."contactors.0.gap"]
values = [0.1e-3, 0.229e-3]
[parameters."excitation.amplitude"]
values = ["10 g", "15 g", "20 g"]
[parameters."solver.end_time"]
values = [0.03]
[outputs]
metrics = "all"
"""


def _spec(text: str = GRID):
    return parse_sweep(tomllib.loads(text), base_dir=CASE3.parent)


def _leftovers(tmp: Path) -> list[str]:
    return sorted(p.name for p in tmp.iterdir() if ".tmp-" in p.name)


def test_store_made_by_the_forked_maker_is_the_one_made_here(tmp_path):
    """The same store, whichever process made it: identical Dataset, and its metadata consolidated."""
    spec = _spec()
    chunk = _chunk_shape(spec, 2)
    forked = store_mod.StoreMaker(spec, tmp_path / "forked.zarr", chunk).result()
    here = store_mod._create_store(spec, tmp_path / "here.zarr", chunk)
    a = xr.open_zarr(forked, consolidated=True)  # consolidated at creation: opens without the fallback
    b = xr.open_zarr(here, consolidated=True)
    xr.testing.assert_identical(a.load(), b.load())
    assert a["status"].encoding["chunks"] == chunk
    assert _leftovers(tmp_path) == []


@pytest.mark.skipif(not FORK, reason="the maker forks on Linux only")
def test_maker_error_reaches_the_caller_and_leaves_nothing(tmp_path, monkeypatch):
    """An error while the store is made is raised again by result(), message intact; no directory is left."""
    spec = _spec()

    def broken(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(store_mod, "_template", broken)  # the fork inherits the patch
    maker = store_mod.StoreMaker(spec, tmp_path / "s.zarr", (1, 3, 1))
    with pytest.raises(OSError, match="No space left") as info:
        maker.result()
    assert info.value.errno == 28
    assert not (tmp_path / "s.zarr").exists() and _leftovers(tmp_path) == []


@pytest.mark.skipif(not FORK, reason="the maker forks on Linux only")
def test_unpicklable_maker_error_is_reported_as_text(tmp_path, monkeypatch):
    class Odd(Exception):
        def __init__(self, a, b):  # pickles, but cannot be rebuilt from its args
            super().__init__(f"odd {a} {b}")

    def broken(*args, **kwargs):
        raise Odd(1, 2)

    monkeypatch.setattr(store_mod, "_template", broken)
    with pytest.raises(ImpactBeamError, match=r"creating the store failed \(Odd: odd 1 2\)"):
        store_mod.StoreMaker(_spec(), tmp_path / "s.zarr", (1, 3, 1)).result()


@pytest.mark.skipif(not FORK, reason="the maker forks on Linux only")
def test_interrupted_maker_removes_its_partial_store(tmp_path, monkeypatch):
    """close() on a maker still writing (an interrupt of the sweep) stops it and removes its directory."""

    class Slow:
        def to_zarr(self, path, **kwargs):
            Path(path).mkdir()
            (Path(path) / "zarr.json").write_text("{}")
            time.sleep(60)

    monkeypatch.setattr(store_mod, "_template", lambda spec, chunk: (Slow(), {}))
    maker = store_mod.StoreMaker(_spec(), tmp_path / "s.zarr", (1, 3, 1))
    deadline = time.monotonic() + 30
    while not _leftovers(tmp_path) and time.monotonic() < deadline:
        time.sleep(0.01)
    assert _leftovers(tmp_path), "the maker started writing"
    t0 = time.monotonic()
    maker.close()
    assert time.monotonic() - t0 < 10  # stopped by its signal, not by the join's timeout
    assert _leftovers(tmp_path) == [] and not (tmp_path / "s.zarr").exists()


def test_sweep_with_the_forked_maker_equals_the_in_process_sweep(tmp_path):
    """workers=1 (the store made beside the first batch, in a fork) against workers=0 (made first, here)."""
    spec = _spec()
    one = run_sweep(spec, tmp_path / "one.zarr", workers=1, batch_size=2, progress=False)
    zero = run_sweep(spec, tmp_path / "zero.zarr", workers=0, batch_size=2, progress=False)
    assert one.computed == zero.computed == 6
    xr.testing.assert_identical(one.dataset.load(), zero.dataset.load())
    assert (one.dataset["status"].values == 0).all()


def test_default_batches_are_few_and_bounded():
    """About 16 batches, at most 1,000 cases each, and at most 64 MB of histories per batch."""
    assert default_batch_size(4000) == 250
    assert default_batch_size(10) == 1
    assert default_batch_size(10**6) == 1000
    # histories of 80 kB per case: 800 cases make 64 MB
    assert default_batch_size(10**6, 80e3) == 800
    assert default_batch_size(100, 1e9) == 1  # a case larger than the bound still runs, alone


def test_default_batch_of_a_sweep_counts_its_histories(monkeypatch):
    """A sweep's default batch is bounded by its histories' bytes (a bound made to bind on this small grid)."""
    from impactbeam.sweeps import spec as spec_mod

    text = GRID + 'histories = { points = [0.05, 0.1], time_step = 1e-5 }\n'
    spec = _spec(text)
    per_case = 8.0 * spec.history_times().size * 2
    assert spec.history_bytes() == per_case and _spec().history_bytes() == 0.0
    monkeypatch.setattr(spec_mod, "_DEFAULT_BATCHES", 1)  # by count alone: one batch of all 6 cases
    monkeypatch.setattr(spec_mod, "_DEFAULT_BATCH_BYTES", 2.5 * per_case)
    assert default_batch_size(spec.n_cases) == 6
    assert spec.default_batch() == 2  # two cases' histories fit the bound
    assert _spec().default_batch() == 6  # without histories only the count bounds it
