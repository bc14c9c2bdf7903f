"""Reading the worked examples and tables of README.md and docs/*.md, and comparing numbers.

The conventions a page follows (HTML comments, invisible on GitHub and in the
built site; each stands on the line(s) right above what it marks):

``<!-- example [cwd=DIR] [requires=MOD,...] [ignore=REGEX] -->``
    Above a fenced block. A console block (lines ``$ command`` followed by the
    output shown) is run in a shell; a Python block in doctest form
    (``>>> code`` followed by the output shown) is run by :mod:`doctest`. The
    blocks of one page run in order, in one temporary copy of ``examples/``
    (``cwd`` is relative to the copy's parent, so ``examples/case03.toml``
    resolves), sharing files and, for Python, one namespace. Output lines
    matching ``ignore`` (a measurement such as a progress bar's rate) are
    left out on both sides.
``<!-- table NAME -->``
    Above a Markdown table: the table producer ``NAME`` of the test computes
    the rows from the shipped code and every number of those rows is compared.
``<!-- numbers NAME -->``
    Above a paragraph or list: every number in it must be one that the text
    producer ``NAME`` prints (a rephrasing of generated text).
``<!-- unchecked: REASON -->``
    Above a block or table whose numbers are not compared, with the reason
    (timings measured on a named machine; errors measured by a named test).

Numbers are compared at the precision shown: ``...`` right after a number
means it is cut short, and ``...`` elsewhere stands for any text.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: The pages whose examples and tables are checked.
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]

#: Pages written by the program itself (``impactbeam reproduce --docs docs``): compared as a whole.
GENERATED = {ROOT / "docs" / "paper-reproduction.md"}

NUMBER = r"[-+]?(?:\d+\.\d+|\d+)(?:[eE][-+]?\d+)?"
_TOKEN = re.compile(rf"(?P<ellipsis>\.\.\.)|(?P<number>{NUMBER})|(?P<space>\s+)|(?P<other>.)", re.S)
_DIRECTIVE = re.compile(r"^<!--\s*(example|table|numbers|unchecked)\b:?\s*(.*?)\s*-->\s*$")
_FENCE = re.compile(r"^(\s*)(```+|~~~+)\s*([\w+-]*)")

#: Relative difference allowed between two IEEE machines for the same computation (round-off of
#: other SIMD widths, FMA contraction and BLAS kernels is ~1e-15 relative per operation; the solver's
#: event times are located to 1e-13 s): it only matters where a value sits on a rounding boundary.
ROUNDOFF = 1e-12


@dataclass
class Directive:
    kind: str
    args: dict[str, str]
    text: str
    line: int


@dataclass
class Item:
    """A fenced block, a table or a paragraph of a page, with the directives above it."""

    page: Path
    line: int  # 1-based line of the first line of the item
    kind: str  # "fence", "table", "paragraph"
    lines: list[str]
    lang: str = ""
    directives: list[Directive] = field(default_factory=list)

    @property
    def where(self) -> str:
        return f"{self.page.relative_to(ROOT)}:{self.line}"

    def directive(self, kind: str) -> Directive | None:
        return next((d for d in self.directives if d.kind == kind), None)


def _parse_args(text: str) -> dict[str, str]:
    out: dict[str, str] = {}
    for m in re.finditer(r'(\w[\w-]*)=("([^"]*)"|\S+)|(\S+)', text):
        if m.group(4):
            out.setdefault("name", m.group(4))
        else:
            out[m.group(1)] = m.group(3) if m.group(3) is not None else m.group(2)
    return out


def items(page: Path) -> list[Item]:
    """The fenced blocks, tables and paragraphs of a Markdown page, in order, with their directives."""
    lines = page.read_text(encoding="utf-8").splitlines()
    out: list[Item] = []
    pending: list[Directive] = []
    i = 0
    while i < len(lines):
        line = lines[i]
        d = _DIRECTIVE.match(line.strip())
        if d:
            pending.append(Directive(d.group(1), _parse_args(d.group(2)), d.group(2), i + 1))
            i += 1
            continue
        if not line.strip() or re.fullmatch(r"<!--.*-->", line.strip()):  # other comments are transparent
            i += 1
            continue
        f = _FENCE.match(line)
        if f:
            fence = f.group(2)
            j = i + 1
            while j < len(lines) and not lines[j].strip().startswith(fence):
                j += 1
            body = [ln[len(f.group(1)):] if ln.startswith(f.group(1)) else ln for ln in lines[i + 1 : j]]
            out.append(Item(page, i + 1, "fence", body, f.group(3), pending))
            i = j + 1
        else:
            kind = "table" if line.lstrip().startswith("|") else "paragraph"
            j = i
            while j < len(lines) and lines[j].strip() and not _FENCE.match(lines[j]) and not _DIRECTIVE.match(
                    lines[j].strip()) and (lines[j].lstrip().startswith("|") == (kind == "table")):
                j += 1
            out.append(Item(page, i + 1, kind, lines[i:j], "", pending))
            i = j
        pending = []
    return out


# --------------------------------------------------------------------------- what a block shows


def console_steps(item: Item) -> list[tuple[str, str]]:
    """(command, output shown) pairs of a console block: ``$ `` lines and the lines after them."""
    steps: list[tuple[str, list[str]]] = []
    for line in item.lines:
        if line.startswith("$ "):
            steps.append((line[2:], []))
        elif steps:
            steps[-1][1].append(line)
    return [(cmd, "\n".join(out).strip("\n")) for cmd, out in steps]


def shows_output(item: Item) -> bool:
    """Whether a fenced block shows what a command or an expression prints."""
    if item.kind != "fence":
        return False
    if any(out.strip() for _, out in console_steps(item)):
        return True
    import doctest

    text = "\n".join(item.lines)
    return ">>>" in text and any(ex.want.strip() for ex in doctest.DocTestParser().get_examples(text))


def has_numbers(item: Item) -> bool:
    """Whether a table has a number in a body cell (the rows below the header and rule)."""
    return any(numbers_in(ln) for ln in item.lines[2:])


# --------------------------------------------------------------------------- comparing


def _ulp(token: str) -> float:
    """One unit in the last place shown of a number token (0 for an integer: compared exactly)."""
    mant, _, exp = token.lower().partition("e")
    if "." not in mant:
        return 0.0 if not exp else 10.0 ** int(exp)
    return 10.0 ** (int(exp or 0) - len(mant.split(".")[1]))


def numbers_agree(shown: str, printed: str) -> bool:
    """Two numbers printed by two runs, possibly on two machines, at their shown precisions.

    Integers (counts) must be equal. Otherwise each string is the rounding of a
    value, and the two values may differ by round-off (:data:`ROUNDOFF`); a
    value on a rounding boundary can then print one unit apart in the last
    place, so that much is allowed and no more.
    """
    a, b = float(shown), float(printed)
    ua, ub = _ulp(shown), _ulp(printed)
    if ua == 0.0 and ub == 0.0:
        return a == b
    return abs(a - b) <= max(ua, ub) * (1 + 1e-9) + ROUNDOFF * max(abs(a), abs(b))


def value_agrees(shown: str, value: float) -> bool:
    """A number shown in a table against the full-precision value it is the rounding of.

    The value computed here may differ from the one the page was written
    from by what another IEEE machine changes (FMA, SIMD width, BLAS; for
    event times, where Brent's method stops inside its tolerance of
    1e-13 s). A value that sat on a rounding boundary then rounds one unit
    away, so one unit in the last place is allowed, and no more: any drift
    of a unit or more in the last digit shown fails.
    """
    if math.isnan(value):
        return shown.lower() == "nan"
    a, u = float(shown), _ulp(shown)
    if u == 0.0 and float(value).is_integer():
        return a == value
    u = u or 1.0  # a value rounded to a whole number
    return abs(a - value) <= u * (1 + 1e-9) + ROUNDOFF * abs(value)


def _pattern(shown: str) -> tuple[str, list[str]]:
    """A regular expression matching printed text like ``shown``, and the numbers it captures."""
    parts, nums = [], []
    for m in _TOKEN.finditer(shown):
        if m.group("ellipsis"):
            parts.append(r".*?")
        elif m.group("number"):
            parts.append(f"({NUMBER})")
            nums.append(m.group("number"))
        elif m.group("space"):
            parts.append(r"\s+")
        else:
            parts.append(re.escape(m.group("other")))
    return "".join(parts), nums


def compare_text(shown: str, printed: str) -> list[str]:
    """Differences between output shown on a page and output printed now (empty: they agree)."""
    shown, printed = shown.strip().replace("±", "+-"), printed.strip().replace("±", "+-")
    pat, nums = _pattern(shown)
    m = re.fullmatch(pat, printed, re.S)
    if m is None:
        return [f"the text differs:\n--- shown\n{shown}\n--- printed\n{printed}"]
    return [f"{s} shown, {p} printed" for s, p in zip(nums, m.groups()) if not numbers_agree(s, p)]


def numbers_in(text: str) -> list[str]:
    """The numbers of a text that are not part of a word or name (``f1``, ``h5py`` are not numbers)."""
    return re.findall(rf"(?<![\w.]){NUMBER}(?![\w])", text)


def table_rows(item: Item) -> tuple[list[str], list[list[str]]]:
    """Header cells and body rows of a Markdown table; a repeated header gets its rank, ``diff (2)``."""

    def cells(line: str) -> list[str]:
        return [c.strip() for c in line.strip().strip("|").split("|")]

    header = cells(item.lines[0])
    unique = [h if header[:i].count(h) == 0 else f"{h} ({header[:i].count(h) + 1})" for i, h in enumerate(header)]
    return unique, [cells(ln) for ln in item.lines[2:]]


def compare_table(item: Item, expected: dict[str, dict[str, object]], external: dict[str, str],
                  keys: int = 1) -> list[str]:
    """Every row of a page's table against the rows a producer computed.

    A row's label is its first ``keys`` cells joined by `` | `` (an empty
    cell repeats the one above it). ``expected`` maps a label to {column
    header: value}; a float is the full-precision value the cell rounds, an
    int an exact count, None an empty cell ("-" or ""), a string the text the
    cell must show (numbers at their precision). ``external`` maps the start
    of the labels of rows computed elsewhere (e.g. by the finite-element
    reference of the tests) to where they are checked.
    """
    header, rows = table_rows(item)
    problems = []
    seen = set()
    above = [""] * keys
    for row in rows:
        above = [c or a for c, a in zip(row[:keys], above)]
        label = " | ".join(above)
        if any(label.startswith(prefix) for prefix in external):
            continue
        if label not in expected:
            problems.append(f"{item.where}: row {label!r} is computed by no producer")
            continue
        seen.add(label)
        for col, cell in zip(header[keys:], row[keys:]):
            if col not in expected[label]:
                continue
            want = expected[label][col]
            where = f"{item.where}: row {label!r}, column {col!r}"
            if want is None:
                if cell not in ("-", "", "n/a"):
                    problems.append(f"{where}: {cell!r} shown where nothing is defined")
            elif isinstance(want, str):
                problems += [f"{where}: {p}" for p in compare_text(cell, want)]
            elif not re.fullmatch(NUMBER, cell):
                problems.append(f"{where}: {cell!r} is not a number (expected {want!r})")
            elif isinstance(want, int) and not isinstance(want, bool):
                if float(cell) != want:
                    problems.append(f"{where}: {cell} shown, {want} computed")
            elif not value_agrees(cell, float(want)):  # type: ignore[arg-type]
                problems.append(f"{where}: {cell} shown, {float(want)!r} computed")  # type: ignore[arg-type]
    problems += [f"{item.where}: row {label!r} computed but not shown" for label in expected if label not in seen]
    return problems
