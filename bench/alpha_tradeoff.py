"""What another significance level would buy: detections under strong colour against
false alarms on the null records (issue #9, ``bench/README.md``).

Offline, from the stored decisions of ``bench/detection.py`` (each record's
``"decision"``: every structure scored, as data).  The rule is applied again to each
stored table by :func:`inflowsim.diagnose.rule.decide` at each level ``alpha``; the
tables are not refitted, so the pairs are those of the level the study ran at (a
looser level could have paired atoms the stored table did not): an estimate of the
trade-off, exact for every single-atom decision.

    python bench/alpha_tradeoff.py --null bench/results/current/null.jsonl.gz \\
        --hidden bench/results/current/hidden.jsonl.gz
"""
from __future__ import annotations

import argparse
import gzip
import json
from dataclasses import replace

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
                    if "decision" in r:
                        out[(r["effect"], r["hold"], r["rate"], r["noise"], r["seed"])] = r
    return out


def decided_at(record: dict, alpha: float):
    """The stored decision of ``record`` made again at level ``alpha``."""
    from inflowsim.diagnose.rule import Scored, decide, rule_from_json
    doc = record["decision"]
    rule = replace(rule_from_json(doc["rule"]), alpha=alpha)
    return decide([Scored.from_json(s) for s in doc["structures"]], rule)


def tradeoff(null, hidden, noise="coloured", alphas=ALPHAS):
    """Rows ``(alpha, null records with an alarm, misses at the stored level, of
    those named right, named wrong, hidden records of that noise)``: a miss is a
    hidden record of ``noise`` whose stored decision does not add its effect."""
    missed = [r for r in hidden.values() if r["noise"] == noise
              and r["effect"] not in (r.get("missing_effects") or [])]
    n = sum(r["noise"] == noise for r in hidden.values())
    out = []
    for a in alphas:
        alarms = sum(decided_at(r, a).accepted for r in null.values())
        right = wrong = 0
        for r in missed:
            d = decided_at(r, a)
            if d.accepted:
                if r["effect"] in d.effects:
                    right += 1
                else:
                    wrong += 1
        out.append((a, alarms, len(missed), right, wrong, n))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--null", nargs="+", required=True)
    ap.add_argument("--hidden", nargs="+", required=True)
    ap.add_argument("--noise", default="coloured")
    a = ap.parse_args(argv)
    null, hidden = _rows(a.null), _rows(a.hidden)
    print(f"| alpha | null records with an alarm (of {len(null)}) | misses | named right "
          "| named wrong |")
    print("| --- | --- | --- | --- | --- |")
    for alpha, alarms, missed, right, wrong, _ in tradeoff(null, hidden, a.noise):
        print(f"| {alpha:g} | {alarms} | {missed} | {right} | {wrong} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
