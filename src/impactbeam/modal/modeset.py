"""Exact modal analysis of a beam with supports, steps, point masses and springs.

The beam of :class:`~impactbeam.model.beam.Beam` (piecewise uniform sections, point
masses, permanent interior springs) with any set of engaged translational
springs (the contact springs) is cut at every step, mass and spring into ``s``
uniform segments. On each segment ``[x0, x1]`` (length ``l``, wavenumber
``beta_j``) a mode shape is written in the bounded basis

.. math:: W(x) = C_1 \\cos\\beta_j u + C_2 \\sin\\beta_j u + C_3 e^{-\\beta_j u}
          + C_4 e^{-\\beta_j (l - u)}, \\qquad u = x - x_0,

which spans the same space as the paper's eq. (5) but never grows: every
entry of the characteristic matrix is bounded, so the frequencies and shapes
keep full precision up to hundreds of modes (the textbook ``cosh - sigma
sinh`` form loses every digit past mode ~12).

The ``4 s`` conditions are the end conditions of the paper (after eq. 5),

.. math:: K_{t1} W'(0) = EI W''(0), \\quad EI W'''(0) = -k_1 W(0),\\quad
          -K_{t2} W'(L) = EI W''(L), \\quad EI W'''(L) = k_2 W(L),

and at each interior node continuity of ``W, W'`` with the jumps
``[EI W'']^+_- = (K_t - J omega^2) W'`` and ``-[EI W''']^+_- = (k - m omega^2) W``
(a spring alone: the paper's contact-state compatibilities; a section step:
continuity of ``EI W''`` and ``EI W'''``; point masses at an end enter the end
conditions the same way). :mod:`impactbeam.modal.euler` builds the matrix, counts
and refines the roots.

Every root is found exactly once: the Wittrick-Williams count
``J(omega) = sum J0 + s{K(omega)}`` (number of natural frequencies below
``omega``, from the sign count of the exact dynamic stiffness matrix with the
node terms ``k - m omega^2`` and ``K_t - J omega^2``) brackets each root alone,
and Brent's method refines it on the determinant of the characteristic
matrix. Rigid-body modes (zero frequency) are found from the linear shapes
the supports allow. Shapes are orthonormal in the kinetic-energy inner
product ``int rho A W W dx + sum_j (m_j W W + J_j W' W')``, which is also the
projection of eq. (12) between states.

References
----------
.. [1] W. Xu, E. K. Ervin, "Parameters affecting the transient response of an
   impacting beam", Shock and Vibration 20 (2013), section 2, eqs. (2)-(5), (12).
.. [2] W. H. Wittrick, F. W. Williams, "A general algorithm for computing
   natural frequencies of elastic structures", Q. J. Mech. Appl. Math. 24 (1971).
.. [3] M. Goncalves, M. Brennan, S. Elliott, "Numerical evaluation of high-order
   modes of vibration in uniform Euler-Bernoulli beams", J. Sound Vib. 301 (2007).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from .euler import (
    Layout,
    _basis,
    bracket_roots,
    characteristic,
    count_below as _count_below_eb,
    krylov_mask,
    layout,
    null_vector,
    quadrature,
    refine,
    rigid_modes,
)
from ..model.beam import Beam
from .disk_cache import stored
from ..exceptions import ParameterError

if TYPE_CHECKING:
    from .timoshenko import TimoshenkoShapes
    from ..scenario import Scenario

__all__ = ["ModeSet", "ScenarioModes", "mode_set", "scenario_modes", "modes", "count_below"]

# --------------------------------------------------------------------------- ModeSet


@dataclass(frozen=True, eq=False)
class ModeSet:
    """Natural frequencies and mass-normalised mode shapes of one state.

    Attributes
    ----------
    beam : Beam
    springs : tuple of (position [m], stiffness [N/m])
        Engaged interior springs (contact springs) of this state.
    omega : ndarray, shape (n,), [rad/s]
        Natural circular frequencies, ascending; 0 for rigid-body modes.
    beta : ndarray, shape (n,), [1/m]
        Wavenumbers of the reference (``[beam]``) section, ``omega = beta^2 sqrt(EI / rho A)``
        (paper, after eq. 5); a segment of a stepped beam has ``beta_j = r_j beta``.
    n_rigid : int
        Number of rigid-body modes (they come first).

    Notes
    -----
    Shapes are normalised so that ``int rho A W_n W_m dx = delta_nm`` (paper,
    orthonormality after eq. 7; plus ``m_j W_n W_m + J_j W_n' W_m'`` at point
    masses); their sign makes the largest displacement
    positive.
    """

    beam: Beam
    springs: tuple[tuple[float, float], ...]
    omega: np.ndarray
    beta: np.ndarray
    n_rigid: int
    _layout: Layout = field(repr=False)
    _coef: np.ndarray = field(repr=False)  # (n, s, 4) elastic coefficients
    _rigid: np.ndarray = field(repr=False)  # (n_rigid, 2)
    _kry: np.ndarray = field(repr=False)  # (n, s) True where a segment uses the Krylov basis
    _timo: TimoshenkoShapes | None = field(default=None, repr=False)  # elastic shapes of a Timoshenko beam

    def _repr_html_(self) -> str:
        """Compact summary table for Jupyter: the state's springs and first frequencies."""
        from .._html import modeset_html

        return modeset_html(self)

    @property
    def count(self) -> int:
        """Number of modes in the set."""
        return int(self.omega.size)

    @property
    def frequencies_hz(self) -> np.ndarray:
        """Natural frequencies [Hz]."""
        return self.omega / (2.0 * np.pi)

    @property
    def nodes(self) -> np.ndarray:
        """Segment boundaries [m] (ends and spring positions)."""
        return self._layout.nodes

    def shapes(self, x: float | Sequence[float] | np.ndarray, derivative: int = 0) -> np.ndarray:
        """Mode shapes or their derivatives at ``x``.

        Parameters
        ----------
        x : array_like, shape (p,), [m]
        derivative : {0, 1, 2, 3}
            Order of the derivative in x.

        Returns
        -------
        ndarray, shape (n, p)
            ``d^k W_n / dx^k (x)`` in [kg^-0.5 m^-k]. At a node (spring, mass,
            section step) the second and third derivatives are the values just
            to the right; the bending moment is ``EI(x) W''`` with
            :meth:`~impactbeam.model.beam.Beam.bending_stiffness_at`.
        """
        if derivative not in (0, 1, 2, 3):
            raise ParameterError(f"derivative: must be 0, 1, 2 or 3, got {derivative!r}")
        x = np.atleast_1d(np.asarray(x, dtype=float))
        lay = self._layout
        out = np.zeros((self.count, x.size))
        r = self.n_rigid
        if r:
            c = self._rigid
            if derivative == 0:
                out[:r] = c[:, :1] + c[:, 1:] * x[None, :]
            elif derivative == 1:
                out[:r] = c[:, 1:]
        if self.count > r and self._timo is not None:
            out[r:] = self._timo.derivative(x, derivative)
        elif self.count > r:
            seg = np.clip(np.searchsorted(lay.nodes, x, side="right") - 1, 0, lay.n_segments - 1)
            u = x - lay.nodes[seg]
            ell = lay.lengths[seg]
            b = self.beta[r:, None] * lay.r[seg][None, :]  # wavenumber of each point's segment
            kry = self._kry[r:][:, seg]
            phi = _basis(b * u[None, :], b * ell[None, :], derivative, kry)
            coef = self._coef[r:][:, seg, :]  # (n_el, p, 4)
            val = sum(coef[:, :, k] * phi[k] for k in range(4))
            out[r:] = val * b**derivative
        return out

    def moment_shapes(self, x: float | Sequence[float] | np.ndarray) -> np.ndarray:
        """Bending moment per unit modal coordinate, ``EI(x) W_n''(x)`` [N m kg^-0.5], shape (n, p).

        ``M(x, t) = sum_n eta_n(t) EI(x) W_n''(x)`` (sign: positive for
        ``w'' > 0``); the outer-fibre stress is ``M c(x) / I(x)`` with
        :meth:`~impactbeam.model.beam.Beam.fibre_distance_at` and
        :meth:`~impactbeam.model.beam.Beam.second_moment_at`. A plain modal sum of
        moments converges slowly near loads and stops (a static correction
        helps there). At a step the section to the right is used on both
        sides of ``x`` alike, which is exact since ``EI W''`` is continuous.

        Parameters
        ----------
        x : float or array_like, [m]
            Positions on the beam.
        """
        x = np.atleast_1d(np.asarray(x, dtype=float))
        if self._timo is not None:  # M = EI Psi'
            out = np.zeros((self.count, x.size))
            out[self.n_rigid :] = self._timo.state(x)[2]
            return out
        return self.beam.bending_stiffness_at(x)[None, :] * self.shapes(x, 2)

    def rotations(self, x: float | Sequence[float] | np.ndarray) -> np.ndarray:
        """Cross-section rotation per unit modal coordinate [kg^-0.5], shape (n, p).

        ``W'`` for an Euler-Bernoulli beam; the independent field ``Psi`` of a
        Timoshenko beam (``W' - Psi`` is the shear strain).

        Parameters
        ----------
        x : float or array_like, [m]
            Positions on the beam.
        """
        if self._timo is None:
            return self.shapes(x, 1)
        x = np.atleast_1d(np.asarray(x, dtype=float))
        out = np.zeros((self.count, x.size))
        out[: self.n_rigid] = self._rigid[:, 1:]
        out[self.n_rigid :] = self._timo.state(x)[1]
        return out

    def _kinetic(self, other: ModeSet, x: np.ndarray, w: np.ndarray) -> np.ndarray:
        """``int rho A W W~ + rho I Psi Psi~`` (the last for a Timoshenko beam) plus the point masses."""
        P = (self.shapes(x) * (w * self.beam.mass_per_length_at(x))) @ other.shapes(x).T
        if self._timo is not None:
            P = P + (self.rotations(x) * (w * self.beam.rotary_inertia_at(x))) @ other.rotations(x).T
        lay = self._layout
        at = lay.m > 0.0
        if np.any(at):
            xm = lay.nodes[at]
            P = P + (self.shapes(xm) * lay.m[at]) @ other.shapes(xm).T
        at = lay.J > 0.0
        if np.any(at):
            xj = lay.nodes[at]
            P = P + (self.rotations(xj) * lay.J[at]) @ other.rotations(xj).T
        return P

    def __call__(self, x: float | Sequence[float] | np.ndarray) -> np.ndarray:
        """Same as :meth:`shapes` with ``derivative=0``."""
        return self.shapes(x)

    @functools.cached_property
    def _beta_max(self) -> float:
        """Largest segment wavenumber of the set [1/m]."""
        if self._timo is not None and self._timo.omega.size:
            from .timoshenko import wavenumbers

            return float(wavenumbers(self._timo.seg, float(self._timo.omega.max()))[0].max())
        return float(self.beta.max(initial=1.0 / self.beam.length) * np.max(self._layout.r))

    @functools.cached_property
    def _quad(self) -> tuple[np.ndarray, np.ndarray]:
        return quadrature(self.nodes, self._beta_max)

    @functools.cached_property
    def _integral(self) -> np.ndarray:
        x, w = self._quad
        out = self.shapes(x) @ w
        out.setflags(write=False)
        return out

    def integral(self) -> np.ndarray:
        """``int_0^L W_n dx`` [m kg^-0.5], shape (n,): modal weight of a uniform load."""
        return self._integral.copy()

    @functools.cached_property
    def _inertia_integral(self) -> np.ndarray:
        x, w = self._quad
        out = self.shapes(x) @ (w * self.beam.mass_per_length_at(x))
        lay = self._layout
        at = lay.m > 0.0
        if np.any(at):
            out = out + self.shapes(lay.nodes[at]) @ lay.m[at]
        out.setflags(write=False)
        return out

    def inertia_integral(self) -> np.ndarray:
        """``int rho A(x) W_n dx + sum_j m_j W_n(x_j)`` [kg^0.5], shape (n,).

        The modal weight of the inertia load of a uniform acceleration: a base
        acceleration ``u_g''`` loads mode ``n`` with ``-inertia_integral()[n] u_g''``
        (paper eq. 8 with ``f = -rho A u_g''``, plus the point masses; a
        rotary inertia is not loaded by a translation). Equals
        ``rho A * integral()`` for the paper's uniform beam.
        """
        return self._inertia_integral.copy()

    def mass_matrix(self) -> np.ndarray:
        """``int rho A W_n W_m dx + sum (m W_n W_m + J W_n' W_m')``: the identity up to round-off (a check)."""
        return self.overlap(self)

    def overlap(self, other: ModeSet) -> np.ndarray:
        """Projection matrix ``P[n, p] = <W_n^self, W_p^other>`` (paper eq. 12).

        The inner product is the kinetic-energy one, ``int rho A(x) W W' dx``
        (plus ``int rho I Psi Psi' dx`` for a Timoshenko beam) and
        ``m_j W(x_j) W'(x_j) + J_j Psi(x_j) Psi'(x_j)`` at the point masses
        (those of this set's layout; ``Psi = W_x`` for Euler-Bernoulli). ``eta_self = P @ eta_other`` carries modal
        coordinates of ``other`` into this set (displacement and velocity alike).

        Parameters
        ----------
        other : ModeSet
            Modes of another state of the same beam.
        """
        if other.beam != self.beam:
            raise ParameterError("overlap: the two mode sets belong to different beams")
        cache = self.__dict__.setdefault("_overlaps", {})
        hit = cache.get(id(other))
        if hit is not None and hit[0] is other:
            return hit[1].copy()
        breaks = np.union1d(self.nodes, other.nodes)
        x, w = quadrature(breaks, max(self._beta_max, other._beta_max))
        P = self._kinetic(other, x, w)
        P.setflags(write=False)
        cache[id(other)] = (other, P)
        return P.copy()

    def static_coordinates(self, position: float, force: float = 1.0) -> np.ndarray:
        """Modal coordinates of the static deflection under a point ``force`` at ``position``.

        ``eta_n = F W_n(a) / omega_n^2``: the exact projection of the static shape.

        Parameters
        ----------
        position : float, [m]
            Where the force acts.
        force : float, [N]
            The static point force.
        """
        if self.n_rigid:
            raise ParameterError(
                "initial.tip_displacement: the supports allow rigid-body motion, so a static load shape does not exist"
            )
        return force * self.shapes([position])[:, 0] / self.omega**2


