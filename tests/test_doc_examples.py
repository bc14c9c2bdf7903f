"""Every worked example and computed table of README.md and docs/*.md against what the code prints now.

The pages mark what is checked with HTML comments (``tests/doc_examples.py``
describes them): ``example`` blocks are run (console commands in a shell,
``>>>`` Python by doctest) and their output compared with the output shown;
``table NAME`` tables are recomputed by the producer ``NAME`` below;
``numbers NAME`` paragraphs may only quote numbers that producer prints;
``unchecked: REASON`` says why a block or table is not compared (timings, or
errors measured and asserted by a named test). A guard test requires one of
these marks on every block that shows output and every table with numbers,
so a new example cannot escape.

Tolerance. A number shown with d decimals is compared at that precision,
within one unit in the last place shown: the page was written from one
machine, the test may run on another IEEE machine whose round-off (FMA, SIMD
width, BLAS; event times located inside Brent's 1e-13 s) moves a value that
sat on a rounding boundary to the next digit. Counts are compared exactly.
A drift such as that of the README's worked example when the default basis
changed (contact duration 4.0159923 -> 4.0171297 ms, 3e-4 relative) is
thousands of units in the last place.
"""

from __future__ import annotations

import doctest
import functools
import os
import re
import shutil
import subprocess
import sys
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import doc_examples as dx

import impactbeam as ib

ROOT = dx.ROOT
EXAMPLES = ROOT / "examples"

#: Pages with nothing computed, left out of the guard: the contributors' map (a table of modules).
NOT_CHECKED_PAGES = {ROOT / "docs" / "architecture.md"}

#: Output lines never compared: the one-time notice of the first compilation (stderr).
ALWAYS_IGNORED = re.compile(r"^impactbeam: compiling the solver")


def _pages() -> list[Path]:
    return [p for p in dx.PAGES if p not in NOT_CHECKED_PAGES]


def _all_items() -> list[dx.Item]:
    return [it for p in _pages() for it in dx.items(p)]


# --------------------------------------------------------------------------- the comparison itself


def test_numbers_are_compared_at_the_precision_shown():
    # the README's drift of issue 19 fails, a rounding-boundary flip of the last digit passes
    assert dx.compare_text("0.0010172407 0.0040159923 12", "0.0010172409 0.0040171297 12")
    assert not dx.compare_text("0.0010172407 0.0040159923 12", "0.0010172408 0.0040159924 12")
    assert dx.compare_text("n_impacts 12", "n_impacts 13")  # counts exactly
    assert dx.compare_text("1.2462 mm", "1.2464 mm")
    assert not dx.compare_text('"period": 0.01818..., "x": 1', '"period": 0.018181818181818, "x": 1')
    assert dx.compare_text('"period": 0.01818...', '"period": 0.018199')
    assert dx.compare_text("first peak [mm] 0.9738", "first peak [mm]  0.9738 extra")  # text differs
    assert not dx.compare_text("a ... b 3", "a anything at all b 3")
    # tables: the value must round to the cell
    assert dx.value_agrees("4.017129724", 4.0171297244847234) and not dx.value_agrees("4.017129722", 4.0171297244)
    assert dx.value_agrees("12", 12) and not dx.value_agrees("12", 13)
    assert dx.numbers_in("f1 = 56.97 Hz, h5py, 0.4840 L, -0.2433 mm") == ["56.97", "0.4840", "-0.2433"]


def test_every_example_with_output_and_every_table_with_numbers_is_marked():
    # A new worked example or table must say how its numbers are checked (or why not).
    unmarked = []
    for it in _all_items():
        if it.page in dx.GENERATED:
            continue
        marks = {d.kind for d in it.directives}
        if it.kind == "fence" and dx.shows_output(it) and not marks & {"example", "unchecked"}:
            unmarked.append(f"{it.where}: a block showing output without <!-- example --> or <!-- unchecked: -->")
        if it.kind == "table" and dx.has_numbers(it) and not marks & {"table", "unchecked"}:
            unmarked.append(f"{it.where}: a table with numbers without <!-- table NAME --> or <!-- unchecked: -->")
        for d in it.directives:
            if d.kind == "unchecked" and len(d.text) < 15:
                unmarked.append(f"{it.where}: <!-- unchecked: --> needs its reason")
            if d.kind == "table" and (it.kind != "table" or d.args.get("name") not in TABLES):
                unmarked.append(f"{it.where}: <!-- table {d.text} --> names no table producer, or is not above a table")
            if d.kind == "numbers" and d.args.get("name") not in TEXTS:
                unmarked.append(f"{it.where}: <!-- numbers {d.text} --> names no text producer")
            if d.kind == "example" and it.kind != "fence":
                unmarked.append(f"{it.where}: <!-- example --> is not above a fenced block")
    assert not unmarked, "\n".join(unmarked)


