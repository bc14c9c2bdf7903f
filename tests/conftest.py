"""Shared test configuration.

BLAS threads are limited to one: the matrices here are small, threading only
adds overhead and run-to-run round-off differences on a 2-core machine.
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

# Figures render off-screen; the library itself never chooses a backend.
os.environ.setdefault("MPLBACKEND", "Agg")

# Mode sets kept between processes (impactbeam.modal.disk_cache) go to a directory of this session, not
# the user's cache: every test session starts from computed sets, and its command-line runs share them.
if "IMPACTBEAM_CACHE_DIR" not in os.environ:
    import tempfile

    os.environ["IMPACTBEAM_CACHE_DIR"] = tempfile.mkdtemp(prefix="impactbeam-test-cache-")


import pytest  # noqa: E402

import specimen  # noqa: E402


@pytest.fixture
def specimen_toml() -> str:
    """The specimen's ``[beam]`` table and Case-3 contactor as TOML text (see ``specimen.py``)."""
    return specimen.BEAM + specimen.CONTACTOR


@pytest.fixture
def scenario_file(tmp_path):
    """A factory writing scenario text into the test's temporary directory: ``scenario_file(text, name)``."""

    def write(text: str, name: str = "case.toml"):
        return specimen.write_scenario(tmp_path, text, name)

    return write
