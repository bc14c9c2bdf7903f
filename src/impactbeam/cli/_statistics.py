"""The short tables of impact and fatigue statistics in the command-line summaries (simulate, random)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

__all__ = ["statistics_lines"]


def _fmt(value: Any, scale: float = 1.0) -> str:
    try:
        x = float(value)
    except (TypeError, ValueError):
        return "n/a"
    return f"{x * scale:.4g}" if math.isfinite(x) else ("inf" if x > 0 else "n/a")


def statistics_lines(impacts: Sequence[Mapping[str, Any]], fatigue: Sequence[Mapping[str, Any]] = (),
                     window: Sequence[float] | None = None) -> list[str]:
    """Rows of the impact statistics per contactor and of the fatigue per point (``_ci`` intervals when given).

    Parameters
    ----------
    impacts : sequence of dict
        Per contactor, the keys of :data:`impactbeam.statistics.STATISTICS_DISPLAY`.
    fatigue : sequence of dict
        Per point: ``point``, ``damage_rate``, ``life`` (and ``damage_rate_ci``).
    window : (float, float), optional, [s]
        The analysis window, shown in the heading.
    """
    from ..statistics import STATISTICS_DISPLAY

    lines: list[str] = []
    if impacts:
        span = "" if window is None else f" over {window[0]:.4g}-{window[1]:.4g} s"
        lines.append(f"  impact statistics{span} (exact events):")
        head = "    " + "".ljust(26) + "".join(f"  contactor {c.get('contactor', i):<6}" for i, c in enumerate(impacts))
        lines.append(head)
        for key, label, scale, unit in STATISTICS_DISPLAY:
            cells = []
            for c in impacts:
                text = _fmt(c.get(key), scale)
                ci = c.get(f"{key}_ci")
                if ci is not None and all(math.isfinite(float(v)) for v in ci):
                    text += f" [{_fmt(ci[0], scale)}, {_fmt(ci[1], scale)}]"
                cells.append(f"  {text:<16}")
            lines.append(f"    {(label + (f' [{unit}]' if unit else '')).ljust(26)}" + "".join(cells))
    for f in fatigue:
        ci = f.get("damage_rate_ci")
        extra = ""
        if ci is not None and all(math.isfinite(float(v)) for v in ci):
            extra = f" [{_fmt(ci[0])}, {_fmt(ci[1])}]"
        lines.append(f"  fatigue at x = {_fmt(f.get('point'), 1e3)} mm: damage rate {_fmt(f.get('damage_rate'))} 1/s"
                     f"{extra}, life {_fmt(f.get('life'))} s")
    return lines
