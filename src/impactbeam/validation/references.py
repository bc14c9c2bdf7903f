"""The published reference values of the validation manual, with their sources (never inputs of a run).

code_aster's validation tests are cited by test file and manual: the values
are those of the files ``astest/<test>.comm`` of the code_aster source
(snapshot of November 2020, commit ``34161d7955a6``; unchanged in the
2021 sources), ``VALE_REFE`` the reference and ``PRECISION`` the relative
tolerance code_aster applies to its own result (``VALE_CALC``), also given.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Source", "SOURCES", "SDLX400", "SDNL32", "SDNL104", "PAPER_FREQUENCY_BAND"]

CODE_ASTER_SNAPSHOT = "code_aster source, astest/ (commit 34161d7955a6, November 2020)"


@dataclass(frozen=True)
class Source:
    """Where a reference comes from.

    Attributes
    ----------
    key : str
        Short name used in the tables.
    citation : str
        Full citation (document, version, file, lines).
    kind : str
        What the reference is: ``"analytical"``, ``"external"`` (an
        independent published solution), ``"code"`` (another code's converged
        run), ``"experiment"``.
    """

    key: str
    citation: str
    kind: str


SOURCES: dict[str, Source] = {
    "SDLX400": Source(
        "SDLX400",
        "code_aster validation test SDLX400 (validation manual V2.05.400), test file sdlx400a.comm "
        f"(POU_D_E, lines 96-137 free, 276-325 with the spring; {CODE_ASTER_SNAPSHOT}); REFERENCE='ANALYTIQUE'",
        "analytical",
    ),
    "SDNL32": Source(
        "SDNL32",
        "code_aster validation test SDNL32, 'Impact of an articulated beam on elastic support' (validation manual "
        f"V5.02.032), test file sdnl32a.comm (lines 151-259 k = 18000 N/m, 298-407 k = 45000 N/m; "
        f"{CODE_ASTER_SNAPSHOT}); REFERENCE='SOURCE_EXTERNE', the VPCS guide (SFM, Guide de validation des "
        "progiciels de calcul de structures, 1990)",
        "external",
    ),
    "SDNL104": Source(
        "SDNL104",
        "code_aster validation test SDNL104, 'Non-linear transient substructuration: impact of a beam on 1 support' "
        "(validation manual V5.02.104); reference values: sdnl104a.comm (DYNA_NON_LINE, Newmark, dt = 1e-4 s; "
        "used as valref/valrefv in sdnl104c.comm lines 322-323); 5-mode runs: sdnl104c.comm lines 325-421 "
        f"({CODE_ASTER_SNAPSHOT}); REFERENCE='AUTRE_ASTER'",
        "code",
    ),
    "XuErvin2013": Source(
        "Xu & Ervin (2013)",
        "W. Xu, E. K. Ervin, 'Parameters affecting the transient response of an impacting beam', Shock and "
        "Vibration 20 (2013) 907-919: Table 2 (measured), section 3 (natural frequencies 57.13 +- 2.20 Hz and "
        "355.96 +- 2.20 Hz from the release test), section 4 (the paper's own model against its tests)",
        "experiment",
    ),
}


@dataclass(frozen=True)
class Tabulated:
    """A published value with code_aster's tolerance and result.

    Attributes
    ----------
    label : str
    reference : float
        ``VALE_REFE`` (SI).
    precision : float or None
        code_aster's relative ``PRECISION`` (None: not tested there).
    code_aster : float or None
        code_aster's ``VALE_CALC`` (its own result).
    """

    label: str
    reference: float
    precision: float | None = None
    code_aster: float | None = None


#: SDLX400: pinned-free beam, L = 0.783 m, 14 mm square, E = 6.7e10 Pa, rho = 2400 kg/m^3, nu = 0; frequencies [Hz],
#: without (``free``, modes 2-6; mode 1 is the rigid rotation) and with (``spring``, modes 1-6) a tip spring
#: k = 18000 N/m. PRECISION and VALE_CALC of sdlx400a (POU_D_E, 10 elements).
SDLX400: dict[str, tuple[Tabulated, ...]] = {
    "free": (
        Tabulated("mode 2", 85.5, 1e-3, 85.468622725),
        Tabulated("mode 3", 277.0, 1e-3, 277.014981159),
        Tabulated("mode 4", 577.9, 1e-3, 578.283946285),
        Tabulated("mode 5", 988.2, 3e-3, 990.189596128),
        Tabulated("mode 6", 1507.9, 5e-3, 1514.75582),
    ),
    "spring": (
        Tabulated("mode 1", 43.1, 1e-3, 43.090426897),
        Tabulated("mode 2", 115.4, 1e-3, 115.367143318),
        Tabulated("mode 3", 286.5, 1e-3, 286.582534135),
        Tabulated("mode 4", 582.3, 1e-3, 582.699711671),
        Tabulated("mode 5", 990.7, 3e-3, 992.743946446),
        Tabulated("mode 6", 1509.6, 5e-3, 1516.43027),
    ),
}

#: SDNL32: tip deflection DY(NO11) [m] at t = 1 ... 12 ms (VALE_REFE, VPCS), PRECISION and VALE_CALC of sdnl32a.
SDNL32: dict[float, tuple[Tabulated, ...]] = {
    18000.0: tuple(Tabulated(f"{i + 1} ms", r, p, c) for i, (r, p, c) in enumerate((
        (-2.66e-3, 1.1e-3, -2.6627590257986e-03), (-4.33e-3, 1.2e-3, -4.3350345295e-03),
        (-4.92e-3, 1e-2, -4.9527612787e-03), (-4.78e-3, 1e-3, -4.7819171373e-03),
        (-3.82e-3, 2e-3, -3.8242004129e-03), (-2.87e-3, 2e-3, -2.8745139070e-03),
        (-2.71e-3, 1e-3, -2.7099551923e-03), (-3.09e-3, 1e-3, -3.0877216671e-03),
        (-3.41e-3, 1e-3, -3.4066468458e-03), (-3.36e-3, 2e-3, -3.3641583511e-03),
        (-2.64e-3, 1.2e-3, -2.6422009677e-03), (-7.42e-4, 1.5e-2, -7.4273628435e-04),
    ))),
    45000.0: tuple(Tabulated(f"{i + 1} ms", r, p, c) for i, (r, p, c) in enumerate((
        (-2.25e-3, 2e-3, -2.2499139339e-03), (-2.66e-3, 2e-3, -2.6571933710e-03),
        (-1.96e-3, 3e-3, -1.9644467682e-03), (-1.15e-3, 5.2e-3, -1.1558832978e-03),
        (-1.24e-4, 1.201e-2, -1.2253880979e-04), (-3.64e-4, 1.6e-3, -3.6343897589e-04),
        (-2.01e-3, 1e-3, -2.0093063318e-03), (-2.74e-3, 1e-3, -2.7406203056e-03),
        (-1.89e-3, 2e-3, -1.8936271216e-03), (-3.52e-4, 1e-3, -3.5204249460e-04),
        (1.70e-3, 5e-3, 1.7043769266e-03), (4.99e-3, 1e-3, 4.9858100660e-03),
    ))),
}

#: SDNL104: tip deflection [m] at 0.1315 s and tip velocity [m/s] at 0.1566 s. ``reference``: sdnl104a
#: (DYNA_NON_LINE); the 5-mode runs of sdnl104c with their PRECISION against it.
SDNL104: dict[str, object] = {
    "times": (0.1315, 0.1566),
    "reference": (-1.85356696663e-06, -0.00463289359505),
    "five_modes": Tabulated("5 modes only (sdnl104c TRAN4, 'sans modstat')", -1.72233853215e-06, 8e-2,
                            -1.72233853215e-06),
    "five_modes_velocity": Tabulated("5 modes only (sdnl104c TRAN4)", -0.0044840631965, 4e-2, -0.0044840631965),
    "with_static_mode": Tabulated("5 modes + static mode (sdnl104c TRAN3, 'sans ortho')", -1.88612760632e-06, 2e-2,
                                  -1.88612760632e-06),
    "with_static_mode_velocity": Tabulated("5 modes + static mode (sdnl104c TRAN3)", -0.00465969129421, 2e-2,
                                           -0.00465969129421),
}

#: Section 3 of the paper: the specimen's first two natural frequencies from the release test, +- 2.20 Hz [Hz].
PAPER_FREQUENCY_BAND: tuple[tuple[float, float], ...] = ((57.13, 2.20), (355.96, 2.20))
