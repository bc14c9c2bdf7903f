"""The solver's kernels: compiled by numba, or interpreted while the compiled ones are not yet cached.

Numba compiles the kernels once per machine and keeps them in its disk cache.
Compiling them takes 10-30 s of CPU, so on first use (an empty cache: a new
environment, a new version) a run does not wait for it:

* :func:`active` gives the compiled kernels when numba's cache holds them for
  this machine (:func:`ready`), else their *interpreted twins*: the same
  source executed by Python (:func:`interpreted`, the modules loaded a second
  time with the decorator of :mod:`~impactbeam.solver._jit` replaced by the
  identity), and starts one background process that compiles the kernels
  into the cache (``python -m impactbeam.solver.warmup``);
* :func:`for_work` runs small work interpreted until the compiled kernels
  are loaded in the process: Case 3 (0.2 s, 26 segments) and its metrics
  take ~0.04 s interpreted, less than importing numba and loading the
  compiled code (~0.5 s), so a short run never loads them;
* both give the same results to the bit (the kernels use only IEEE
  arithmetic in a fixed order and the C library's ``exp``, ``sin``, ``cos``,
  ``sqrt``; integer powers are written out as numba computes them; a test
  compares the two on every code path), so a run may switch from one to the
  other at any checkpoint: the engine asks :func:`active` again whenever the
  loop returns to Python, and a long first run moves to the compiled kernels
  as soon as the background compile has finished;
* :func:`compiled` gives the compiled kernels whatever the cache holds
  (compiling them in this process if needed): the batched paths (sweeps,
  bifurcation diagrams) ask for them, since they run long enough to pay for
  the compile.

``make install`` compiles the kernels once (``python -m impactbeam.solver.warmup``).
"""

from __future__ import annotations

import importlib
import logging
import os
import subprocess
import sys
import threading
import time
import types
from contextlib import contextmanager
from collections.abc import Iterator

__all__ = ["Kernels", "active", "for_work", "compiled", "interpreted", "ready", "forced", "batched", "ENTRY_POINTS",
           "SMALL"]

_LOG = logging.getLogger("impactbeam")
_PACKAGE = __name__.rsplit(".", 1)[0]  # impactbeam.solver
_TWIN = _PACKAGE + "._interpreted"
_MODULES = ("_elementary", "_closed", "_events", "_loop", "_dense", "_metrics", "_batch")
#: The kernels called from Python, (module, function): what the cache must hold for :func:`ready`.
ENTRY_POINTS = (("_loop", "run"), ("_dense", "sample"), ("_dense", "extremum"), ("_dense", "integral"),
                ("_metrics", "run_metrics"), ("_batch", "run_batch"))


class Kernels(types.SimpleNamespace):
    """The kernel modules' public names in one namespace (``K.run``, ``K.run_metrics``, ``K.DONE``, ...)."""

    interpreted: bool


def _namespace(prefix: str, interpreted_: bool) -> Kernels:
    ns: dict[str, object] = {}
    for name in _MODULES:
        mod = importlib.import_module(f"{prefix}.{name}")
        ns.update({k: v for k, v in vars(mod).items() if not k.startswith("__")})
    return Kernels(**ns, interpreted=interpreted_)


_COMPILED: Kernels | None = None
_INTERPRETED: Kernels | None = None
_READY = False
_LOADED = False  # the compiled kernels are in use in this process
_CHECKED = -1e9  # when the cache was last looked at
_SPENT = 0.0  # seconds spent in the interpreted kernels' entry points
_SPAWNED = False
_FORCED: str | None = None
# choosing and loading the kernels changes the state above: one thread at a time (a bifurcation diagram searches
# the extremes of its records on a second thread while the next value runs)
_LOCK = threading.RLock()


def compiled() -> Kernels:
    """The numba kernels (loaded from the cache, or compiled here on their first call).

    Numba keys a cached kernel on its own source only, not on the functions
    it calls: after a kernel module changed, a caller's cache entry would
    still load, with the old callee inside. So the cache counts as this
    code's only when the digest of every kernel module (written by the
    warm-up once it has compiled them all) matches; when it does not (and no
    warm-up is running), the kernels' cache files are removed before any is
    loaded, and numba compiles them afresh.
    """
    global _COMPILED
    if _COMPILED is not None:  # loaded: no lock needed to read it
        return _COMPILED
    with _LOCK:
        if _COMPILED is None:
            ns = _namespace(_PACKAGE, False)
            if not _digest_matches(ns) and not warmup_running(ns):
                purge_cache(ns)
            _COMPILED = ns
        return _COMPILED


