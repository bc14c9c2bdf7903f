"""Identification from a free-decay record: frequencies, damping, modulus, contact stiffness.

:func:`identify` is the API behind ``impactbeam identify`` (paper section 4):
the natural frequencies from the spectrum
(:func:`impactbeam.experiment.identify_frequencies`), the damping ratio of
each mode by two independent estimators that work on records of ~10 cycles
(:mod:`impactbeam.experiment.damping`: a damped-sine least-squares fit and the
matrix-pencil method) with their spread, the logarithmic decrement of the
paper where the record is long enough, and, with a scenario, the Young's
modulus matching the first frequency (section 4.1) and the contact
stiffness matching a contact-state frequency (section 4.2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from .._warnings import emit_user_level_warning
from ..exceptions import ParameterError

if TYPE_CHECKING:
    from .damping import DampingEstimate
    from .records import Record
    from .spectral import FrequencyEstimate
    from ..scenario import Scenario

__all__ = ["MIN_OSCILLATION", "Identification", "ModeDamping", "identify"]

#: A record whose detrended rms is below this fraction of its largest magnitude
#: holds no oscillation (round-off of a constant is ~1e-16 of it).
MIN_OSCILLATION = 1e-9


@dataclass(frozen=True)
class ModeDamping:
    """Damping of one mode by each estimator.

    Attributes
    ----------
    frequency_hz : float
        Spectral peak (damped frequency) [Hz].
    fit : float
        Damped-sine least-squares estimate (the reported value; NaN, with a
        warning, if the fit did not converge).
    fit_standard_error : float
        Its linearised standard error.
    pencil : float
        Matrix-pencil estimate (NaN if no pole near the frequency).
    log_decrement : DampingEstimate or None
        The paper's logarithmic decrement, when the record holds enough
        cycles clear of the band-pass filter's transients.
    log_decrement_note : str or None
        Why there is no logarithmic decrement.
    """

    frequency_hz: float
    fit: float
    fit_standard_error: float
    pencil: float
    log_decrement: DampingEstimate | None = None
    log_decrement_note: str | None = None

    @property
    def spread(self) -> float:
        """``|fit - pencil|``: the disagreement of the two independent estimators (NaN without a pencil value)."""
        return abs(self.fit - self.pencil)


@dataclass(frozen=True, eq=False)
class Identification:
    """Result of :func:`identify`; :meth:`to_dict` is the ``identify --json`` output.

    Parameters
    ----------
    record : Record
        The free-decay record.
    frequencies : FrequencyEstimate
        Spectral peaks.
    damping : tuple of ModeDamping
        Per mode, the damping estimates.
    model : dict
        Modulus and contact stiffness identified with a scenario.
    updates : dict of str to float
        Dotted scenario paths -> identified values.
    """

    record: Record
    frequencies: FrequencyEstimate = field(repr=False)
    damping: tuple[ModeDamping, ...]
    model: dict[str, Any] = field(default_factory=dict)
    updates: dict[str, float] = field(default_factory=dict)

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Identified (damped) frequencies [Hz]."""
        return self.frequencies.frequencies_hz

    @property
    def damping_ratios(self) -> np.ndarray:
        """Reported damping ratios (the least-squares fit), one per mode."""
        return np.array([d.fit for d in self.damping])

    def to_dict(self) -> dict[str, Any]:
        """Plain-Python summary (the JSON of the command line)."""
        rec = self.record
        out: dict[str, Any] = {
            "record": str(rec.source) if rec.source is not None else rec.name,
            "n_samples": int(rec.time.size),
            "duration_s": rec.duration,
            "sample_rate_hz": rec.sample_rate,
            "resolution_hz": self.frequencies.resolution_hz,
            "frequencies_hz": [float(f) for f in self.frequencies_hz],
            "damping_ratios": [_finite_or_none(d.fit) for d in self.damping],
            "damping_standard_errors": [_finite_or_none(d.fit_standard_error) for d in self.damping],
            "damping_matrix_pencil": [_finite_or_none(d.pencil) for d in self.damping],
            "damping_spread": [_finite_or_none(d.spread) for d in self.damping],
            "damping_log_decrement": [
                None if d.log_decrement is None else d.log_decrement.damping_ratio for d in self.damping
            ],
            "damping_cycle_spread": [None if d.log_decrement is None else d.log_decrement.spread for d in self.damping],
            "damping_cycles": [None if d.log_decrement is None else d.log_decrement.n_cycles for d in self.damping],
            "notes": list(rec.notes),
        }
        out.update(self.model)
        return out


