"""The validated scenario: :class:`Scenario`, :func:`parse_scenario` and :func:`load_scenario`."""

from __future__ import annotations

import copy
import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .._io import read_text_file
from .._warnings import emit_user_level_warning
from ..model.beam import Beam, Contactor
from ..exceptions import ScenarioError
from ..model.loading import Excitation
from ..model.starting import InitialCondition, Preload
from ..model.fatigue import FatigueSpec
from ..model import Damping, SolverOptions
from .edit import _normalise, scenario_toml, set_path
from .checks import check_magnitudes, check_response, check_run, warn_numeric_strings
from .fields import _string
from .parse_run import (
    _parse_damping,
    _parse_excitation,
    _parse_fatigue,
    _parse_initial,
    _parse_output,
    _parse_output_fields,
    _parse_preload,
    _parse_solver,
)
from .parse_structure import _parse_beam, _parse_contactors
from .schema import _SCHEMA, _check_structure

__all__ = ["Scenario", "load_scenario", "parse_scenario"]

#: Peak memory of reading a TOML scenario per byte of the file (tomllib's tables and the checked
#: values): measured 9.1 (peak RSS) on a 5.8 MiB file of 300 000 output points; a file whose
#: estimate exceeds the memory limit is refused before it is read.
SCENARIO_MEMORY_FACTOR = 20


@dataclass(frozen=True, eq=False)
class Scenario:
    """A validated simulation case (see the scenario reference).

    Attributes
    ----------
    beam : Beam
    contactors : tuple of Contactor
    damping : Damping
    excitation : Excitation
    initial : InitialCondition
    solver : SolverOptions
    output_points : tuple of float, [m]
        Where the response is recorded; default: the contactor positions,
        then the right end (without repeats).
    data : dict
        The normalised raw mapping (a private deep copy): vary a dotted path
        with :func:`set_path` / :meth:`with_values` and re-parse.
    source : Path or None
        The file the scenario came from.
    base_dir : Path or None
        Directory against which relative file names (trace CSV) are resolved.
    name : str
        ``name`` from the file, else the file stem.
    output_fields : tuple of str
        Fields of result files (``[output] fields``, canonical names):
        ``displacement`` and ``velocity`` (always written), ``moment`` and
        ``stress`` (which also adds its maximum to the metrics).
    fatigue : FatigueSpec or None
        ``[fatigue]``: the points and S-N curve of the fatigue statistics.
    preload : Preload or None
        The constant load of ``[preload]`` (acting during the whole run; the
        load of ``initial.equilibrium``).
    """

    beam: Beam
    contactors: tuple[Contactor, ...]
    damping: Damping
    excitation: Excitation
    initial: InitialCondition
    solver: SolverOptions
    output_points: tuple[float, ...]
    data: dict[str, Any] = field(repr=False)
    source: Path | None = None
    base_dir: Path | None = None
    name: str = "scenario"
    output_fields: tuple[str, ...] = ()
    fatigue: FatigueSpec | None = None
    preload: Preload | None = None

    def to_toml(self) -> str:
        """The scenario as TOML text (``load_scenario`` of it gives the same scenario, from any directory).

        The files it names relative to its directory (``excitation.file``,
        ``initial.*_file``) are written as absolute paths.
        """
        if self.base_dir is None:
            return scenario_toml(self.data)
        data = copy.deepcopy(self.data)
        tables = [data.get("excitation"), data.get("initial")]
        for table in (t for t in tables if isinstance(t, dict)):
            for key, value in table.items():
                if (key == "file" or key.endswith("_file")) and isinstance(value, str):
                    path = Path(value).expanduser()
                    table[key] = str(path if path.is_absolute() else (Path(self.base_dir) / path).resolve())
        return scenario_toml(data)

    def path_dimension(self, path: str) -> str | None:
        """The dimension a value at the dotted ``path`` is read in, this scenario's kinds of load given.

        :func:`~impactbeam.scenario.schema.path_dimension` with ``excitation.kind``
        and ``preload.kind`` (the dimensions of their amplitudes): what sweeps,
        fits and bifurcation diagrams read their values in.

        Parameters
        ----------
        path : str
            A dotted path of the schema (``"contactors.0.gap"``, ``"preload.amplitude"``).
        """
        from .schema import path_dimension

        return path_dimension(path, *self.load_kinds)

    @property
    def load_kinds(self) -> tuple[str, str | None]:
        """``(excitation.kind, preload.kind)``, None for the second without a ``[preload]``: what the
        amplitudes' dimensions follow."""
        return self.excitation.kind, None if self.preload is None else self.preload.kind

    @property
    def description(self) -> str | None:
        """The ``description`` string of the file, if any."""
        return self.data.get("description")

    def _repr_html_(self) -> str:
        """Compact summary table for Jupyter."""
        from .._html import scenario_html

        return scenario_html(self)

    def with_values(self, values: Mapping[str, Any]) -> Scenario:
        """A new scenario with the dotted paths in ``values`` set, re-validated.

        >>> sc2 = sc.with_values({"contactors.0.gap": "0.432 mm", "solver.modes": 12})  # doctest: +SKIP

        Raises :class:`ScenarioError` for an unknown path or an invalid value
        (the message starts with the dotted key).

        Parameters
        ----------
        values : mapping of str to value
            Dotted path -> new value (SI number, string with units, list; None removes
            the key).
        """
        data: dict[str, Any] = self.data
        for path, value in values.items():
            data = set_path(data, path, value)
        return parse_scenario(data, base_dir=self.base_dir, source=self.source, name=self.name)


