"""The ladder on a record from the nonlinear individual-blade truth (issue #9).

The truth keeps every blade's flap inertia and feels in-plane velocity directly
on the blades; the paper's candidates alone would credit that to the inflow.
On the default virtual flight test (one longitudinal doublet, 100 Hz, 1e-4 rad
white flap noise, continuous time) the ladder names flap inertia first and the
direct in-plane forcing with ``k_mu`` near its theory value 1, and ends within
1.5 times the sensor noise (``bench/README.md`` has other rates and seeds).
"""
import functools

import pytest

import numpy as np

from inflowsim.diagnose import ladder
from inflowsim.flighttest import FlightTest, nonlinear_flighttest
from inflowsim.report.ladder import format_diagnosis


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason=(
    "issue #29: on one doublet mux moves a little, so Glauert's c1, c3, c4 are now "
    "estimated (no longer held whole with the undetermined c2) and G mimics the direct "
    "in-plane forcing: the ladder names glauert where the truth has "
    "advance-ratio-perturbation.  The record does not separate the two; the redesigned "
    "rule must say so (each atom significant beside the other) instead of naming either"))
def test_ladder_on_nonlinear_truth_names_flap_inertia_and_inplane_forcing():
    test = FlightTest(seed=1)
    rec = nonlinear_flighttest(test).record
    assert rec.hold == "continuous"
    lad = ladder(rec, "basic")
    added = [r.added for r in lad.rungs[1:]]
    assert added[0] == "flap-inertia"
    assert "advance-ratio-perturbation" in added
    costs = [r.fit.cost for r in lad.rungs]
    assert costs == sorted(costs, reverse=True)
    final = lad.final.fit
    ratio = np.array([abs(final.S[0][i, i]) for i in range(3)]) / (
        len(rec) * test.noise_flap ** 2)
    assert np.all(ratio < 1.5), ratio
    assert final.parameters["flap_inertia"] == pytest_approx(1.0, 3 * final.sigma[
        "flap_inertia"] + 0.05)
    k_mu, s = final.parameters["k_mu"], final.sigma["k_mu"]
    assert abs(k_mu - 1.0) < 3 * s + 0.1           # theory value, up to nonlinearity
    assert lad.final.diagnosis.missing_effect is None


def pytest_approx(v, tol):
    import pytest
    return pytest.approx(v, abs=tol)


@pytest.mark.slow
def test_at_256_hz_the_ladder_names_the_blades_2rev_flap():
    """At 256 Hz the noise per bin is four times lower, and what the first-harmonic
    multiblade model drops shows: the blades' 2/rev flap (order mu^2, 1 % of the
    cyclic flap at mu = 0.249).  Two cyclic doublets, seed 0, as in
    ``bench/detection.py --kind nonlinear``: the ladder adds flap inertia, then the
    2/rev flap with ``k_beta2`` at its theory value, and ends within 1.5 times the
    noise in every channel (before the effect existed it ended at 4-5 times and
    said the residual was outside the catalogue).

    The in-plane forcing is named as the direct forcing: ``glauert`` alone is more
    likely than it or the separate time constants alone, but the two together fit
    better by the Schwarz criterion (162.5 against 156.9, ``bench/README.md``), so
    ``glauert`` is not named before them, and beside them it is not worth its seven
    gains.  ``k_mu`` comes out above its theory value 1: it also carries the Eq. (14)
    in-plane coupling of the truth, which acts the same way on the flap."""
    from inflowsim.flighttest.virtual import Manoeuvre
    test = FlightTest(dt=1 / 256, seed=0, noise_flap=1e-4,
                      manoeuvres=(Manoeuvre(), Manoeuvre(channel="theta1c", t_start=12.0)))
    rec = nonlinear_flighttest(test).record
    lad = ladder(rec, "basic")
    added = [r.added for r in lad.rungs[1:]]
    assert added[:3] == ["flap-inertia", "second-harmonic-flap",
                         "advance-ratio-perturbation"], added
    assert "glauert" not in added
    final = lad.final.fit
    ratio = np.array([abs(final.S[0][i, i]) for i in range(3)]) / (
        len(rec) * test.noise_flap ** 2)
    assert np.all(ratio < 1.5), ratio
    k, s = final.parameters["k_beta2"], final.sigma["k_beta2"]
    assert abs(k - 1.0) < 3 * s, (k, s)
    assert 0.9 < final.parameters["k_mu"] < 1.5
    assert not [f for f in lad.final.diagnosis.failures if f.kind == "unexplained"]
    d = lad.rungs[2].diagnosis
    assert d.missing_effect == "advance-ratio-perturbation"
    named = {c.effect: c for c in d.candidates}
    assert named["advance-ratio-perturbation"].displaced == "glauert"
    g = named["glauert"]
    assert not g.accepted and g.reason.startswith(
        "not named before advance-ratio-perturbation+separate-time-constants")
    assert ("named before glauert: with separate-time-constants it explains the residual "
            "better than glauert with fewer parameters" in format_diagnosis(d))