def count_below(beam: Beam, omega: float, springs: Sequence[tuple[float, float]] = ()) -> int:
    """Number of natural frequencies strictly below ``omega`` [rad/s] (Wittrick-Williams).

    Rigid-body modes count as frequencies at zero. For a Timoshenko beam both
    spectra count (above the cut-off ``sqrt(kappa G A / rho I)`` too).

    Parameters
    ----------
    beam : Beam
    omega : float, [rad/s]
    springs : sequence of (position, stiffness)
        Engaged contact springs, [m] and [N/m].
    """
    omega = float(omega)
    if not math.isfinite(omega):
        raise ParameterError(f"omega: must be finite, got {omega!r}")
    if omega <= 0.0:
        return 0  # no frequency is negative (rigid-body modes are at zero, not below it)
    if beam.is_timoshenko:
        from . import timoshenko as _timoshenko

        return _timoshenko.count_below(_timoshenko.segments(beam, layout(beam, springs)), float(omega))
    return _count_below_eb(beam, omega, springs)


def _clusters(betas: np.ndarray) -> list[tuple[int, int]]:
    """Index ranges ``[i, j)`` of (nearly) repeated roots."""
    out, i = [], 0
    while i < betas.size:
        j = i + 1
        while j < betas.size and betas[j] - betas[j - 1] <= 1e-7 * betas[j]:
            j += 1
        out.append((i, j))
        i = j
    return out


