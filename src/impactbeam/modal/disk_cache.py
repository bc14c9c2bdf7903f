"""Mode sets kept on disk between processes: the same bits, without solving the frequency equation again.

Building a mode set refines each root of the frequency equation (paper,
eq. 5 and its stepped-beam generalisation) by bisection and Brent's method
in Python: ~10 to 50 ms a set. A command-line ``simulate`` of Case 3 builds
ten (its states at three mode counts, for the convergence estimate), ~0.3 s
of a process of ~1.3 s, and builds the same ten in every process. So a
built set is also written to a file (its pickle) and the next process that
asks for the same one reads it (~1 ms).

A file stands for one set only when everything that made it is the same:

* the arguments (the beam, the engaged springs, the count), pickled into
  the file's key and compared in full when it is read (a hash collision or
  a truncated file is a miss, never another set);
* the code: the key includes a digest of every source file of the package,
  its version, the versions of NumPy and SciPy and the CPU features NumPy
  dispatches on (its vector paths may round differently on another
  processor); where the sources cannot be read (a zipped install) nothing
  is stored.

A file that cannot be read is computed again and rewritten; a directory
that cannot be written leaves every set computed as before. Writes are
atomic (a temporary file renamed), so concurrent processes (a sweep's
workers) never read half a file. The directory holds at most
:data:`MAX_FILES` sets; beyond that the least recently used are removed.

Where: ``IMPACTBEAM_CACHE_DIR`` if set (an empty value or ``off`` turns
the cache off), else ``$XDG_CACHE_HOME/impactbeam/modes`` or
``~/.cache/impactbeam/modes`` (none without a home directory).
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import pickle
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

__all__ = ["stored", "cache_dir", "MAX_FILES"]

T = TypeVar("T")

#: Sets kept in the directory (a few kB to a few hundred kB each).
MAX_FILES = 2000
_PROTOCOL = 5
_DIGEST: str | None = None
_WRITES = 0  # sets written by this process: the directory is pruned at the first and every 100th


def cache_dir() -> Path | None:
    """The directory of the stored sets, or None when the cache is off (module docstring)."""
    env = os.environ.get("IMPACTBEAM_CACHE_DIR")
    if env is not None:
        return None if env.strip().lower() in ("", "off", "0", "none") else Path(env) / "modes"
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    if not os.path.isabs(base):  # no home directory (expanduser left "~"): no cache, not a "~" in the cwd
        return None
    return Path(base) / "impactbeam" / "modes"


def code_digest() -> str | None:
    """SHA-256 of the package's sources, NumPy's and SciPy's versions and NumPy's dispatched CPU features.

    None when the sources cannot be read (a zipped install): then nothing is stored.
    """
    global _DIGEST
    if _DIGEST is None:
        import numpy as np
        import scipy

        from .. import __version__

        h = hashlib.sha256(f"impactbeam {__version__} numpy {np.__version__} scipy {scipy.__version__}".encode())
        try:
            from numpy._core._multiarray_umath import __cpu_features__ as features
        except ImportError:  # another NumPy layout: the version alone
            features = {}
        h.update(" ".join(sorted(k for k, on in features.items() if on)).encode())
        root = Path(__file__).resolve().parents[1]
        sources = []
        for where, dirs, files in os.walk(root):
            dirs[:] = [d for d in dirs if d != "__pycache__"]  # numba's cache files live there too
            sources += [os.path.join(where, f) for f in files if f.endswith(".py")]
        try:
            for path in sorted(sources):
                h.update(os.path.relpath(path, root).encode())
                h.update(Path(path).read_bytes())
        except OSError:
            sources = []
        _DIGEST = h.hexdigest() if sources else ""
    return _DIGEST or None


def stored(key: tuple[Any, ...], compute: Callable[[], T]) -> T:
    """``compute()``, or the value a previous process stored for the same ``key`` and code.

    Parameters
    ----------
    key : tuple
        Everything the value depends on besides the code (picklable).
    compute : callable
        Builds the value (picklable).

    Returns
    -------
    object
        The value: read from the file, or computed (and written).
    """
    where = cache_dir()
    digest = code_digest() if where is not None else None
    if digest is None:
        return compute()
    try:
        blob = pickle.dumps(key, protocol=_PROTOCOL)
    except Exception:  # an argument that does not pickle: no file for it
        return compute()
    name = hashlib.sha256(digest.encode() + blob).hexdigest()
    path = where / name[:2] / f"{name}.pkl"
    found = _read(path, blob)
    if found is not None:
        return found[0]
    value = compute()
    _write(where, path, blob, value)
    return value


def _read(path: Path, blob: bytes) -> tuple[Any] | None:
    try:
        with open(path, "rb") as fh:
            stored_key, value = pickle.load(fh)
    except Exception:  # missing, truncated or from another pickle: a miss
        return None
    if stored_key != blob:
        return None
    with contextlib.suppress(OSError):
        os.utime(path)  # recently used: kept when the directory is pruned
    return (value,)


def _write(where: Path, path: Path, blob: bytes, value: Any) -> None:
    from .._io import write_bytes

    try:
        data = pickle.dumps((blob, value), protocol=_PROTOCOL)
    except Exception:
        return
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_bytes(path, data)  # atomic: a concurrent reader (a sweep's worker) never sees half a file
        global _WRITES
        if _WRITES % 100 == 0:
            _prune(where)
        _WRITES += 1
    except OSError:  # read-only, full or missing (WriteError is one): the value is used without being kept
        return


def _prune(where: Path) -> None:
    """Keep at most :data:`MAX_FILES` sets: remove the least recently used beyond that."""
    files = list(where.glob("*/*.pkl"))
    if len(files) <= MAX_FILES:
        return
    times = []
    for p in files:
        with contextlib.suppress(OSError):
            times.append((p.stat().st_mtime, p))
    times.sort()
    for _, p in times[: len(times) - MAX_FILES * 3 // 4]:
        with contextlib.suppress(OSError):
            p.unlink()
