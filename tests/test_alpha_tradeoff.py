"""``bench/alpha_tradeoff.py``: the stored decisions (data) decided again at other
levels by the rule itself, on tables made by hand."""
import importlib.util
from pathlib import Path

import numpy as np

from inflowsim.diagnose.rule import DEFAULT_RULE, Scored

_spec = importlib.util.spec_from_file_location(
    "alpha_tradeoff", Path(__file__).parent.parent / "bench" / "alpha_tradeoff.py")
tradeoff_mod = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(tradeoff_mod)


def _s(atom, p, gain, implausible=()):
    return Scored((atom,), (atom,), "s", 1, statistic=2 * gain, schwarz_gain=gain,
                  beside=((atom, float(np.log10(p))),), beside_gain=((atom, gain),),
                  implausible=implausible, excess_before=100.0, excess_after=40.0,
                  excess_noise=10.0)


def _rec(effect, rows, noise="coloured"):
    from inflowsim.diagnose.rule import decide
    d = decide(rows, DEFAULT_RULE)
    return {"effect": effect, "noise": noise, "missing_effects": list(d.effects),
            "decision": d.to_json()}


def test_stored_decisions_are_decided_again_at_each_level():
    bad = (("k_skew", -1.0, 0.1, 0.0, 1.5, "positive"),)
    null = {1: _rec("glauert", [_s("time-delay", 2e-3, 7.0)]),
            2: _rec("glauert", [_s("azimuth-bias", 0.5, -5.0)]),
            # implausible: never an alarm at any level
            3: _rec("basic", [_s("skewed-wake", 2e-3, 7.0, bad)])}
    hidden = {
        # a miss the looser level names right
        1: _rec("second-harmonic-flap", [_s("second-harmonic-flap", 5e-3, 5.2)]),
        # a miss it names wrong: the wrong one has the larger Schwarz gain
        2: _rec("second-harmonic-flap", [_s("second-harmonic-flap", 5e-3, 5.2),
                                         _s("time-delay", 2e-3, 7.0)]),
        # named right already: not a miss
        3: _rec("glauert", [_s("glauert", 1e-9, 30.0)]),
        # white noise: not counted under the default noise kind
        4: _rec("time-delay", [_s("time-delay", 5e-3, 5.0)], noise="white")}
    assert hidden[3]["missing_effects"] == ["glauert"]
    rows = {a: rest for a, *rest in tradeoff_mod.tradeoff(null, hidden,
                                                          alphas=(1e-3, 3e-3, 1e-2))}
    assert rows[1e-3] == [0, 2, 0, 0, 3]
    # the null time-delay at 2e-3 alarms; the second miss now names its time-delay
    assert rows[3e-3] == [1, 2, 0, 1, 3]
    assert rows[1e-2] == [1, 2, 1, 1, 3]            # both misses named, one wrong


def test_a_row_round_trips_through_json():
    r = _s("time-delay", 2e-3, 7.0, (("delay", 1.0, 0.1, 0.0, 0.5, "why"),))
    back = Scored.from_json(r.to_json())
    assert back == r
