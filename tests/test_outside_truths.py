"""Truths outside the catalogue (issue #36): the generator, and the done-when study.

The generator (``tests/outside_truths.py``) is checked against its own statement:
each kind at strength 0 is the base record itself (same seed, same noise), its
term changes the record, the sensor cross-coupling is exactly ``k beta1s`` in the
recorded ``beta1c``, and where each truth acts is named in the map's own terms.
The study (``bench/outside.py``, slow) asks the done-when of the diagnosis.
"""
import importlib.util
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest

from inflowsim.channels import FLAP, FLAP_RATE, INFLOW, INPUTS
from inflowsim.diagnose.terms import BLOCKS, CONFIRM, PITCH_FEEDS, PITCH_ROWS, missing_terms
from inflowsim.identify import identify
from outside_truths import KINDS, TRUTHS, outside_record

SHORT = 6.0


def test_where_each_truth_acts_is_named_in_the_map_s_terms():
    assert len(KINDS) >= 4
    for t in TRUTHS.values():
        assert t.equations and t.variables, t.kind
        for block, eq in t.equations:
            assert block in BLOCKS
            assert eq in {"inflow": INFLOW, "pitch": PITCH_ROWS}.get(block, FLAP)
        assert set(t.variables) <= set(FLAP + FLAP_RATE + INFLOW + INPUTS) | {
            v for _, v in PITCH_FEEDS}
        b, e = t.equations[0]
        assert t.acts_at(b, e, t.variables[0])
        assert not t.acts_at("nowhere", e, t.variables[0])
        assert t.to_json()["kind"] == t.kind


def test_a_truth_at_strength_zero_is_the_base_record(tmp_path):
    """A kind with extra states at strength 0 gives the same record as one without
    (the base, same seed); at its strength each kind's term moves the recorded flap
    above the noise."""
    base, _ = outside_record(tmp_path / "z.csv", "cyclic-entry", 3, rate=40,
                             strength=0.0, duration=SHORT)
    assert base.hold == "continuous" and abs(base.dt - 0.025) < 1e-12
    assert len(base) == int(SHORT * 40)
    for kind in ("pitch-lag", "rotor-speed"):
        zero, _ = outside_record(tmp_path / "z.csv", kind, 3, rate=40, strength=0.0,
                                 duration=SHORT)
        for c in FLAP:
            np.testing.assert_allclose(zero[c], base[c], atol=1e-10, err_msg=kind)
    for kind in KINDS:
        rec, info = outside_record(tmp_path / "r.csv", kind, 3, rate=40, axes="both",
                                   duration=SHORT)
        moved = max(np.abs(rec[c] - base[c]).max() for c in FLAP)
        assert moved > 1e-4, (kind, moved)        # the term is above the noise
        assert info["strength"] == TRUTHS[kind].strength
        if kind == "cross-sensor":
            # the recorded beta1c gains k times the true beta1s (the noise of the
            # recorded beta1s is not in it), the recorded beta1s is untouched
            k = info["strength"]
            tr = base.constants.trim
            np.testing.assert_allclose(rec["beta1c"] - base["beta1c"],
                                       k * (base["beta1s"] - tr["beta1s"]),
                                       atol=5 * k * 1e-4)
            np.testing.assert_allclose(rec["beta1s"], base["beta1s"], atol=1e-10)


def test_only_the_pilot_s_axes_move(tmp_path):
    rec, _ = outside_record(tmp_path / "r.csv", "pitch-lag", 1, rate=40, axes="theta1c",
                            duration=SHORT)
    assert np.ptp(rec["theta1s"]) == 0 and np.ptp(rec["theta1c"]) > 0.01
    with pytest.raises(ValueError, match="axes"):
        outside_record(tmp_path / "x.csv", "pitch-lag", 1, axes="theta0")


