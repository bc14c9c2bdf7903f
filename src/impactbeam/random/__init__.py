"""Random vibration ensembles: many independent records of a random load, on Dask, resumable.

:func:`random_response` runs one scenario with a random excitation for
``seeds`` independent streams (``numpy.random.SeedSequence(seed).spawn``),
as a parameter study over ``excitation.stream`` (so on the sweeps' Dask
cluster, batches, Zarr store, lock and resume), keeps each record's
statistics (:mod:`impactbeam.statistics.record`) and combines them into
estimates with confidence intervals (batch means, Student t).
"""

from __future__ import annotations

from .ensemble import RandomResponse, random_response

__all__ = ["RandomResponse", "random_response"]
