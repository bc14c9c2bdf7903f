"""The linear steady state of the harmonically forced beam, and when it is the answer.

Without contact the free state's modal equations (paper eq. 9) under the
harmonic load ``u(t) = A sin(2 pi f (t - start) + phase)`` have the periodic
solution

``eta_n(t) = Im[ p_n A e^{i (Omega (t - start) + phase)} / (omega_n^2 - Omega^2 + 2 i xi_n omega_n Omega) ]``,

``Omega = 2 pi f``, with the modes ``W_n``, frequencies ``omega_n``, decay
rates ``xi_n omega_n`` and load weights ``p_n`` of the solver's free state
(:func:`linear_frf` is its amplitude at a point, :func:`linear_steady_state`
its state at the load's start).

Any other motion is that solution plus a free transient. Mode ``n`` of the
transient, underdamped, is ``e^{-xi_n omega_n t} (a_n cos omega_dn t + b_n
sin omega_dn t)``, never larger than ``R_n = sqrt(a_n^2 + b_n^2)``; so at a
contactor ``a`` the deflection never exceeds ``|H(a)| A + sum_n |W_n(a)|
R_n``. When that bound stays short of every contactor's gap, the beam never
touches a stop from this state on, and the transient decays to the linear
steady state: :func:`linear_limit` returns it, and a steady-state analysis
records it exactly instead of waiting for a lightly damped transient to fade
(:func:`~impactbeam.periodic.strobe.settle_and_record`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from ..exceptions import ParameterError
from .forcing import harmonic_period, strobe_point

if TYPE_CHECKING:
    from ..scenario import Scenario
    from ..solver.solution import ModalState

__all__ = ["linear_frf", "linear_steady_state", "linear_limit"]

#: Part of each gap the bound of :func:`linear_limit` may reach: a margin far above round-off.
CLEAR_FRACTION = 1.0 - 1e-6


def _free_state(scenario: Scenario) -> tuple[Any, Any]:
    """The packed problem of the solver and its free state (slot 0)."""
    from ..solver.engine import pack

    opt = scenario.solver
    if opt.modes == "auto":
        opt = dataclasses.replace(opt, modes=8)
    pk = pack(scenario.beam, tuple(scenario.contactors), scenario.damping, scenario.excitation, opt)
    return pk, opt


def linear_frf(scenario: Scenario, frequencies: Sequence[float | str] | np.ndarray,
               points: Sequence[float] | None = None) -> np.ndarray:
    """Complex amplitude of ``w`` per unit load amplitude, without contact (module docstring).

    Parameters
    ----------
    scenario : Scenario
        Its beam, damping, load distribution (``excitation.kind``) and modes
        (``solver.modes = "auto"`` is read as 8); contactors are kept open.
    frequencies : array_like, [Hz]
        Numbers in Hz, or strings with units (``"60 Hz"``, ``"3600 rpm"``).
    points : sequence of float, optional, [m]
        Default: the strobe point (first contactor, else first output point).

    Returns
    -------
    ndarray, complex, (n_frequencies, n_points)
        ``H`` in m per unit of ``excitation.amplitude`` (times ``excitation.scale``).

    Raises
    ------
    ParameterError
        A point off the beam, or a negative or non-finite frequency.
    """
    pk, _ = _free_state(scenario)
    x = np.asarray([strobe_point(scenario)] if points is None else points, dtype=float)
    L = scenario.beam.length
    bad = ~np.isfinite(x) | (x < 0.0) | (x > L * (1.0 + 1e-12))
    if x.ndim != 1 or bad.any():
        shown = x[bad][0] if x.ndim == 1 else x
        raise ParameterError(f"points: {shown} m is not a position on the beam [0, {L:g}] m (a 1-D list)")
    if not isinstance(frequencies, np.ndarray) and any(isinstance(v, str) for v in np.ravel(frequencies)):
        from ..units import to_si  # strings with units, as everywhere else ("60 Hz", "3600 rpm")

        frequencies = [to_si(v, "frequency", f"frequencies (value {i + 1})") for i, v in enumerate(frequencies)]
    f = np.asarray(frequencies, dtype=float)
    if f.ndim > 1 or not np.all(np.isfinite(f)) or np.any(f < 0.0):
        raise ParameterError("frequencies: expected finite frequencies >= 0 [Hz] in a 1-D list")
    W = pk.rows(x)[0]  # (n_x, n_modes), free state
    om, dec, pw = pk.om[0], pk.dec[0], pk.pw[0]
    Om = 2.0 * np.pi * np.atleast_1d(f)[:, None]
    modal = pw[None, :] / (om[None, :] ** 2 - Om**2 + 2j * dec[None, :] * Om)
    return modal @ W.T


def _complex_amplitudes(pk: Any, scenario: Scenario) -> np.ndarray:
    """``p_n A e^{i phase} / (omega_n^2 - Omega^2 + 2 i xi_n omega_n Omega)`` (module docstring)."""
    ex = scenario.excitation
    om, dec, pw = pk.om[0], pk.dec[0], pk.pw[0]
    Om = 2.0 * np.pi * float(ex.frequency)  # type: ignore[arg-type]
    return pw * (ex.scale * ex.amplitude) / (om**2 - Om**2 + 2j * dec * Om) * np.exp(1j * ex.phase)


def linear_steady_state(scenario: Scenario) -> ModalState:
    """The periodic state of the free (no contact) beam when its harmonic load has phase ``phase``.

    A run from this state (``simulate(..., start=)``, load on from t = 0)
    stays on the linear steady state as long as no contactor is touched:
    a start with no transient for frequency-response curves and tests.
    """
    harmonic_period(scenario)
    pk, opt = _free_state(scenario)
    return _steady_state(pk, opt, scenario, _complex_amplitudes(pk, scenario))


def _steady_state(pk: Any, opt: Any, scenario: Scenario, q: np.ndarray) -> ModalState:
    """:func:`linear_steady_state` from the complex amplitudes ``q`` of the free state's modes."""
    from ..solver.solution import ModalState, basis_signature

    Om = 2.0 * np.pi * float(scenario.excitation.frequency)  # type: ignore[arg-type]
    basis = basis_signature(scenario.beam, scenario.contactors, int(opt.modes), opt.basis, scenario.excitation)
    return ModalState(0.0, np.ascontiguousarray(q.imag), np.ascontiguousarray((1j * Om * q).imag), basis)


