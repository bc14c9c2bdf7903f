"""Reading delimited text data (scenario traces, measured records)."""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

__all__ = ["read_data_lines"]


def read_data_lines(
    path: str | os.PathLike[str],
    fail: Callable[[str], Exception],
    *,
    not_found: str | None = "not found",
    not_text: str = "is not a text (UTF-8) file",
) -> tuple[list[tuple[int, str]], str | None]:
    """Numbered data lines of a UTF-8 text file and its delimiter.

    Blank lines and lines starting with ``#`` are skipped; the delimiter is the
    first of ``,``, ``;`` and tab that occurs, or None (white space). Read
    errors are raised as ``fail(detail)`` (``not_found=None``: a missing file
    is reported like any other read error).
    """
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except FileNotFoundError as exc:
        if not_found is None:
            raise fail(f"cannot be read: {exc.strerror or exc}") from None
        raise fail(not_found) from None
    except IsADirectoryError:
        raise fail("is a directory, not a CSV file") from None
    except UnicodeDecodeError:
        raise fail(not_text) from None
    except OSError as exc:
        raise fail(f"cannot be read: {exc.strerror or exc}") from None
    lines = [
        (n, line) for n, line in enumerate(text.splitlines(), start=1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    delimiter = next((d for d in (",", ";", "\t") if any(d in line for _, line in lines)), None)
    return lines, delimiter
