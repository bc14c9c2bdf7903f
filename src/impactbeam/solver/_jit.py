"""The decorator of the compiled kernels: numba's ``njit``.

The kernel modules (``_elementary``, ``_closed``, ``_events``, ``_loop``,
``_dense``, ``_metrics``, ``_batch``) take ``njit`` from here, so that
:mod:`~impactbeam.solver.kernels` can load interpreted twins of them (the
same source with this decorator replaced by the identity) while numba
compiles the real ones.

Kernels that allocate no array are compiled without numba's reference
counting (``njit(..., _nrt=False)``): numba otherwise increments and
decrements, with atomic instructions, the reference count of every array
argument at every call and of every view it makes. In the event loop, whose
helpers take twenty arrays each and run a few times per segment, that was
half of a long run's time (100 s of random load on Case 3: 3.9 s, 1.0 s
without). An allocating kernel (the loop's entry :func:`._loop.run`) makes
its scratch arrays and hands them to a counting-free one (:func:`._loop._walk`);
arrays made inside a counting-free kernel are forbidden by numba.
"""

from __future__ import annotations

from numba import njit

__all__ = ["njit", "COMPILED"]

#: False in the interpreted twins: a kernel may then take a path that is cheaper for Python and gives the
#: same bits (numba folds the constant, so the compiled code has only its own path).
COMPILED = True
