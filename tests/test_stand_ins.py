"""Stand-ins called stand-ins (issue #36 item 3).

A named effect whose estimate is impossible for what it claims to be (a
``time-delay`` that leads: no measurement chain leads) or that leaves most of the
excess is reported as a stand-in, as data on the verdict, in its text, ``--json``
and the HTML report; a delay that lags, explaining the record, is not one.
"""
import json
import sys
from pathlib import Path

import pytest

import inflowsim as ifs
from conftest import TWO_AXES
from inflowsim.diagnose import diagnose
from inflowsim.diagnose.rule import DEFAULT_RULE
from inflowsim.diagnose.verdict import StandIn, stand_ins
from inflowsim.flighttest.virtual import VirtualTest, virtual_record
from inflowsim.model.params import SPECS
from inflowsim.model.presets import theory_parameters

sys.path.insert(0, str(Path(__file__).parent))
from outside_truths import outside_record  # noqa: E402

POOL = ["time-delay", "azimuth-bias"]


def _delayed(delay, seed=4):
    k = virtual_record(VirtualTest(duration=1.0)).constants
    s = ifs.Structure.parse("basic+time-delay")
    p = theory_parameters(s, k) | {"tau": 5.0, "delay": delay}
    return virtual_record(VirtualTest(structure=s, parameters=p, seed=seed, dt=1 / 64,
                                      noise_flap=1e-4, manoeuvres=TWO_AXES, hold="zoh"))


def test_the_delay_s_physical_range_excludes_a_lead():
    lo, hi, why = SPECS["delay"].physical
    assert lo == 0.0 and hi > 0.1 and "lead" in why
    # the plausible range is the rule's and stays as it was
    assert SPECS["delay"].plausible[:2] == (-0.1, 0.1)


@pytest.mark.parametrize("delay, stand_in", [(-0.004, True), (0.004, False)])
def test_a_delay_that_leads_is_a_stand_in_and_one_that_lags_is_not(tmp_path, delay,
                                                                    stand_in):
    d = diagnose(_delayed(delay), "basic", pool=POOL)
    assert d.missing_effect == "time-delay", [(c.effect, c.reason) for c in d.candidates]
    v = d.verdict
    assert v.is_stand_in("time-delay") is stand_in, v.stand_ins
    doc = d.to_json()["verdict"]
    from inflowsim.report.ladder import diagnosis_report, format_diagnosis
    text = format_diagnosis(d)
    if stand_in:
        (x,) = v.stand_ins
        kind, name, est, sig, lo, hi, why = x.reasons[0]
        assert (kind, name, lo) == ("physical", "delay", 0.0)
        assert est + 3 * sig < 0
        assert doc["stand_ins"][0]["effect"] == "time-delay"
        assert doc["stand_ins"][0]["reasons"][0]["kind"] == "physical"
        assert "time-delay is a stand-in: it behaves like time-delay in this band" in text
        assert "see the map" in text and "a stand-in, see the verdict" in text
        index = diagnosis_report(d).write(tmp_path / "rep")
        assert "time-delay is a stand-in" in Path(index).read_text()
    else:
        assert v.status == "explained" and doc["stand_ins"] == []
        assert "stand-in" not in text


def test_an_effect_that_leaves_most_of_the_excess_is_a_stand_in(tmp_path):
    """The recorded beta1c carries k beta1s (outside the catalogue): an azimuth
    offset, which rotates both cyclics, takes a third of it."""
    rec, _ = outside_record(tmp_path / "r.csv", "cross-sensor", seed=1, rate=64)
    d = diagnose(rec, "basic", pool=POOL)
    v = d.verdict
    assert v.status in ("partly-explained", "unexplained"), v
    if v.effects:
        assert v.excess_explained < DEFAULT_RULE.stand_in_share
        assert all(v.is_stand_in(e) for e in v.effects), v.stand_ins
        assert all(x.reasons[-1][0] == "excess" for x in v.stand_ins)
        assert "stand-in" in v.describe()
    json.dumps(d.to_json())


def test_stand_ins_are_data_rendered_to_text():
    x = StandIn("time-delay", (("physical", "delay", -0.0035, 0.0003, 0.0, 1.0,
                                "a measurement chain cannot lead"),))
    assert x.to_json()["reasons"][0]["estimate"] == -0.0035
    assert "delay = -0.0035 +- 0.0003 is outside its physical range [0, 1]" in x.describe()
    assert stand_ins(("azimuth-bias",), None, 0.9) == ()
    (y,) = stand_ins(("azimuth-bias",), None, 0.2)
    assert y.reasons == (("excess", None, 0.2, None, DEFAULT_RULE.stand_in_share, None, None),)


def test_effects_that_explain_only_together_are_stand_ins():
    """Issue 36: two effects named in one decision that each alone remove almost
    nothing of what they remove together compensate each other (a wake distortion
    and a Glauert term named for a cyclic-entry truth: 3 % and 2 % alone, 53 %
    together); true effects named together remove about their own parts."""
    both = ("wake-distortion", "glauert")
    xs = stand_ins(both, None, 0.53, alone={"wake-distortion": 0.03, "glauert": 0.02})
    assert [x.effect for x in xs] == list(both)
    assert xs[0].reasons == (("partner", None, 0.03, None, 0.05, 0.53, None),)
    assert "explains excess only together with them" in xs[0].describe()
    assert xs[0].to_json()["reasons"][0]["kind"] == "partner"
    # parts that add up (a true pair), one effect, or an effect without its own row:
    # not flagged
    assert stand_ins(both, None, 0.9, alone={"wake-distortion": 0.5,
                                             "glauert": 0.35}) == ()
    assert stand_ins(("glauert",), None, 0.9, alone={"glauert": 0.0}) == ()
    assert stand_ins(both, None, 0.9, alone={"glauert": 0.0}) == ()
