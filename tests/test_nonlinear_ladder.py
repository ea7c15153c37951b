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


@pytest.mark.slow
def test_ladder_on_nonlinear_truth_names_flap_inertia_and_inplane_forcing():
    test = FlightTest(seed=1)
    rec = nonlinear_flighttest(test).record
    assert rec.hold == "continuous"
    lad = ladder(rec, "basic")
    added = [e for r in lad.rungs[1:] for e in r.added.split("+")]
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

    The in-plane forcing is named as the direct forcing, not as Glauert's in-plane
    gains, which mimic it with four parameters.  ``k_mu`` comes out above its
    theory value 1: it also carries the Eq. (14) in-plane coupling of the truth,
    which acts the same way on the flap."""
    from inflowsim.flighttest.virtual import Manoeuvre
    test = FlightTest(dt=1 / 256, seed=0, noise_flap=1e-4,
                      manoeuvres=(Manoeuvre(), Manoeuvre(channel="theta1c", t_start=12.0)))
    rec = nonlinear_flighttest(test).record
    lad = ladder(rec, "basic")
    added = [e for r in lad.rungs[1:] for e in r.added.split("+")]
    assert added[0] == "flap-inertia", added
    assert {"second-harmonic-flap", "advance-ratio-perturbation"} <= set(added), added
    final = lad.final.fit
    ratio = np.array([abs(final.S[0][i, i]) for i in range(3)]) / (
        len(rec) * test.noise_flap ** 2)
    assert np.all(ratio < 1.5), ratio
    k, s = final.parameters["k_beta2"], final.sigma["k_beta2"]
    assert abs(k - 1.0) < 3 * s, (k, s)
    assert 0.9 < final.parameters["k_mu"] < 1.5
    assert not [f for f in lad.final.diagnosis.failures if f.kind == "unexplained"]
    # Glauert's in-plane gains never enter beside the direct forcing
    assert not any(a == "glauert (c1, c2, c3, c4)" for r in lad.rungs for a in r.atoms)


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
    """Glauert's four in-plane gains fit what the direct in-plane forcing explains
    with one parameter, and more: alone they gain more than ``k_mu`` (53 against
    47 after flap inertia), but the pairs the lattice fits beside the 2/rev flap
    and the time constants favour the direct forcing (207 against 194).  The
    ladder names the truth's effects: flap inertia, the time constants, the
    in-plane forcing with ``k_mu`` at its theory value, the 2/rev flap, and no
    Glauert term."""
    test, rec = _no_eq14_record()
    lad = ladder(rec, "basic")
    added = [e for r in lad.rungs[1:] for e in r.added.split("+")]
    assert added[0] == "flap-inertia"
    assert set(added) == {"flap-inertia", "separate-time-constants",
                          "advance-ratio-perturbation", "second-harmonic-flap"}, added
    final = lad.final.fit
    k_mu, s = final.parameters["k_mu"], final.sigma["k_mu"]
    assert abs(k_mu - 1.0) < 3 * s, (k_mu, s)
    ratio = np.array([abs(final.S[0][i, i]) for i in range(3)]) / (
        len(rec) * test.noise_flap ** 2)
    assert np.all(ratio < 1.5), ratio
    assert not any(a.startswith("glauert") for r in lad.rungs for a in r.atoms)


@pytest.mark.slow
def test_a_part_of_glauert_is_named_where_the_whole_is_not_worth_its_gains():
    """256 Hz, seed 7 (``bench/README.md``): after flap inertia, the in-plane
    forcing, the 2/rev flap and the separate time constants, ``beta0`` is still
    twice the noise.  All seven Glauert gains are significant there but not worth
    their parameters (Schwarz gain -2.1); ``F`` alone (``k0p, kc, ks``: the blade's
    normal velocity in the speed through the disc, in the Eq. (14) truth) gains
    10.4 and brings ``beta0`` to within 1.5 times the record's noise: the rule adds
    the part ``F`` with ``G`` held at neutral."""
    from inflowsim.diagnose import diagnose
    from inflowsim.identify import identify
    from inflowsim.flighttest.virtual import Manoeuvre
    test = FlightTest(dt=1 / 256, seed=7, noise_flap=1e-4,
                      manoeuvres=(Manoeuvre(), Manoeuvre(channel="theta1c", t_start=12.0)))
    rec = nonlinear_flighttest(test).record
    base = ("basic+separate-time-constants+flap-inertia+advance-ratio-perturbation"
            "+second-harmonic-flap")
    d = diagnose(rec, base)
    assert d.missing_effect == "glauert" and d.decision.added == ("glauert (k0p, kc, ks)",)
    g = d.accepted
    assert set(g.held) == {"c1", "c2", "c3", "c4"} and g.dof == 3
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
def test_the_direct_forcing_and_glauerts_F_not_glauert_whole():
    """256 Hz, seed 5 (``bench/README.md``): all seven Glauert gains were once named
    for what the direct in-plane forcing explains (beside them it is not
    significant).  The truth (Eq. 14) has the direct forcing and Glauert's ``F``
    (the blade's normal velocity in the speed through the disc), not its in-plane
    gains ``G``: the ladder ends with ``k_mu`` at its theory value, ``G`` held, and
    within 1.5 times the noise."""
    test, rec = _eq14_seed5()
    lad = ladder(rec, "basic")
    added = [e for r in lad.rungs[1:] for e in r.added.split("+")]
    assert added[0] == "flap-inertia"
    assert {"second-harmonic-flap", "advance-ratio-perturbation"} <= set(added), added
    final = lad.final.fit
    k_mu, s = final.parameters["k_mu"], final.sigma["k_mu"]
    assert abs(k_mu - 1.0) < 3 * s, (k_mu, s)
    assert all(final.sigma.get(n) is None for n in ("c1", "c2", "c3", "c4"))
    ratio = np.array([abs(final.S[0][i, i]) for i in range(3)]) / (
        len(rec) * test.noise_flap ** 2)
    assert np.all(ratio < 1.5), ratio


@functools.lru_cache(maxsize=None)
def _ladder_at(rate, seed):
    test = FlightTest(dt=1 / rate, seed=seed)
    return ladder(nonlinear_flighttest(test).record, "basic")


@pytest.mark.slow
def test_ladders_at_three_rates_differ_only_where_the_noise_hides_an_effect():
    """One nonlinear flight (the default doublet) sampled at 50, 100 and 200 Hz,
    each with its own noise draw: the ladders may end at different structures, but
    every effect one of them adds and another does not is, on the other's last
    rung, not significant or not worth its parameters there (the record's noise
    hides it), never rejected as implausible or explained by a simpler effect; and
    none adds a time delay (the truth has none)."""
    ladders = {rate: _ladder_at(rate, seed) for rate, seed in ((50, 11), (100, 12),
                                                                (200, 13))}
    added = {rate: {e for r in lad.rungs[1:] for e in r.added.split("+")}
             for rate, lad in ladders.items()}
    for rate, lad in ladders.items():
        assert "time-delay" not in added[rate], (rate, added)
        assert "flap-inertia" in added[rate], (rate, added)
        last = lad.final.diagnosis.decision
        for other, effects in added.items():
            for e in effects - added[rate] - set(lad.final.structure.effects):
                rows = [r for r in last.rows if r.effects == (e,) and len(r.atoms) == 1]
                assert rows, (rate, e)
                for r in rows:
                    failed = set(r.failed(last.rule))
                    assert failed & {"significant", "parsimonious", "material"}, (
                        rate, other, e, failed)
                    assert not failed & {"plausible", "own"}, (rate, other, e, failed)


@pytest.mark.slow
def test_with_momentum_speed_offered_the_ladder_names_the_truths_own_eq14():
    """The virtual campaign's records at mu 0.20 (a 3-2-1-1 on each control, Eq. 14
    truth), fitted jointly from the base with separate time constants, with
    ``momentum-speed`` offered beside the paper's and the project's candidates:
    the ladder adds flap inertia, the direct in-plane forcing and Eq. (14)
    linearised, never glauert (its approximation), a wake skew or a delay the
    truth lacks, and ends with the truth's own tau0, flap frequency and Lock
    number within 3 of their bounds and k_V near 1 (measured: tau0 1.96 against
    2.12, n_beta 0.992 against 0.987, k_V 0.90).  tau_cs needs the 2/rev flap the
    ladder leaves out as not significant at this speed: an effect below what the
    record detects still moves an estimate by more than its bound."""
    from inflowsim.campaign.work import Settings, condition_task
    from inflowsim.flighttest.bladesim import RotorSpec
    from inflowsim.flighttest.campaign import campaign_items, virtual_campaign
    from inflowsim.flighttest.linearise import truth_parameters
    from inflowsim.model.params import PUMA
    import tempfile
    from pathlib import Path
    controls = ("theta0", "theta1c", "theta1s")
    with tempfile.TemporaryDirectory() as d:
        # 1 deg: the campaign's default when the figures above were measured
        virtual_campaign(d, mus=(0.20,), controls=controls, shapes=("3211",), workers=1,
                         amplitude_deg=1.0)
        pool = ("glauert", "momentum-speed", "flap-inertia", "second-harmonic-flap",
                "advance-ratio-perturbation", "skewed-wake", "time-delay", "azimuth-bias")
        paths = [str(Path(d) / it.name)
                 for it in campaign_items((0.20,), controls, ("3211",))]
        c = condition_task("mu=0.200", paths,
                           Settings(model="basic+separate-time-constants", pool=pool))
        assert c["status"] == "ok", c.get("error")
        added = set(c["ladder_added"])
        assert {"flap-inertia", "momentum-speed"} <= added
        assert not added & {"glauert", "skewed-wake", "time-delay"}
        final = c["final_fit"]["parameters"]
        truth = truth_parameters(RotorSpec(constants=PUMA.with_mu(0.20)))
        for name in ("tau0", "lambda_beta2", "n_beta"):
            e = final[name]
            assert abs(e["estimate"] - truth[name]) < 3 * e["sigma"], (name, e)
        assert abs(final["k_V"]["estimate"] - 1.0) < 3 * final["k_V"]["sigma"] + 0.1
        # tau_cs: 5 bounds low (0.99 against 1.13) while the 2/rev flap, not
        # significant here, is left out; with it, within its bound
        assert final["tau_cs"]["estimate"] < truth["tau_cs"]
        if "second-harmonic-flap" not in added:
            more = condition_task("mu=0.200", paths, Settings(
                model=c["final_structure"] + "+second-harmonic-flap", max_steps=0))
            e = more["base_fit"]["parameters"]["tau_cs"]
            assert abs(e["estimate"] - truth["tau_cs"]) < 3 * e["sigma"], e
