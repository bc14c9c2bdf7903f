"""Packaging: a small core, optional extras with a clear message, metadata files.

The optional packages are hidden from a child interpreter by setting
``sys.modules[name] = None`` (then ``import name`` raises ImportError, as if
it were not installed); the feature must stop with one ``error:`` line that
names the extra to install, before doing any work.
"""

from __future__ import annotations

import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
OPTIONAL = ("dask", "distributed", "zarr", "lmfit", "h5netcdf", "h5py", "pyarrow", "matplotlib", "panel", "bokeh")


def _run_cli(args: list[str], blocked: tuple[str, ...], tmp_path: Path) -> subprocess.CompletedProcess[str]:
    code = (
        "import sys\n"
        f"for _n in {blocked!r}: sys.modules[_n] = None\n"
        "from impactbeam.cli import main\n"
        f"main({args!r}, prog_name='impactbeam')\n"
    )
    return subprocess.run(
        [sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=300,
        env={**__import__("os").environ, "PYTHONPATH": str(ROOT / "src")},
    )


@pytest.mark.parametrize(
    ("args", "blocked", "extra"),
    [
        (["sweep", str(EXAMPLES / "sweep_gap_duration.toml"), "--out", "s.zarr"], ("zarr",), "sweep"),
        (["simulate", str(EXAMPLES / "case03.toml"), "--out", "r.nc"], ("h5netcdf",), "io"),
        (["simulate", str(EXAMPLES / "case03.toml"), "--out", "r.parquet"], ("pyarrow",), "io"),
        (["simulate", str(EXAMPLES / "case03.toml"), "--plot", "r.png"], ("matplotlib",), "plot"),
        (["explore", str(EXAMPLES / "case03.toml"), "--port", "0"], ("panel",), "explore"),
    ],
)
def test_missing_extra_is_named(args: list[str], blocked: tuple[str, ...], extra: str, tmp_path: Path) -> None:
    proc = _run_cli(args, blocked, tmp_path)
    assert proc.returncode == 1, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), proc.stderr
    assert f'pip install "impactbeam[{extra}]"' in lines[0]
    assert repr(blocked[0]) in lines[0]
    assert "Traceback" not in proc.stderr
    assert not any(tmp_path.iterdir()), "nothing is written when the extra is missing"


def test_require_in_process_names_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    from impactbeam._optional import MissingDependencyError, require
    from impactbeam.exceptions import ImpactBeamError

    monkeypatch.setitem(sys.modules, "lmfit", None)
    with pytest.raises(MissingDependencyError, match=r'impactbeam\[fit\]') as info:
        require("lmfit")  # the extra is looked up from the package name
    assert isinstance(info.value, ImportError) and isinstance(info.value, ImpactBeamError)
    assert require("math").sqrt(4.0) == 2.0


def test_core_commands_run_without_any_extra(tmp_path: Path) -> None:
    """`modes` and `simulate` need only the core dependencies."""
    proc = _run_cli(["modes", str(EXAMPLES / "specimen.toml")], OPTIONAL, tmp_path)
    assert proc.returncode == 0, proc.stderr
    proc = _run_cli(["simulate", str(EXAMPLES / "case03.toml"), "--json"], OPTIONAL, tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert '"first_impact_time"' in proc.stdout


def test_core_dependencies_are_small() -> None:
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    core = {d.split(">")[0].split("[")[0].split("=")[0].strip().lower() for d in meta["dependencies"]}
    assert not core & set(OPTIONAL), core & set(OPTIONAL)
    extras = meta["optional-dependencies"]
    for name in ("sweep", "fit", "io", "plot", "explore", "docs", "all", "test"):
        assert name in extras
    from impactbeam._optional import EXTRAS

    for module, extra in EXTRAS.items():  # the message points at an extra that installs it
        assert any(module in dep.replace("dask[distributed]", "dask distributed") for dep in extras[extra]), (module, extra)


def test_python_dash_m_and_metadata_files() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "impactbeam", "--help"], capture_output=True, text=True, timeout=120,
        env={**__import__("os").environ, "PYTHONPATH": str(ROOT / "src")},
    )
    assert proc.returncode == 0 and "simulate" in proc.stdout, proc.stderr
    for name in ("LICENSE", "CITATION.cff", "CHANGELOG.md", "src/impactbeam/py.typed"):
        assert (ROOT / name).is_file(), name
    assert "BSD 3-Clause" in (ROOT / "LICENSE").read_text()
    cff = (ROOT / "CITATION.cff").read_text()
    assert "10.3233/SAV-130793" in cff and "Shock and Vibration" in cff


def test_no_design_md_in_help_and_readme_links_absolute() -> None:
    import re

    from click.testing import CliRunner

    from impactbeam.cli import main

    runner = CliRunner()
    for name in [None, *main.commands]:
        out = runner.invoke(main, ([name] if name else []) + ["--help"]).output
        assert "DESIGN" not in out, name
    readme = (ROOT / "README.md").read_text()
    assert readme.splitlines()[3].startswith("make demo") and readme.splitlines()[4].startswith("make test")
    for target in re.findall(r"\]\(([^)]+)\)", readme):  # PyPI renders only absolute links
        assert target.startswith(("https://", "http://", "#")), target


def test_library_never_sets_matplotlib_backend() -> None:
    hits = [p for p in (ROOT / "src").rglob("*.py") if "matplotlib.use(" in p.read_text()]
    assert not hits, hits
