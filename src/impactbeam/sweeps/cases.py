"""Many runs at once: the cases of a study, those sharing their packed problem in one compiled batch.

:func:`run_cases` is the path of sweeps and random ensembles: each case
gives exactly what ``simulate_system(...).metrics(impacts=False)`` gives
alone, its warnings included.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from .._warnings import WarningLog, emit_user_level_warning as warn
from ..model import Damping, SolverOptions
from ..model.beam import Beam, Contactor
from ..model.loading import Excitation
from ..model.starting import InitialCondition, Preload
from ..simulation import _checked_points, simulate_system

__all__ = ["Case", "CaseMetrics", "run_cases", "BATCH_BYTES", "case_bytes"]


@dataclass(frozen=True, eq=False)
class Case:
    """One run given as model objects (what a scenario holds), for :func:`run_cases`.

    Attributes
    ----------
    beam : Beam
    contactors : tuple of Contactor
    damping : Damping
    excitation : Excitation
    initial : InitialCondition
    options : SolverOptions
    points : tuple of float or None, [m]
        Output points (default: the contactors, then the right end).
    preload : Preload or None
        The constant load of ``[preload]``.
    """

    beam: Beam
    contactors: tuple[Contactor, ...]
    damping: Damping
    excitation: Excitation
    initial: InitialCondition
    options: SolverOptions
    points: tuple[float, ...] | None = None
    preload: Preload | None = None


@dataclass
class CaseMetrics:
    """The metrics of :func:`run_cases`, one entry per case.

    Attributes
    ----------
    scalars : ndarray, (n_cases, 10)
        The keys of :data:`impactbeam.result.metrics.METRIC_UNITS` in order, NaN where undefined or failed.
    status : ndarray of int, (n_cases,)
        0 end time reached, 1 stopped by the chattering guard, -1 failed.
    messages : list of str
        The solver's message, or the error of a failed case.
    errors : list of Exception or None
        The exception of each failed case.
    modes : ndarray of int, (n_cases,)
        Modes per state of each run (what ``solver.modes = "auto"`` chose); 0 for a failed case.
    warnings : list of list of str
        The warnings of each run (also issued as ImpactBeamWarning).
    """

    scalars: np.ndarray
    status: np.ndarray
    messages: list[str]
    errors: list[BaseException | None] = field(default_factory=list)
    modes: np.ndarray | None = None
    warnings: list[list[str]] = field(default_factory=list)


def run_cases(cases: Sequence[Case], *, progress: Callable[[int], None] | None = None) -> CaseMetrics:
    """The metrics of many runs, the cases of each packed problem in one compiled batch.

    Each case gives exactly what ``simulate_system(...).metrics(impacts=False)``
    gives (the same checks, the same compiled loop and metrics): cases that
    share their packed problem (beam, contactor positions, stiffnesses and
    dashpots, damping, load distribution, modes, basis) and initial state run
    as one batch (:func:`impactbeam.solver.batch.integrate_batch`), with no
    Python per case; ``solver.modes = "auto"`` runs case by case.

    Parameters
    ----------
    cases : sequence of Case
    progress : callable, optional
        ``progress(n)`` with the number of cases finished so far.

    Returns
    -------
    CaseMetrics
    """
    from ..result.metrics import METRIC_UNITS, response_point
    from ..solver.batch import integrate_batch
    from ..solver.engine import pack_key

    n = len(cases)
    scalars = np.full((n, len(METRIC_UNITS)), np.nan)
    status = np.full(n, -1, dtype=np.int64)
    modes = np.zeros(n, dtype=np.int64)
    messages = [""] * n
    errors: list[BaseException | None] = [None] * n
    warned: list[list[str]] = [[] for _ in range(n)]
    groups: dict[tuple, list[int]] = {}
    points: dict[int, np.ndarray] = {}
    for k, c in enumerate(cases):
        try:
            points[k] = _checked_points(c.beam, c.contactors, c.excitation, c.initial, c.options, c.points, "exact")
            if c.options.modes == "auto":
                raise _CaseByCase
            key = (pack_key(c.beam, c.contactors, c.damping, c.excitation, c.options, c.preload), c.initial.key(),
                   response_point(c.contactors, points[k])[0])
            groups.setdefault(key, []).append(k)
        except _CaseByCase:
            groups.setdefault(("one", k), []).append(k)
        except Exception as exc:
            errors[k] = exc
            messages[k] = " ".join(str(exc).split())
    done = 0
    for key, ks in groups.items():
        first = cases[ks[0]]
        if key[0] == "one":
            try:
                with WarningLog() as log:
                    res = simulate_system(first.beam, first.contactors, damping=first.damping,
                                          excitation=first.excitation, initial=first.initial, options=first.options,
                                          points=first.points, preload=first.preload)
                    m = res.metrics(impacts=False)
                warned[ks[0]] = log.messages
                for text in log.messages:
                    warn(text)
            except Exception as exc:
                errors[ks[0]] = exc
                messages[ks[0]] = " ".join(str(exc).split())
            else:
                scalars[ks[0]] = [np.nan if m[name] is None else m[name] for name in METRIC_UNITS]
                status[ks[0]] = res.status
                modes[ks[0]] = res.n_modes
                messages[ks[0]] = res.message
            done += 1
        else:
            for part in _memory_parts(ks, [case_bytes(cases[k]) for k in ks]):
                x = key[2]
                signs = [response_point(cases[k].contactors, points[k])[1] for k in part]
                br = integrate_batch(first.beam, [cases[k].contactors for k in part], first.damping,
                                     [cases[k].excitation for k in part], first.initial,
                                     [cases[k].options for k in part], point=x, sign=np.array(signs),
                                     preload=first.preload,
                                     progress=None if progress is None else (lambda j, done=done: progress(done + j)))
                scalars[part] = br.scalars
                status[part] = br.status
                modes[part] = np.where(br.status >= 0, int(first.options.modes), 0)
                for j, k in enumerate(part):
                    messages[k] = br.messages[j]
                    errors[k] = br.errors[j]
                    warned[k] = list(br.warnings[j])
                    if br.status[j] >= 0:
                        warned[k] += _unresolved(cases[k], br.scalars[j])
                    for text in warned[k]:
                        warn(text)
                done += len(part)
        if progress is not None:
            progress(done)
    return CaseMetrics(scalars, status, messages, errors, modes, warned)


def _unresolved(case: Case, scalars: np.ndarray) -> list[str]:
    """The warning a response too small for the extrema gives alone (:func:`~impactbeam.result.metrics.warn_unresolved`).

    Only such a case, rare, is run again alone: the batch keeps no solution
    to ask the least ``u`` of, and a lone run gives the same bits.
    """
    from ..result.metrics import UNRESOLVED, metrics_dict, response_size, warn_unresolved

    m = metrics_dict(scalars)
    driven = case.excitation.active or not case.initial.at_rest
    if not driven or response_size(m) >= UNRESOLVED * case.beam.length:
        return []
    with WarningLog():  # the run's own warnings are the batch's already
        res = simulate_system(case.beam, case.contactors, damping=case.damping, excitation=case.excitation,
                              initial=case.initial, options=case.options, points=case.points, preload=case.preload)
    with WarningLog() as log:
        warn_unresolved(res, m, driven=True)
    return log.messages


#: Bytes of load pieces one compiled batch may hold (a batch pads every case's pieces to the longest).
BATCH_BYTES = 64 * 2**20


def case_bytes(case: Case) -> int:
    """Memory a case brings to a batch: its load samples and their pieces, padded (8-byte values, 2 + 7 columns)."""
    times = case.excitation.times
    return 72 * (4 + (0 if times is None else int(times.size)))


def _memory_parts(ks: list[int], sizes: list[int]) -> list[list[int]]:
    """``ks`` cut into runs whose padded pieces (count x largest) stay within :data:`BATCH_BYTES` (one case at least)."""
    parts: list[list[int]] = []
    largest = 0
    for k, size in zip(ks, sizes):
        largest = max(largest, size)
        if parts and (len(parts[-1]) + 1) * largest <= BATCH_BYTES:
            parts[-1].append(k)
        else:
            parts.append([k])
            largest = size
    return parts


class _CaseByCase(Exception):
    """A case the batches do not take (``solver.modes = "auto"``)."""
