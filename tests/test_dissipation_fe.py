"""Dashpots, Rayleigh and free-mode damping against a finite-element reference with the same laws.

The reference (:mod:`fe_dissipation`, from :mod:`fe_reference`, which imports
nothing from the package) is the specimen's Hermite-cubic FE model integrated
exactly in time between events (matrix exponentials, events by Brent's
method), with the contactor's force-release law, Rayleigh's ``alpha M + beta
K`` of each state and the free state's modal damping kept in every state;
converged in the mesh (80 -> 160 elements: impact counts equal, event times
within 9e-7 s, the first peak force within 1.7e-3, deflections within 2.4e-5
of the peak; cached with the data).

Targets (issue: dissipation): impact count equal, contact start and end
times within 5e-6 s, the first peak force within 1 %, deflections at the
contactor within 0.3 % of the peak. With 16 modes the measured errors are at
most 1.8e-6 s, 0.35 % and 4.3e-5 (the dashpot on the stiff stop is the
hardest: at 8 modes its first peak force is 2.5 % off, which is why 16 modes
are used, and said in docs/dissipation.md). The bars are the issue's; the
measured errors leave at least a factor 2.5 on each, above the reference's own
mesh error.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import impactbeam as ib

import fe_dissipation as fd

MODES = 16


@pytest.fixture(scope="module", params=fd.CASES)
def case(request):
    ref = fd.reference(request.param)
    sc = ib.parse_scenario(ref["scenario"]).with_values({"solver.modes": MODES})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ib.ImpactBeamWarning)
        res = ib.simulate(sc)
    return request.param, ref, sc, res


def test_impacts_contact_times_and_first_peak_force(case):
    name, ref, sc, res = case
    imp = res.impacts
    assert len(imp) == ref["n_impacts"], name
    np.testing.assert_allclose(imp["start"], ref["contact_start"], rtol=0, atol=5e-6)
    np.testing.assert_allclose(imp["end"], ref["contact_end"], rtol=0, atol=5e-6)
    assert imp["peak_force"].iloc[0] == pytest.approx(ref["first_peak_force"], rel=1e-2)


def test_deflection_at_the_contactor(case):
    name, ref, sc, res = case
    t = np.asarray(ref["t_history"])
    w_ref = np.asarray(ref["w_contactor"])
    w = res.displacement([sc.contactors[0].position], t)[0]
    assert np.abs(w - w_ref).max() <= 3e-3 * np.abs(w_ref).max(), name


def test_what_the_dashpots_dissipate():
    # the dashpots' energy (during contact and at the releases) against the FE's, both integrated from
    # the exact solutions; the ledger here is sampled at 2 us (trapezoid rule), measured 3e-4 and 1.3e-3
    for name in ("dashpot_soft", "dashpot_stiff"):
        ref = fd.reference(name)
        sc = ib.parse_scenario(ref["scenario"]).with_values({"solver.modes": MODES, "solver.time_step": 2e-6})
        res = ib.simulate(sc)
        assert res.energy["dashpots"][-1] == pytest.approx(ref["dashpot_energy"], rel=5e-3), name
