"""Single-axis records (issue #29): the project's own default virtual flight test moves
one control.  The ladder from basic must add nothing the truth lacks, and every
estimate it reports must hold the truth within 3 sigma or be marked as not
determined by the record, with the manoeuvre that would determine it.

The records come from ``inflowsim flighttest --truth linear`` (the Table-3 glauert
truth, continuous time, the project's airframe answering the pilot), written and
read back as a user would.  ``theta1s`` (the default) runs by default; the other
two controls are the slow set.
"""
import json

import numpy as np
import pytest

from conftest import run
from inflowsim.data.record import read_record
from inflowsim.model.presets import paper_table

TRUTH_EFFECTS = {"glauert", "azimuth-bias", "separate-time-constants"}


_LADDERS = {}


def single_axis_ladder(tmp_path, capsys, channel, seed=0):
    """``(record, ladder JSON, path)``: the record written by the command and the
    ladder's JSON, made once a session per channel (both tests read the default)."""
    if (channel, seed) not in _LADDERS:
        path = tmp_path / f"{channel}.csv"
        code, _, err = run(capsys, "flighttest", "--truth", "linear", "--channel", channel,
                           "--seed", seed, "--out", path)
        assert code == 0, err
        code, out, err = run(capsys, "ladder", path, "--model", "basic", "--json")
        assert code == 0, err
        _LADDERS[channel, seed] = (read_record(path), json.loads(out), path)
    return _LADDERS[channel, seed]


# every case slow (the default run's budget, issue #38): the map's single-axis
# records (test_outside_truths) stay in the default run
@pytest.mark.parametrize("channel, seed", [
    *(pytest.param(c, s, marks=pytest.mark.slow) for c, s in [
        ("theta1s", 0), ("theta1c", 0), ("theta0", 0), ("theta1s", 1), ("theta1c", 2), ("theta0", 3)])])
def test_single_axis_ladder_adds_nothing_false_and_says_what_it_cannot_see(
        tmp_path, capsys, channel, seed):
    rec, doc, _ = single_axis_ladder(tmp_path, capsys, channel, seed)
    # what the ladder ends with: an atom added on a rung and removed at the end (the
    # later ones explain it) is said in "removed"
    final_effects = set(doc["rungs"][-1]["effects"])
    assert final_effects <= TRUTH_EFFECTS, (final_effects, doc["removed"])
    truth = paper_table(3)[1]
    final = doc["rungs"][-1]["parameters"]
    for name, p in final.items():
        assert "determined" in p and "held" in p, (name, p)
        if not p["determined"]:
            continue                      # said, not hidden: checked below
        if name in truth and p["sigma"] is not None:
            # the bound with the held values' uncertainty carried is the honest one
            sig = p.get("sigma_total") or p["sigma"]
            assert abs(p["estimate"] - truth[name]) < 3 * sig, (name, p, truth[name])
    # a held parameter is never silent: the record's identifiability names it,
    # with the value it is held at and a manoeuvre that would determine it
    ident = doc["identifiability"]
    for name, p in final.items():
        if p["held"]:
            assert name in ident["undetermined"] or p.get("held_why") == "user", name
            assert ident["parameters"][name]["held_at"] == pytest.approx(p["estimate"])
    for name in ident["undetermined"]:
        gains = [m["sigma_after"].get(name) for m in ident["manoeuvres"]]
        assert any(g is not None for g in gains), (name, ident["manoeuvres"])
    assert doc["verdict"]["status"] in ("explained", "no-missing-effect",
                                        "partly-explained")


def test_the_default_flight_test_names_the_truth_and_what_would_show_c2(tmp_path, capsys):
    """The issue's own case: one theta1s doublet.  The in-plane velocity ``muy``
    never moves, so Glauert's c2 (which multiplies only ``muy``) is not determined;
    ``mux`` moves a little, so c1, c3, c4 are estimated, not held at neutral (held
    at zero they biased tau_cs by 9 sigma and drew a spurious k_mu).  A lateral
    input would determine c2."""
    rec, doc, path = single_axis_ladder(tmp_path, capsys, "theta1s")
    assert np.ptp(rec["muy"]) == 0 and np.ptp(rec["mux"]) > 0
    final = doc["rungs"][-1]
    assert set(final["effects"]) == TRUTH_EFFECTS
    assert doc["identifiability"]["undetermined"] == ["c2"]
    assert not final["parameters"]["c2"]["determined"]
    assert all(final["parameters"][c]["determined"] for c in ("c1", "c3", "c4"))
    best = min((m for m in doc["identifiability"]["manoeuvres"]
                if m["sigma_after"].get("c2") is not None),
               key=lambda m: m["sigma_after"]["c2"])
    assert best["manoeuvre"].endswith("theta1c")
    assert doc["verdict"]["status"] == "explained"
    # the text renders the same ladder (from the JSON's own data: no second search)
    from inflowsim.diagnose.search import ladder
    from inflowsim.flighttest.advice import standard_manoeuvres
    from inflowsim.report.ladder import ladder_markdown
    assert path.exists()
    text = ladder_markdown(ladder(rec, "glauert", max_steps=0, pool=["time-delay"],
                                  manoeuvres=standard_manoeuvres))
    assert "c2: not determined by this record" in text and "theta1c" in text
    assert text.strip().splitlines()[-1].startswith("verdict:")
