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
from outside_truths import KINDS, TRUTHS, outside_record

SHORT = 6.0


def test_where_each_truth_acts_is_named_in_the_map_s_terms():
    assert len(KINDS) >= 4
    for t in TRUTHS.values():
        assert t.equations and t.variables, t.kind
        for block, eq in t.equations:
            assert block in ("flap", "inflow", "measurement")
            assert eq in (INFLOW if block == "inflow" else FLAP)
        assert set(t.variables) <= set(FLAP + FLAP_RATE + INFLOW + INPUTS)
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


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="issue #36's done-when asks >= 90 %; measured "
                   "72 % (bench/outside.md): pitch-lag's coning term is placed in the "
                   "recorded coning, rotor-speed's slow extra state on other variables")
def test_the_done_when_study_places_the_map_s_top_entry():
    """The map's top entry lies where the truth's term acts (>= 90 % over the kinds a
    single entry can place: all but cyclic-stiffness)."""
    bench, rows = _study()
    placed = [r for r in rows if r["kind"] not in bench.AMBIGUOUS]
    assert len({r["kind"] for r in placed}) >= 4
    assert sum(r["hit"] for r in placed) >= 0.9 * len(placed), bench.table(rows)
