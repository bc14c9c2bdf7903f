"""The documentation: tutorial notebooks run, the generated references are complete, the site builds.

The notebooks are executed with nbclient in a fresh kernel that imports this
tree's package; their cells assert what they claim (e.g. the fitted contact
stiffness within 5 % of the synthetic records' hidden truth). Together they
must stay under 75 s: 60 s for the first four, and 15 s more for the fifth
(random vibration), whose fresh kernel alone (imports, the compiled kernels
loaded from numba's cache) costs about 10 s of its 20 s on this 2-core machine. The full Sphinx build (``make docs``; warnings are
errors) is the ``docs`` marked test.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
NOTEBOOKS = sorted((DOCS / "tutorials").glob("*.ipynb"))
_TIMES: dict[str, float] = {}


def _kernel_env() -> None:
    os.environ["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), *filter(None, [os.environ.get("PYTHONPATH")])])
    os.environ.setdefault("MPLBACKEND", "Agg")


def test_there_are_five_tutorials() -> None:
    names = {p.stem for p in NOTEBOOKS}
    assert names == {"first-simulation", "parameter-study", "identification", "paper-reproduction", "random-vibration"}


def test_notebooks_are_generated_from_the_script_and_stored_without_outputs() -> None:
    nbformat = pytest.importorskip("nbformat")
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        import make_tutorials
    finally:
        sys.path.pop(0)
    for p in NOTEBOOKS:
        nb = nbformat.read(p, as_version=4)
        cells = make_tutorials.NOTEBOOKS[p.stem]
        assert [c.source for c in nb.cells] == [src for _, src in cells], f"{p.name}: rerun scripts/make_tutorials.py"
        assert all(not c.get("outputs") for c in nb.cells if c.cell_type == "code")


@pytest.mark.timeout(600)
@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_tutorial_notebook_runs(path: Path) -> None:
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient", reason="nbclient and ipykernel run the tutorials (test extra)")
    pytest.importorskip("ipykernel")
    _kernel_env()
    nb = nbformat.read(path, as_version=4)
    t0 = time.perf_counter()
    nbclient.NotebookClient(nb, timeout=300, kernel_name="python3",
                            resources={"metadata": {"path": str(path.parent)}}).execute()
    _TIMES[path.stem] = time.perf_counter() - t0
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])]
    assert not [o for o in outputs if o.output_type == "error"]
    # rich displays, not text dumps: the scenario and mode tables are HTML, figures PNG
    if path.stem == "first-simulation":
        assert any("text/html" in o.get("data", {}) for o in outputs)
    if path.stem != "identification":
        assert any("image/png" in o.get("data", {}) for o in outputs)


def test_tutorials_are_fast_enough() -> None:
    if len(_TIMES) < len(NOTEBOOKS):
        pytest.skip("the notebooks did not all run in this session")
    total = sum(_TIMES.values())
    print(f"\ntutorials: {', '.join(f'{k} {v:.1f} s' for k, v in _TIMES.items())}; total {total:.1f} s")
    assert total < 75.0


def test_scenario_reference_covers_the_schema() -> None:
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        import scenario_reference as ref
    finally:
        sys.path.pop(0)
    assert ref.check() == []
    text = ref.render()
    from impactbeam.scenario import scenario_paths

    for path in scenario_paths():
        if f"## `[{path}]`" in text or f"## `[[{path}]]`" in text or f"`{path}[]." in text:  # tables are headings
            continue
        assert f"`{path}`" in text, path
    assert "`contactors[].gap`" in text and "`clamped`" in text
    # the copy kept with the example files (readable without building the docs) is the same page, up to date
    assert ref.EXAMPLES_COPY.read_text() == ref.render(plain=True), (
        "examples/scenario-reference.md is out of date: run python docs/_ext/scenario_reference.py")


@pytest.mark.docs
@pytest.mark.timeout(600)
def test_docs_build_without_warnings(tmp_path: Path) -> None:
    pytest.importorskip("sphinx", reason="the docs extra (sphinx) is not installed")
    for mod in ("numpydoc", "myst_nb", "sphinx_click"):
        pytest.importorskip(mod, reason=f"the docs extra ({mod}) is not installed")
    _kernel_env()
    t0 = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", "-d", str(tmp_path / "doctrees"),
         str(DOCS), str(tmp_path / "html")],
        capture_output=True, text=True, timeout=600,
    )
    elapsed = time.perf_counter() - t0
    assert proc.returncode == 0, proc.stderr[-4000:]
    print(f"\ndocs build: {elapsed:.1f} s")
    html = tmp_path / "html"
    for page in ("index", "cli", "api", "model", "_generated/scenario-reference", "tutorials/identification"):
        assert (html / f"{page}.html").is_file(), page
    cli = (html / "cli.html").read_text()
    for command in ("explore", "simulate", "modes", "sweep", "fit"):
        assert f'id="impactbeam-{command}"' in cli, command
    assert "image/png" not in (html / "tutorials/first-simulation.html").read_text()  # images are files
    assert list((html / "_images").glob("*.png"))
    # equations render offline: MathJax is served from the site, no page loads a script or style from the network
    assert (html / "_static" / "mathjax" / "tex-chtml.js").is_file()
    assert "_static/mathjax/tex-chtml.js" in (html / "model.html").read_text()
    remote = []
    for page in html.rglob("*.html"):
        text = page.read_text(encoding="utf-8")
        remote += [f"{page.name}: {u}" for u in re.findall(r'<(?:script|link|img)\b[^>]*?(?:src|href)="((?:https?:)?//[^"]+)"', text)]
    assert not remote, remote
    # addresses in command help are literals, not links (tcp://... is not a page)
    assert 'href="tcp://' not in cli and "<span class=\"pre\">tcp://127.0.0.1:8786</span>" in cli
    assert (html / "_images" / "metrics-case03.png").is_file()  # the metrics page's figure, drawn at build time


def test_metrics_figure_is_drawn_from_the_code(tmp_path: Path) -> None:
    # docs/_ext/metrics_figure.py draws the figure of the metrics page at every build (here without Sphinx)
    pytest.importorskip("matplotlib")
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        import metrics_figure
    finally:
        sys.path.pop(0)
    handles = metrics_figure.draw(tmp_path / "m.png")
    assert (tmp_path / "m.png").stat().st_size > 10_000
    assert "Case 3" in handles.axes[0].get_title()


def test_every_docs_page_is_in_a_table_of_contents() -> None:
    index = (DOCS / "index.md").read_text()
    pages = {p.stem for p in DOCS.glob("*.md")} - {"index"}
    assert not [p for p in pages if f"\n{p}\n" not in index], "add the page to a toctree of docs/index.md"


def test_environment_defaults(monkeypatch: pytest.MonkeyPatch) -> None:
    """The defaults in docs/cli.md's "Environment" table are the code's."""
    from impactbeam import _memory
    from impactbeam.modal import disk_cache

    text = (DOCS / "cli.md").read_text()
    rows = {m.group(1): m.group(2) for m in re.finditer(r"^\| `(\w+)` \|[^|]*\| (.*) \|$", text, re.M)}
    for var in ("IMPACTBEAM_MEMORY_LIMIT", "IMPACTBEAM_WORK_LIMIT", "IMPACTBEAM_CACHE_DIR", "XDG_CACHE_HOME"):
        monkeypatch.delenv(var, raising=False)
    assert rows["IMPACTBEAM_WORK_LIMIT"] == f"{_memory.work_limit():.0e}".replace("e+0", "e")
    gib = _memory._size("IMPACTBEAM_MEMORY_LIMIT", 4 << 30) / 2**30
    assert rows["IMPACTBEAM_MEMORY_LIMIT"].startswith(f"{gib:g} GiB")
    home = Path(os.path.expanduser("~"))
    assert disk_cache.cache_dir() == home / ".cache" / "impactbeam" / "modes"
    assert "`~/.cache/impactbeam`" in rows["IMPACTBEAM_CACHE_DIR"]
    monkeypatch.setenv("IMPACTBEAM_CACHE_DIR", "off")
    assert disk_cache.cache_dir() is None