def source_digest() -> str:
    """SHA-256 of the kernel modules' sources and numba's version (what the compiled kernels are made of)."""
    import hashlib

    import numba

    h = hashlib.sha256(numba.__version__.encode())
    here = os.path.dirname(__file__)
    for name in (*_MODULES, "_codes", "_jit"):
        with open(os.path.join(here, name + ".py"), "rb") as fh:
            h.update(fh.read())
    return h.hexdigest()


def _cache_dir(ns: Kernels) -> str | None:
    try:
        return ns.run._cache._cache_path
    except AttributeError:  # the JIT is disabled
        return None


def _digest_path(ns: Kernels) -> str | None:
    where = _cache_dir(ns)
    return None if where is None else os.path.join(where, "impactbeam-kernels.digest")


def _digest_matches(ns: Kernels) -> bool:
    path = _digest_path(ns)
    if path is None:
        return True
    try:
        with open(path) as fh:
            return fh.read().strip() == source_digest()
    except OSError:
        return False


def write_digest() -> None:
    """Record that the cache holds every kernel compiled from the present sources (the warm-up's last step)."""
    path = _digest_path(compiled())
    if path is not None:
        try:
            with open(path + ".tmp", "w") as fh:
                fh.write(source_digest())
            os.replace(path + ".tmp", path)
        except OSError:  # a read-only cache: numba does not write there either
            pass


def purge_cache(ns: Kernels | None = None) -> None:
    """Remove the kernels' files from numba's cache (before any is loaded), so that they are compiled afresh."""
    import glob

    where = _cache_dir(ns or compiled())
    if where is None:
        return
    for name in _MODULES:
        for f in glob.glob(os.path.join(where, f"{name}.*.nb[ic]")):
            try:
                os.unlink(f)
            except OSError:
                pass


def interpreted() -> Kernels:
    """The interpreted twins of the kernels (same source, run by Python; module docstring).

    Their entry points (:data:`ENTRY_POINTS`) add the time they take to
    :data:`_SPENT`, from which :func:`for_work` judges when a process has run
    enough small work to be better off with the compiled kernels.
    """
    if _INTERPRETED is not None:
        return _INTERPRETED
    with _LOCK:
        return _interpreted()


def _interpreted() -> Kernels:
    global _INTERPRETED
    if _INTERPRETED is None:
        if _TWIN not in sys.modules:
            pkg = types.ModuleType(_TWIN, "interpreted twins of the solver's kernels")
            pkg.__path__ = [os.path.dirname(__file__)]  # type: ignore[attr-defined]
            jit = types.ModuleType(_TWIN + "._jit")
            jit.njit = _identity  # type: ignore[attr-defined]
            jit.COMPILED = False  # type: ignore[attr-defined]
            sys.modules[_TWIN] = pkg
            sys.modules[_TWIN + "._jit"] = jit
        ns = _namespace(_TWIN, True)
        for _, name in ENTRY_POINTS:
            setattr(ns, name, _timed(getattr(ns, name)))
        _INTERPRETED = ns
    return _INTERPRETED


def _timed(fn):
    def call(*args):
        global _SPENT
        t0 = time.perf_counter()
        try:
            return fn(*args)
        finally:
            _SPENT += time.perf_counter() - t0
    call.__wrapped__ = fn  # type: ignore[attr-defined]
    call.__doc__ = fn.__doc__
    return call


def _identity(*args, **kwargs):  # the decorator of the twins: njit(f), njit(**options)(f) -> f
    if args and callable(args[0]):
        return args[0]
    return lambda f: f


def _cached(dispatcher) -> bool:
    """Whether numba's disk cache holds a compiled version of ``dispatcher`` for this machine and source."""
    try:
        cache = dispatcher._cache
        index = cache._cache_file._load_index()
        want = cache._index_key(None, dispatcher.targetctx.codegen())[1:]
    except AttributeError:  # the JIT is disabled (a plain function), or numba's internals changed
        return True
    return any(key[1:] == want for key in index)


def ready() -> bool:
    """Whether numba's cache holds every kernel of :data:`ENTRY_POINTS`, compiled for this machine from these sources."""
    global _READY
    if not _READY:
        ns = compiled()  # imports the modules (numba compiles nothing before a first call)
        _READY = _digest_matches(ns) and all(
            _cached(getattr(sys.modules[f"{_PACKAGE}.{m}"], f)) for m, f in ENTRY_POINTS)
    return _READY