def _build(lay: Layout, beam: Beam, springs: tuple[tuple[float, float], ...], count: int) -> ModeSet:
    rotary = float(np.sum(beam.rotary_inertia_at(0.5 * (lay.nodes[:-1] + lay.nodes[1:])) * lay.lengths))
    rigid = rigid_modes(lay, rotary if beam.is_timoshenko else 0.0)
    r = min(rigid.shape[0], count)
    s = lay.n_segments
    coef = np.zeros((count, s, 4))
    kry = np.zeros((count, s), dtype=bool)
    c2 = math.sqrt(lay.EI / lay.rhoA)
    timo = None
    if beam.is_timoshenko:
        from . import timoshenko as _timoshenko

        timo = _timoshenko.solve(_timoshenko.segments(beam, lay), count - r, rigid.shape[0])
        betas = np.sqrt(timo.omega / c2)  # the Euler-Bernoulli-equivalent wavenumber, omega = beta^2 c
        groups = _clusters(betas)
    else:
        brackets = bracket_roots(lay, count - r, rigid.shape[0])
        betas = np.array([refine(lay, lo, hi, j) for lo, hi, j in brackets], dtype=float)
        groups = _clusters(betas)
        for i, j in groups:
            b_mid = float(np.mean(betas[i:j]))
            mask = krylov_mask(lay, b_mid)
            if j - i == 1:
                coef[r + i] = null_vector(lay, betas[i], mask).reshape(s, 4)
            else:  # (nearly) repeated root: the null space of the cluster
                _, _, vt = np.linalg.svd(characteristic(lay, b_mid, mask))
                for m in range(j - i):
                    coef[r + i + m] = vt[-(m + 1)].reshape(s, 4)
            kry[r + i : r + j] = mask
    beta_all = np.concatenate([np.zeros(r), betas])
    omega = np.concatenate([np.zeros(r), timo.omega]) if timo is not None else beta_all**2 * c2
    ms = ModeSet(beam, springs, omega, beta_all, r, lay, coef, rigid[:r], kry, timo)
    if count > r:
        _normalise(ms, groups)
    return ms


