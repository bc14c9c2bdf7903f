"""Compile every kernel of the solver into numba's disk cache: ``python -m impactbeam.solver.warmup``.

``make install`` runs it, and the first run on a machine whose cache is
empty starts it in the background (:mod:`~impactbeam.solver.kernels`). It
runs a small problem through each compiled entry point (the event loop, the
dense output's samples, extrema and integrals, the metrics, the batched
runs and the metric rules the ``solve_ivp`` reference uses), so that later
processes load them from the cache instead of compiling them. One warm-up
at a time: a lock file beside the cache holds its process id.

``--quiet`` prints nothing; otherwise it reports the time it took.
"""

from __future__ import annotations

import dataclasses
import os
import sys
import time

__all__ = ["warm_up", "main"]


def warm_up() -> None:
    """Run one small problem through every compiled kernel (compiling those not yet cached)."""
    import numpy as np

    from ..model import Damping, SolverOptions
    from ..model.beam import Beam, Contactor
    from ..model.loading import Excitation
    from . import kernels
    from .engine import integrate
    from ..model.starting import InitialCondition

    beam = Beam.rectangular(0.1, 0.01, 0.003, 2e9, 1000.0)
    contactors = (Contactor(0.05, 4000.0, 1e-4, "below", damping=0.05), Contactor(0.1, 1000.0, 2e-4, "above"))
    excitation = Excitation(kind="base_acceleration", shape="half_sine", amplitude=150.0, duration=0.01)
    options = SolverOptions(modes=3, end_time=0.03, basis="paper")
    with kernels.forced("compiled"):
        K = kernels.compiled()
        sol = integrate(beam, contactors, Damping(0.01, 0.02), excitation, InitialCondition(), options)
        sol.metric_arrays(0.05, 1.0, True)
        sol.sample(np.array([0.05, 0.1]), np.array([0.0, 0.01]), modal=True, energy=True)
        sol.extrema([(0.05, 0.0, 0.02, 1.0, 0.0, None)])
        sol.integrals([(0.05, 0.0, 0.02)])
        ev_t, ev_kind, ev_c = sol.event_arrays[:3]
        n = ev_t.size + 3
        rows = (np.zeros(n, dtype=np.int64), np.zeros(n), np.zeros(n), np.zeros(n))
        m = int(K.contact_rows(ev_t, ev_kind, ev_c, ev_t.size, 2, 0.03, *rows))
        contact = np.full(5, np.nan)
        K.first_contact(ev_t, ev_kind, ev_c, ev_t.size, 0.01, contact)
        jumps = np.ascontiguousarray(sol.energy_jumps)
        e = K.pairwise_sum(jumps, jumps.size) + K.release_loss_sum(
            ev_c, ev_kind, sol.event_penetrations, ev_t.size, sol.dashpots, np.array([4000.0, 1000.0]),
            np.empty(max(ev_t.size, 1)))
        K.assemble(np.empty(K.N_SCALARS), ev_t.size, 1.0, 0.01, np.nan, e, 1e-5, m, rows[0], rows[1], np.zeros(n),
                   contact, 1e-4, np.nan)
        from .batch import integrate_batch

        shifted = tuple(dataclasses.replace(c, gap=2 * c.gap) for c in contactors)
        integrate_batch(beam, [contactors, shifted], Damping(0.01, 0.02), [excitation, excitation], InitialCondition(),
                        [options, options], point=0.05, sign=1.0)


def _acquire(path: str) -> bool:
    """Create the lock file with this process id; False when another live warm-up holds it."""
    from .kernels import warmup_running

    for _ in range(2):
        try:
            fd = os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            if warmup_running():
                return False
            try:
                os.unlink(path)  # left by a warm-up that died
            except OSError:
                return False
            continue
        except OSError:
            return True  # no lock possible here (a read-only cache directory): compile anyway
        with os.fdopen(fd, "w") as fh:
            fh.write(str(os.getpid()))
        return True
    return False


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``python -m impactbeam.solver.warmup [--quiet]``.

    Parameters
    ----------
    argv : list of str, optional
        Command-line arguments (default ``sys.argv[1:]``).
    """
    argv = sys.argv[1:] if argv is None else argv
    quiet = "--quiet" in argv
    from .kernels import lock_path

    path = lock_path()
    if not _acquire(path):
        if not quiet:
            print("impactbeam: another process is compiling the solver already")
        return 0
    t0 = time.perf_counter()
    try:
        from . import kernels

        ns = kernels.compiled()  # (removes stale cache files unless they match these sources)
        if not kernels._digest_matches(ns):
            kernels.purge_cache(ns)  # the lock is ours: compiled() left them to us
        warm_up()
        kernels.write_digest()
    finally:
        try:
            os.unlink(path)
        except OSError:
            pass
    if not quiet:
        cpu = sum(os.times()[:2])
        print(f"impactbeam: solver compiled and cached in {time.perf_counter() - t0:.1f} s ({cpu:.1f} s CPU)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