def parse_scenario(
    data: Mapping[str, Any],
    *,
    base_dir: str | os.PathLike[str] | None = None,
    source: str | os.PathLike[str] | None = None,
    name: str = "scenario",
) -> Scenario:
    """Validate a scenario mapping (the TOML schema of the scenario reference).

    Parameters
    ----------
    data : mapping
        Tables ``beam`` (required), ``supports``, ``contactors`` (list),
        ``damping``, ``excitation``, ``initial``, ``solver``, ``output`` and
        the strings ``name`` and ``description``. Values are SI numbers or
        strings with units. ``None`` values count as absent.
    base_dir : path-like, optional
        Directory for relative file names (``excitation.file``); default: the
        current directory.
    source : path-like, optional
        The file ``data`` came from (recorded in the result).
    name : str
        Name used when ``data`` has no ``name``.

    Returns
    -------
    Scenario

    Raises
    ------
    ScenarioError
        Naming the dotted key of the first problem found.
    """
    if not isinstance(data, Mapping):
        raise ScenarioError(f"a scenario must be a mapping of tables, got {type(data).__name__}")
    raw = _normalise(data)
    _check_structure(raw, _SCHEMA, "", raw)
    check_magnitudes(raw)
    warn_numeric_strings(raw)
    if "name" in raw:
        name = _string("name", raw["name"])
    if "description" in raw:
        _string("description", raw["description"])
    base = Path(base_dir) if base_dir is not None else None

    beam = _parse_beam(raw)
    contactors = _parse_contactors(raw, beam)
    damping = _parse_damping(raw)
    excitation = _parse_excitation(raw, beam, base)
    initial = _parse_initial(raw, beam, base)
    preload = _parse_preload(raw, beam)
    solver = _parse_solver(raw)
    points = _parse_output(raw, beam, contactors)
    check_response(beam, excitation, initial, solver.end_time)
    check_run(beam, solver.modes, solver.end_time)
    scenario = Scenario(
        beam=beam,
        contactors=contactors,
        damping=damping,
        excitation=excitation,
        initial=initial,
        solver=solver,
        output_points=points,
        data=raw,
        source=Path(source) if source is not None else None,
        base_dir=base,
        name=name,
        output_fields=_parse_output_fields(raw, beam),
        fatigue=_parse_fatigue(raw, beam),
        preload=preload,
    )
    warn_unusual(scenario)
    return scenario