# --------------------------------------------------------------------------- worked examples


def _example_pages() -> list[Path]:
    return [p for p in _pages() if any(it.directive("example") for it in dx.items(p))]


class _NumberChecker(doctest.OutputChecker):
    def check_output(self, want: str, got: str, optionflags: int) -> bool:
        return not dx.compare_text(want, got)


def _shell_env(tmp: Path) -> dict[str, str]:
    """``impactbeam`` on PATH as this interpreter running this tree's package."""
    bin_dir = tmp / "_bin"
    bin_dir.mkdir(exist_ok=True)
    exe = bin_dir / "impactbeam"
    exe.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m impactbeam "$@"\n')
    exe.chmod(0o755)
    env = dict(os.environ)
    env["PATH"] = os.pathsep.join([str(bin_dir), env.get("PATH", "")])
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), *filter(None, [env.get("PYTHONPATH")])])
    env["PYTHONUNBUFFERED"] = "1"  # stdout and stderr in the order a terminal shows them
    env["MPLBACKEND"] = "Agg"
    # Dask's notice that another cluster on this machine holds its dashboard port: a fact about the
    # machine, not about the example
    env["PYTHONWARNINGS"] = "ignore:Port:UserWarning"
    return env


def _kept(text: str, ignore: re.Pattern[str] | None) -> str:
    lines = re.split(r"\r\n|\r|\n", text)
    return "\n".join(ln for ln in lines if not ALWAYS_IGNORED.search(ln) and not (ignore and ignore.search(ln)))


def _run_console(it: dx.Item, cwd: Path, env: dict[str, str], ignore: re.Pattern[str] | None) -> list[str]:
    problems = []
    for cmd, shown in dx.console_steps(it):
        proc = subprocess.run(["bash", "-o", "pipefail", "-c", f"{cmd} 2>&1"], cwd=cwd, env=env,
                              capture_output=True, text=True, timeout=600)
        printed = _kept(proc.stdout, ignore)
        shown = _kept(shown, ignore)
        problems += [f"{it.where}: $ {cmd}: {p}" for p in dx.compare_text(shown, printed)]
    return problems


def _run_python(it: dx.Item, globs: dict[str, Any]) -> list[str]:
    text = "\n".join(it.lines)
    if ">>>" not in text:  # a script that shows no output: it must run
        import contextlib
        import io
        import traceback

        try:
            with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
                warnings.simplefilter("default")
                exec(compile(text, it.where, "exec"), globs)
        except Exception:  # noqa: BLE001 - reported as the example's failure
            return [f"{it.where}: the example fails:\n{traceback.format_exc(limit=3)}"]
        return []
    test = doctest.DocTestParser().get_doctest(text, globs, it.where, str(it.page), it.line)
    report: list[str] = []
    runner = doctest.DocTestRunner(checker=_NumberChecker(), optionflags=doctest.ELLIPSIS)
    with warnings.catch_warnings():
        warnings.simplefilter("default")  # warnings go to stderr, as for a reader running the example
        runner.run(test, out=report.append, clear_globs=False)
    globs.update(test.globs)  # the page's later blocks continue in this namespace
    return [f"{it.where}:\n{r}" for r in report]


