"""What the record cannot tell apart (:func:`inflowsim.diagnose.rule.vuong_z`,
``Decision.indistinguishable``): Vuong's non-nested test of the added atom's fit
against each other admissible single atom's, on constructed per-bin costs (default)
and on servo records (slow: the servos hidden behind coloured noise, where a pure
delay fits as well, and behind white noise, where it does not)."""
import json
import math
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

from inflowsim.diagnose.rule import (DEFAULT_RULE, Decision, Scored, decide,
                                     vuong_critical, vuong_z)
from inflowsim.errors import InputError
from inflowsim.report.ladder import decision_lines

ROOT = Path(__file__).resolve().parents[1]


def test_vuong_z_of_equal_fits_is_small_and_of_a_clearly_better_one_large():
    rng = np.random.default_rng(3)
    n = 400
    # per-bin costs of a 3-channel circular residual: chi-square(6)/2 + ln|S|
    a = rng.chisquare(6, n) / 2 - 10.0
    # an equally good fit: independent draws of the same law
    same = rng.chisquare(6, n) / 2 - 10.0
    assert abs(vuong_z(a, same)) < vuong_critical(DEFAULT_RULE.alpha)
    # the same fit, bin for bin: nothing between them
    assert vuong_z(a, a) == 0.0
    # a clearly worse rival: each bin's cost up by a shift of 1 (half its spread)
    worse = a + 1.0 + 0.5 * rng.standard_normal(n)
    z = vuong_z(a, worse)
    assert z > 10 and vuong_z(worse, a) == pytest.approx(-z)
    # the statistic by hand: mean over its standard error
    d = worse - a
    assert z == pytest.approx(np.sqrt(n) * d.mean() / d.std())
    assert vuong_critical(1e-3) == pytest.approx(3.2905, abs=1e-4)
    with pytest.raises(InputError):
        vuong_z(a, a[:-1])


def _row(name, gain, bins):
    return Scored(atoms=(name,), effects=(name,), structure=f"basic+{name}", dof=1,
                  statistic=gain + 5.0, schwarz_gain=gain, beside=((name, -20.0),),
                  beside_gain=((name, gain),), excess_before=100.0, excess_after=10.0,
                  excess_noise=5.0, bins=tuple(bins))


def test_the_decision_says_which_admissible_single_atoms_it_cannot_tell_apart():
    rng = np.random.default_rng(7)
    n = 200
    base = rng.chisquare(6, n) / 2
    rows = [_row("time-delay", 60.0, base),
            _row("servo-actuators", 59.0, base + 0.05 * rng.standard_normal(n)),
            _row("azimuth-bias", 30.0, base + 1.0 + 0.3 * rng.standard_normal(n)),
            # not admissible (implausible): never compared
            Scored(atoms=("glauert",), effects=("glauert",), structure="basic+glauert",
                   dof=7, schwarz_gain=80.0, beside=(("glauert", -30.0),),
                   implausible=(("kc", 9.0, 0.1, 0.0, 2.0, "above"),),
                   bins=tuple(base))]
    d = decide(rows)
    assert d.accepted and d.added == ("time-delay",)
    names = [a for a, _ in d.vuong]
    assert names == ["servo-actuators", "azimuth-bias"]       # |z| ascending
    assert [a for a, _ in d.indistinguishable] == ["servo-actuators"]
    doc = json.loads(json.dumps(d.to_json()))
    assert doc["indistinguishable_from"] == ["servo-actuators"]
    assert [x["indistinguishable"] for x in doc["vuong"]] == [True, False]
    text = "\n".join(decision_lines(d))
    assert "time-delay added; the record cannot tell it from servo-actuators" in text
    assert "azimuth-bias (Vuong" not in text
    # a stored table keeps no per-bin costs: the choice is the same, nothing compared
    again = decide([Scored.from_json(r.to_json()) for r in d.rows])
    assert again.added == d.added and again.vuong == ()
    # nothing accepted: nothing compared
    assert Decision(tuple(rows), None, False).vuong == ()


# -- records -----------------------------------------------------------------------------
def _servo_ladder(case, seed=0):
    sys.path.insert(0, str(ROOT / "bench"))
    import rotor_physics_done as R
    from inflowsim.diagnose import ladder
    from inflowsim.diagnose.rule import offered_effects
    tmp = Path(tempfile.mkdtemp(prefix="indist_"))
    rec, _ = R.make_record("servo-actuators", case, seed, tmp / "rec.csv")
    return ladder(rec, "basic", pool=offered_effects())


@pytest.mark.slow
def test_behind_coloured_noise_the_servos_and_a_delay_are_said_to_be_indistinguishable():
    """bench/rotor_physics_done.py's coloured case, seed 0: ``time-delay`` is named
    (its statistic 588.0 against the servos' 582.7); the ladder says the record
    cannot tell it from the servos."""
    from inflowsim.report.ladder import ladder_markdown
    lad = _servo_ladder("coloured")
    from inflowsim.diagnose.rule import atom_of
    told = {frozenset((r.added, atom_of(a).effect))
            for r in lad.rungs[1:] for a, _ in r.indistinguishable}
    assert frozenset(("time-delay", "servo-actuators")) in told, told
    assert "the record cannot tell it from" in ladder_markdown(lad)
    doc = json.loads(json.dumps(lad.to_json()))
    assert any(x["indistinguishable_from"] for x in doc["rungs"][1:])


@pytest.mark.slow
def test_behind_white_noise_the_servos_are_told_apart_from_a_delay():
    lad = _servo_ladder("two-axis")
    first = lad.rungs[1]
    assert first.added == "servo-actuators"
    assert "time-delay" not in {a for a, _ in first.indistinguishable}
    # compared, and told apart: the servos fit better beyond the quantile
    z = dict(lad.rungs[0].diagnosis.decision.vuong)
    assert z["time-delay"] > vuong_critical(DEFAULT_RULE.alpha)
