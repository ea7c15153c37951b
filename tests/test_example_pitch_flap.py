"""The worked example of a user effect (issue #24, item 3), end to end on a record
this test makes: the truth is basic+glauert with pitch-flap coupling (delta-3,
``k3 = 0.3``), written by ``examples/effects/pitch_flap_coupling.py``.

Without the file the catalogue cannot explain the record (the diagnosis does not
claim to) and the score map points at the flap-to-pitch terms; with the file the
ladder names ``pitch-flap-coupling`` first, ``k3`` within 3 sigma, the residual at
the noise floor.  The ladders take a minute each on a loaded machine: the whole
story is marked slow; the default run checks the record, the map and the fit
from the file.
"""
import json
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest

import inflowsim as ifs
from conftest import TWO_AXES, run
from inflowsim.data.record import write_record
from inflowsim.diagnose import diagnose
from inflowsim.flighttest.virtual import VirtualTest, virtual_record
from inflowsim.identify import identify
from inflowsim.model.effects.user import USER_EFFECTS, load_effect_file, unregister
from inflowsim.model.presets import paper_table, theory_parameters

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "effects" / \
    "pitch_flap_coupling.py"
K3 = 0.3
NOISE = 1e-4


@pytest.fixture
def effect_file():
    """The example registered for one test, then removed (so that no other test
    sees a tenth offered candidate)."""
    before = set(USER_EFFECTS)
    load_effect_file(EXAMPLE)
    yield EXAMPLE
    for n in set(USER_EFFECTS) - before:
        unregister(n)


@lru_cache(maxsize=None)
def story_record():
    """basic+glauert (the paper's Table 3 gains, tau = 5) with ``k3 = 0.3``; two
    cyclic doublets, held inputs at 64 Hz, white flap noise 1e-4 rad."""
    before = set(USER_EFFECTS)
    load_effect_file(EXAMPLE)
    try:
        k = virtual_record(VirtualTest(duration=1.0)).constants
        s = ifs.Structure.parse("basic+glauert+pitch-flap-coupling")
        p = theory_parameters(s, k) | {"tau": 5.0, "k3": K3} | {
            n: v for n, v in paper_table(3)[1].items() if n[0] in "ck"}
        p = {n: v for n, v in p.items() if n in s.parameters}
        return virtual_record(VirtualTest(structure=s, parameters=p, seed=1, dt=1 / 64,
                                          noise_flap=NOISE, manoeuvres=TWO_AXES,
                                          hold="zoh"))
    finally:
        for n in set(USER_EFFECTS) - before:
            unregister(n)


def floor_ratio(fit, rec):
    """Residual power per flap channel over the white noise's level in the band."""
    return np.array([abs(fit.S[0][i, i]) for i in range(3)]) / (len(rec) * NOISE ** 2)


def test_the_map_points_at_the_flap_to_pitch_terms():
    from inflowsim.diagnose.terms import missing_terms
    rec = story_record()
    fit = identify(rec, "basic+glauert")
    assert floor_ratio(fit, rec).max() > 1.5        # the model misses something
    terms = missing_terms(rec, fit)
    top = terms.significant[:3]
    assert top, terms.rows[:3]
    # a pitch-flap coupling gives cross-flap stiffness terms (the label names the
    # entry, not one of the causes that give it)
    assert any(t.group == "cross-flap stiffness" for t in top), \
        [(t.equation, t.variable, t.group) for t in top]
    # and first the map's pitch entry (issue #36): the cyclic blade pitch fed from
    # its own cyclic flap, with the example file's coupling (theta = -k3 beta)
    first = terms.terms[0]
    assert (first.block, first.equation, first.variable) == ("pitch", "theta1", "beta1")
    assert first.refit_coefficient == pytest.approx(-K3, rel=0.1)


def test_the_fit_from_the_file_recovers_k3(tmp_path, capsys):
    path = write_record(story_record(), tmp_path / "story.csv")
    code, out, err = run(capsys, "identify", path, "--model",
                         "basic+glauert+pitch-flap-coupling", "--effect-file", EXAMPLE,
                         "--json")
    assert code == 0, err
    k3 = json.loads(out)["parameters"]["k3"]
    assert abs(k3["estimate"] - K3) < 3 * k3["sigma"], k3
    unregister("pitch-flap-coupling")


@pytest.mark.slow
def test_without_the_file_the_diagnosis_does_not_explain_it():
    rec = story_record()
    d = diagnose(rec, "basic+glauert")
    assert "pitch-flap-coupling" not in [c.effect for c in d.candidates]
    # whatever the catalogue adds, the residual stays above the noise floor
    from inflowsim.diagnose import ladder
    lad = ladder(rec, "basic+glauert")
    assert floor_ratio(lad.final.fit, rec).max() > 1.5, \
        ([r.added for r in lad.rungs], floor_ratio(lad.final.fit, rec))
    final = lad.final.diagnosis
    assert final.missing_effect is None
    assert any(f.kind == "unexplained" for f in final.failures)
    assert final.missing_terms.significant        # and the map says where to look


@pytest.mark.slow
def test_with_the_file_the_ladder_names_it_first(tmp_path, capsys):
    rec = story_record()
    path = write_record(rec, tmp_path / "story.csv")
    code, out, err = run(capsys, "ladder", path, "--model", "basic+glauert",
                         "--effect-file", EXAMPLE, "--json")
    assert code == 0, err
    rungs = json.loads(out)["rungs"]
    assert rungs[1]["added"] == "pitch-flap-coupling", [r["added"] for r in rungs]
    final = rungs[-1]
    k3 = final["parameters"]["k3"]
    assert abs(k3["estimate"] - K3) < 3 * k3["sigma"], k3
    floor = len(rec) * NOISE ** 2
    assert max(final["S_diag"][0]) < 1.5 * floor, (final["S_diag"], floor)
    unregister("pitch-flap-coupling")