@pytest.mark.timeout(900)
@pytest.mark.parametrize("page", _example_pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_worked_examples_print_what_the_page_shows(page: Path, tmp_path: Path, monkeypatch) -> None:
    shutil.copytree(EXAMPLES, tmp_path / "examples")
    env = _shell_env(tmp_path)
    globs: dict[str, Any] = {}
    problems: list[str] = []
    for it in dx.items(page):
        d = it.directive("example")
        if d is None:
            continue
        for mod in filter(None, d.args.get("requires", "").split(",")):
            pytest.importorskip(mod)
        cwd = tmp_path / d.args.get("cwd", ".")
        ignore = re.compile(d.args["ignore"]) if "ignore" in d.args else None
        if dx.console_steps(it):
            problems += _run_console(it, cwd, env, ignore)
        else:
            monkeypatch.chdir(cwd)
            problems += _run_python(it, globs)
    assert not problems, "\n\n".join(problems)


# --------------------------------------------------------------------------- computed tables

#: name -> producer returning (rows, external): rows map a row's label (its first ``keys`` cells,
#: joined by " | ") to {column header: value}; external maps a label prefix to where those rows are
#: computed and checked instead (the finite-element reference of the test suite is not shipped code).
TABLES: dict[str, Callable[[], tuple[dict[str, dict[str, Any]], dict[str, str]]]] = {}
#: name -> producer of a text whose numbers a paragraph may quote.
TEXTS: dict[str, Callable[[], str]] = {}

_SCALE = {"mm": 1e3, "ms": 1e3, "um": 1e6, "us": 1e6, "m": 1.0, "s": 1.0, "J": 1.0}
FE_EXTERNAL = {"FE": "tests/test_solver_fe.py (the FE reference; its digits are asserted there)"}


def _producer(registry: dict, name: str) -> Callable:
    def deco(fn: Callable) -> Callable:
        registry[name] = functools.cache(fn)
        return fn

    return deco


@functools.cache
def _metrics(case: str, **values: Any) -> dict[str, Any]:
    sc = ib.load_scenario(EXAMPLES / f"{case}.toml")
    method = values.pop("method", "exact")
    return ib.simulate(sc.with_values(values) if values else sc, method=method).metrics()


def metric_cells(metrics: dict[str, Any], columns: list[str]) -> dict[str, Any]:
    """The cells of metric columns (``max_response [mm]``, ``n_impacts``) from a metrics dictionary."""
    out = {}
    for col in columns:
        m = re.fullmatch(r"(\w+)(?: \[(\w+)\])?", col)
        if not m or m.group(1) not in metrics:
            continue
        v = metrics[m.group(1)]
        out[col] = v if v is None or m.group(2) is None else v * _SCALE[m.group(2)]
    return out


_FE_COLUMNS = ["max_response [mm]", "t_max [ms]", "first_impact_time [ms]", "contact_duration [ms]", "n_impacts"]


@_producer(TABLES, "fe-case03")
def _fe_case03():
    rows = {
        "modal exact, 8 modes": _metrics("case03", **{"solver.modes": 8}),
        "modal exact, 32 modes": _metrics("case03", **{"solver.modes": 32}),
        "modal `solve_ivp` (DOP853, rtol 1e-10), 8 modes": _metrics("case03", method="ivp"),
        "paper's basis, 8 modes": _metrics("case03", **{"solver.basis": "paper"}),
        "paper's basis, 32 modes": _metrics("case03", **{"solver.basis": "paper", "solver.modes": 32}),
    }
    return {k: metric_cells(v, _FE_COLUMNS) for k, v in rows.items()}, FE_EXTERNAL


@_producer(TABLES, "fe-case09")
def _fe_case09():
    rows = {f"modal exact, {n} modes": _metrics("case09", **{"solver.modes": n}) for n in (8, 32)}
    return {k: metric_cells(v, _FE_COLUMNS) for k, v in rows.items()}, FE_EXTERNAL


def _mode_table(case: str, basis: str | None) -> tuple[dict, dict]:
    extra = {"solver.basis": basis} if basis else {}
    return {str(n): metric_cells(_metrics(case, **{"solver.modes": n}, **extra), _FE_COLUMNS)
            for n in (2, 4, 8, 16)}, {}


@_producer(TABLES, "restitution")
def _restitution():
    from impactbeam.solver.damping import restitution_ratio

    es = (0.95, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1, 0.05)
    return {f"{e:g}": {"ξ": restitution_ratio(e)} for e in es}, {}


TABLES["modes-case12"] = functools.cache(lambda: _mode_table("case12", None))
TABLES["modes-case03"] = functools.cache(lambda: _mode_table("case03", None))
TABLES["modes-case12-paper"] = functools.cache(lambda: _mode_table("case12", "paper"))
TABLES["modes-case03-paper"] = functools.cache(lambda: _mode_table("case03", "paper"))


def _stiff(values: dict[str, Any], modes: int, basis: str) -> dict[str, Any]:
    m = _metrics("specimen", **values, **{"solver.modes": modes, "solver.basis": basis})
    return {"impacts": m["n_impacts"], "max penetration [um]": m["max_penetration"] * 1e6,
            "first contact [ms]": m["impacts"][0]["duration"] * 1e3,
            "first impact [ms]": m["first_impact_time"] * 1e3}


#: The tip stop of the stiff-contactor section: the specimen cantilever with a stop k = 1e5 N/m
#: at its free end, gap 1 mm, the Case 3 pulse, 0.1 s.
TIP_STOP = {"contactors.0.position_ratio": 1.0, "contactors.0.stiffness": 1e5, "contactors.0.gap": 1e-3,
            "solver.end_time": 0.1, "output.point_ratios": (1.0,)}


@_producer(TABLES, "ritz")
def _ritz():
    k5, k6, k4 = {"contactors.0.stiffness": 1e5}, {"contactors.0.stiffness": 1e6}, {}
    rows = {
        "k = 1e5 N/m | enriched, 8": _stiff(k5, 8, "enriched"),
        "k = 1e5 N/m | enriched, 32": _stiff(k5, 32, "enriched"),
        "k = 1e5 N/m | paper, 8": _stiff(k5, 8, "paper"),
        "k = 1e6 N/m | enriched, 16": _stiff(k6, 16, "enriched"),
        "k = 1e6 N/m | enriched, 32": _stiff(k6, 32, "enriched"),
        "k = 1e6 N/m | paper, 16": _stiff(k6, 16, "paper"),
        "k = 4030 N/m (Case 3) | enriched, 8": _stiff(k4, 8, "enriched"),
        "k = 4030 N/m (Case 3) | enriched, 32": _stiff(k4, 32, "enriched"),
        "k = 4030 N/m (Case 3) | paper, 8": _stiff(k4, 8, "paper"),
        "k = 4030 N/m (Case 3) | paper, 32": _stiff(k4, 32, "paper"),
        "tip stop | enriched, 8": _stiff(TIP_STOP, 8, "enriched"),
        "tip stop | enriched, 16": _stiff(TIP_STOP, 16, "enriched"),
        "tip stop | paper, 8": _stiff(TIP_STOP, 8, "paper"),
    }
    return rows, {"k = 1e5 N/m | FE": "tests/test_ritz.py", "k = 1e6 N/m | FE": "tests/test_ritz.py",
                  "k = 4030 N/m (Case 3) | FE": "tests/test_solver_fe.py", "tip stop | FE": "tests/test_ritz.py"}


@_producer(TEXTS, "convergence")
def _convergence_text() -> str:
    """Relative changes of Case 3's contact duration between mode counts, both bases (as % and as ratio)."""
    lines = ["modes 2 4 8 16 32"]
    for basis in ("enriched", "paper"):
        cd = {n: _metrics("case03", **{"solver.modes": n, "solver.basis": basis})["contact_duration"]
              for n in (2, 4, 8, 16, 32)}
        for a, b in ((2, 4), (4, 8), (8, 16), (16, 32), (8, 32)):
            rel = abs(cd[b] - cd[a]) / cd[32]
            lines.append(f"{basis} {a} -> {b}: {rel:.2g} = {rel * 100:.2g} %")
    return "\n".join(lines)


@_producer(TEXTS, "random-modes")
def _random_modes() -> str:
    """docs/random-vibration.md, "Modes": a density above the retained modes, its warning and the damage lost."""
    import warnings

    from impactbeam.statistics import fatigue_statistics

    L = 0.1092
    lines, damage = [], {}
    for n in (2, 4, 12):
        sc = ib.parse_scenario({
            "beam": {"length": L, "width": 0.00993, "height": 0.00303, "youngs_modulus": 1834e6, "density": 951.98},
            "damping": {"free": 0.011, "contact": 0.02},
            "excitation": {"kind": "point_force", "position": L, "shape": "random", "seed": 1,
                           "psd": [["10 Hz", "1e-4 N^2/Hz"], ["5000 Hz", "1e-4 N^2/Hz"]]},
            "fatigue": {"points": [0.0], "sn_stress": "10 MPa", "sn_cycles": 1e6, "sn_exponent": 10},
            "solver": {"modes": n, "end_time": 1.0}})
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ib.ImpactBeamWarning)
            res = ib.simulate(sc)
        damage[n] = fatigue_statistics(res)[0]["damage"]
        lines += [w for w in res.warnings if "excitation.psd" in w]
    lines.append(f"1 s record: damage low by {damage[12] / damage[4]:.2g} (4 modes), {damage[12] / damage[2]:.2g} "
                 "(2 modes)")
    return "\n".join(lines)


