"""Mode sets kept on disk between processes (impactbeam.modal.disk_cache).

The reference is the set computed in the process: a set read from its file
must be the same bits (frequencies, coefficients, shapes and their
derivatives at any point), and whatever goes wrong with the files (another
key in the file, a truncated file, an unwritable directory, the cache
turned off) must give the computed set, never another one.
"""

from __future__ import annotations

import dataclasses
import os
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import impactbeam as ib
from impactbeam.modal import disk_cache
from impactbeam.modal.modeset import _build, _cached
from impactbeam.model.beam import Beam

CASE3 = Path(__file__).resolve().parents[1] / "examples" / "case03.toml"


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("IMPACTBEAM_CACHE_DIR", str(tmp_path))
    _cached.cache_clear()  # the process's own cache would answer first
    yield tmp_path / "modes"
    _cached.cache_clear()


def _beam() -> Beam:
    return ib.load_scenario(CASE3).beam


def _files(where: Path) -> list[Path]:
    return sorted(where.glob("*/*.pkl")) if where.exists() else []


def _same_bits(a, b) -> None:
    x = np.linspace(0.0, a.beam.length, 37)
    assert np.array_equal(a.omega, b.omega) and np.array_equal(a.beta, b.beta)
    assert np.array_equal(a._coef, b._coef) and np.array_equal(a._kry, b._kry)
    for d in range(4):
        assert np.array_equal(a.shapes(x, d), b.shapes(x, d))
    assert a.springs == b.springs and a.n_rigid == b.n_rigid


def test_a_stored_set_is_the_computed_set_to_the_bit(cache):
    beam = _beam()
    springs = ((0.0528528, 4030.0),)
    first = ib.mode_set(beam, springs, 8)
    assert len(_files(cache)) == 1
    _cached.cache_clear()
    again = ib.mode_set(beam, springs, 8)  # read from the file
    assert again is not first
    _same_bits(again, first)
    _same_bits(again, _build(first._layout, beam, springs, 8))  # and a fresh computation


def test_another_process_reads_the_set(cache):
    """A second process reads the file the first wrote (no new file) and gets the same frequencies."""
    code = ("import impactbeam as ib, sys\nsc = ib.load_scenario(sys.argv[1])\n"
            "print(repr(ib.mode_set(sc.beam, (), 6).omega.tolist()))")
    env = {**os.environ, "IMPACTBEAM_CACHE_DIR": str(cache.parent)}
    outs = [subprocess.run([sys.executable, "-c", code, str(CASE3)], capture_output=True, text=True, env=env,
                           timeout=300, check=True).stdout for _ in range(2)]
    assert outs[0] == outs[1]
    assert len(_files(cache)) == 1
    _cached.cache_clear()
    assert outs[0].strip() == repr(ib.mode_set(_beam(), (), 6).omega.tolist())


def test_keys_differ_by_every_argument(cache):
    beam = _beam()
    ib.mode_set(beam, (), 6)
    ib.mode_set(beam, (), 7)
    ib.mode_set(beam, ((0.05, 4030.0),), 6)
    ib.mode_set(beam, ((0.05, 4031.0),), 6)
    stiffer = dataclasses.replace(beam, youngs_modulus=beam.youngs_modulus * 1.01)
    ib.mode_set(stiffer, (), 6)
    assert len(_files(cache)) == 5
    assert not np.array_equal(ib.mode_set(stiffer, (), 6).omega, ib.mode_set(beam, (), 6).omega)
    assert len({p.name for p in _files(cache)}) == len(_files(cache))


def test_a_file_holding_another_key_or_garbage_is_a_miss(cache):
    beam = _beam()
    ref = ib.mode_set(beam, (), 5)
    (path,) = _files(cache)
    other = ib.mode_set(beam, (), 4)
    _cached.cache_clear()
    # another set under this key's name (a collision): its key inside differs, so it is not used
    path.write_bytes(pickle.dumps((pickle.dumps(("mode_set", beam, (), 4), protocol=5), other), protocol=5))
    _same_bits(ib.mode_set(beam, (), 5), ref)
    _cached.cache_clear()
    path.write_bytes(b"\x80\x05truncated")
    _same_bits(ib.mode_set(beam, (), 5), ref)
    _cached.cache_clear()
    _same_bits(ib.mode_set(beam, (), 5), ref)  # the file was rewritten by the last miss
    with open(path, "rb") as fh:
        key, value = pickle.load(fh)
    _same_bits(value, ref)


def test_cache_off_or_unwritable_computes_as_before(tmp_path, monkeypatch):
    beam = _beam()
    _cached.cache_clear()
    monkeypatch.setenv("IMPACTBEAM_CACHE_DIR", "off")
    ref = ib.mode_set(beam, (), 5)
    assert disk_cache.cache_dir() is None
    blocked = tmp_path / "file"
    blocked.write_text("not a directory")
    monkeypatch.setenv("IMPACTBEAM_CACHE_DIR", str(blocked))
    _cached.cache_clear()
    _same_bits(ib.mode_set(beam, (), 5), ref)
    _cached.cache_clear()


def test_the_directory_is_pruned_to_its_bound(cache, monkeypatch):
    monkeypatch.setattr(disk_cache, "MAX_FILES", 4)
    monkeypatch.setattr(disk_cache, "_WRITES", 0)
    beam = _beam()
    for k in range(7):
        disk_cache._WRITES = 0  # prune at every write here
        ib.mode_set(beam, ((0.05, 1000.0 + k),), 3)
    assert len(_files(cache)) <= 4


def _forget_in_process() -> None:
    """Drop what this process keeps of earlier runs (mode sets, bases, packed problems): the next run builds."""
    from impactbeam.solver import engine
    from impactbeam.solver.ritz import _cached_basis

    _cached.cache_clear()
    _cached_basis.cache_clear()
    engine._CACHE.clear()


def test_simulation_with_stored_sets_is_the_same_bits(cache):
    """A whole run (its three states' sets and enriched basis) from stored sets: the same metrics, bit for bit."""
    sc = ib.load_scenario(CASE3)
    _forget_in_process()  # earlier tests ran Case 3 in this process
    first = ib.simulate(sc).metrics()
    n = len(_files(cache))
    assert n >= 2
    _forget_in_process()
    again = ib.simulate(sc).metrics()
    assert len(_files(cache)) == n  # every set read, none built
    assert again == first


def test_no_home_directory_means_no_cache(monkeypatch):
    """Without HOME (expanduser leaves "~"), nothing is written to a "~" directory in the working directory."""
    monkeypatch.delenv("IMPACTBEAM_CACHE_DIR", raising=False)
    monkeypatch.delenv("XDG_CACHE_HOME", raising=False)
    monkeypatch.setattr(os.path, "expanduser", lambda p: p)
    assert disk_cache.cache_dir() is None
    monkeypatch.setenv("XDG_CACHE_HOME", "/somewhere")
    assert disk_cache.cache_dir() == Path("/somewhere/impactbeam/modes")


def test_unreadable_sources_store_nothing(cache, monkeypatch):
    """A digest of no source (a zipped install) cannot tell versions apart: nothing is stored."""
    monkeypatch.setattr(disk_cache, "_DIGEST", "")
    beam = _beam()
    ref = ib.mode_set(beam, (), 4)
    assert _files(cache) == []
    _cached.cache_clear()
    _same_bits(ib.mode_set(beam, (), 4), ref)
