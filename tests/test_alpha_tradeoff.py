"""``bench/alpha_tradeoff.py``: what a looser significance level would buy, counted
from stored candidates (``bench/README.md``), on rows made by hand."""
import importlib.util
from pathlib import Path

import numpy as np

_spec = importlib.util.spec_from_file_location(
    "alpha_tradeoff", Path(__file__).parent.parent / "bench" / "alpha_tradeoff.py")
tradeoff_mod = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(tradeoff_mod)


def _cand(effect, p, gain, accepted=False, other_reason=None):
    reason = "accepted" if accepted else f"not significant (p = {p:.2g} >= 0.001)"
    if other_reason:
        reason += f"; {other_reason}"
    return {"effect": effect, "accepted": accepted, "reason": reason,
            "log10_p_value": float(np.log10(p)), "schwarz_gain": gain}


def _row(effect, named, cands, noise="coloured"):
    return {"effect": effect, "noise": noise, "missing_effect": named, "candidates": cands}


def test_a_candidate_failing_only_significance_counts_below_alpha():
    null = {1: _row("glauert", None, [_cand("time-delay", 2e-3, 7.0)]),
            2: _row("glauert", None, [_cand("azimuth-bias", 0.5, -5.0)]),
            # fails another test too: never counted
            3: _row("basic", None, [_cand("skewed-wake", 2e-3, 7.0,
                                          other_reason="implausible: k_skew < 0")])}
    hidden = {
        # a miss the looser level names right
        1: _row("second-harmonic-flap", None, [_cand("second-harmonic-flap", 5e-3, 5.2)]),
        # a miss it names wrong: the wrong one has the larger Schwarz gain
        2: _row("second-harmonic-flap", None, [_cand("second-harmonic-flap", 5e-3, 5.2),
                                               _cand("time-delay", 2e-3, 7.0)]),
        # named right already: not a miss
        3: _row("glauert", "glauert", [_cand("glauert", 1e-9, 30.0, accepted=True)]),
        # white noise: not counted under the default noise kind
        4: _row("time-delay", None, [_cand("time-delay", 5e-3, 5.0)], noise="white")}
    rows = {a: rest for a, *rest in tradeoff_mod.tradeoff(null, hidden,
                                                          alphas=(1e-3, 3e-3, 1e-2))}
    assert rows[1e-3] == [0, 3, 0, 0, 2]
    # the null time-delay at 2e-3; the second miss now names its time-delay
    assert rows[3e-3] == [1, 3, 0, 1, 2]
    assert rows[1e-2] == [1, 3, 1, 1, 2]            # both misses named, one wrong