def _require_oscillation(record: Record) -> None:
    """Refuse a record with no oscillation (constant, or a pure trend) before any spectrum."""
    from scipy.signal import detrend

    x = np.asarray(record.values, dtype=float)
    scale = float(np.max(np.abs(x)))
    rms = float(np.sqrt(np.mean(detrend(x) ** 2)))
    if scale == 0.0 or rms <= MIN_OSCILLATION * scale:
        raise ParameterError(
            f"{record.label}: no significant oscillation (detrended rms {rms:.3g} {record.unit}, "
            f"{'all zero' if scale == 0.0 else f'{rms / scale:.2g} of the largest value'}); "
            "identification needs a free decay"
        )


def _fit_values(fit: Any) -> tuple[np.ndarray, np.ndarray]:
    return np.asarray(fit.damping_ratios, dtype=float), np.asarray(fit.standard_errors, dtype=float)


def _finite_or_none(x: float) -> float | None:
    return x if math.isfinite(x) else None


def _damping(record: Record, freqs: list[float]) -> tuple[ModeDamping, ...]:
    from .damping import damping_log_decrement, damping_matrix_pencil, damping_sine_fit

    nan = np.full(len(freqs), np.nan)
    try:
        fit_xi, fit_se = _fit_values(damping_sine_fit(record.time, record.values, freqs))
    except ParameterError as exc:  # no convergence: report the other estimators, say why
        emit_user_level_warning(f"{record.label}: no damped-sine fit ({exc}); damping from the matrix pencil only")
        fit_xi, fit_se = nan, nan
    try:
        pencil, _ = damping_matrix_pencil(record.values, record.step, freqs)
    except ParameterError as exc:
        emit_user_level_warning(f"{record.label}: no matrix-pencil estimate ({exc})")
        pencil = nan
    out = []
    for k, f in enumerate(freqs):
        logdec, note = None, None
        try:
            logdec = damping_log_decrement(record, f, neighbours=[g for g in freqs if g != f])
        except ParameterError as exc:
            note = str(exc).split(": ", 1)[-1]
        out.append(ModeDamping(
            frequency_hz=f, fit=float(fit_xi[k]), fit_standard_error=float(fit_se[k]),
            pencil=float(pencil[k]), log_decrement=logdec, log_decrement_note=note,
        ))
    return tuple(out)