def _normalise(ms: ModeSet, groups: list[tuple[int, int]]) -> None:
    """Orthonormalise the elastic shapes in the kinetic-energy inner product, largest displacement positive.

    Within a cluster of repeated roots by Gram-Schmidt (Cholesky); the
    coefficients are scaled in place (the set is being built).
    """
    r, n = ms.n_rigid, ms.count
    x, w = ms._quad
    gram = ms._kinetic(ms, x, w)
    scale = np.ones(n)
    mix = np.eye(n)
    for i, j in groups:
        if j - i > 1:
            sl = slice(r + i, r + j)
            mix[sl, sl] = np.linalg.inv(np.linalg.cholesky(gram[sl, sl]))
    gram = mix @ gram @ mix.T
    scale[r:] = 1.0 / np.sqrt(np.diag(gram)[r:])
    W = (mix @ ms.shapes(x))[r:]
    idx = np.argmax(np.abs(W), axis=1)
    scale[r:] *= np.sign(W[np.arange(W.shape[0]), idx])
    T = (scale[:, None] * mix)[r:, r:]
    if ms._timo is not None:
        ms._timo.transform(T)
    else:
        ms._coef[r:] = np.einsum("ab,bsk->ask", T, ms._coef[r:])


@functools.lru_cache(maxsize=512)
def _cached(beam: Beam, springs: tuple[tuple[float, float], ...], count: int) -> ModeSet:
    # in this process by the LRU cache, between processes by the files of .disk_cache (the same bits)
    return stored(("mode_set", beam, springs, count), lambda: _build(layout(beam, springs), beam, springs, count))


