"""The specimen and the Table 1 cases as scenarios: read from ``examples/`` when the source tree is present,
else built from the paper's parameters (the two agree; the tests check it).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any
import numpy as np

from ..exceptions import ParameterError
if TYPE_CHECKING:
    from ..scenario import Scenario
from .data import EXAMPLES_DIR, G, SPECIMEN, TABLE1, TableOneCase

__all__ = ["case", "case_data", "cases", "specimen", "specimen_data"]


def specimen_data(
    *,
    gap: float | str | None = 0.229e-3,
    amplitude: float | str | None = 15 * G,
    duration: float | str | None = 15e-3,
    initial_tip_displacement: float | None = None,
    modes: int = 8,
    time_step: float = 1e-5,
    end_time: float = 0.2,
    output_ratios: Sequence[float] | None = (0.4840, 1.0),
    name: str = "specimen",
) -> dict[str, Any]:
    """The raw scenario mapping of the specimen (section 3) with one load case.

    Parameters
    ----------
    gap : float or None, [m]
        Contactor clearance; None for no contactor.
    amplitude, duration : float or None, [m/s^2], [s]
        Half-sine base pulse; ``amplitude=None`` for no excitation.
    initial_tip_displacement : float or None, [m]
        Release from the static tip-load shape (Cases 0 and 13).
    modes, time_step, end_time
        Solver settings (the example files: 8, 1e-5 s, 0.2 s; 0.5 s for the release).
    output_ratios : sequence of float or None
        Output points as fractions of L (None: the default points).
    name : str
    """
    p = SPECIMEN
    data: dict[str, Any] = {
        "name": name,
        "beam": {k: p[k] for k in ("length", "width", "height", "youngs_modulus", "density")},
        "supports": {"left": "clamped", "right": "free"},
        "damping": {"free": p["damping_free"], "contact": p["damping_contact"]},
        "solver": {"modes": modes, "time_step": time_step, "end_time": end_time},
    }
    if gap is not None:
        data["contactors"] = [
            {"position_ratio": p["contact_position_ratio"], "stiffness": p["contact_stiffness"], "gap": gap, "side": "above"}
        ]
    if amplitude is not None:
        data["excitation"] = {"kind": "base_acceleration", "shape": "half_sine", "amplitude": amplitude,
                              "duration": duration, "start": 0.0}
    else:
        data["excitation"] = {"kind": "none"}
    if initial_tip_displacement is not None:
        data["initial"] = {"tip_displacement": initial_tip_displacement}
    if output_ratios is not None:
        data["output"] = {"point_ratios": list(output_ratios)}
    return data


def _examples_dir(examples_dir: str | os.PathLike[str] | None) -> Path:
    return Path(examples_dir) if examples_dir is not None else EXAMPLES_DIR


def _choose_source(source: str, path: Path) -> bool:
    """True to read ``path``; validates ``source``."""
    if source not in ("auto", "file", "parameters"):
        raise ParameterError(f'source: must be "auto", "file" or "parameters", got {source!r}')
    if source == "file" and not path.is_file():
        raise ParameterError(f'source: "{path}" does not exist')
    return source == "file" or (source == "auto" and path.is_file())


def specimen(*, source: str = "auto", examples_dir: str | os.PathLike[str] | None = None) -> Scenario:
    """The paper's specimen under the reference pulse (Case 3), as a Scenario.

    Run by the paper's own method (``solver.basis = "paper"``: exact state
    modes and the projection of eq. 12), as the reproduction requires.

    Parameters
    ----------
    source : {"auto", "file", "parameters"}
        ``"file"``: ``examples/specimen.toml``; ``"parameters"``: built from
        :data:`SPECIMEN`; ``"auto"``: the file when present.
    examples_dir : path-like, optional
        Where the example files are (default :data:`EXAMPLES_DIR`).
    """
    from ..scenario import load_scenario, parse_scenario

    path = _examples_dir(examples_dir) / "specimen.toml"
    if _choose_source(source, path):
        return _paper_method(load_scenario(path))
    return _paper_method(parse_scenario(specimen_data(), name="specimen"))


def _paper_method(sc: Scenario) -> Scenario:
    """The scenario run by the paper's own method (exact state modes, eq. 12 projection): ``solver.basis = "paper"``."""
    return sc.with_values({"solver.basis": "paper"})


def _table1(number: int) -> TableOneCase:
    if not isinstance(number, (int, np.integer)) or not 0 <= int(number) <= 13:
        raise ParameterError(f"case: Table 1 has cases 0 to 13, got {number!r}")
    return TABLE1[int(number)]


def case_data(number: int) -> dict[str, Any]:
    """The raw scenario mapping of Table 1 case ``number``, built from the parameters.

    Parameters
    ----------
    number : int
        Table 1 case (0-13).
    """
    c = _table1(number)
    release = c.initial_tip_displacement is not None
    return specimen_data(
        # in g as in the paper, so that "10 g" parses to the same float as in the example files
        amplitude=None if c.amplitude is None else f"{c.amplitude / G:g} g",
        duration=None if c.duration is None else f"{round(c.duration * 1e3, 9):g} ms",
        gap=None if c.gap is None else f"{round(c.gap * 1e3, 9):g} mm",
        initial_tip_displacement=c.initial_tip_displacement,
        end_time=0.5 if release else 0.2,
        output_ratios=None,
        name=f"case{int(number):02d}",
    )


def case(number: int, *, source: str = "auto", examples_dir: str | os.PathLike[str] | None = None) -> Scenario:
    """Table 1 case ``number`` (0-13) as a Scenario, with ``solver.basis = "paper"`` (the paper's method).

    Read from ``examples/caseNN.toml`` (``source="file"``, or ``"auto"`` when
    the file exists), else built from :data:`TABLE1` and :data:`SPECIMEN`.

    Parameters
    ----------
    number : int
        Table 1 case (0-13).
    source : {"auto", "file", "parameters"}
        Read ``examples/`` or build from the parameters.
    examples_dir : str or path-like, optional
        Where the case files are (default: the source tree's ``examples/``).

    Raises
    ------
    ParameterError
        ``number`` is not 0..13, or ``source="file"`` and the file is missing.
    """
    from ..scenario import load_scenario, parse_scenario

    _table1(number)
    path = _examples_dir(examples_dir) / f"case{int(number):02d}.toml"
    if _choose_source(source, path):
        return _paper_method(load_scenario(path))
    return _paper_method(parse_scenario(case_data(number), name=f"case{int(number):02d}"))


def cases(*, source: str = "auto", examples_dir: str | os.PathLike[str] | None = None) -> dict[int, Scenario]:
    """Every Table 1 case, by number.

    Parameters
    ----------
    source : {"auto", "file", "parameters"}
        As for :func:`case`.
    examples_dir : str or path-like, optional
        As for :func:`case`.
    """
    return {c.number: case(c.number, source=source, examples_dir=examples_dir) for c in TABLE1}