def identify(
    record: Record,
    count: int = 2,
    *,
    scenario: Scenario | None = None,
    contact_frequency: float | None = None,
    contact_record: Record | None = None,
    contactor: int = 0,
) -> Identification:
    """Identify frequencies, damping and (with a scenario) modulus and contact stiffness.

    Parameters
    ----------
    record : Record
        A free-decay deflection record (paper Case 0/13), uniformly sampled.
    count : int
        Number of modes.
    scenario : Scenario, optional
        Its Young's modulus is matched to the first (undamped) frequency, paper 4.1.
    contact_frequency : float, optional, [Hz]
        Measured contact-state fundamental: gives the contact stiffness (paper 4.2).
    contact_record : Record, optional
        Deflection at the contactor; its contact portions give the contact frequency.
    contactor : int
        Index of the contactor for the contact stiffness.

    Returns
    -------
    Identification
        ``updates`` maps scenario paths to identified values
        (``beam.youngs_modulus``, ``contactors.N.stiffness``).

    Notes
    -----
    The damping ratio reported is the damped-sine least-squares fit over all
    ``count`` modes at once; the matrix pencil is the second, independent
    estimate and ``spread`` their difference. The undamped first frequency
    used for the modulus is ``f_d / sqrt(1 - xi^2)``.

    Raises
    ------
    ParameterError
        For an acceleration record, a record with no significant oscillation,
        ``count < 1``, too few spectral peaks, a contact option without a
        scenario, or both contact options.
    """
    from .inversion import (
        contact_frequency_from_record,
        contact_state_frequency,
        contact_stiffness_from_frequency,
        modulus_from_frequency,
    )
    from .spectral import identify_frequencies

    if isinstance(count, bool) or not isinstance(count, int) or count < 1:
        raise ParameterError(f"count: must be a positive integer, got {count!r}")
    if (contact_frequency is not None or contact_record is not None) and scenario is None:
        raise ParameterError("contact_frequency/contact_record: need a scenario (the beam and contactor)")
    if contact_frequency is not None and contact_record is not None:
        raise ParameterError("contact_frequency and contact_record: give one, not both")
    if record.quantity != "deflection":
        raise ParameterError(f"{record.label}: identification needs a deflection record, got an acceleration")
    _require_oscillation(record)
    _warn_clipped(record)
    fe = identify_frequencies(record, count)
    freqs = [float(f) for f in fe.frequencies_hz]
    damping = _damping(record, freqs)
    _warn_disagreement(record, damping)
    model: dict[str, Any] = {}
    updates: dict[str, float] = {}
    if scenario is not None:
        from ..modal import mode_set

        f1n = freqs[0] / math.sqrt(1.0 - _resolved_damping(damping[0]) ** 2)
        ms0 = mode_set(scenario.beam, (), scenario.solver.modes)
        mode = _model_mode(record, freqs[0], f1n, ms0.frequencies_hz[ms0.n_rigid:])
        e_new = modulus_from_frequency(scenario, f1n, mode=mode)
        updates["beam.youngs_modulus"] = e_new
        sc_e = scenario.with_values({"beam.youngs_modulus": e_new})
        ms1 = mode_set(sc_e.beam, (), scenario.solver.modes)
        _warn_aliases(record, freqs, ms1.frequencies_hz[ms1.n_rigid:], fe.resolution_hz)
        model.update({
            "natural_frequency_hz": f1n,
            "mode": mode,
            "model_frequencies_hz": [float(f) for f in ms0.frequencies_hz[ms0.n_rigid : ms0.n_rigid + count]],
            "scenario_youngs_modulus": scenario.beam.youngs_modulus,
            "youngs_modulus": e_new,
            "youngs_modulus_change_percent": 100.0 * (e_new / scenario.beam.youngs_modulus - 1.0),
            "tuned_frequencies_hz": [float(f) for f in ms1.frequencies_hz[ms1.n_rigid : ms1.n_rigid + count]],
        })
        f_contact = contact_frequency
        if contact_record is not None:
            cf = contact_frequency_from_record(contact_record, sc_e, contactor=contactor)
            f_contact = cf.frequency_hz
            model.update({
                "contact_record": str(contact_record.source) if contact_record.source else contact_record.name,
                "contact_intervals": len(cf.intervals),
                "contact_frequency_half_period_hz": cf.half_period_hz,
            })
        if f_contact is not None:
            k = contact_stiffness_from_frequency(sc_e, f_contact, contactor)
            updates[f"contactors.{contactor}.stiffness"] = k
            k0 = scenario.contactors[contactor].stiffness
            model.update({
                "contact_frequency_hz": f_contact,
                "scenario_contact_stiffness": k0,
                "scenario_contact_frequency_hz": contact_state_frequency(sc_e, k0, contactor),
                "contact_stiffness": k,
            })
    return Identification(record=record, frequencies=fe, damping=damping, model=model, updates=updates)


def _resolved_damping(d: ModeDamping) -> float:
    """The damping that corrects the first mode's damped frequency: the fit's, when it is resolved, else 0.

    Resolved: a ratio in [0, 1) with a standard error under half of it, which
    the matrix pencil confirms within half of it too. On a record of about
    one cycle the fit can land on a large damping with a standard error just
    under half of it (71 +/- 30 % against the pencil's 0.97 % on 20 ms of a
    61 Hz decay), and its correction would raise the frequency 1.4 times and
    the modulus twice.
    """
    fit, se, pencil = d.fit, d.fit_standard_error, d.pencil
    if not (math.isfinite(fit) and 0.0 <= fit < 1.0 and se < 0.5 * fit):
        return 0.0
    if math.isfinite(pencil) and abs(fit - pencil) > 0.5 * fit:
        return 0.0
    return fit


#: Fit and pencil disagreeing by more than this many standard errors of the fit, and by more than
#: DISAGREE_RELATIVE of the fit, are warned about (:func:`_warn_disagreement`).
DISAGREE_ERRORS = 5.0
DISAGREE_RELATIVE = 0.05


def _warn_disagreement(record: Record, damping: tuple[ModeDamping, ...]) -> None:
    """Warn of modes whose two damping estimates disagree: the record does not follow the model.

    The standard error is the fit's alone, under the model of decaying
    sines in white noise; a clipped sensor, a mode missing from the count or
    an alias breaks that model, and the estimates then part by many standard
    errors (0.709 +/- 0.010 % against the pencil's 1.26 % on a record clipped
    at its rails, the truth 1.0 %).
    """
    for k, d in enumerate(damping, start=1):
        if not (math.isfinite(d.spread) and math.isfinite(d.fit_standard_error)):
            continue
        if d.spread > DISAGREE_ERRORS * d.fit_standard_error and d.spread > DISAGREE_RELATIVE * abs(d.fit):
            emit_user_level_warning(
                f"{record.label}: mode {k} ({d.frequency_hz:.5g} Hz): the damping fit {100 * d.fit:.4g} +/- "
                f"{100 * d.fit_standard_error:.2g} % and the matrix pencil {100 * d.pencil:.4g} % differ by "
                f"{d.spread / d.fit_standard_error:.0f} standard errors: the record does not follow a sum of "
                "decaying sines in noise (a clipped sensor, a mode missing from the count, an alias, non-linear "
                "damping), so neither value nor the standard error can be trusted"
            )