def active() -> Kernels:
    """The compiled kernels when numba's cache holds them (loading them), else the interpreted ones.

    In the second case one background process starts compiling them (module
    docstring); the cache is looked at again at most once a second.
    """
    global _LOADED, _CHECKED
    if _FORCED is not None:
        return compiled() if _FORCED == "compiled" else interpreted()
    if _LOADED:
        return compiled()
    with _LOCK:
        now = time.monotonic()
        if _LOADED or _READY or now - _CHECKED >= 1.0:
            _CHECKED = now
            if _LOADED or ready():
                _LOADED = True
                return compiled()
            _compile_in_background()
        return interpreted()


def for_work(size: int) -> Kernels:
    """The kernels for a piece of work of ``size`` (segments, samples or queries; see :data:`SMALL`).

    The compiled ones once they are loaded in this process; before that a
    small piece runs interpreted, which costs less than importing numba and
    loading the compiled code (a few tenths of a second) would; a larger one,
    or any once the process has spent :data:`SPENT_LIMIT` seconds in
    interpreted kernels (a loop of short runs), asks :func:`active`. A run (:func:`impactbeam.solver.engine.integrate`)
    starts with ``size = 0`` and asks :func:`active` at its first checkpoint,
    so a short run never loads the compiled kernels and a long one moves to
    them (the same results, to the bit).
    """
    if _FORCED is not None or _LOADED or size > SMALL or _SPENT > SPENT_LIMIT:
        return active()
    return interpreted()


def batched() -> Kernels:
    """The compiled kernels for a batch of cases, compiled here first if numba's cache lacks them.

    A batch runs long enough to pay for the compile (and a sweep's workers
    then find the cache warm).
    """
    global _LOADED
    if _FORCED == "interpreted":
        return interpreted()
    with _LOCK:
        if _FORCED is None and not _LOADED and not ready():
            _LOG.warning("impactbeam: compiling the solver for this machine (first use only; up to a minute on 2 "
                         "cores)")
        _LOADED = True
        return compiled()


#: Seconds of interpreted kernels after which a process asks for the compiled ones (a loop of short runs).
SPENT_LIMIT = 0.3

#: Work done interpreted before the compiled kernels are loaded: a run's metrics up to this many segments and
#: events, samples at up to this many times, extrema and integrals over up to this many segments in all.
SMALL = 400


@contextmanager
def forced(kind: str) -> Iterator[None]:
    """Use the ``"compiled"`` or ``"interpreted"`` kernels within the block (tests, the warm-up).

    Parameters
    ----------
    kind : {"compiled", "interpreted"}
    """
    global _FORCED
    if kind not in ("compiled", "interpreted"):
        raise ValueError(f"kind: 'compiled' or 'interpreted', got {kind!r}")
    before, _FORCED = _FORCED, kind
    try:
        yield
    finally:
        _FORCED = before


def lock_path(ns: Kernels | None = None) -> str:
    """The warm-up's lock file, beside numba's cache of the kernels.

    Parameters
    ----------
    ns : Kernels, optional
        The compiled kernels' namespace (default :func:`compiled`).
    """
    where = _cache_dir(ns or compiled())
    if where is None:
        import tempfile

        where = tempfile.gettempdir()
    return os.path.join(where, "impactbeam-warmup.pid")


def warmup_running(ns: Kernels | None = None) -> bool:
    """Whether a warm-up process (``python -m impactbeam.solver.warmup``) is compiling the kernels now.

    Parameters
    ----------
    ns : Kernels, optional
        The compiled kernels' namespace (default :func:`compiled`).
    """
    try:
        with open(lock_path(ns)) as fh:
            pid = int(fh.read().strip() or 0)
    except (OSError, ValueError):
        return False
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _compile_in_background() -> None:
    """Start ``python -m impactbeam.solver.warmup`` once per process (unless one runs already), and say so."""
    global _SPAWNED
    if _SPAWNED:
        return
    _SPAWNED = True
    running = warmup_running()
    if not running:
        try:
            subprocess.Popen([sys.executable, "-m", f"{_PACKAGE}.warmup"], stdin=subprocess.DEVNULL,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True,
                             close_fds=True)
        except OSError as exc:  # no subprocess here: the run stays interpreted, correct and slower
            _LOG.warning("impactbeam: cannot start the solver's compilation in the background (%s); "
                         "runs use the interpreted solver", exc)
            return
    _LOG.warning("impactbeam: first use on this machine: the solver is being compiled in the background "
                 "(about a minute); until then runs use its interpreted form (the same results, slower on long "
                 "runs)")
