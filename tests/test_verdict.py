"""The verdict (issue #29 item 3): a truth with a term no catalogue effect holds is
never reported as explained.

The truths are those of ``test_missing_terms`` (the basic model plus one matrix
entry outside the catalogue, in each block of Eq. (1)); the diagnosis starts from
basic, the structure the truth extends.  Whatever a catalogue effect takes of the
residual, the verdict must say that excess is left (``partly-explained``) or that
nothing explains it (``unexplained``), name the channel, and never claim the
residual is at the floor.
"""
import pytest

from inflowsim.diagnose import diagnose
from inflowsim.diagnose.verdict import STATUSES
from test_missing_terms import HIDDEN, truth_record


@pytest.mark.parametrize("block", [
    "flap", *(pytest.param(b, marks=pytest.mark.slow) for b in ("inflow", "measurement"))])
def test_a_term_outside_the_catalogue_is_never_explained(block):
    rec, value = truth_record(block, seed=2)
    d = diagnose(rec, "basic", assess=False)   # the verdict (test_missing_terms: the map)
    v = d.verdict
    assert v.status in ("unexplained", "partly-explained"), (v, d.missing_effect)
    assert v.where, v
    doc = d.to_json()["verdict"]
    assert doc["status"] == v.status and set(doc["remaining_excess"]) == {
        "beta0", "beta1c", "beta1s"}
    if d.missing_effect is not None:
        # a catalogue effect that takes part of it is named as a part, not the answer
        assert v.status == "partly-explained" and v.effects == (d.missing_effect,)
        assert v.excess_explained < 1.0
        from inflowsim.report.ladder import format_diagnosis
        text = format_diagnosis(d)
        assert "part of the missing physics" in text and "missing effect:" not in text


def test_null_record_verdict_and_statuses():
    rec, _ = truth_record(None, seed=2)
    d = diagnose(rec, "basic", assess=False)   # the verdict (test_missing_terms: the map)
    assert d.verdict.status == "no-missing-effect", d.verdict
    assert d.verdict.status in STATUSES and not d.verdict.where
    assert all(0.5 < v < 1.6 for _, v in d.verdict.remaining_excess)
    assert d.verdict.describe().startswith("verdict: no missing effect")
