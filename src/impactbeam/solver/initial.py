"""The state at t = 0 in the run's basis: fields projected in the kinetic inner product, or the static equilibrium.

The one rule for every initial condition of ``[initial]``
(:class:`~impactbeam.model.starting.InitialCondition`), for the paper's
per-state modes and for the shared Ritz basis alike. A displacement field
``u(x)`` and a velocity field ``v(x)`` along the beam become modal
coordinates by the projection that defines them (paper eq. 12 with the
field in place of the old state's modes),

.. math:: \\eta_n = \\int_0^L \\rho A\\, u\\, W_n\\,dx + \\sum_j m_j u(x_j) W_n(x_j)
          + \\int_0^L \\rho I\\, \\theta_u \\Psi_n\\,dx + \\sum_j J_j \\theta_u(x_j) \\Psi_n(x_j),

the kinetic inner product of the model (the ``rho I`` term for a Timoshenko
beam, the point masses' ``m`` and ``J``), ``theta_u`` being the rotation of
the cross-sections that goes with the field (``u'``, or the rotation of a
rigid rotation, or the static solver's ``Psi``). The modes are
mass-orthonormal, so this is the best approximation of the field in the
kinetic norm, and what it misses,
``|u - sum eta_n W_n| / |u|`` in that norm (the relative kinetic-norm
residual), is reported by a warning when it exceeds
:data:`RESIDUAL_WARNING`: motion the supports forbid (a uniform velocity of a
clamped beam), or detail finer than the retained modes.

The fields:

* ``tip_displacement``: the exact static shape of a point force at
  ``position`` (default the right end), from the static solver
  (:func:`impactbeam.modal.static_state`), scaled to that deflection there;
* ``displacement`` / ``velocity`` profiles: linear between their rows;
* ``velocity``: a uniform translation; ``angular_velocity`` about ``pivot``:
  the rigid rotation ``v = Omega (x - pivot)``, sections turning at ``Omega``;
  the two add up (any rigid motion);
* ``equilibrium``: the static equilibrium of the run's model under the
  preload (:mod:`.equilibrium`), with the contactors it engages.

Quadrature: 20-point Gauss-Legendre on pieces no longer than half the
shortest wavelength of the retained modes (twice the Euler-Bernoulli
wavenumber of the highest frequency, or its shear and bar wavenumbers when
larger), cut at every node of the beam, contactor, profile row and load
point, so every piece is smooth; the projection is exact to round-off.

``modal_displacement`` / ``modal_velocity`` add to the first ``N``
coordinates of the free state (the retained free modes).

The state is built in the state it starts in (the free state, or the
equilibrium's engaged state) and carried back to the free state's
coordinates through the transfers the engine applies at t = 0 when it
engages those contactors one by one (in increasing index), so that the
engine, starting in the free state, arrives exactly in it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from .._warnings import emit_user_level_warning
from ..exceptions import ParameterError
from ..modal import static_state
from ..model.beam import Beam, Contactor
from ..model.starting import InitialCondition, Preload, Profile
from .equilibrium import continuum_equilibrium, modal_equilibrium

__all__ = ["RESIDUAL_WARNING", "Field", "initial_coordinates", "project_field"]

#: A projection that misses more than this fraction of the field (relative kinetic norm) is reported.
RESIDUAL_WARNING = 1e-3
_GX, _GW = np.polynomial.legendre.leggauss(20)


@dataclass(frozen=True)
class Field:
    """A field along the beam to project: ``u(x)`` and the cross-section rotation ``theta(x)`` that goes with it.

    Parameters
    ----------
    values : callable
        ``u(x)`` (vectorised), [m] or [m/s].
    rotation : callable
        ``theta(x)``, [rad] or [rad/s].
    key : str
        The scenario key(s) the field comes from, for the warning.
    breaks : tuple of float
        Points where the field is not smooth (profile rows, load points).
    """

    values: Callable[[np.ndarray], np.ndarray]
    rotation: Callable[[np.ndarray], np.ndarray]
    key: str
    breaks: tuple[float, ...] = ()


def _max_wavenumber(beam: Beam, omega: float) -> float:
    """Largest wavenumber [1/m] of a free wave of the beam at ``omega`` (a bound, all sections)."""
    out = 4.0 / beam.length
    for p in beam.pieces():
        out = max(out, (omega**2 * p.mass_per_length / p.bending_stiffness) ** 0.25)
        if beam.is_timoshenko:
            out = max(out, omega * math.sqrt(p.mass_per_length / beam.shear_stiffness(p)),
                      omega * math.sqrt(p.density / p.youngs_modulus))
    return out


def _quadrature(beam: Beam, omega_max: float, breaks: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """Gauss points and weights on [0, L]: 20 per piece, pieces <= half the shortest wavelength."""
    L = beam.length
    edges = np.cumsum([p.length for p in beam.pieces()])[:-1]
    cuts = [0.0, L, *edges, *(m.position for m in beam.masses), *(s.position for s in beam.springs), *breaks]
    cuts = np.unique(np.clip(np.asarray(cuts, dtype=float), 0.0, L))
    cuts = cuts[np.concatenate([[True], np.diff(cuts) > 1e-12 * L])]
    step = math.pi / (2.0 * _max_wavenumber(beam, omega_max))
    xs, ws = [], []
    for a, b in zip(cuts[:-1], cuts[1:]):
        n = max(1, math.ceil((b - a) / step))
        e = np.linspace(a, b, n + 1)
        half, mid = 0.5 * np.diff(e), 0.5 * (e[:-1] + e[1:])
        xs.append((mid[:, None] + half[:, None] * _GX).ravel())
        ws.append((half[:, None] * _GW).ravel())
    return np.concatenate(xs), np.concatenate(ws)


def project_field(modes, beam: Beam, field: Field, breaks: Sequence[float] = ()) -> tuple[np.ndarray, float]:
    """Modal coordinates of a field in the kinetic inner product, and the relative residual (module notes).

    Parameters
    ----------
    modes : ModeSet or RitzModes
        Mass-orthonormal modes of one state (``shapes``, ``rotations``, ``omega``).
    beam : Beam
    field : Field
    breaks : sequence of float, [m]
        Further points where the modes are not smooth (contactor positions).

    Returns
    -------
    coordinates : ndarray, (n,)
    residual : float
        ``|u - sum eta_n W_n| / |u|`` in the kinetic norm (0 for a zero field).
    """
    omega_max = float(np.max(modes.omega, initial=0.0))
    x, w = _quadrature(beam, omega_max, [*breaks, *field.breaks])
    rows = [(modes.shapes(x), beam.mass_per_length_at(x) * w, field.values(x))]
    masses = [m for m in beam.masses if m.mass or m.rotary_inertia]
    if masses:
        xm = np.array([m.position for m in masses])
        rows.append((modes.shapes(xm), np.array([m.mass for m in masses]), field.values(xm)))
    if beam.is_timoshenko:
        rows.append((modes.rotations(x), beam.rotary_inertia_at(x) * w, field.rotation(x)))
    if any(m.rotary_inertia for m in masses):
        rows.append((modes.rotations(xm), np.array([m.rotary_inertia for m in masses]), field.rotation(xm)))
    eta = sum(W @ (m * np.broadcast_to(u, m.shape)) for W, m, u in rows)
    norm2 = sum(float(np.sum(m * np.broadcast_to(u, m.shape) ** 2)) for _, m, u in rows)
    miss2 = sum(float(np.sum(m * (np.broadcast_to(u, m.shape) - W.T @ eta) ** 2)) for W, m, u in rows)
    return np.asarray(eta, dtype=float), (math.sqrt(miss2 / norm2) if norm2 > 0.0 else 0.0)


def _static_field(beam: Beam, initial: InitialCondition) -> Field:
    """The exact static shape of a point force at ``initial.position`` scaled to ``tip_displacement`` there."""
    x0 = beam.length if initial.position is None else float(initial.position)
    try:
        w0 = float(static_state(beam, [x0], [(x0, 1.0)])[0][0])
    except ParameterError:
        raise ParameterError(
            "initial.tip_displacement: the supports allow rigid-body motion, so a static load shape does not exist"
        ) from None
    scale = float(initial.tip_displacement) / w0  # type: ignore[arg-type]
    return Field(lambda x: scale * static_state(beam, x, [(x0, 1.0)])[0],
                 lambda x: scale * static_state(beam, x, [(x0, 1.0)])[1], "initial.tip_displacement", (x0,))


def _profile_field(profile: Profile) -> Field:
    return Field(profile, profile.slope, profile.name, tuple(float(v) for v in profile.positions))


def _velocity_field(initial: InitialCondition) -> Field | None:
    """The sum of the uniform translation, the rigid rotation and the velocity profile given."""
    parts: list[Field] = []
    if initial.velocity:
        v = float(initial.velocity)
        parts.append(Field(lambda x: np.full(np.shape(x), v), lambda x: np.zeros(np.shape(x)), "initial.velocity"))
    if initial.angular_velocity:
        om, p = float(initial.angular_velocity), float(initial.pivot)  # type: ignore[arg-type]
        parts.append(Field(lambda x: om * (np.asarray(x) - p), lambda x: np.full(np.shape(x), om),
                           "initial.angular_velocity"))
    if initial.velocity_profile is not None:
        parts.append(_profile_field(initial.velocity_profile))
    if not parts:
        return None
    if len(parts) == 1:
        return parts[0]
    return Field(lambda x: sum(f.values(x) for f in parts), lambda x: sum(f.rotation(x) for f in parts),
                 " + ".join(f.key for f in parts), tuple(b for f in parts for b in f.breaks))


def _checked(modes, beam: Beam, field: Field, breaks: Sequence[float], what: str) -> np.ndarray:
    eta, residual = project_field(modes, beam, field, breaks)
    if residual > RESIDUAL_WARNING:
        emit_user_level_warning(
            f"{field.key}: the projection onto the run's {modes.count}-function basis misses {100 * residual:.3g} % "
            f"of this initial {what} (relative kinetic-norm residual); that part (motion the supports forbid, "
            "or detail finer than the modes) is dropped from the initial state"
        )
    return eta


def _start_path(engaged: tuple[int, ...]) -> list[tuple[int, ...]]:
    """The states the engine passes through at t = 0 to reach ``engaged``: contactors engaged in increasing index."""
    return [tuple(sorted(engaged)[:i]) for i in range(len(engaged) + 1)]


def _to_free(space, engaged: tuple[int, ...], vectors: Sequence[np.ndarray], preserve_contacts: bool) -> list[np.ndarray]:
    """Coordinates in state ``engaged`` carried back to the free state's (inverse of the engine's t = 0 switches)."""
    if not engaged:
        return [np.asarray(v, dtype=float) for v in vectors]
    path = _start_path(engaged)
    T = np.eye(vectors[0].size)
    for frm, to in zip(path[:-1], path[1:]):
        T = space.transfer(to, frm, preserve_contacts) @ T
    cond = np.linalg.cond(T)
    if not cond < 1e10:
        raise ParameterError(
            "initial.equilibrium: the engaged state's modes cannot be reached from the free state's "
            f"(transfer matrix condition number {cond:.2g}); use solver.basis = \"enriched\""
        )
    return [np.linalg.solve(T, v) for v in vectors]


def _truncation(space, beam: Beam, preload: Preload, contactors: Sequence[Contactor], engaged: tuple[int, ...],
                eta: np.ndarray, forces: np.ndarray) -> None:
    """Warn when the modal equilibrium differs from the exact static contact solution by more than RESIDUAL_WARNING:
    its deflection (relative kinetic norm) or its contact forces (relative to the largest exact one)."""
    try:
        exact = continuum_equilibrium(beam, preload, contactors)
    except ParameterError:  # the model holds the beam, the continuum does not: certainly truncated
        exact = None
    if exact is None:
        emit_user_level_warning(
            f"initial.equilibrium: the run's model finds an equilibrium (contactors {list(engaged)} engaged) that "
            "the exact static solution does not have; add modes"
        )
        return
    modes = space.state(engaged).modes
    field = Field(lambda x: exact.deflection(x)[0], lambda x: exact.deflection(x)[1], "initial.equilibrium",
                  tuple(p for p, _ in exact.loads))
    x_q, w_q = _quadrature(beam, float(np.max(modes.omega, initial=0.0)), [*space.positions, *field.breaks])
    u = field.values(x_q)
    diff = u - modes.shapes(x_q).T @ eta
    m = beam.mass_per_length_at(x_q) * w_q
    norm = math.sqrt(float(np.sum(m * u * u)))
    miss = math.sqrt(float(np.sum(m * diff * diff)))
    top = float(np.max(np.abs(exact.forces), initial=0.0))
    force_miss = float(np.max(np.abs(np.asarray(forces) - exact.forces), initial=0.0))
    if (exact.engaged != tuple(engaged) or (norm > 0.0 and miss > RESIDUAL_WARNING * norm)
            or force_miss > RESIDUAL_WARNING * top):
        emit_user_level_warning(
            f"initial.equilibrium: the run's {modes.count}-function model puts the static equilibrium "
            f"{100 * miss / max(norm, 1e-300):.3g} % (relative kinetic norm) from the exact static solution, "
            f"its contact forces {100 * force_miss / max(top, 1e-300):.3g} % of the largest exact one (contactors "
            f"engaged: model {list(engaged)}, exact {list(exact.engaged)}); add modes"
        )


def initial_coordinates(
    space,
    beam: Beam,
    initial: InitialCondition,
    preload: Preload | None = None,
    *,
    contactors: Sequence[Contactor] | None = None,
    preserve_contacts: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """Free-state modal displacement and velocity at t = 0 in the basis of ``space`` (module notes).

    Parameters
    ----------
    space : StateSpace or RitzStateSpace
        The run's state space (paper basis or shared Ritz basis).
    beam : Beam
    initial : InitialCondition
    preload : Preload, optional
        The constant load of the run; needed by ``initial.equilibrium``.
    contactors : sequence of Contactor, optional
        The run's contactors with their gaps and sides (default the space's).
    preserve_contacts : bool
        The run's ``solver.projection == "contact"`` (how the engine carries
        the state across a switch in the paper's basis).

    Returns
    -------
    eta, deta : ndarray, (n,)
        In the free state's coordinates [m kg^0.5], [m kg^0.5 / s].

    Raises
    ------
    ParameterError
        A profile that does not span the beam, a static shape on a beam that
        can move as a rigid body, an equilibrium without preload or that does
        not exist.
    """
    contactors = tuple(space.contactors if contactors is None else contactors)
    engaged: tuple[int, ...] = ()
    n = space.state(()).modes.count
    eta_s, deta_s = np.zeros(n), np.zeros(n)
    if initial.equilibrium:
        if preload is None:
            raise ParameterError("initial.equilibrium: needs a preload (the constant load the equilibrium is taken under)")
        eq = modal_equilibrium(space, beam, preload, contactors)
        engaged, eta_s = eq.engaged, eq.eta.copy()
        _truncation(space, beam, preload, contactors, engaged, eta_s, eq.forces)
    modes = space.state(engaged).modes
    breaks = [float(p) for p in space.positions]
    for profile in (initial.displacement_profile, initial.velocity_profile):
        if profile is not None:
            profile.check_on(beam.length)
    if initial.tip_displacement:
        eta_s = eta_s + _checked(modes, beam, _static_field(beam, initial), breaks, "displacement")
    elif initial.displacement_profile is not None:
        eta_s = eta_s + _checked(modes, beam, _profile_field(initial.displacement_profile), breaks, "displacement")
    velocity = _velocity_field(initial)
    if velocity is not None:
        deta_s = deta_s + _checked(modes, beam, velocity, breaks, "velocity")
    eta, deta = _to_free(space, engaged, [eta_s, deta_s], preserve_contacts)
    N = min(space.n_modes, n)
    for src, dst in ((initial.modal_displacement, eta), (initial.modal_velocity, deta)):
        if src is not None:
            v = np.asarray(src, dtype=float)
            m = min(v.size, N)
            dst[:m] += v[:m]
    return eta, deta
