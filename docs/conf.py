"""Sphinx configuration of the impactbeam documentation (``make docs``).

Sphinx rather than MkDocs: the docstrings are numpydoc (rendered by the
numpydoc extension), the command-line reference is generated from the click
objects by sphinx-click, and myst-nb executes the tutorial notebooks during
the build, so every output shown is the output of the current code. The
scenario reference is generated from the schema in ``impactbeam.scenario``
by ``_ext/scenario_reference.py``. Warnings fail the build (``-W``).
"""

from __future__ import annotations

import os
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
    "sphinx.ext.intersphinx",
    "numpydoc",
    "myst_nb",
    "sphinx_click",
    "scenario_reference",
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


def _plain_help(app, ctx, lines):  # noqa: ANN001 - sphinx-click event signature
    """Click help is plain text: escape the characters reStructuredText would interpret."""
    for i, line in enumerate(lines):
        lines[i] = line.replace("\\", "\\\\").replace("|", "\\|").replace("*", "\\*").replace("`", "\\`")


def setup(app):  # noqa: ANN001, ANN201
    app.connect("sphinx-click-process-description", _plain_help)
    app.connect("sphinx-click-process-epilog", _plain_help)
    app.connect("sphinx-click-process-options", _plain_help)
    app.connect("sphinx-click-process-arguments", _plain_help)