@functools.lru_cache(maxsize=1)
def _no_eq14_record():
    """The 256 Hz record of the test above from a truth whose momentum loads use the
    trim ``mu`` for the speed through the disc: no Eq. (14) coupling, so no Glauert
    term in the truth; the direct in-plane forcing and the Pitt-Peters time
    constants (``tau0 != tau_cs``) stay."""
    from inflowsim.flighttest.bladesim import RotorSpec
    from inflowsim.flighttest.virtual import Manoeuvre
    test = FlightTest(rotor=RotorSpec(speed="mu"), dt=1 / 256, seed=0, noise_flap=1e-4,
                      manoeuvres=(Manoeuvre(), Manoeuvre(channel="theta1c", t_start=12.0)))
    return test, nonlinear_flighttest(test).record


@pytest.mark.slow
def test_without_the_glauert_coupling_in_the_truth_glauert_is_not_named():
    """``glauert``'s seven free gains fit what the direct in-plane forcing and the
    separate time constants explain with two parameters (Schwarz gain 251 against
    219, ``bench/README.md``); beside those two it adds nothing (p 0.4).  The test
    of a flexible candidate against pairs of simple ones names the truth's effects:
    flap inertia, the time constants, the in-plane forcing with ``k_mu`` at its
    theory value, the 2/rev flap, and no ``glauert``.  Without that test the ladder
    named ``glauert`` second."""
    test, rec = _no_eq14_record()
    lad = ladder(rec, "basic")
    added = [r.added for r in lad.rungs[1:]]
    assert added[0] == "flap-inertia"
    assert set(added) == {"flap-inertia", "separate-time-constants",
                          "advance-ratio-perturbation", "second-harmonic-flap"}, added
    final = lad.final.fit
    k_mu, s = final.parameters["k_mu"], final.sigma["k_mu"]
    assert abs(k_mu - 1.0) < 3 * s, (k_mu, s)
    ratio = np.array([abs(final.S[0][i, i]) for i in range(3)]) / (
        len(rec) * test.noise_flap ** 2)
    assert np.all(ratio < 1.5), ratio
    d = lad.rungs[1].diagnosis
    g = {c.effect: c for c in d.candidates}["glauert"]
    assert not g.accepted and g.explained_by is not None
    assert set(g.explained_by.split("+")) == {"advance-ratio-perturbation",
                                              "separate-time-constants"}


@pytest.mark.slow
def test_without_the_pair_test_glauert_would_be_named():
    from inflowsim.diagnose import diagnose
    from inflowsim.diagnose.rule import Rule
    _, rec = _no_eq14_record()
    assert diagnose(rec, "basic+flap-inertia",
                    rule=Rule(pair_min_dof=99)).missing_effect == "glauert"


