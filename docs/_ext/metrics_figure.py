"""Sphinx extension: the figure of the metrics page, drawn from the code at build time.

``_generated/metrics-case03.png`` is :func:`impactbeam.plot.plot_metrics` of
the reference Case 3 (``examples/case03.toml``), so the figure always shows
what the shipped code computes. ``python docs/_ext/metrics_figure.py OUT.png``
draws it outside a build.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "examples" / "case03.toml"


def draw(path: str | Path) -> Any:
    """Simulate Case 3 and write the metrics figure to ``path``; return its :class:`PlotHandles`."""
    import impactbeam as ib
    from impactbeam.plot import plot_metrics

    result = ib.simulate(ib.load_scenario(CASE))
    return plot_metrics(result, path, title="Case 3: the metrics on u = -w at the contactor (x = 52.85 mm)",
                        dpi=200)


def _write(app: Any) -> None:
    out = Path(app.srcdir) / "_generated" / "metrics-case03.png"
    out.parent.mkdir(exist_ok=True)
    draw(out)


def setup(app: Any) -> dict[str, Any]:
    app.connect("builder-inited", _write)
    return {"parallel_read_safe": True, "version": "1"}


if __name__ == "__main__":
    draw(sys.argv[1] if len(sys.argv) > 1 else "metrics-case03.png")