def _bench():
    path = Path(__file__).parent.parent / "bench" / "outside.py"
    spec = importlib.util.spec_from_file_location("bench_outside", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@lru_cache(maxsize=None)
def _study():
    bench = _bench()
    return bench, bench.run(say=lambda msg: None)


@pytest.mark.slow
def test_the_done_when_study_flags_every_stand_in():
    """Issue 36, done when: over the generator's truths (five kinds, seeds 1-5 each,
    two-axis and single-axis), no delay lead nor an effect that leaves most of the
    excess is named without the stand-in flag."""
    bench, rows = _study()
    assert len(rows) == 50 and len({r["kind"] for r in rows}) == 5
    assert not any(r["lead_unflagged"] for r in rows)
    assert not any(r["unflagged_excess"] for r in rows), bench.table(rows)


def test_the_map_places_a_pitch_lag_in_the_cyclic_pitch(tmp_path):
    """Issue 36: a torsion that makes the cyclic pitch lag the cyclic flap acts in
    every row the pitch enters; no single row's entry is it, and the shared
    parameters freed per row group soak up its cyclic part.  The map's pitch entry
    (both cyclics fed from their own cyclic flap, one coefficient) comes first,
    alone, with the truth's coefficient (-k: the elastic pitch is -k beta1)."""
    rec, info = outside_record(tmp_path / "r.csv", "pitch-lag", 2, rate=64.0,
                               axes="both")
    terms = missing_terms(rec, identify(rec, "basic"))
    top = terms.terms[0]
    assert (top.block, top.equation, top.variable) == ("pitch", "theta1", "beta1"), \
        terms.rows[:3]
    assert info["truth"].places([(t.block, t.equation, t.variable)
                                 for t in terms.first_group])
    assert top.significant() and len(terms.first_group) == 1
    assert top.refit_coefficient == pytest.approx(-info["strength"], rel=0.15)
    assert "the cyclic pitch" in " ".join(terms.describe())


@pytest.mark.slow
def test_the_map_determines_a_slow_state_as_a_lagged_entry(tmp_path):
    """Issue 36: rotor-speed variation is a slow state driven by the uniform inflow
    (``tau_w w' + w = -g lambda0``, 0.8 s) forcing the coning row: no constant entry
    is it, and entries on other variables tied with ``beta0 x lambda0``.  The lagged
    entry (the map's one ``T``, the band's lowest corner, not the truth's) is named
    alone, in place, its coefficient near the truth's ``-k g`` (the lag differs)."""
    rec, info = outside_record(tmp_path / "r.csv", "rotor-speed", 2, rate=100.0,
                               axes="both")
    terms = missing_terms(rec, identify(rec, "basic"))
    top = terms.answer
    assert top is not None, terms.rows[:3]
    assert (top.block, top.equation, top.variable) == ("flap", "beta0", "lambda0")
    assert top.lag == pytest.approx(1 / (2 * np.pi * 0.2256), rel=0.02)
    assert info["truth"].acts_at(*top.key)
    truth = info["truth"]
    assert top.refit_coefficient == pytest.approx(-truth.strength * truth.gain, rel=0.2)
    assert "lambda0 lagged" in " ".join(terms.describe())


@pytest.mark.slow
def test_the_map_finds_a_slow_state_behind_tied_stand_ins(tmp_path):
    """Issue 36: on a single-axis record (theta1c alone, which hardly moves the
    uniform inflow) the rotor-speed truth's slow state is absorbed by the base's
    inflow time constant: entries of the uniform inflow row tie at the top, and the
    lagged ``flap beta0 x lambda0``, whose score is near zero there (a refit from
    zero stays on the saddle), is not among the entries of largest score.  The
    refits of the lagged inflow entries in the refitted entries' rows, from unit
    gain, find it: named alone, in place, its coefficient near the truth's ``-k g``
    (seed 6: the first group tied in the inflow row before those refits)."""
    rec, info = outside_record(tmp_path / "r.csv", "rotor-speed", 6, rate=64.0,
                               axes="theta1c", colour_hz=None)
    terms = missing_terms(rec, identify(rec, "basic"))
    top = terms.answer
    assert top is not None, terms.rows[:4]
    assert top.key[:3] == ("flap", "beta0", "lambda0") and top.lag, top.key
    # not among the entries of largest score that the map refits first
    assert sum(t.statistic > top.statistic for t in terms.terms) >= CONFIRM
    truth = info["truth"]
    assert top.refit_coefficient == pytest.approx(-truth.strength * truth.gain, rel=0.35)


@pytest.mark.slow
def test_the_done_when_study_places_the_map_s_first_group():
    """The map's first group (the entries the record cannot tell apart) lies where
    the truth's term acts on >= 90 % of the records of the kinds a single entry can
    place (all but cyclic-stiffness); the groups are mostly one entry, and the top
    entry alone is in place on >= 90 % too (issue 36's criterion, ties counted as
    they fall); the entry the map names, where it names one, on >= 90 %."""
    bench, rows = _study()
    placed = [r for r in rows if r["kind"] not in bench.AMBIGUOUS]
    assert len({r["kind"] for r in placed}) >= 4
    assert sum(r["hit"] for r in placed) >= 0.9 * len(placed), bench.table(rows)
    assert sum(len(r["group"]) == 1 for r in placed) >= 0.75 * len(placed)
    assert sum(r["entry_hit"] for r in placed) >= 0.9 * len(placed), bench.table(rows)
    # the entry the map names (determined: significant, alone in its first group) is
    # in place on >= 90 % of the records it names one on, and it names one on most
    named = [r for r in placed if r["determination"] == "determined"]
    assert len(named) >= 0.75 * len(placed), bench.table(rows)
    assert sum(r["entry_hit"] for r in named) >= 0.9 * len(named), bench.table(rows)