@pytest.mark.slow
def test_a_part_of_glauert_is_named_where_the_whole_is_not_worth_its_gains():
    """256 Hz, seed 7 (``bench/README.md``): after flap inertia, the in-plane
    forcing, the 2/rev flap and the separate time constants, ``beta0`` is still
    twice the noise.  All seven Glauert gains are significant there but not worth
    their parameters (Schwarz gain -2.1); ``F`` alone (``k0p, kc, ks``: the blade's
    normal velocity in the speed through the disc, in the Eq. (14) truth) gains
    10.4 and brings ``beta0`` to within 1.5 times the record's noise."""
    from inflowsim.diagnose import diagnose
    from inflowsim.identify import identify
    from inflowsim.flighttest.virtual import Manoeuvre
    test = FlightTest(dt=1 / 256, seed=7, noise_flap=1e-4,
                      manoeuvres=(Manoeuvre(), Manoeuvre(channel="theta1c", t_start=12.0)))
    rec = nonlinear_flighttest(test).record
    base = ("basic+separate-time-constants+flap-inertia+advance-ratio-perturbation"
            "+second-harmonic-flap")
    d = diagnose(rec, base)
    assert d.missing_effect == "glauert"
    g = {c.effect: c for c in d.candidates}["glauert"]
    assert g.held == ("c1", "c2", "c3", "c4") and g.dof == 3
    assert "not worth their parameters beside the effect's other part" in g.reason
    whole = identify(rec, d.structure.with_effect("glauert"))
    n_data = 6 * whole.n_freq
    assert 2 * (d.fit.cost - whole.cost) - 7 * np.log(n_data) < 0 < g.schwarz_gain
    level = len(rec) * test.noise_flap ** 2
    assert abs(d.fit.S[0][0, 0]) / level > 1.9
    assert abs(g.fit.S[0][0, 0]) / level < 1.5


@functools.lru_cache(maxsize=1)
def _eq14_seed5():
    """256 Hz, seed 5 of ``bench/detection.py --kind nonlinear`` (white noise)."""
    from inflowsim.flighttest.virtual import Manoeuvre
    test = FlightTest(dt=1 / 256, seed=5, noise_flap=1e-4,
                      manoeuvres=(Manoeuvre(), Manoeuvre(channel="theta1c", t_start=12.0)))
    return test, nonlinear_flighttest(test).record


@pytest.mark.slow
def test_the_direct_forcing_with_glauerts_F_is_named_before_glauert_whole():
    """256 Hz, seed 5 (``bench/README.md``): after flap inertia and the 2/rev flap,
    all seven Glauert gains are more likely than the direct in-plane forcing (Schwarz
    gain 194.9 against 180.6) and take what it explains (beside them it is not
    significant), and the time constants are not significant, so no pair of simple
    candidates beats them: the ladder named ``glauert`` whole.  But the direct forcing
    with Glauert's ``F`` alone (the blade's normal velocity in the speed through the
    disc: the Eq. (14) truth has it) fits better with four parameters (206.7), and
    ``G`` adds nothing beside them.  So the direct forcing is named, with ``k_mu`` at
    its theory value, then Glauert's ``F`` with ``G`` held, and the ladder ends
    within 1.5 times the noise."""
    test, rec = _eq14_seed5()
    lad = ladder(rec, "basic")
    added = [r.added for r in lad.rungs[1:]]
    assert added == ["flap-inertia", "second-harmonic-flap", "advance-ratio-perturbation",
                     "glauert"], added
    final = lad.final.fit
    k_mu, s = final.parameters["k_mu"], final.sigma["k_mu"]
    assert abs(k_mu - 1.0) < 3 * s, (k_mu, s)
    assert all(final.sigma.get(n) is None for n in ("c1", "c2", "c3", "c4"))
    assert all(final.sigma.get(n) for n in ("k0p", "kc", "ks"))
    ratio = np.array([abs(final.S[0][i, i]) for i in range(3)]) / (
        len(rec) * test.noise_flap ** 2)
    assert np.all(ratio < 1.5), ratio
    d = lad.rungs[2].diagnosis
    named = {c.effect: c for c in d.candidates}
    assert d.missing_effect == "advance-ratio-perturbation"
    assert named["advance-ratio-perturbation"].displaced == "glauert"
    g = named["glauert"]
    assert not g.accepted and g.explained_by is None and g.held == ()
    assert g.reason.startswith("not named whole before advance-ratio-perturbation+"
                               "glauert (k0p, kc, ks)")
    assert "its c1, c2, c3, c4 are not significant" in g.reason
    assert "named before glauert: with glauert (k0p, kc, ks)" in format_diagnosis(d)


@pytest.mark.slow
def test_without_part_pairs_glauert_whole_would_be_named():
    from inflowsim.diagnose import diagnose
    from inflowsim.diagnose.rule import Rule
    _, rec = _eq14_seed5()
    d = diagnose(rec, "basic+flap-inertia+second-harmonic-flap", rule=Rule(max_part_pairs=0))
    assert d.missing_effect == "glauert"
    assert {c.effect: c for c in d.candidates}["glauert"].held == ()
