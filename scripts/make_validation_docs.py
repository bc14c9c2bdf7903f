"""Tables and figures of docs/validation.md from ``impactbeam validate``.

Run from the repository root: ``python scripts/make_validation_docs.py`` (about 15 s).
Rewrites the generated blocks of docs/validation.md (between the
``<!-- validation table NAME -->`` and ``<!-- end validation table -->``
markers, and the same for ``figure``) and docs/figures/validation_*.png. tests/test_validation.py checks
that the committed tables are what the code prints.
"""

from __future__ import annotations

import os
import re
import warnings
from pathlib import Path

os.environ.setdefault("MPLBACKEND", "Agg")

import impactbeam as ib  # noqa: E402
from impactbeam.validation import validate  # noqa: E402
from impactbeam.validation.figures import write_figures  # noqa: E402
from impactbeam.validation.report import markdown_table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "validation.md"
BLOCK = re.compile(r"(<!-- validation (table|figure) (\w+) -->\n)(.*?)(<!-- end validation \2 -->)", re.S)


def fill(text: str, blocks: dict[tuple[str, str], str]) -> str:
    """``text`` with every generated block (table or figure of a case) replaced."""
    return BLOCK.sub(lambda m: m.group(1) + blocks[(m.group(2), m.group(3))] + m.group(5), text)


def blocks(report) -> dict[tuple[str, str], str]:
    """The generated text of every block: each case's table, and its figure directive once it has run."""
    out = {}
    for case in report.cases:
        out[("table", case.name)] = markdown_table(case)
        if case.status == "not run":
            out[("figure", case.name)] = "*(No figure: the case did not run; see the table.)*\n"
        else:
            out[("figure", case.name)] = (f"```{{figure}} figures/validation_{case.name.lower()}.png\n"
                                          f"{CAPTIONS[case.name]}\n```\n")
    return out


CAPTIONS = {
    "SDLX400": "Relative difference of each frequency from the analytical reference, and code_aster's PRECISION.",
    "SDNL32": "Tip deflection of both cases against the VPCS reference values.",
    "SDNL104": "Tip deflection of the runs; the circle is the reference deflection at 0.1315 s, the grey line the stop.",
    "Table2": "Maximum response: measured (Table 2) and simulated with the ideal pulses.",
}


def main() -> None:
    warnings.simplefilter("ignore", ib.ImpactBeamWarning)
    report = validate()
    PAGE.write_text(fill(PAGE.read_text(), blocks(report)))
    for path in write_figures(report, ROOT / "docs" / "figures"):
        print(path)
    for case in report.cases:
        print(case.name, case.status, case.message)


if __name__ == "__main__":
    main()
