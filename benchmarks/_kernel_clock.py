"""Time spent inside the compiled kernels' entry points, for the benchmark scripts' breakdowns."""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from typing import Any


class KernelClock:
    """Time spent in the named compiled kernels while active (``with`` block), and their calls.

    Parameters
    ----------
    names : mapping of str -> str
        Kernel entry point (``"run"``, ``"run_metrics"``, ...) -> label.
    clock : callable
        ``time.perf_counter`` (wall, the default) or ``time.process_time`` (CPU).
    """

    def __init__(self, names: Mapping[str, str], clock: Callable[[], float] = time.perf_counter) -> None:
        from impactbeam.solver import kernels

        self.ns = kernels.compiled()
        self.names = dict(names)
        self.clock = clock
        self.spent = dict.fromkeys(self.names, 0.0)
        self.calls = dict.fromkeys(self.names, 0)

    def __enter__(self) -> "KernelClock":
        self.saved = {name: getattr(self.ns, name) for name in self.names}
        for name, fn in self.saved.items():
            setattr(self.ns, name, self._timed(name, fn))
        return self

    def __exit__(self, *exc: object) -> None:
        for name, fn in self.saved.items():
            setattr(self.ns, name, fn)

    def _timed(self, name: str, fn: Callable[..., Any]) -> Callable[..., Any]:
        def call(*args: Any) -> Any:
            t0 = self.clock()
            try:
                return fn(*args)
            finally:
                self.spent[name] += self.clock() - t0
                self.calls[name] += 1
        return call
