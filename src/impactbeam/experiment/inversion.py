"""Model parameters from measured frequencies: the Young's modulus from the first free frequency, the contact
stiffness from the contact-state fundamental, and that fundamental from a contact record (paper sections 4.1-4.2).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any
import numpy as np

from ..exceptions import ParameterError, SimulationError
if TYPE_CHECKING:
    from ..scenario import Scenario
from .records import Record, _require

__all__ = [
    "ContactFrequency",
    "contact_frequency_from_record",
    "contact_state_frequency",
    "contact_stiffness_from_frequency",
    "modulus_from_frequency",
]


def _elastic_frequency(beam: Any, springs: Sequence[tuple[float, float]], mode: int) -> float:
    from ..modal import mode_set

    count = mode
    while True:
        ms = mode_set(beam, springs, count)
        if ms.count - ms.n_rigid >= mode:
            return float(ms.frequencies_hz[ms.n_rigid + mode - 1])
        count += ms.n_rigid


def modulus_from_frequency(scenario: Scenario, f1_measured: float, *, mode: int = 1) -> float:
    """Young's modulus that gives the scenario's free state the measured frequency (paper 4.1).

    Parameters
    ----------
    scenario : Scenario
    f1_measured : float, [Hz]
        Measured natural frequency of elastic mode ``mode`` (rigid-body modes
        are not counted).
    mode : int
        Which elastic mode (1 = the fundamental).

    Returns
    -------
    float, [Pa]

    Notes
    -----
    With rigid or free ends, ``omega_n = beta_n^2 sqrt(EI / rho A)`` with
    ``beta_n`` independent of E (paper, after eq. 5), so
    ``E_new = E (f_measured / f_model)^2``. The modes are then recomputed with
    ``E_new``; when they do not match to 1e-10 relative (elastic end springs
    make ``beta_n`` depend on E), E is refined by Brent's method.

    Raises
    ------
    ParameterError
        For a frequency that is not positive and finite.
    SimulationError
        If the recomputed frequency cannot be matched.
    """
    from scipy.optimize import brentq

    f_meas = float(f1_measured)
    if not (math.isfinite(f_meas) and f_meas > 0):
        raise ParameterError(f"f1_measured: must be a positive frequency in Hz, got {f1_measured!r}")
    beam = scenario.beam
    f_model = _elastic_frequency(beam, (), mode)
    e_new = beam.youngs_modulus * (f_meas / f_model) ** 2

    def mismatch(e: float) -> float:
        return _elastic_frequency(dataclasses.replace(beam, youngs_modulus=e), (), mode) / f_meas - 1.0

    err = mismatch(e_new)
    if abs(err) > 1e-10:
        lo, hi = e_new, e_new
        for _ in range(60):
            lo, hi = lo / 1.5, hi * 1.5
            if mismatch(lo) < 0 < mismatch(hi):
                break
        else:
            raise SimulationError(f"modulus_from_frequency: no modulus gives {f_meas:g} Hz")
        e_new = brentq(mismatch, lo, hi, xtol=1e-14 * e_new, rtol=1e-14)
        if abs(mismatch(e_new)) > 1e-9:
            raise SimulationError(f"modulus_from_frequency: could not match {f_meas:g} Hz")
    return float(e_new)


def contact_state_frequency(scenario: Scenario, stiffness: float, contactor: int = 0, *, mode: int = 1) -> float:
    """Elastic frequency ``mode`` [Hz] of the state with contactor ``contactor`` engaged at ``stiffness``.

    Parameters
    ----------
    scenario : Scenario
    stiffness : float, [N/m]
        Contact stiffness of the engaged contactor.
    contactor : int
        Index of the contactor.
    mode : int
        Which elastic mode (1 = the fundamental).
    """
    c = _contactor(scenario, contactor)
    return _elastic_frequency(scenario.beam, ((c.position, float(stiffness)),), mode)


def _contactor(scenario: Scenario, contactor: int) -> Any:
    if not scenario.contactors:
        raise ParameterError("contactors: the scenario has no contactor")
    if not 0 <= contactor < len(scenario.contactors):
        raise ParameterError(
            f"contactor: index {contactor} out of range (the scenario has {len(scenario.contactors)})"
        )
    return scenario.contactors[contactor]


def contact_stiffness_from_frequency(scenario: Scenario, f_contact: float, contactor: int = 0) -> float:
    """Contact stiffness whose contact-state fundamental equals ``f_contact`` (paper 4.2).

    Parameters
    ----------
    scenario : Scenario
        Beam and contactor position (the gap does not change the contact
        state's frequencies: it only adds a constant force).
    f_contact : float, [Hz]
        Measured fundamental of the contact state.
    contactor : int
        Which contactor is engaged (the others stay free).

    Returns
    -------
    float, [N/m]

    Notes
    -----
    The fundamental of the beam with the spring ``k`` at ``a`` rises
    monotonically from the free-state fundamental (``k -> 0``) to that of the
    beam pinned at ``a`` (``k -> inf``); ``k`` is found by Brent's method on
    ``log k``, each step an exact modal analysis (:func:`impactbeam.mode_set`).
    The paper matched the frequency of the contact portion of Case 3 and
    found 4030 N/m.

    Raises
    ------
    ParameterError
        When ``f_contact`` lies outside the attainable range (the message
        gives it), or the scenario has no such contactor.
    """
    from scipy.optimize import brentq

    f = float(f_contact)
    if not (math.isfinite(f) and f > 0):
        raise ParameterError(f"f_contact: must be a positive frequency in Hz, got {f_contact!r}")
    c = _contactor(scenario, contactor)
    beam = scenario.beam
    k_ref = 3.0 * beam.bending_stiffness / beam.length**3
    lo, hi = math.log(k_ref * 1e-8), math.log(k_ref * 1e10)

    def g(logk: float) -> float:
        return _elastic_frequency(beam, ((c.position, math.exp(logk)),), 1) - f

    g_lo, g_hi = g(lo) + f, g(hi) + f
    if not g_lo < f < g_hi:
        raise ParameterError(
            f"f_contact: {f:.6g} Hz is outside the range of contact-state fundamentals "
            f"({g_lo:.6g} Hz for a soft contact to {g_hi:.6g} Hz for a rigid one at x = {c.position:.6g} m)"
        )
    logk = brentq(g, lo, hi, xtol=1e-13, rtol=1e-14)
    return float(math.exp(logk))


@dataclass(frozen=True, eq=False)
class ContactFrequency:
    """Frequency of the contact portions of a deflection record (paper 4.2).

    Attributes
    ----------
    frequency_hz : float
        From a least-squares fit of ``c_i + a_i sin(omega t) + b_i cos(omega t)``
        to the samples of every contact interval ``i``, with one ``omega``
        shared by all intervals.
    half_period_hz : float
        ``1 / (2 mean duration)``: each contact taken as half a cycle (biased high, see Notes).
    intervals : list of (float, float)
        Contact intervals [s] (threshold crossings, linearly interpolated).
    n_samples : int
        Samples used by the fit.
    rms_residual : float, [m]
        RMS of the fit residual.
    """

    frequency_hz: float
    half_period_hz: float
    intervals: list[tuple[float, float]]
    n_samples: int
    rms_residual: float


def _crossings(t: np.ndarray, s: np.ndarray) -> list[tuple[float, float, int, int]]:
    """Intervals where ``s > 0``: (start, end, first index, last index), ends linearly interpolated."""
    pos = s > 0
    out = []
    i = 0
    n = s.size
    while i < n:
        if not pos[i]:
            i += 1
            continue
        j = i
        while j + 1 < n and pos[j + 1]:
            j += 1
        if i > 0:
            t0 = t[i - 1] + (t[i] - t[i - 1]) * (0 - s[i - 1]) / (s[i] - s[i - 1])
        else:
            t0 = t[0]
        if j < n - 1:
            t1 = t[j] + (t[j + 1] - t[j]) * (0 - s[j]) / (s[j + 1] - s[j])
        else:
            t1 = t[-1]
        out.append((float(t0), float(t1), i, j))
        i = j + 1
    return out


def contact_frequency_from_record(
    record: Record, scenario: Scenario, *, contactor: int = 0, min_samples: int = 5
) -> ContactFrequency:
    """Frequency of the contact portions of a deflection record at the contactor (paper 4.2).

    Parameters
    ----------
    record : Record
        Deflection ``w`` at the contactor's position (model sign convention).
    scenario : Scenario
        Gives the contactor's side and gap: a sample is in contact when the
        beam is beyond the contactor surface (``w > gap`` above, ``w < -gap`` below).
    contactor : int
    min_samples : int
        Contact intervals with fewer samples are not used by the fit.

    Returns
    -------
    ContactFrequency

    Notes
    -----
    The paper took an FFT of "the contact portion of a captured response".
    The portions are short (about 4 ms, 8 samples at 2 kHz), so neither
    concatenating them for an FFT (the joins add spurious content) nor timing
    them as half cycles is accurate: while engaged the beam oscillates about
    the contact state's equilibrium, which the gap preload puts on the free
    side of the surface (``w_eq(a) = k c / (k + K_a)``, ``K_a`` the beam's
    stiffness at ``a``), so each contact lasts *less* than half a period and
    ``half_period_hz`` is biased high (by 10-30 % in Case 3, more as the
    contacts weaken). Instead, the samples of all contact intervals are
    fitted together by ``w_eq + a_i sin(omega t) + b_i cos(omega t)``: one
    amplitude and phase per interval, one equilibrium ``w_eq`` and one
    frequency shared by all (variable projection: grid search over omega
    refined by Brent's method); intervals of different amplitudes make
    ``w_eq`` and omega separable.

    This is an *approximate* frequency: a contact lasts less than half a
    cycle of the fundamental while the projection of the free motion onto
    the contact modes (paper eq. 12) also excites the second contact mode,
    so a single sinusoid describes the arcs only roughly. On noise-free
    simulated Case 3 records at 2 kHz it lands within about 10 % of the
    model's contact fundamental (often within 1-2 %), and noise of 5 um adds
    a few percent; the contact stiffness it gives (about 5 times more
    sensitive) is a starting value for :func:`impactbeam.fit.fit`, which
    recovers k from the whole history within 2 %.

    Raises
    ------
    ParameterError
        A record that is not a deflection, or no contact interval with
        ``min_samples`` samples.
    """
    from scipy.optimize import minimize_scalar

    _require(record, "deflection", "the contact frequency")
    c = _contactor(scenario, contactor)
    t, w = record.time, record.values
    beyond = c.direction * w - c.gap
    ivs = _crossings(t, beyond)
    used = [(i0, i1) for _, _, i0, i1 in ivs if i1 - i0 + 1 >= min_samples]
    if not used:
        raise ParameterError(
            f"{record.label}: no contact interval with {min_samples} samples or more "
            f"(beyond the contactor surface at w = {c.direction * c.gap:+.4g} m)"
        )
    durations = [b - a for a, b, i0, i1 in ivs if i1 - i0 + 1 >= min_samples]
    half = 1.0 / (2.0 * float(np.mean(durations)))
    segs = [(t[i0 : i1 + 1], w[i0 : i1 + 1]) for i0, i1 in used]

    n_used = sum(ts.size for ts, _ in segs)
    rows = np.concatenate([np.full(ts.size, i) for i, (ts, _) in enumerate(segs)])
    tau = np.concatenate([ts - ts.mean() for ts, _ in segs])
    ws = np.concatenate([w_ for _, w_ in segs])

    def design(omega: float) -> np.ndarray:
        A = np.zeros((n_used, 1 + 2 * len(segs)))
        A[:, 0] = 1.0  # the contact-state equilibrium, shared by every interval
        A[np.arange(n_used), 1 + 2 * rows] = np.sin(omega * tau)
        A[np.arange(n_used), 2 + 2 * rows] = np.cos(omega * tau)
        return A

    def cost(omega: float) -> float:
        A = design(omega)
        coef, *_ = np.linalg.lstsq(A, ws, rcond=None)
        r = ws - A @ coef
        return float(r @ r)

    w0 = 2 * math.pi * half
    grid = np.linspace(0.4 * w0, 1.6 * w0, 241)
    costs = np.array([cost(o) for o in grid])
    k = int(np.argmin(costs))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    res = minimize_scalar(cost, bounds=(lo, hi), method="bounded", options={"xatol": 1e-10 * w0})
    omega = float(res.x)
    return ContactFrequency(
        frequency_hz=omega / (2 * math.pi),
        half_period_hz=half,
        intervals=[(a, b) for a, b, _, _ in ivs],
        n_samples=int(n_used),
        rms_residual=math.sqrt(cost(omega) / n_used),
    )
