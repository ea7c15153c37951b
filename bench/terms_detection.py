"""How often the score map ranks a hidden single entry first (issue #24): the study
behind ``tests/test_missing_terms.py``'s slow tests, with the counts written out.

Run::

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python bench/terms_detection.py   # bench/terms.md

Per block of Eq. (1) (flap, inflow, measurement map) and per kind of record (held
``zoh`` and continuous inputs, 64 Hz): ten seeds of basic (tau = 5) plus the hidden
entry, fitted with basic; the hidden entry's rank, its statistic, the largest other
statistic, and the significant entries after Holm.  Null records: basic alone,
seeds 1-10, the number of significant entries and the mean statistic.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_missing_terms import HIDDEN, mapped  # noqa: E402


def main():
    print("| block | hold | ranked first | median statistic of the hidden entry | "
          "median largest other | median significant entries |")
    print("| --- | --- | --- | --- | --- | --- |")
    for block, (eq, var, _, value) in HIDDEN.items():
        for hold in ("zoh", "continuous"):
            first, own, other, sig = 0, [], [], []
            for seed in range(10):
                terms = mapped(block, seed, hold=hold)[2]
                key = [(t.block, t.equation, t.variable) for t in terms.terms]
                i = key.index((block, eq, var))
                first += i == 0 and terms.terms[0].sign == np.sign(value)
                own.append(terms.terms[i].statistic)
                other.append(max(t.statistic for j, t in enumerate(terms.terms) if j != i))
                sig.append(len(terms.significant))
            print(f"| {block} ({eq} <- {var}, {value:g}) | {hold} | {first}/10 | "
                  f"{np.median(own):.1f} | {np.median(other):.1f} | {np.median(sig):.0f} |")
    for hold in ("zoh", "continuous"):
        found, stats_all = [], []
        for seed in range(1, 11):
            terms = mapped(None, seed, hold=hold)[2]
            found.append(len(terms.significant))
            stats_all += [t.statistic for t in terms.terms if t.testable]
        print(f"\nnull, {hold}: significant entries per record {found}; mean statistic "
              f"{np.mean(stats_all):.2f} over {len(stats_all)} (chi-square 1 dof: 1)")


if __name__ == "__main__":
    main()
