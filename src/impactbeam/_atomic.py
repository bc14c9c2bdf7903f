"""Atomic file writing: a temporary file beside the target, then :func:`os.replace`.

A reader never sees half a file, and a failed or interrupted write leaves
nothing behind. The temporary name holds the writer's pid, so a file left by a
writer killed outright (SIGKILL) is removed by the next write to the same
target.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from glob import escape as glob_escape
from pathlib import Path

__all__ = ["atomic_path", "write_text", "pid_alive"]


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str], suffix: str | None = None) -> Iterator[str]:
    """Yield a temporary path to write; on success it replaces ``path``.

    The temporary file lives in the target's directory (so the replace is
    atomic) and ends with ``suffix`` (default: the target's suffix, which lets
    writers choose a format from it). It gets the usual ``0666 & ~umask`` mode.
    """
    target = Path(path)
    directory = target.parent if str(target.parent) else Path(".")
    _remove_stale(directory, target.name)
    fd, tmp = tempfile.mkstemp(
        prefix=f".{target.name}.{os.getpid()}.", suffix=target.suffix if suffix is None else suffix, dir=directory
    )
    os.close(fd)
    try:
        yield tmp
        mask = os.umask(0)
        os.umask(mask)
        os.chmod(tmp, 0o666 & ~mask)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise


def _remove_stale(directory: Path, name: str) -> None:
    """Remove temporary files of ``name`` left by writers that were killed (their pid is gone)."""
    for p in directory.glob(f".{glob_escape(name)}.*"):
        parts = p.name[len(name) + 2 :].split(".", 1)
        if parts[0].isdigit() and not pid_alive(int(parts[0])):
            with contextlib.suppress(OSError):
                p.unlink()


def pid_alive(pid: object) -> bool:
    """Whether a process with this pid exists on this host (True when it cannot be told)."""
    try:
        os.kill(int(pid), 0)  # type: ignore[call-overload]
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, TypeError, ValueError):
        return True
    return True


def write_text(path: str | os.PathLike[str], text: str) -> None:
    """Write UTF-8 text (LF line ends) to ``path`` atomically."""
    with atomic_path(path, ".tmp") as tmp:
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
