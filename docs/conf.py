"""Sphinx configuration of the impactbeam documentation (``make docs``).

Sphinx rather than MkDocs: the docstrings are numpydoc (rendered by the
numpydoc extension), the command-line reference is generated from the click
objects by sphinx-click, MathJax is served from the site itself
(sphinx-mathjax-offline: no network is needed to read the equations), and
myst-nb executes the tutorial notebooks during the build, so every output
shown is the output of the current code. The scenario reference is
generated from the schema in ``impactbeam.scenario`` by
``_ext/scenario_reference.py``, the metrics figure from the solver by
``_ext/metrics_figure.py``. Warnings fail the build (``-W``).
"""

from __future__ import annotations

import os
import re
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE / "_ext"))
sys.path.insert(0, str(HERE.parent / "src"))
os.environ.setdefault("MPLBACKEND", "Agg")
# the notebook kernels import this tree's package, whatever is installed
os.environ["PYTHONPATH"] = os.pathsep.join([str(HERE.parent / "src"), *filter(None, [os.environ.get("PYTHONPATH")])])

import impactbeam  # noqa: E402

project = "impactbeam"
author = "impactbeam developers"
copyright = "2026, impactbeam developers"
release = impactbeam.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",  # MathJax copied into _static/mathjax: no CDN, equations render offline
    "sphinx.ext.intersphinx",
    "numpydoc",
    "myst_nb",
    "sphinx_click",
    "scenario_reference",
    "metrics_figure",
]

source_suffix = {".md": "myst-nb", ".ipynb": "myst-nb", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "**.ipynb_checkpoints", "figures/README*", "Thumbs.db", ".DS_Store"]
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence"]
myst_heading_anchors = 3
# pages pulled in from the README start at level-3 headings
suppress_warnings = ["myst.header"]

# notebooks are stored without outputs and executed at build time
nb_execution_mode = "force"
nb_execution_timeout = 300
nb_execution_raise_on_error = True
nb_execution_show_tb = True

autodoc_typehints = "none"
autodoc_member_order = "bysource"
autosummary_generate = False
numpydoc_show_class_members = False
numpydoc_validation_checks: set[str] = set()
numpydoc_xref_param_type = False

intersphinx_mapping: dict[str, tuple[str, None]] = {}  # offline builds: no inventories

html_theme = "alabaster"
html_title = f"impactbeam {release}"
html_static_path: list[str] = []
html_theme_options = {"description": "Transient response of impacting beams", "fixed_sidebar": True}


_ADDRESS = re.compile(r"\b([a-z][a-z0-9+.-]*://[^\s),]+)")
_OPTION = re.compile(r"(?<![\w`-])(--[a-z][\w-]*)")


def _plain_help(app, ctx, lines):  # noqa: ANN001 - sphinx-click event signature
    """Click help is plain text: escape the characters reStructuredText would interpret.

    Addresses such as ``tcp://127.0.0.1:8786`` are examples to type, not
    pages to visit: they are set as literals, which docutils does not link;
    so are options (``--json``), which smart quotes would turn into a dash.
    """
    for i, line in enumerate(lines):
        if line.lstrip().startswith(".. "):  # sphinx-click's own directives (``.. option:: --modes <N|auto>``)
            continue
        block = re.match(r"\s*\| ", line)  # a line block: sphinx-click's rendering of click's \b paragraphs
        head, body = (line[: block.end()], line[block.end():]) if block else ("", line)
        body = body.replace("\\", "\\\\").replace("|", "\\|").replace("*", "\\*").replace("`", "\\`")
        body = _OPTION.sub(r"``\1``", _ADDRESS.sub(r"``\1``", body))
        lines[i] = head + body


def setup(app):  # noqa: ANN001, ANN201
    app.connect("sphinx-click-process-description", _plain_help)
    app.connect("sphinx-click-process-epilog", _plain_help)
    app.connect("sphinx-click-process-options", _plain_help)
    app.connect("sphinx-click-process-arguments", _plain_help)
