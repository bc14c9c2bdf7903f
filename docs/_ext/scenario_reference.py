"""Generate the scenario reference page from the schema of :mod:`impactbeam.scenario`.

The keys, their nesting, which ones take lists, the allowed choices and the
support presets are read from the code (``_SCHEMA``, ``_KINDS`` ...), so the
page cannot drift from what the parser accepts. The one-line meanings are
kept here in :data:`MEANING`; :func:`check` fails the docs build (and the
test suite) when a schema key has no meaning or a meaning names a key the
schema does not have.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from impactbeam.scenario import schema as S
from impactbeam.model.beam import SUPPORT_PRESETS
from impactbeam.model.damping import DAMPING_MODELS

#: Meaning and unit of every leaf key, by dotted path ([] marks the array of tables).
MEANING: dict[str, str] = {
    "name": "Name of the case (default: the file stem).",
    "description": "Free text shown in summaries.",
    "beam.length": "Beam length L [m].",
    "beam.width": "Width of the rectangular section [m] (with `height`, instead of `area` and `second_moment`).",
    "beam.height": "Height of the rectangular section [m], in the direction of w.",
    "beam.area": "Cross-section area A [m^2] (instead of `width` and `height`).",
    "beam.second_moment": "Second moment of area I [m^4] (instead of `width` and `height`).",
    "beam.youngs_modulus": "Young's modulus E [Pa].",
    "beam.density": "Density rho [kg/m^3].",
    "supports.left": "Support at x = 0: a preset name or a table of springs.",
    "supports.left.translational": "Translational spring at x = 0 [N/m] (`inf`: pinned).",
    "supports.left.rotational": "Rotational spring at x = 0 [N m/rad] (`inf`: no rotation).",
    "supports.right": "Support at x = L: a preset name or a table of springs.",
    "supports.right.translational": "Translational spring at x = L [N/m].",
    "supports.right.rotational": "Rotational spring at x = L [N m/rad].",
    "contactors[].position": "Contact point a [m] from the left end.",
    "contactors[].position_ratio": "Contact point as a fraction a/L (instead of `position`).",
    "contactors[].stiffness": "Contact spring stiffness k [N/m], acting only while engaged.",
    "contactors[].gap": "Clearance c [m] between the beam at rest and the contactor surface.",
    "contactors[].side": "Where the contactor is: `below` pushes while w(a) < -gap, `above` while w(a) > gap.",
    "damping.model": "`modal` (default: each state damps its own modes, ratios `free` and `contact`), "
                     "`free_modes` (the free state's ratios `free` as one damping matrix kept in every state) or "
                     "`rayleigh` (C = alpha M + beta K of each state); keys of another model are refused.",
    "damping.alpha": "Rayleigh mass-proportional coefficient alpha [1/s] (`model = \"rayleigh\"`).",
    "damping.beta": "Rayleigh stiffness-proportional coefficient beta [s] (`model = \"rayleigh\"`).",
    "contactors[].damping": "Dashpot c [N s/m] in parallel with the spring: force k d + c d' while the penetration "
                            "d > 0 and that force is positive (it never pulls).",
    "contactors[].restitution": "Coefficient of restitution 0 < e <= 1 instead of `damping`.",
    "damping.free": "Modal damping ratio xi_n of the free state (paper eq. 9): one value or one per mode.",
    "damping.contact": "Modal damping ratio of states with a contactor engaged: one value or one per mode.",
    "excitation.kind": "What the load is.",
    "excitation.shape": "Time history: half-sine pulse, step, harmonic, a table from `file`, or random (from `psd`).",
    "excitation.amplitude": "Peak value: [m/s^2] (or g) for base acceleration, [N] point force, [N/m] distributed.",
    "excitation.duration": "Pulse length [s] (half_sine).",
    "excitation.frequency": "Forcing frequency f [Hz] (harmonic): amplitude sin(2 pi f (t - start) + phase) for t >= start.",
    "excitation.phase": "Phase of the harmonic load at `start` [rad] (default 0; `\"90 deg\"` accepted).",
    "excitation.start": "When the load begins [s].",
    "excitation.position": "Point of application of a point force [m].",
    "excitation.position_ratio": "Point of application as a fraction of L.",
    "excitation.scale": "Factor on the whole history (fits and sweeps of the load level).",
    "excitation.file": "CSV or text table of time and value (shape = table), relative to the scenario file.",
    "excitation.hold": "How a table is held between samples.",
    "excitation.psd": "Random load (shape = random): one-sided power spectral density as [[frequency, level], ...], "
                      "log-log between the points, zero outside; levels in the square of the load's unit per Hz "
                      "(`\"0.01 g^2/Hz\"`, N^2/Hz, (N/m)^2/Hz). See the random vibration page.",
    "excitation.seed": "Random load: the integer seed of its stream (numpy SeedSequence); drawn, reported and kept "
                       "when absent.",
    "excitation.stream": "Random load: member of an ensemble, the stream SeedSequence(seed).spawn(n)[stream] "
                         "(set by `impactbeam random`).",
    "excitation.sample_rate": "Random load: samples per second of the held history [Hz]; default 8 times the "
                              "density's highest frequency.",
    "fatigue.points": "Positions [m] where the bending stress is counted for fatigue (list).",
    "fatigue.sn_stress": "Basquin S-N curve N(S) = sn_cycles (S / sn_stress)^-sn_exponent: the stress amplitude "
                         "S_ref [Pa] of its reference point.",
    "fatigue.sn_cycles": "Cycles to failure N_ref at `sn_stress`.",
    "fatigue.sn_exponent": "Basquin exponent m (> 0).",
    "fatigue.endurance_limit": "Amplitudes at or below it do no damage [Pa] (default 0: none).",
    "fatigue.mean_stress": "Mean-stress correction of each cycle's amplitude.",
    "fatigue.ultimate_strength": "S_u [Pa] of Goodman's line (with mean_stress = goodman).",
    "initial.tip_displacement": "Static tip deflection to release from [m] (paper Case 0).",
    "initial.position": "Where the initial static deflection is imposed [m] (default the tip).",
    "initial.modal_displacement": "Initial modal coordinates eta_n(0) of the free state (list).",
    "initial.modal_velocity": "Initial modal velocities d eta_n/dt (0) of the free state (list).",
    "initial.velocity": "Uniform initial velocity [m/s] (a translation), or a velocity field along the beam as rows "
                        '`[[x, v], ...]` (units in strings: `[["0 m", "0 m/s"], ["0.78 m", "-3 m/s"]]`), linear '
                        "between rows, spanning 0 .. L. Projected on the run's modes (see below).",
    "initial.velocity_file": "The velocity field from a two-column file `position, velocity` (unit headers such as "
                             "`x [mm],v [mm/s]`), relative to the scenario file.",
    "initial.displacement": "Initial deflection along the beam as rows `[[x, w], ...]` [m], linear between rows, "
                            "spanning 0 .. L.",
    "initial.displacement_file": "The deflection field from a two-column file `position, displacement`.",
    "initial.angular_velocity": "Rigid rotation [rad/s] about `pivot`: w_t(x, 0) = angular_velocity (x - pivot) "
                                "(positive turns +x toward +w); adds to `velocity`.",
    "initial.pivot": "Axis of the rigid rotation [m] (on the beam; required with `angular_velocity`).",
    "initial.equilibrium": "`true`: start from the static equilibrium under `[preload]`, with the contactors it "
                           "engages (exact static contact problem of the run's model).",
    "preload.kind": "Constant load during the whole run: `gravity` (the acceleration of gravity along +w: `\"-1 g\"` "
                    "when w points up), `base_acceleration` (the base's acceleration, as in `[excitation]`: gravity "
                    "toward -w is `\"1 g\"`), or `point_force`.",
    "preload.amplitude": "[m/s^2] (or g) for gravity and base acceleration, [N] for a point force; along +w.",
    "preload.position": "Point of application of a point force [m].",
    "preload.position_ratio": "The same as a fraction of L.",
    "solver.modes": "Modes per state N (paper: 8), or `auto`: add modes until the metrics change by less than `solver.tolerance`.",
    "solver.time_step": "Output sampling interval [s]; events, extrema and metrics do not depend on it.",
    "solver.end_time": "Simulated duration [s].",
    "solver.max_events": "Stop (with a warning) after this many impacts and rebounds: the chattering guard.",
    "solver.event_tolerance": "Tolerance of the event-time root finder [s].",
    "solver.projection": "How the modal state is carried across an event: `paper` (default, the L2 projection of eq. 12) or `contact`.",
    "solver.tolerance": "Relative change of the Table-2 metrics that counts as converged in the modes (default 2e-3); with `modes = \"auto\"` the stopping rule, otherwise the threshold of the unconverged warning.",
    "solver.basis": "`enriched` (default): one shared basis, the free modes plus a static attachment shape per contactor (and the engaged state's modes for a stop much stiffer than the beam), exact switches; `paper`: each state's own modes joined by the projection of eq. 12.",
    "beam.sections[].length": "Length of this uniform piece [m]; the pieces, in order from x = 0, sum to `beam.length`.",
    "beam.sections[].width": "Width of this piece [m] (default the `[beam]` value).",
    "beam.sections[].height": "Height of this piece [m] (default the `[beam]` value).",
    "beam.sections[].area": "Cross-section area of this piece [m^2].",
    "beam.sections[].second_moment": "Second moment of area of this piece [m^4].",
    "beam.sections[].youngs_modulus": "Young's modulus of this piece [Pa].",
    "beam.sections[].density": "Density of this piece [kg/m^3].",
    "masses[].position": "Where the point mass is attached [m].",
    "masses[].position_ratio": "The same as a fraction of L.",
    "masses[].mass": "Mass of the attached body [kg].",
    "masses[].rotary_inertia": "Its rotary inertia about the beam's axis of bending [kg m^2] (default 0).",
    "springs[].position": "Where the permanent interior support is [m].",
    "springs[].position_ratio": "The same as a fraction of L.",
    "springs[].translational": "Its translational stiffness [N/m] (`inf`: a rigid prop).",
    "springs[].rotational": "Its rotational stiffness [N m/rad] (`inf`: no rotation there).",
    "beam.theory": '`"euler-bernoulli"` (default, the paper\'s beam) or `"timoshenko"` (shear deformation and '
                   "rotary inertia; exact modes in both frequency regimes).",
    "beam.poisson_ratio": "Timoshenko beams: Poisson's ratio in (-1, 0.5); G = E / (2 (1 + nu)) in every section "
                          "(refused on an Euler-Bernoulli beam).",
    "beam.shear_modulus": "Timoshenko beams: instead of `poisson_ratio`, G [Pa] of the `[beam]` values "
                          "(nu = E / 2G - 1 must lie in (-1, 0.5)).",
    "beam.shear_coefficient": "Timoshenko beams: kappa; default Cowper's value for a rectangle, "
                              "10 (1 + nu) / (12 + 11 nu) (required for a section given as area and second moment).",
    "output.points": "Positions [m] where the response is recorded (list).",
    "output.point_ratios": "The same as fractions of L (instead of `points`).",
    "output.fields": "Fields of result files: `displacement` and `velocity` (always written), `moment` [N m] "
                     "and `stress` [Pa] (also spelt `bending_moment`, `bending_stress`); `stress` also adds the "
                     "largest stress, its time and place, to the metrics. List; default none.",
}

#: Allowed values of the choice keys, read from the parser's own tuples.
CHOICES: dict[str, tuple[str, ...]] = {
    "excitation.kind": S._KINDS,
    "excitation.shape": S._SHAPES,
    "excitation.hold": S._HOLDS,
    "preload.kind": S._PRELOAD_KINDS,
    "damping.model": DAMPING_MODELS,
    "contactors[].side": S._SIDES,
    "damping.model": DAMPING_MODELS,
    "output.fields": S.OUTPUT_FIELDS,
    "fatigue.mean_stress": S._MEAN_STRESS,
    "supports.left": tuple(SUPPORT_PRESETS),
    "supports.right": tuple(SUPPORT_PRESETS),
}


def schema_keys() -> list[tuple[str, Any]]:
    """Every (dotted path, schema node) of the scenario schema, depth first."""
    out: list[tuple[str, Any]] = []

    def walk(node: Any, prefix: str) -> None:
        for key, child in node.fields.items():
            path = f"{prefix}.{key}" if prefix else key
            if isinstance(child, S._Array):
                out.append((path + "[]", child))
                walk(child.item, path + "[]")
            else:
                out.append((path, child))
                if isinstance(child, S._Table):
                    walk(child, path)

    walk(S._SCHEMA, "")
    return out


def check() -> list[str]:
    """Problems between the schema and :data:`MEANING` (empty when they agree)."""
    keys = {p for p, node in schema_keys() if not isinstance(node, S._Array)
            and not (isinstance(node, S._Table) and not node.preset_ok)}
    problems = [f"scenario key {k!r} has no meaning in docs/_ext/scenario_reference.py" for k in sorted(keys - set(MEANING))]
    problems += [f"docs/_ext/scenario_reference.py describes {k!r}, which the schema does not have"
                 for k in sorted(set(MEANING) - keys)]
    return problems


def _kind(node: Any) -> str:
    if isinstance(node, S._Table):
        return "preset name or table" if node.preset_ok else "table"
    if isinstance(node, S._Array):
        return "array of tables"
    if node.columns:
        row = "rows [" + ", ".join(c.replace("psd_level", "level") for c in node.columns) + "]"
        return row if node.list_only else f"value or {row}"
    if node.list_only:
        return "list"
    return "value or list" if node.list_ok else "value"


#: Arrays of tables at the top level (written ``[[name]]`` in TOML).
_ARRAYS = {key for key, node in S._SCHEMA.fields.items() if isinstance(node, S._Array)}


#: The copy of the page kept with the example files (plain Markdown: readable without building the docs).
EXAMPLES_COPY = Path(__file__).resolve().parents[2] / "examples" / "scenario-reference.md"


def render(plain: bool = False) -> str:
    """The Markdown text of the reference page; ``plain``: the copy of :data:`EXAMPLES_COPY` (no MyST directive)."""
    problems = check()
    if problems:
        raise RuntimeError("; ".join(problems))
    lines = [
        "# Scenario reference",
        "",
        "Every key a scenario file accepts, generated from the parser's schema",
        "(`impactbeam.scenario`). Numbers are SI; a string with a unit is converted",
        '(`"0.229 mm"`, `"15 g"`, `"1834 MPa"`, `"1.1 %"`); logarithmic and offset',
        "units (dB, octave, degC) are refused. Unknown keys are errors that name",
        "the key and suggest the closest one. `contactors`, `masses`, `springs`",
        "and `beam.sections` are arrays of tables (`[[contactors]]`,",
        "`[[beam.sections]]`); their keys are written `contactors[].key` here and",
        "`contactors.0.key` in sweeps and `with_values`.",
        "",
    ]
    if plain:
        lines += ["This copy, kept with the example files, is written by `python docs/_ext/scenario_reference.py`",
                  "(the documentation builds the same page); edit the meanings there, not here.", ""]
    groups: dict[str, list[str]] = {}
    for path, node in schema_keys():
        if path not in MEANING:
            continue
        top = path.split(".")[0].removesuffix("[]") if "." in path or not isinstance(node, S._Leaf) else ""
        allowed = ", ".join(f"`{c}`" for c in CHOICES.get(path, ()))
        default = S.SUPPORT_DEFAULTS.get(path.split(".")[-1]) if path.count(".") == 1 and top == "supports" else None
        if default:
            allowed += f" (default `{default}`)"
        groups.setdefault(top, []).append(f"| `{path}` | {_kind(node)} | {MEANING[path]} | {allowed} |")
    for top, rows in groups.items():
        title = f"`[{top}]`" if top else "Top level"
        if top in _ARRAYS:
            title = f"`[[{top}]]`"
        lines += [f"## {title}", "", "| key | kind | meaning | allowed |", "|---|---|---|---|", *rows, ""]
    lines += _initial_section()
    lines += ["", "## Support presets", "", "| preset | translational [N/m] | rotational [N m/rad] |", "|---|---|---|"]
    for name, (k, kt) in SUPPORT_PRESETS.items():
        lines.append(f"| `{name}` | {k:g} | {kt:g} |")
    if plain:
        lines += ["", "## Example", "", "[`case03.toml`](case03.toml), the paper's Case 3; the other files of this",
                  "directory are described in [README.md](README.md).", ""]
    else:
        lines += ["", "## Example", "", "```{literalinclude} ../../examples/case03.toml", ":language: toml", "```", ""]
    return "\n".join(lines)


def _initial_section() -> list[str]:
    """Prose on initial states and the preload (the rule of :mod:`impactbeam.solver.initial`)."""
    from impactbeam.solver.initial import RESIDUAL_WARNING

    return [
        "## Initial states and preload",
        "",
        "Every initial field (`tip_displacement`'s static shape, the `displacement` and `velocity` rows or files,",
        "the uniform `velocity`, the rigid rotation `angular_velocity` about `pivot`) is projected onto the run's",
        "free-state basis (the paper's modes or the shared Ritz basis of `solver.basis`) in the kinetic inner",
        "product of the model: rho A(x), the point masses' mass and rotary inertia, and rho I for a Timoshenko",
        "beam. The modes are mass-orthonormal, so this is the best approximation of the field in that norm; when",
        f"it misses more than {100 * RESIDUAL_WARNING:g} % of the field (relative kinetic-norm residual: motion the supports",
        "forbid, such as a uniform velocity of a clamped beam, or detail finer than the modes) a warning gives",
        "the residual. A rigid rotation of a beam whose supports allow it (pinned-free) is represented exactly.",
        "Displacements and velocities from several keys add up; a uniform `velocity` and `angular_velocity`",
        "together are any rigid motion.",
        "",
        "`[preload]` is a constant load acting during the whole run. With `initial.equilibrium = true` the run",
        "starts from the static equilibrium of its own model under it, with the contactors it engages: the",
        "static contact problem (one-sided springs with their gaps) is solved exactly, as a linear",
        "complementarity problem, and compared with the exact static solution of the continuum (a warning",
        "gives the difference when it exceeds the same fraction). A beam that nothing holds against the preload",
        "(free-free under gravity with no stop under it) is refused. Gravity pulling toward -w (w up) is",
        '`kind = "gravity"`, `amplitude = "-1 g"`, or equivalently `kind = "base_acceleration"`,',
        '`amplitude = "1 g"` (the base accelerating upward), the convention of `[excitation]`.',
        "",
        "```toml",
        "[initial]                      # a pinned beam swung about its pin (code_aster SDNL32)",
        'angular_velocity = "-3.8 rad/s"',
        "pivot = 0.0",
        "",
        "[preload]                      # or: a tube resting on its support under gravity",
        'kind = "gravity"',
        'amplitude = "-1 g"',
        "```",
        "",
    ]


def _write(app: Any) -> None:
    out = Path(app.srcdir) / "_generated" / "scenario-reference.md"
    out.parent.mkdir(exist_ok=True)
    text = render()
    if not out.exists() or out.read_text() != text:  # unchanged files do not trigger a rebuild
        out.write_text(text)


def setup(app: Any) -> dict[str, Any]:
    app.connect("builder-inited", _write)
    return {"parallel_read_safe": True, "version": "1"}


if __name__ == "__main__":  # rewrite the copy kept with the example files (tests/test_docs.py checks it)
    EXAMPLES_COPY.write_text(render(plain=True))
    print(f"wrote {EXAMPLES_COPY}")