def _warn_clipped(record: Record) -> None:
    """Warn when the record sits at its largest or smallest value in more than one place (a saturated sensor).

    A free decay reaches its extremes once, in its first cycles; a sensor
    that saturates holds its rail on several cycles (16 % of the samples at
    +/-1 mm on a 2 mm decay). Clipping biases the damping and adds harmonics
    that pass for modes (one at 5 f1 was read as mode 2).
    """
    v = np.asarray(record.values, dtype=float)
    for rail, name in ((v.max(), "largest"), (v.min(), "smallest")):
        at = v == rail
        runs = int(np.count_nonzero(at[1:] & ~at[:-1]) + at[0])
        if runs >= 2 and np.count_nonzero(at) >= 4:
            emit_user_level_warning(
                f"{record.label}: {np.count_nonzero(at)} samples in {runs} separate places sit exactly at the "
                f"record's {name} value ({rail:.6g} {record.unit}): a saturated (clipped) sensor; clipping biases "
                "the damping and adds harmonics of the first mode that pass for modes"
            )


def _warn_aliases(record: Record, freqs: list[float], model_hz: np.ndarray, resolution: float) -> None:
    """Warn of identified frequencies where a model mode above the Nyquist frequency would appear aliased.

    Sampled at ``fs``, a mode at ``f > fs / 2`` shows at ``|f - n fs|``; its
    damping is then read ``f / |f - n fs|`` times too high (the decay per
    second is the true one, the cycles fewer). ``model_hz``: the model's
    elastic frequencies with the identified modulus; a frequency one of them
    below the Nyquist frequency explains is not questioned (the high modes'
    aliases fall anywhere).
    """
    fs = record.sample_rate

    def near(a: float, f: float) -> bool:
        return abs(a - f) <= max(0.03 * f, 3.0 * resolution)

    for k, f in enumerate(freqs, start=1):
        if any(near(fm, f) for fm in model_hz if fm <= 0.5 * fs):
            continue  # a mode of the model below the Nyquist frequency explains it
        for m, fm in enumerate(model_hz, start=1):
            if fm <= 0.5 * fs:
                continue
            if near(abs(fm - fs * round(fm / fs)), f):
                emit_user_level_warning(
                    f"{record.label}: mode {k} at {f:.5g} Hz is where the model's mode {m} ({fm:.5g} Hz, above the "
                    f"Nyquist frequency {0.5 * fs:.5g} Hz of the {fs:.5g} Hz sampling) appears aliased: if it is "
                    f"that mode, its damping reads {fm / f:.3g} times too high; sample faster or filter "
                    "(anti-aliasing) before sampling"
                )
                break


def _model_mode(record: Record, f_damped: float, f: float, model_hz: np.ndarray) -> int:
    """The model's elastic mode (1, 2, ...) nearest ``f`` in ratio, warned when it is not the first.

    The record's lowest identified frequency is taken for the first mode; on a
    record of few cycles of it (or with it weakly excited) the strongest peak
    can be the second, and the modulus from it read as the first's would be
    off by the square of their ratio (x88 on a 0.05 s free decay of the
    specimen). A record sampled below twice the model's first frequency
    shows aliases: warned too.
    """
    dt = float(np.median(np.diff(record.time)))
    if model_hz.size and 0.5 / dt < model_hz[0]:
        emit_user_level_warning(
            f"{record.label}: sampled at {1 / dt:.4g} Hz, below twice the model's first frequency "
            f"({model_hz[0]:.4g} Hz): the identified frequencies may be aliases"
        )
    if not model_hz.size:
        return 1
    mode = int(np.argmin(np.abs(np.log(model_hz / f)))) + 1
    if mode != 1:
        emit_user_level_warning(
            f"{record.label}: the lowest identified frequency, {f_damped:.5g} Hz ({f:.5g} Hz undamped), is nearest "
            f"the model's mode {mode} "
            f"({model_hz[mode - 1]:.5g} Hz), not its first ({model_hz[0]:.5g} Hz): the modulus is taken from "
            f"mode {mode}; a longer record or a larger count finds the first"
        )
    return mode