def linear_limit(scenario: Scenario, start: ModalState | None) -> ModalState | None:
    """The linear steady state when the beam provably never touches a stop from ``start``; else None.

    Parameters
    ----------
    scenario : Scenario
        Harmonically forced, with the load on from the start of the run.
    start : ModalState or None
        The state the run begins from (the load switched on at once); None
        for the scenario's initial condition, which must then be rest.

    Returns
    -------
    ModalState or None
        :func:`linear_steady_state` when the bound of the module docstring
        stays within :data:`CLEAR_FRACTION` of every gap (without contactors:
        always, the beam being linear); None when it does
        not, or when the bound does not apply: a preload, a mode that is not
        underdamped (or undamped, so no transient decays), a free state whose
        damping its modes do not diagonalise, ``solver.modes = "auto"``, a
        start in another basis or a non-rest initial condition.
    """
    opt = scenario.solver
    if opt.modes == "auto" or scenario.preload is not None:
        return None
    if start is None and not scenario.initial.at_rest:
        return None
    pk, opt = _free_state(scenario)
    om, dec, wd = pk.om[0], pk.dec[0], pk.wdh[0]
    if pk.gen[0] or np.any(pk.reg[0] != 0) or not np.all(dec > 0.0) or np.any(pk.pre[0] != 0.0):
        return None
    q = _complex_amplitudes(pk, scenario)
    steady = _steady_state(pk, opt, scenario, q)
    if start is not None and start.basis != steady.basis:
        return None
    # the transient: the start's departure from the steady state (from rest, minus the steady state itself)
    a = (np.zeros_like(om) if start is None else start.eta) - steady.eta
    b = (np.zeros_like(om) if start is None else start.deta) - steady.deta
    R = np.hypot(a, (b + dec * a) / wd)
    Wc = pk.Wc[0]  # (n_contactors, n_modes)
    reach = np.abs(Wc @ q) + np.abs(Wc) @ R
    gaps = np.array([c.gap for c in scenario.contactors], dtype=float)
    return steady if bool(np.all(reach < CLEAR_FRACTION * gaps)) else None
