"""The decorator of the compiled kernels: numba's ``njit``.

The kernel modules (``_closed``, ``_events``, ``_loop``, ``_dense``,
``_metrics``, ``_batch``) take ``njit`` from here, so that
:mod:`~impactbeam.solver.kernels` can load interpreted twins of them (the
same source with this decorator replaced by the identity) while numba
compiles the real ones.
"""

from __future__ import annotations

from numba import njit

__all__ = ["njit"]
