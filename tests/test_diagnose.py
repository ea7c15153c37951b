"""Find the missing physics: hidden-effect records (issue: workflow.md, "Data with a
hidden effect").  For each candidate effect, a record whose truth has it and whose
starting model (basic) lacks it: diagnose must name it first, and after adding it the
residual must fall to the noise floor with the true values inside 3 sigma.  The
records excite both axes (a longitudinal then a lateral cyclic doublet) so that
every candidate's parameters are determined; one fixed seed, not tuned.
"""
import json

import numpy as np
import pytest

import inflowsim as ifs
from inflowsim.cli import main
from inflowsim.diagnose import diagnose, explicit_ladder, ladder
from inflowsim.presets import paper_table, theory_parameters
from inflowsim.record import write_record
from inflowsim.virtual import Manoeuvre, VirtualTest, virtual_record

SEED = 1
NOISE = 1e-4
TWO_AXES = (Manoeuvre(), Manoeuvre(channel="theta1c", t_start=12.0))
TRUE_VALUES = {
    "separate-time-constants": {"tau0": 2.0, "tau_cs": 20.0},
    "hub-velocity-coupling": {k: v for k, v in paper_table(2)[1].items() if k[0] == "k"},
    "glauert": {k: v for k, v in paper_table(3)[1].items() if k[0] in "ck"},
    "azimuth-bias": {"azimuth_bias": 0.3},
    "time-delay": {"delay": 0.03},
    "flap-inertia": {},
    "skewed-wake": {},                      # its theory value for the Puma
    "advance-ratio-perturbation": {},       # k_mu = 1
}


def hidden(effect, seed=SEED):
    s = ifs.Structure.parse("basic").with_effect(effect)
    k = virtual_record(VirtualTest(duration=1.0)).constants
    p = theory_parameters(s, k) | {"tau": 5.0} | TRUE_VALUES[effect]
    p = {n: v for n, v in p.items() if n in s.parameters}
    rec = virtual_record(VirtualTest(structure=s, parameters=p, seed=seed,
                                     noise_flap=NOISE, manoeuvres=TWO_AXES))
    return rec, s, p


def floor_ratio(fit, rec):
    """Residual power per flap channel over the white-noise level N sigma^2."""
    return np.array([abs(fit.S[0][i, i]) for i in range(3)]) / (len(rec) * NOISE**2)


@pytest.mark.parametrize("effect", list(TRUE_VALUES))
def test_hidden_effect_is_named_first_and_explains_the_data(effect):
    rec, s, truth = hidden(effect)
    d = diagnose(rec, "basic")
    assert d.candidates[0].effect == effect, [(c.effect, c.log10_p) for c in d.candidates]
    assert d.missing_effect == effect
    base_floor = floor_ratio(d.fit, rec)
    fit = d.candidates[0].fit
    assert fit.structure == s
    ratio = floor_ratio(fit, rec)
    assert np.all(ratio < 1.3) and np.all(ratio > 0.7), ratio     # at the noise floor
    assert np.max(base_floor) > 3 * np.max(ratio)
    for n, v in truth.items():
        assert abs(fit.parameters[n] - v) < 3 * fit.sigma[n], (n, fit.parameters[n], v)


def test_no_missing_effect_no_alarm():
    rec, s, truth = hidden("separate-time-constants")
    d = diagnose(rec, s)
    assert d.missing_effect is None
    assert not any(c.significant for c in d.candidates)
    assert not [f for f in d.failures if f.kind in ("spectrum", "whiteness")]


def test_three_missing_effects_resolved_step_by_step():
    """The paper's own story: truth glauert (Table 3), start basic."""
    rec = virtual_record(VirtualTest(structure="glauert", seed=SEED))
    lad = ladder(rec, "basic")
    assert [r.structure.name for r in lad.rungs][-1] == "glauert"
    assert {r.added for r in lad.rungs[1:]} == {"glauert", "azimuth-bias",
                                                "separate-time-constants"}
    costs = [r.fit.cost for r in lad.rungs]
    assert costs == sorted(costs, reverse=True)
    assert lad.final.diagnosis.missing_effect is None
    assert np.all(floor_ratio(lad.final.fit, rec) < 1.3)


def test_explicit_ladder_tables_1_2_3(tmp_path, capsys):
    rec = virtual_record(VirtualTest(structure="glauert", seed=SEED))
    lad = explicit_ladder(rec, ["basic", "empirical", "glauert"])
    assert lad.rungs[0].added is None
    assert set(lad.rungs[2].added.split("+")) == {"glauert"}
    assert lad.rungs[2].fit.cost < lad.rungs[1].fit.cost < lad.rungs[0].fit.cost
    path = write_record(rec, tmp_path / "g.csv")
    assert main(["ladder", str(path), "--structures", "basic", "empirical", "glauert",
                 "--report", str(tmp_path / "rep")]) == 0
    out = capsys.readouterr().out
    assert "| quantity | basic | empirical | glauert |" in out and "tau_cs" in out
    assert (tmp_path / "rep" / "ladder.png").exists()


def test_diagnose_command_json_shape(tmp_path, capsys):
    rec, s, truth = hidden("azimuth-bias")
    path = write_record(rec, tmp_path / "r.csv")
    assert main(["diagnose", str(path), "--model", "basic", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert {"structure", "cost", "failures", "candidates", "missing_effect"} <= set(doc)
    assert doc["missing_effect"] == "azimuth-bias"
    c0 = doc["candidates"][0]
    assert {"effect", "cost_reduction", "significant"} <= set(c0)
    assert [c["cost_reduction"] for c in doc["candidates"] if c["significant"]] != []
    assert main(["diagnose", str(tmp_path / "none.csv"), "--model", "basic"]) == 2
    assert main(["diagnose", str(path), "--model", "basic", "--candidates", "bogus"]) == 2
