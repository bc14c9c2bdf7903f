"""Shared test configuration.

BLAS threads are limited to one: the matrices here are small, threading only
adds overhead and run-to-run round-off differences on a 2-core machine.
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

# Figures render off-screen; the library itself never chooses a backend.
os.environ.setdefault("MPLBACKEND", "Agg")
