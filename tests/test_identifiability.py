"""What a record determines (issue #29 item 2): Cramer-Rao bounds, insensitivities,
flat directions, the held values' uncertainty carried into the other bounds, and
the manoeuvres that would determine the rest.

The carried uncertainty is checked by an independent route: refits with a held
value moved (the estimates' shift must be the information matrix's prediction).
"""
import numpy as np
import pytest

from conftest import virtual
from inflowsim.flighttest.advice import standard_manoeuvres
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record
from inflowsim.model.presets import paper_table
from inflowsim.identify import identify
from inflowsim.identify.identifiability import (CR_PERCENT_LIMIT, describe,
                                                identifiability, prior_sigma)

ONE_AXIS = (Manoeuvre(),)                       # a theta1s doublet: muy never moves


@pytest.fixture(scope="module")
def one_axis():
    rec = virtual(structure="glauert", manoeuvres=ONE_AXIS, seed=3)
    fit = identify(rec, "glauert", fixed={"c2": 0.0})
    return rec, fit, identifiability(rec, fit, manoeuvres=standard_manoeuvres)


def test_an_input_that_never_moves_leaves_its_gain_undetermined(one_axis):
    rec, fit, ident = one_axis
    assert np.ptp(rec["muy"]) == 0
    assert ident.undetermined == ("c2",)
    p = ident["c2"]
    assert p.held and not p.determined and p.held_why == "undetermined"
    assert p.held_at == 0.0 and p.prior_sigma == pytest.approx(2.5)
    # c2 multiplies muy only: the one flat direction is c2 alone
    assert len(ident.flat_directions) == 1
    assert ident.flat_directions[0].components[0][0] == "c2"
    assert "muy" in ident.quiet_inputs
    # and it moves nothing else: no estimate is conditional on it
    assert not any("c2" in q.conditional_on for q in ident.parameters)
    # a lateral input would determine it; no longitudinal or collective one would
    m = {g.manoeuvre: dict(g.sigma_after)["c2"] for g in ident.manoeuvres}
    assert m["doublet on theta1c"] is not None and m["3211 on theta1c"] is not None
    assert m["doublet on theta1s"] is None and m["doublet on theta0"] is None


def test_bounds_and_insensitivities_are_cifer_measures(one_axis):
    rec, fit, ident = one_axis
    for p in ident.parameters:
        if p.held:
            continue
        # the Cramer-Rao bound is the fit's own
        assert p.sigma == pytest.approx(fit.sigma[p.name], rel=0.05), p.name
        # knowing every other parameter can only help: insensitivity <= bound
        assert p.insensitivity <= p.sigma * (1 + 1e-9), p.name
        assert p.cr_percent == pytest.approx(100 * p.sigma / abs(p.estimate))
        assert ("cr" in p.flags) == (p.cr_percent > CR_PERCENT_LIMIT)
    doc = ident.to_json()
    assert set(doc["parameters"]) == set(fit.parameters)
    assert all("determined" in v for v in doc["parameters"].values())


def test_held_values_uncertainty_is_carried_and_matches_refits():
    """Hold c1..c4 at zero on a one-axis record: the other estimates are
    conditional on them.  Moving a held value by delta moves each estimate by
    -K delta, K = M_ee^-1 M_ef (the linearisation about the fit; the truth here
    has c1..c4 = 0, so the held values are right and the fit has no model
    error): refits confirm it, and sigma_total carries K's share of the held
    values' plausible range."""
    p = dict(paper_table(3)[1]) | {"c1": 0.0, "c2": 0.0, "c3": 0.0, "c4": 0.0}
    rec = virtual_record(VirtualTest(structure="glauert", parameters=p,
                                     manoeuvres=ONE_AXIS, seed=3))
    held = {"c1": 0.0, "c2": 0.0, "c3": 0.0, "c4": 0.0}
    fit = identify(rec, "glauert", fixed=held)
    ident = identifiability(rec, fit)
    tau = ident["tau_cs"]
    assert "c3" in tau.conditional_on
    assert tau.sigma_total > 2 * tau.sigma
    delta = 0.01
    moved = identify(rec, "glauert", fixed={**held, "c3": delta},
                     start=dict(fit.parameters) | {"c3": delta}, multistart=False)
    for name in ("tau0", "kc", "azimuth_bias", "lambda_beta2"):
        shift = moved.parameters[name] - fit.parameters[name]
        predicted = dict(ident[name].held_gain)["c3"] * delta
        assert shift == pytest.approx(predicted, rel=0.25), name
    # tau_cs (12 % bound) is the least linear: sign and size within a factor 2
    shift = moved.parameters["tau_cs"] - fit.parameters["tau_cs"]
    ratio = shift / (dict(tau.held_gain)["c3"] * delta)
    assert 0.5 < ratio < 2.0, ratio
    # sigma_total^2 - sigma^2 = sum_f (gain_f prior_f)^2
    k = rec.constants
    carried = sum((g * prior_sigma(n, k)) ** 2 for n, g in tau.held_gain)
    assert tau.sigma_total ** 2 - tau.sigma ** 2 == pytest.approx(carried, rel=1e-6)
    text = "\n".join(describe(ident))
    assert "tau_cs" in text and "conditional on the held" in text