def mode_set(beam: Beam, springs: Iterable[tuple[float, float]] = (), count: int = 8) -> ModeSet:
    """Compute (or fetch from the cache) the first ``count`` modes of a beam state.

    Parameters
    ----------
    beam : Beam
    springs : iterable of (position [m], stiffness [N/m])
        Engaged translational springs; at an end they add to the support, two
        at one point add up; ``inf`` pins the point.
    count : int
        Number of modes, rigid-body modes included.

    Returns
    -------
    ModeSet

    Examples
    --------
    >>> import impactbeam as ib
    >>> beam = ib.Beam.rectangular(1.0, 0.01, 0.01, 2e11, 7800.0, "clamped", "free")
    >>> ms = ib.mode_set(beam, count=3)
    >>> lam = (ms.omega / ms.omega[0]) ** 0.5 * 1.875104069
    >>> [round(float(v), 6) for v in lam]
    [1.875104, 4.694091, 7.854757]
    """
    if isinstance(count, bool) or int(count) != count or count < 1:
        raise ParameterError(f"count: must be a positive integer, got {count!r}")
    key = tuple(sorted((float(x), float(k)) for x, k in springs))
    return _cached(beam, key, int(count))


@dataclass(frozen=True)
class ScenarioModes:
    """Mode sets of a scenario: the free state and the state with all contactors engaged.

    Parameters
    ----------
    free : ModeSet
        Modes of the free state.
    contact : ModeSet or None
        Modes with every contactor engaged (None without contactors).
    """

    free: ModeSet
    contact: ModeSet | None

    def _repr_html_(self) -> str:
        """Both states side by side for Jupyter."""
        from .._html import modeset_html

        parts = [modeset_html(self.free).replace("ModeSet", "Free state", 1)]
        if self.contact is not None:
            parts.append(modeset_html(self.contact).replace("ModeSet", "Contact state", 1))
        cells = "".join(f'<div style="margin-right:2em">{p}</div>' for p in parts)
        return f'<div style="display:flex;flex-wrap:wrap">{cells}</div>'


def scenario_modes(scenario: Scenario, count: int | None = None) -> ScenarioModes:
    """Free-state and all-engaged contact-state modes of a scenario.

    Parameters
    ----------
    scenario : Scenario
    count : int, optional
        Modes per state; default the scenario's ``solver.modes`` (required when that is ``"auto"``).

    Raises
    ------
    TypeError
        When ``scenario`` is not a Scenario.
    ParameterError
        For ``solver.modes = "auto"`` without ``count``, or a bad ``count``.
    """
    from ..scenario import Scenario

    if not isinstance(scenario, Scenario):
        raise TypeError(f"modes: expected a Scenario (from impactbeam.load_scenario), got {type(scenario).__name__}")
    n = scenario.solver.modes if count is None else count
    if n == "auto":
        raise ParameterError('count: the scenario has solver.modes = "auto", which a simulation settles; give the '
                             "number of modes (modes(scenario, count=8), impactbeam modes --count 8)")
    free = mode_set(scenario.beam, (), n)
    contact = None
    if scenario.contactors:
        contact = mode_set(scenario.beam, [(c.position, c.stiffness) for c in scenario.contactors], n)
    return ScenarioModes(free, contact)


#: ``ib.modes(scenario)`` (see the API reference).
modes = scenario_modes