def load_scenario(path: str | os.PathLike[str]) -> Scenario:
    """Read and validate a scenario TOML file.

    Relative file names inside it (``excitation.file``) are resolved against
    the file's directory; the scenario's name is its ``name`` or the file stem.

    Parameters
    ----------
    path : str or path-like
        A ``.toml`` scenario file.

    Raises
    ------
    ScenarioError
        For a missing or unreadable file, a TOML syntax error (with the
        parser's line and column) or invalid content.
    """
    if not str(path).strip():
        raise ScenarioError("cannot read scenario: the path is empty; give a scenario file (.toml)")
    p = Path(path)

    def fail(detail: str) -> ScenarioError:
        return ScenarioError(f'cannot read scenario "{path}": {detail}')

    text = read_text_file(p, fail, not_found="file not found", not_text="not UTF-8 text",
                          memory_factor=SCENARIO_MEMORY_FACTOR)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ScenarioError(f'"{path}": invalid TOML: {exc}') from None
    resolved = p.resolve()
    return parse_scenario(data, base_dir=resolved.parent, source=resolved, name=p.stem)


def warn_unusual(sc: Scenario) -> None:
    """Warn (ImpactBeamWarning) for valid inputs that are very likely mistakes.

    * ``initial.modal_displacement`` / ``modal_velocity`` with more entries
      than ``solver.modes``: the extra entries are ignored by the solver;
    * an excitation that starts at or after ``solver.end_time``: it never acts;
    * an endurance limit at or above the S-N curve's reference stress, an
      ultimate strength at or below it, a fatigue stress below 1e-6 of the
      Young's modulus (a bare number meant as MPa) (``[fatigue]``).

    (A contactor at a support that holds ``w = 0`` is refused, not warned
    about: :meth:`~impactbeam.model.beam.Contactor.check_on`.)
    """
    n = sc.solver.modes
    for name in ("modal_displacement", "modal_velocity"):
        values = getattr(sc.initial, name)
        if values is not None and len(values) > n:
            emit_user_level_warning(
                f"initial.{name}: {len(values)} entries but solver.modes = {n}; the entries beyond mode {n} "
                f"are ignored (raise solver.modes to {len(values)} to use them)"
            )
    ex = sc.excitation
    if ex.kind != "none":
        first = ex.start + (float(ex.times[0]) if ex.shape == "table" and ex.times is not None else 0.0)
        if first >= sc.solver.end_time:
            key = "excitation.start" if ex.shape != "table" or ex.start >= sc.solver.end_time else "excitation.file"
            emit_user_level_warning(
                f"{key}: the excitation starts at {first:g} s, at or after solver.end_time = "
                f"{sc.solver.end_time:g} s; it never acts in this run"
            )
    fat = sc.fatigue
    if fat is not None:  # a stress given as a bare number is in Pa: "800" meant as MPa is a million times small
        modulus = min(p.youngs_modulus for p in sc.beam.pieces())
        for name in ("sn_stress", "endurance_limit", "ultimate_strength"):
            value = getattr(fat, name)
            if value is not None and 0.0 < value < 1e-6 * modulus:
                emit_user_level_warning(
                    f"fatigue.{name}: {value:g} Pa is below 1e-6 of the beam's Young's modulus ({modulus:g} Pa); "
                    f'a plain number is in Pa: give the unit ("{value:g} MPa")'
                )
    if fat is not None and fat.endurance_limit >= fat.sn_stress:
        emit_user_level_warning(
            f"fatigue.endurance_limit: {fat.endurance_limit:g} Pa is at or above sn_stress = {fat.sn_stress:g} Pa, "
            "so the S-N curve's own reference point does no damage; check the two values and their units"
        )
    if fat is not None and fat.ultimate_strength is not None and fat.ultimate_strength <= fat.sn_stress:
        emit_user_level_warning(
            f"fatigue.ultimate_strength: {fat.ultimate_strength:g} Pa is at or below sn_stress = {fat.sn_stress:g} "
            "Pa, a fatigue amplitude the material would not survive once; check the two values and their units"
        )

