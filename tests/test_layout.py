"""The package's layout: no import cycle, modules and functions of a readable size.

The imports are read from the source (``ast``), every one of them: at module
level, inside functions and under ``TYPE_CHECKING``. A cycle means two modules
depend on each other, i.e. one responsibility split in two places or a layer
reaching up (docs/architecture.md). The size limits are the project's
(600 lines a module, 150 a function).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "src" / "impactbeam"
MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 150


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


MODULES = {_module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def _resolve(module: str, is_package: bool, level: int, target: str | None) -> str:
    base = module.split(".")
    if not is_package:
        base = base[:-1]
    if level > 1:
        base = base[: len(base) - (level - 1)]
    return ".".join(base + ([target] if target else []))


def _imports(name: str, path: Path) -> set[str]:
    """Modules of the package that ``name`` imports anywhere in its source."""
    is_package = path.name == "__init__.py"
    out: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = _resolve(name, is_package, node.level, node.module) if node.level else (node.module or "")
            targets = [base] + [f"{base}.{a.name}" for a in node.names]
        else:
            continue
        for t in targets:
            # the deepest module of the package that the import names
            while t and t not in MODULES:
                t = t.rpartition(".")[0]
            if t and t != name and not name.startswith(t + "."):  # a package's own __init__ is not a dependency
                out.add(t)
    return out


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_the_reader_sees_a_cycle() -> None:
    # Reason: the check must be able to fail; a two-module loop is found.
    assert _cycles({"a": {"b"}, "b": {"a"}, "c": {"a"}}) == [["a", "b"]]
    assert _cycles({"a": {"b"}, "b": set()}) == []


def test_no_import_cycle() -> None:
    graph = {name: _imports(name, path) for name, path in MODULES.items()}
    assert graph["impactbeam.result"], "the import reader found nothing: it is broken"
    assert not _cycles(graph), f"import cycles: {_cycles(graph)}"


@pytest.mark.parametrize("name", sorted(MODULES))
def test_sizes(name: str) -> None:
    path = MODULES[name]
    text = path.read_text(encoding="utf-8")
    assert text.count("\n") <= MAX_MODULE_LINES, f"{name}: {text.count(chr(10))} lines"
    long = [
        f"{node.name} ({node.end_lineno - node.lineno + 1} lines)"
        for node in ast.walk(ast.parse(text))
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
        and node.end_lineno - node.lineno + 1 > MAX_FUNCTION_LINES
    ]
    assert not long, f"{name}: functions over {MAX_FUNCTION_LINES} lines: {', '.join(long)}"


# --------------------------------------------------------------------------- layers (docs/architecture.md)

FOUNDATION = {"exceptions", "units", "_io", "_optional", "_validation", "_warnings", "_memory", "_html"}
#: what each package or top-level module may import besides the foundation (docs/architecture.md, "Layers")
MAY_IMPORT: dict[str, set[str]] = {
    "model": set(),
    "scenario": {"model"},
    "modal": {"model", "scenario"},
    "solver": {"model", "modal"},
    "result": {"model", "modal", "solver", "plot"},  # plot: SimulationResult.plot() forwards to the figure
    "plot": {"model", "modal", "result", "statistics"},
    "simulation": {"model", "scenario", "solver", "result"},
    "statistics": {"model", "modal", "solver", "result"},
    "sweeps": {"model", "scenario", "modal", "solver", "result", "plot", "simulation", "statistics"},
    "periodic": {"model", "scenario", "modal", "solver", "result", "plot", "simulation", "sweeps", "statistics"},
    "random": {"model", "scenario", "modal", "solver", "result", "plot", "simulation", "sweeps", "statistics"},
    "experiment": {"model", "scenario", "modal", "solver", "result", "plot", "simulation"},
    "fit": {"model", "scenario", "modal", "solver", "result", "plot", "simulation", "experiment"},
    "explore": {"model", "scenario", "modal", "solver", "result", "plot", "simulation"},
    "paper": {"model", "scenario", "modal", "solver", "result", "plot", "simulation", "experiment"},
    "validation": {"model", "scenario", "modal", "solver", "result", "plot", "simulation", "paper"},
}


def _part(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def test_the_top_level_holds_packages_and_at_most_ten_modules() -> None:
    loose = sorted(p.name for p in PACKAGE.glob("*.py") if p.name not in ("__init__.py", "__main__.py"))
    assert len(loose) <= 10, f"{len(loose)} modules directly under impactbeam/: {loose}"


def test_every_package_imports_only_the_layers_below_it() -> None:
    # Reason: the layer table of docs/architecture.md, checked on every import
    # (module level, functions, TYPE_CHECKING). A new package must be added here
    # with what it may use.
    bad = []
    for name, path in MODULES.items():
        part = _part(name)
        if part in FOUNDATION or part in ("", "cli", "__main__"):
            if part in FOUNDATION:
                bad += [f"{name} -> {t}" for t in _imports(name, path) if _part(t) not in FOUNDATION]
            continue
        assert part in MAY_IMPORT, f"{part}: a package missing from the layer table"
        allowed = MAY_IMPORT[part] | FOUNDATION | {part}
        bad += [f"{name} -> {t}" for t in _imports(name, path) if _part(t) not in allowed]
    assert not bad, "imports against the layers:\n" + "\n".join(bad)


def test_the_layer_check_sees_a_wrong_import() -> None:
    # Reason: the check must be able to fail: a model module that imports the solver is caught.
    assert _part("impactbeam.solver.engine") not in MAY_IMPORT["model"]


def test_simulate_does_not_import_matplotlib() -> None:
    import subprocess
    import sys

    code = (
        "import sys, impactbeam as ib\n"
        "sc = ib.parse_scenario({'beam': {'length': 0.1, 'width': 0.01, 'height': 0.003, 'youngs_modulus': 2e9,"
        " 'density': 950}, 'solver': {'modes': 2, 'end_time': 0.001}})\n"
        "ib.simulate(sc).metrics()\n"
        "print('matplotlib' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False", out.stdout + out.stderr
