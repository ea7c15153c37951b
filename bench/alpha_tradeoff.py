"""What a looser significance level would buy: detections under strong colour
against false alarms on the null records (issue #9, ``bench/README.md``).

Offline, from the stored results of ``bench/detection.py``: at level ``alpha`` a
candidate whose *only* failed test was significance (its ``reason`` is "not
significant (p = ...)" and nothing else) counts as accepted when its p-value is below
``alpha``; on a null record any accepted candidate is a false alarm; on a hidden-effect
record the accepted candidate with the largest Schwarz gain is the one named.  The
rivals and pair tests are not re-run (they act on fitted pairs the results do not
hold), so the figures are an estimate of the trade-off, not a re-run of the rule.

    python bench/alpha_tradeoff.py --null bench/results/parts/null.jsonl.gz \\
        --hidden bench/results/parts/hidden_simple.jsonl.gz \\
                 bench/results/parts/hidden_flexible.jsonl.gz \\
                 bench/results/partpairs/hidden_affected.jsonl.gz
"""
from __future__ import annotations

import argparse
import gzip
import json
from pathlib import Path

import numpy as np

ALPHAS = (1e-3, 3e-3, 1e-2, 3e-2, 1e-1)


def _rows(paths):
    """Records by (effect, hold, rate, noise, seed); a later file replaces an earlier
    file's record."""
    out = {}
    for p in paths:
        text = gzip.open(p, "rt") if str(p).endswith(".gz") else open(p)
        with text as f:
            for line in f:
                if line.strip():
                    r = json.loads(line)
                    out[(r["effect"], r["hold"], r["rate"], r["noise"], r["seed"])] = r
    return out


def _only_significance_failed(c):
    return c["reason"].startswith("not significant") and ";" not in c["reason"]


def _accepted_at(r, alpha):
    lim = np.log10(alpha)
    return [c for c in r["candidates"] if c["accepted"] or (
        _only_significance_failed(c) and c["log10_p_value"] < lim)]


def tradeoff(null, hidden, noise="coloured", alphas=ALPHAS):
    """Rows ``(alpha, null records with an alarm, misses now named right, named
    wrong)`` over the hidden records of ``noise`` the rule at 1e-3 missed."""
    missed = [r for r in hidden.values() if r["noise"] == noise
              and r["missing_effect"] != r["effect"]]
    out = []
    for a in alphas:
        alarms = sum(bool(_accepted_at(r, a)) for r in null.values())
        right = wrong = 0
        for r in missed:
            acc = _accepted_at(r, a)
            if acc:
                best = max(acc, key=lambda c: c["schwarz_gain"])
                right += best["effect"] == r["effect"]
                wrong += best["effect"] != r["effect"]
        out.append((a, alarms, len(null), right, wrong, len(missed)))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--null", nargs="+", type=Path, required=True)
    ap.add_argument("--hidden", nargs="+", type=Path, required=True)
    ap.add_argument("--noise", default="coloured")
    a = ap.parse_args(argv)
    print("| alpha | null records with an alarm | misses named right | named wrong |")
    print("| --- | --- | --- | --- |")
    for alpha, fa, n, right, wrong, m in tradeoff(_rows(a.null), _rows(a.hidden), a.noise):
        print(f"| {alpha:g} | {fa}/{n} | {right}/{m} | {wrong} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
