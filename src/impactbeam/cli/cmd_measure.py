"""``impactbeam identify | compare | fit``: working with measurements (paper section 4).

Thin wrappers around :mod:`impactbeam.experiment` and :mod:`impactbeam.fit`.
Bad input (an unreadable or malformed record, an unknown path, bad bounds)
exits with status 2 and one ``error:`` line; notes about the records (e.g.
resampling) go to stderr as ``note:`` lines.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import click

from .._io import PLOT_SUFFIXES, WriteError, check_output, json_text
from ._group import handle_errors, number_or_text, take_warnings
from ..exceptions import ImpactBeamError, ParameterError

__all__ = ["compare", "fit", "identify"]

_RECORD_OPTIONS = [
    click.option("--time-unit", default=None, metavar="UNIT",
                 help='Unit of the time column when the file gives none (e.g. "ms").'),
    click.option("--value-unit", default=None, metavar="UNIT",
                 help='Unit of the deflection column when the file gives none (e.g. "mm").'),
    click.option("--channel", default=None, metavar="NAME",
                 help="Column (netCDF variable) to read when the record holds several."),
]


def _record_options(fn: Any) -> Any:
    for opt in reversed(_RECORD_OPTIONS):
        fn = opt(fn)
    return fn


def _note(record: Any) -> None:
    for note in record.notes:
        click.echo(f"note: {record.label}: {note}", err=True)


def _frequency(text: str, option: str) -> float:
    """A positive frequency [Hz] from ``107.8`` or ``"107.8 Hz"`` (any frequency unit)."""
    from ..units import to_si

    f = to_si(number_or_text(text), "frequency", option)
    if not (math.isfinite(f) and f > 0):
        raise ParameterError(f"{option}: must be a positive frequency, got {text}")
    return f


def _window(text: str | None) -> tuple[float | None, float | None] | None:
    if text is None:
        return None
    from ..units import to_si

    lo, colon, hi = text.partition(":")
    if not colon:
        raise ParameterError(f'--window: "{text}" is not of the form START:STOP (seconds; either may be empty)')
    out = []
    for part in (lo, hi):
        part = part.strip()
        out.append(None if not part else to_si(part, "time", "--window"))
    if out[0] is not None and out[1] is not None and not out[1] > out[0]:
        raise ParameterError(f"--window: STOP {out[1]:g} s must come after START {out[0]:g} s")
    return out[0], out[1]


def _point(text: str | None) -> float | None:
    if text is None:
        return None
    from ..units import to_si

    return to_si(text, "length", "--point")


def _load_trace(path: str | None) -> Any:
    if path is None:
        return None
    from ..experiment import load_record

    trace = load_record(path, quantity="acceleration", resample=False)
    _note(trace)
    return trace


# --------------------------------------------------------------------------- identify


@click.command()
@click.argument("record", metavar="RECORD")
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
@click.option("--count", "count", type=int, default=2, show_default=True, help="Number of modes to identify.")
@click.option("--scenario", "scenario", default=None, metavar="S",
              help="Scenario whose Young's modulus is matched to the first frequency.")
@click.option("--contact-frequency", "contact_frequency", default=None, metavar="F",
              help="Measured contact-state fundamental [Hz]: gives the contact stiffness (needs --scenario).")
@click.option("--contact-record", "contact_record", default=None, metavar="FILE",
              help="Deflection record at the contactor: its contact portions give the contact frequency.")
@click.option("--contactor", "contactor", type=int, default=0, show_default=True,
              help="Index of the contactor (with --contact-*).")
@click.option("--out", "out", default=None, metavar="FILE.toml",
              help="Write the scenario with the identified modulus (and contact stiffness).")
@_record_options
@handle_errors
def identify(
    record: str, as_json: bool, count: int, scenario: str | None, contact_frequency: str | None,
    contact_record: str | None, contactor: int, out: str | None, time_unit: str | None,
    value_unit: str | None, channel: str | None,
) -> None:
    """Natural frequencies, damping, modulus and contact stiffness from a free-decay RECORD.

    RECORD is a CSV (header `time,deflection`, SI, or with units such as
    `time [s],deflection [mm]`) or netCDF file of a release test (paper
    Case 0/13). Frequencies come from the Hann-windowed, zero-padded
    spectrum with interpolated peaks. Damping ratios by two independent
    estimators that work on ~10 cycles: a damped-sine least-squares fit of
    all modes (reported, with its standard error) and the matrix-pencil
    method; their difference is the spread. The paper's logarithmic
    decrement is shown too when the record is long enough. With --scenario,
    the Young's modulus that gives the model's first free-state frequency
    the measured (undamped) value; with --contact-frequency or
    --contact-record as well, the contact stiffness whose contact-state
    fundamental matches (paper section 4.2), computed with the identified
    modulus. A record with no significant oscillation exits with status 2.
    """
    from ..experiment import load_record
    from ..experiment import identify as run_identify

    if count < 1:
        raise ParameterError(f"--count: must be a positive integer, got {count}")
    if (contact_frequency or contact_record) and scenario is None:
        raise ParameterError("--contact-frequency/--contact-record: need --scenario (the beam and contactor)")
    if contact_frequency and contact_record:
        raise ParameterError("--contact-frequency and --contact-record: give one, not both")
    if out is not None and scenario is None:
        raise ParameterError("--out: needs --scenario (the scenario to update)")
    check_output("--out", out, (".toml",))
    f_contact = _frequency(contact_frequency, "--contact-frequency") if contact_frequency else None
    sc = None
    if scenario is not None:
        from ..scenario import load_scenario

        sc = load_scenario(scenario)
    rec = load_record(record, time_unit=time_unit, value_unit=value_unit, channel=channel)
    _note(rec)
    if rec.quantity != "deflection":
        raise ParameterError(f"{rec.label}: identify needs a deflection record, got an acceleration")
    crec = None
    if contact_record is not None:
        crec = load_record(contact_record, time_unit=time_unit, value_unit=value_unit, channel=channel)
        _note(crec)
    ident = run_identify(rec, count, scenario=sc, contact_frequency=f_contact, contact_record=crec, contactor=contactor)
    for d in ident.damping:
        if d.log_decrement is None:
            click.echo(f"note: no logarithmic decrement at {d.frequency_hz:.4g} Hz: {d.log_decrement_note}", err=True)
    result = ident.to_dict()
    result["record"] = record
    data = None
    if sc is not None:
        result["scenario"] = scenario
        if contact_record is not None:
            result["contact_record"] = contact_record
        if out is not None:
            from ..scenario import set_path

            data = sc.data
            for path, value in ident.updates.items():
                data = set_path(data, path, value)
            result["out"] = out
    failure: WriteError | None = None
    if out is not None and data is not None:
        from ..scenario import dump_scenario

        try:
            dump_scenario(data, out)
        except WriteError as exc:  # reported after the identified values, so they are not lost
            failure = exc
            result["out"] = None
    if as_json:
        click.echo(json_text({**result, "warnings": take_warnings()}))
    else:  # the warnings go to stderr, printed by handle_errors when the command ends
        click.echo(_identify_text(result))
    if failure is not None:
        raise failure
    if out is not None:
        click.echo(f"wrote scenario to {out}", err=True)


def _pct(x: float | None, digits: int = 3) -> str:
    return "n/a" if x is None else f"{100 * x:.{digits}f}"


def _identify_text(r: dict[str, Any]) -> str:
    lines = [
        f"Identification from {r['record']}: {r['n_samples']} samples at {r['sample_rate_hz']:.6g} Hz "
        f"over {r['duration_s']:.4g} s (resolution {r['resolution_hz']:.4g} Hz)",
        "  damping ratio [%]: least-squares fit +/- standard error; matrix pencil; spread = |fit - pencil|;",
        "  logarithmic decrement +/- its spread over cycles (paper 4.1), where the record allows it",
        "  mode  frequency [Hz]       fit [%]  pencil [%]  spread [%]   log decrement [%] (cycles)",
    ]
    for i, f in enumerate(r["frequencies_hz"]):
        fit = "n/a" if r["damping_ratios"][i] is None else (
            f"{_pct(r['damping_ratios'][i])} +/- {_pct(r['damping_standard_errors'][i])}")
        ld = r["damping_log_decrement"][i]
        ldt = "n/a" if ld is None else (
            f"{_pct(ld)} +/- {_pct(r['damping_cycle_spread'][i])} ({r['damping_cycles'][i]})")
        lines.append(
            f"  {i + 1:>4}  {f:>14.4f}  {fit:>14}  {_pct(r['damping_matrix_pencil'][i]):>10}  "
            f"{_pct(r['damping_spread'][i]):>10}   {ldt}"
        )
    if "youngs_modulus" in r:
        lines.append(
            f"  model ({r['scenario']}): first frequency {r['model_frequencies_hz'][0]:.4f} Hz with "
            f"E = {r['scenario_youngs_modulus'] / 1e6:.6g} MPa"
        )
        lines.append(
            f"  Young's modulus matching {r['natural_frequency_hz']:.4f} Hz (undamped): "
            f"{r['youngs_modulus'] / 1e6:.6g} MPa ({r['youngs_modulus_change_percent']:+.2f} %); "
            f"model frequencies then {', '.join(f'{f:.4f}' for f in r['tuned_frequencies_hz'])} Hz"
        )
    if "contact_stiffness" in r:
        src = (f"from the {r['contact_intervals']} contact intervals of {r['contact_record']} "
               f"(half-period estimate {r['contact_frequency_half_period_hz']:.4f} Hz)"
               if "contact_record" in r else "given")
        lines.append(f"  contact-state fundamental {r['contact_frequency_hz']:.4f} Hz ({src})")
        lines.append(
            f"  contact stiffness matching it: {r['contact_stiffness']:.6g} N/m "
            f"(scenario: {r['scenario_contact_stiffness']:.6g} N/m, giving {r['scenario_contact_frequency_hz']:.4f} Hz)"
        )
    return "\n".join(lines)


# --------------------------------------------------------------------------- compare


@click.command()
@click.argument("scenario", metavar="SCENARIO")
@click.argument("measured", metavar="MEASURED")
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
@click.option("--excitation", "excitation", default=None, metavar="TRACE",
              help="Measured base-acceleration trace (CSV/netCDF) driving the model instead of the scenario's pulse.")
@click.option("--hold", type=click.Choice(["linear", "constant"]), default="linear", show_default=True,
              help="How the trace is held between samples.")
@click.option("--plot", "plot", default=None, metavar="FILE", help="Write an overlay plot (e.g. .png).")
@click.option("--point", "point", default=None, metavar="X",
              help="Where MEASURED was taken [m] (default: the first contactor).")
@click.option("--window", "window", default=None, metavar="START:STOP",
              help="Compare only this time window [s] (either end may be empty).")
@_record_options
@handle_errors
def compare(
    scenario: str, measured: str, as_json: bool, excitation: str | None, hold: str, plot: str | None,
    point: str | None, window: str | None, time_unit: str | None, value_unit: str | None, channel: str | None,
) -> None:
    """Simulate SCENARIO and compare it with the MEASURED deflection (paper section 4).

    Prints the section-4 quantities side by side with percentage differences
    (sim - meas)/|meas|: the first major peak and its time, the first
    negative peak and its time, the first contact duration and the period
    around the first negative peak, plus the rms difference. They are
    computed on u, positive away from the first contactor (u = -w for a
    contactor "above").
    """
    from ..experiment import compare as run_compare
    from ..experiment import load_record
    from ..scenario import load_scenario

    check_output("--plot", plot, PLOT_SUFFIXES)
    win = _window(window)
    x = _point(point)
    sc = load_scenario(scenario)
    meas = load_record(measured, time_unit=time_unit, value_unit=value_unit, channel=channel, quantity="deflection")
    _note(meas)
    trace = _load_trace(excitation)
    cmp = run_compare(sc, meas, excitation=trace, hold=hold, point=x, window=win)  # type: ignore[arg-type]
    if plot is not None:
        cmp.plot(plot)
    if as_json:
        d = cmp.to_dict()
        d.update({"scenario": scenario, "measured": measured, "excitation": excitation,
                  "hold": hold if excitation else None, "plot": plot, "warnings": take_warnings()})
        click.echo(json_text(d))
    else:  # the warnings go to stderr, printed by handle_errors when the command ends
        click.echo(cmp.table())
    if plot is not None:
        click.echo(f"wrote figure to {plot}", err=True)


# --------------------------------------------------------------------------- fit


@click.command()
@click.argument("scenario", metavar="SCENARIO")
@click.argument("measured", metavar="MEASURED")
@click.option("--params", "params", required=True, metavar="PATH[,PATH...]",
              help="Dotted scenario paths to fit, e.g. contactors.0.stiffness,excitation.scale.")
@click.option("--bounds", "bounds", multiple=True, metavar="PATH=LO:HI",
              help="Bounds of one parameter (repeatable; either end may be empty; units allowed).")
@click.option("--out", "out", default=None, metavar="FITTED.toml", help="Write the fitted scenario.")
@click.option("--json", "as_json", is_flag=True, help="Print JSON.")
@click.option("--excitation", "excitation", default=None, metavar="TRACE",
              help="Measured base-acceleration trace driving the model (its scale is excitation.scale).")
@click.option("--hold", type=click.Choice(["linear", "constant"]), default="linear", show_default=True)
@click.option("--point", "point", default=None, metavar="X", help="Where MEASURED was taken [m].")
@click.option("--window", "window", default=None, metavar="START:STOP", help="Fit only this time window [s].")
@click.option("--max-nfev", "max_nfev", type=int, default=100, show_default=True,
              help="Most simulations to run.")
@click.option("--conf-interval", "conf_interval", is_flag=True,
              help="Also compute lmfit's profile confidence intervals (slower).")
@_record_options
@handle_errors
def fit(
    scenario: str, measured: str, params: str, bounds: tuple[str, ...], out: str | None, as_json: bool,
    excitation: str | None, hold: str, point: str | None, window: str | None, max_nfev: int,
    conf_interval: bool, time_unit: str | None, value_unit: str | None, channel: str | None,
) -> None:
    """Least-squares fit of scenario parameters to the MEASURED deflection history.

    Each parameter starts at the scenario's value; the report gives the
    fitted values with standard errors and linearised 95 % intervals.
    With --out the fitted scenario is written as TOML (and a measured trace
    beside it as <stem>_excitation.csv). A fit that does not converge exits
    with status 1 after its report and writes nothing.
    """
    from ..experiment import load_record
    from ..fit import fit as run_fit
    from ..scenario import load_scenario

    check_output("--out", out, (".toml",))
    if max_nfev < 1:
        raise ParameterError(f"--max-nfev: must be a positive integer, got {max_nfev}")
    paths = [p.strip() for p in params.split(",") if p.strip()]
    bnds = list(bounds) if bounds else None
    win = _window(window)
    x = _point(point)
    sc = load_scenario(scenario)
    meas = load_record(measured, time_unit=time_unit, value_unit=value_unit, channel=channel, quantity="deflection")
    _note(meas)
    trace = _load_trace(excitation)
    res = run_fit(sc, meas, paths, bounds=bnds, point=x, excitation=trace, hold=hold,  # type: ignore[arg-type]
                  window=win, max_nfev=max_nfev, conf_interval=conf_interval)
    written: list[Path] = []
    failure: ImpactBeamError | None = None
    if not res.success:  # a failed computation: status 1, and no "fitted" scenario written
        failure = ImpactBeamError(
            f"the fit did not converge ({res.message}): its values are not a least-squares minimum"
            + (f"; {out} not written" if out is not None else "") + "; raise --max-nfev or narrow --bounds")
    elif out is not None:
        try:
            written = res.write_scenario(out)
        except WriteError as exc:  # reported after the fitted values, so they are not lost
            failure = exc
    if as_json:
        d = res.to_dict()
        d.update({"scenario": scenario, "measured": measured, "out": out,
                  "written": [str(p) for p in written], "warnings": take_warnings()})
        click.echo(json_text(d))
    else:  # the warnings go to stderr, printed by handle_errors when the command ends
        click.echo(res.report())
    for p in written:
        click.echo(f"wrote {p}", err=True)
    if failure is not None:
        raise failure