@_producer(TEXTS, "periodic-diagram")
def _periodic_diagram() -> str:
    """The worked example of docs/periodic.md: its transitions, and the evidence behind what the text says."""
    import warnings

    import numpy as np

    sc = ib.load_scenario(EXAMPLES / "periodic" / "specimen_harmonic.toml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ib.ImpactBeamWarning)
        d = ib.bifurcation(sc, "excitation.frequency", np.linspace(25.0, 90.0, 261), sweep="both")
        lines, prev = [], None
        for p in d.points:
            key = (p.direction, p.state.period, round(p.state.impacts_per_period, 2))
            if key != prev:
                lines.append(f"{p.value:.4g} Hz: {key}")
            prev = key
        at = {(p.direction, p.value): p for p in d.points}
        for p in d.points:  # where the sweeps disagree: coexisting orbits (hysteresis), or no period on one
            if p.direction == "up":
                q = at[("down", p.value)]
                up, down = ((s.period, round(s.impacts_per_period, 2)) for s in (p.state, q.state))
                if up != down:
                    lines.append(f"{p.value:.4g} Hz differs: up {up}, down {down}")
        for f in (55.5, 56.5):
            p = at[("up", f)]
            on = ib.steady_state(sc.with_values({"excitation.frequency": f}), settle_periods=3000,
                                 start_state=p.state.result.final_state())
            lines.append(f"{f} Hz up, then 3000 periods: period {on.period}")
        for f in (39.75, 55.5):
            mu = ib.periodic_orbit(sc.with_values({"excitation.frequency": f}), settle_periods=150).multipliers[0]
            lines.append(f"{f} Hz period-1 orbit: |mu| {abs(mu):.3f} at {np.angle(mu) / 2 / np.pi:.3f} of a turn")
    top = max((p for p in d.points if p.direction == "up"), key=lambda p: p.state.max)
    lines.append(f"settling limit {10 * d.settle_periods} periods; largest max at {top.value:.0f} Hz; free first "
                 f"mode {ib.modes(sc).free.frequencies_hz[0]:.0f} Hz")
    return "\n".join(lines)


@_producer(TABLES, "energy-jumps")
def _energy_jumps():
    # Case 3 undamped over 0.1 s with the paper's basis: the energy changes only at the switches.
    import numpy as np

    rows = {}
    base = ib.load_scenario(EXAMPLES / "case03.toml")
    for n in (4, 8, 16, 32):
        r = ib.simulate(base.with_values({"solver.basis": "paper", "solver.modes": n, "damping.free": 0.0,
                                          "damping.contact": 0.0, "solver.end_time": 0.1}))
        jumps = np.asarray(r.energy_jumps)
        mean_abs = float(np.abs(jumps).mean())
        impacts = sum(e.kind == "impact" for e in r.events)
        rows[str(n)] = {"events": len(r.events), "mean jump per switch [J]": mean_abs,
                        "net drift per impact [J]": float(jumps.sum()) / impacts,
                        "jump / energy": mean_abs / float(np.nanmax(r.energy["total"]))}
    return rows, {}


@_producer(TABLES, "sampled-hold")
def _sampled_hold():
    # Case 12's half-sine sampled every h and held (linear or constant) against the exact half-sine:
    # the largest |w| error at the output points over 40 ms.
    import numpy as np

    sc = ib.load_scenario(EXAMPLES / "case12.toml").with_values({"solver.basis": "paper", "solver.end_time": 0.04})
    ex = sc.excitation
    exact = ib.simulate(sc).w
    rows = {}
    for n in (15, 30, 60):
        tt = np.linspace(0.0, ex.duration, n + 1)
        trace = ex.amplitude * np.sin(np.pi * tt / ex.duration)
        row: dict[str, Any] = {"h [ms]": ex.duration / n * 1e3}
        for hold in ("linear", "constant"):
            table = ib.Excitation(ex.kind, "table", times=tt, values=trace, hold=hold)
            r = ib.simulate_system(sc.beam, sc.contactors, damping=sc.damping, excitation=table,
                                   initial=sc.initial, options=sc.solver, points=sc.output_points)
            row[f"{hold} hold [m]"] = float(np.abs(r.w - exact).max())
        rows[str(n)] = row
    return rows, {}


TEXTS["ritz"] = lambda: repr(TABLES["ritz"]()[0])


# ------------------------------------------------------------------ the paper's reproduction


@functools.cache
def _paper_section() -> str:
    """``docs/paper-reproduction.md`` as ``impactbeam reproduce --docs`` writes it now, without its figures."""
    import tempfile

    from impactbeam.paper.document import write_readme_section
    from impactbeam.paper.study import _assemble, _compute, _Runner

    data = _compute(_Runner(None))
    with tempfile.TemporaryDirectory() as tmp:
        report = _assemble(data, Path(tmp), {}, 0, 0.0)
        return write_readme_section(report, tmp, figures=()).read_text(encoding="utf-8")


def _generated_tables() -> list[dx.Item]:
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "generated.md"
        p.write_text(_paper_section(), encoding="utf-8")
        return [it for it in dx.items(p) if it.kind == "table"]


def _paper_table(index: int) -> tuple[dict, dict]:
    table = _generated_tables()[index]
    header, rows = dx.table_rows(table)
    return {" | ".join(r[:3]) if index else r[0]: dict(zip(header, r)) for r in rows}, {}


TABLES["paper-frequencies"] = functools.cache(lambda: _paper_table(0))
TABLES["paper-table2"] = functools.cache(lambda: _paper_table(1))
TEXTS["paper"] = _paper_section


@pytest.mark.slow
@pytest.mark.timeout(600)
def test_generated_paper_page_is_what_reproduce_writes_now():
    # docs/paper-reproduction.md is written by `impactbeam reproduce --docs docs`; regenerate it
    # after a change of the model. Compared without its figure lines (the figures are not rebuilt here).
    page = (ROOT / "docs" / "paper-reproduction.md").read_text(encoding="utf-8")
    drop = re.compile(r"^!\[.*\]\(figures/.*\)$", re.M)
    problems = dx.compare_text(drop.sub("", page), drop.sub("", _paper_section()))
    assert not problems, "\n".join(problems)


def _table_items(name: str) -> list[dx.Item]:
    return [it for it in _all_items() if (d := it.directive("table")) and d.args.get("name") == name]


def _label_keys(name: str) -> int:
    return {"ritz": 2, "paper-table2": 3}.get(name, 1)


#: Producers that take long (the `solve_ivp` run of Case 3: 10-20 s).
SLOW_TABLES = {"fe-case03"}


@pytest.mark.timeout(900)
@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in SLOW_TABLES else n
                                  for n in sorted(TABLES)])
def test_tables_show_what_the_code_computes(name: str) -> None:
    marked = _table_items(name)
    if not marked:
        pytest.skip(f"no page shows the table {name} now")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ib.ImpactBeamWarning)  # 2-mode rows warn that they are too few
        expected, external = TABLES[name]()
    problems = []
    for it in marked:
        problems += dx.compare_table(it, expected, external, keys=_label_keys(name))
    assert not problems, "\n".join(problems)


@pytest.mark.parametrize("name", sorted(TEXTS))
def test_paragraphs_quote_only_numbers_the_code_prints(name: str) -> None:
    marked = [it for it in _all_items() if (d := it.directive("numbers")) and d.args.get("name") == name]
    if not marked:
        pytest.skip(f"no page quotes {name}")
    printed = dx.numbers_in(TEXTS[name]())
    problems = []
    for it in marked:
        for num in dx.numbers_in(" ".join(it.lines)):
            if not any(dx.numbers_agree(num.lstrip("+-"), p.lstrip("+-")) for p in printed):
                problems.append(f"{it.where}: {num} is not among the numbers printed by {name}")
    assert not problems, "\n".join(problems)
