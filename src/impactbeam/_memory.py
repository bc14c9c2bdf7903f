"""Output sizes, the memory limit and the work limit: requests are estimated before they are run.

A result's histories (``w`` at the output points and contactors, contact
forces, modal coordinates, energies) are evaluated lazily; before any of them
is allocated, :func:`check_output_size` compares the estimate with
:func:`memory_limit` and refuses a request that would not fit, with the
estimate and a way to ask for less. A run whose work is out of proportion
(:func:`check_work`, against :func:`work_limit`) is refused the same way.
"""

from __future__ import annotations

import math
import os
import re

from .exceptions import ParameterError, ResourceError

__all__ = ["MAX_OUTPUT_SAMPLES", "sample_count", "memory_limit", "check_memory", "output_bytes", "check_output_size",
           "work_limit", "check_work"]

#: Most output samples of one history (``solver.time_step``, a sweep's ``outputs.histories``): 5e7
#: samples of one point already take 400 MB.
MAX_OUTPUT_SAMPLES = 50_000_000


def sample_count(end_time: float, time_step: float) -> int:
    """Number of output samples ``0, dt, 2 dt, ... <= end_time`` (a relative 1e-12 of round-off tolerated).

    Parameters
    ----------
    end_time, time_step : float, [s]

    Returns
    -------
    int
    """
    return int(math.floor(end_time / time_step * (1.0 + 1e-12))) + 1


_SIZE = re.compile(r"^([0-9.]+(?:E[+-]?[0-9]+)?)\s*([KMG]?)(?:I?B)?$")


def _size(name: str, default: float) -> float:
    """The number in environment variable ``name``, else ``default``.

    A ``K``, ``M`` or ``G`` suffix multiplies by 2^10, 2^20 or 2^30, with or
    without a ``B`` or ``iB`` after it (``4G``, ``4GB``, ``4 GiB``); a bare
    ``B`` is bytes.
    """
    raw = os.environ.get(name, "").strip().upper()
    if not raw:
        return default
    m = _SIZE.match(raw)
    value = math.nan
    if m is not None:
        try:
            value = float(m.group(1)) * {"K": 1 << 10, "M": 1 << 20, "G": 1 << 30, "": 1}[m.group(2)]
        except ValueError:
            pass
    if not value > 0:
        raise ParameterError(f"{name}: not a positive size: {raw!r} (a number, optionally with K, M or G: 4G, 4GB)")
    return value


#: Default of :func:`work_limit`, in mode-periods (see :func:`impactbeam.model.magnitudes.scan_work`).
#: The metrics' extrema run as one compiled call, which a Ctrl-C interrupts only when it returns;
#: measured on one core: 1 to 2 us per unit for damped runs, 4 us for an undamped one with impacts
#: (Case 3, 9.5e5 units: 3.7 s). The limit keeps that wait near 2 s (Case 3 with 8 modes:
#: end_time up to ~3.9e3 s); IMPACTBEAM_WORK_LIMIT raises it.
WORK_LIMIT = 5e5


def work_limit() -> float:
    """Mode-periods a run may scan: ``IMPACTBEAM_WORK_LIMIT`` (a number), default :data:`WORK_LIMIT`."""
    return _size("IMPACTBEAM_WORK_LIMIT", WORK_LIMIT)


def check_work(units: float, what: str, hint: str) -> None:
    """Raise ResourceError before a run whose work exceeds :func:`work_limit`.

    Parameters
    ----------
    units : float
        The run's work in mode-periods.
    what : str
        The request, for the message.
    hint : str
        How to ask for less, for the message.

    Raises
    ------
    ResourceError
    """
    limit = work_limit()
    if units > limit:
        raise ResourceError(
            f"{what} would scan ~{units:.2g} mode-periods (modes x end_time x the beam's frequency scale), "
            f"above the limit of {limit:.2g} (about 2 s of exact extrema, which Ctrl-C cannot interrupt; this "
            f"would take ~{units * 2e-6:.2g} to {units * 4e-6:.2g} s); {hint} (or raise IMPACTBEAM_WORK_LIMIT)"
        )


def memory_limit() -> int:
    """Bytes a request may allocate for sampled histories.

    The smallest of: ``IMPACTBEAM_MEMORY_LIMIT`` (bytes, or a number with a
    ``K``, ``M`` or ``G`` suffix; default 4 GiB), half of the machine's
    physical memory, and 80 % of the process's address-space limit
    (``ulimit -v``) when one is set.
    """
    limit = int(_size("IMPACTBEAM_MEMORY_LIMIT", 4 << 30))
    try:
        limit = min(limit, os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") // 2)
    except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
        pass
    try:
        import resource

        soft = resource.getrlimit(resource.RLIMIT_AS)[0]
        if soft != resource.RLIM_INFINITY:
            limit = min(limit, int(0.8 * soft))
    except (ImportError, OSError, ValueError):  # pragma: no cover - not POSIX
        pass
    return limit


def check_memory(nbytes: float, what: str, hint: str) -> None:
    """Raise ResourceError before allocating more than :func:`memory_limit`.

    Parameters
    ----------
    nbytes : float
        What the request would allocate.
    what : str
        The request, for the message (e.g. ``"the sampled histories"``).
    hint : str
        How to ask for less, for the message.

    Raises
    ------
    ResourceError
    """
    limit = memory_limit()
    if nbytes > limit:
        raise ResourceError(
            f"{what} would need {nbytes / 2**30:.3g} GiB, above the limit of {limit / 2**30:.3g} GiB; {hint} "
            "(or raise IMPACTBEAM_MEMORY_LIMIT)"
        )


def output_bytes(n_times: int, n_points: int, n_contactors: int, n_modes: int, *, modal: bool = True) -> int:
    """Estimated peak bytes of the sampled histories of a result and one copy of them.

    ``w, w_t`` at the points and the contactors, contact forces and states,
    and, with ``modal``, the modal coordinates and the seven energy series; the
    factor 2 covers the copy a Dataset or DataFrame makes.

    Parameters
    ----------
    n_times, n_points, n_contactors, n_modes : int
        Output samples, output points, contactors and modes per state.
    modal : bool
        Whether the modal coordinates and energy series are asked for too.

    Returns
    -------
    int
    """
    per = 8 * (2 * (n_points + n_contactors) + 2 * n_contactors) + n_contactors
    if modal:
        per += 8 * (2 * n_modes + 4 + 7)
    return 2 * per * n_times


def check_output_size(n_times: int, n_points: int, n_contactors: int, n_modes: int, modal: bool = True) -> None:
    """Raise ResourceError, before any work, when :func:`output_bytes` exceeds :func:`memory_limit`.

    Parameters
    ----------
    n_times, n_points, n_contactors, n_modes : int
        Output samples, output points, contactors and modes per state.
    modal : bool
        Whether the modal coordinates and energy series are asked for too.
    """
    check_memory(
        output_bytes(n_times, n_points, n_contactors, n_modes, modal=modal),
        f"sampling {n_times} output times at {n_points} points" + (f" with {n_modes} modal coordinates" if modal else ""),
        "use a larger solver.time_step, fewer output points or a shorter end_time",
    )
