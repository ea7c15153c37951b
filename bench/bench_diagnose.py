"""Diagnose benchmark (pytest-benchmark); not part of the default test run.

Run::

    OPENBLAS_NUM_THREADS=1 python -m pytest bench/bench_diagnose.py --benchmark-only -p no:cacheprovider
    OPENBLAS_NUM_THREADS=1 python bench/bench_diagnose.py      # table for bench/README.md

Goal (issue #5, part 8): ``diagnose`` of one 26.6 s record with every candidate
effect in at most 10 s.  Also timed: the ladder from ``basic`` on the hidden-glauert
record (three effects to find) and on the nonlinear blade-element truth.
"""
from __future__ import annotations

import sys
import time

import pytest

from inflowsim.diagnose import diagnose, ladder
from inflowsim.model.effects import CATALOGUE
from inflowsim.flighttest import FlightTest, nonlinear_flighttest
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record

TWO_AXES = (Manoeuvre(), Manoeuvre(channel="theta1c", t_start=12.0))
OFFERED = [n for n, e in CATALOGUE.items() if e.offered]


def hidden_glauert(rate=100.0, colour=None):
    """Continuous-time record (two cyclic doublets), hidden glauert truth; flap noise
    white or through a ``colour`` [Hz] low-pass (judged on the input-correlated
    excess)."""
    return virtual_record(VirtualTest(structure="glauert", seed=1, manoeuvres=TWO_AXES,
                                      dt=1.0 / rate, noise_color_hz=colour))


@pytest.fixture(scope="module")
def rec():
    return hidden_glauert()


def test_diagnose_every_candidate(benchmark, rec):
    d = benchmark.pedantic(diagnose, args=(rec, "basic"), rounds=3, iterations=1)
    assert len(d.candidates) == len(OFFERED) and d.missing_effect == "glauert"


def test_ladder_hidden_glauert(benchmark, rec):
    lad = benchmark.pedantic(ladder, args=(rec, "basic"), rounds=2, iterations=1)
    assert lad.final.structure.name == "glauert"


def _best(f, n=3):
    best = float("inf")
    out = None
    for _ in range(n):
        t = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t)
    return best, out


def main():
    rec = hidden_glauert()
    fast = hidden_glauert(256.0)
    coloured = hidden_glauert(256.0, colour=2.0)
    nl = nonlinear_flighttest(FlightTest(seed=1)).record
    rows = [("diagnose basic, every candidate ({n}), hidden-glauert record, 100 Hz",
             _best(lambda: diagnose(rec, "basic"))),
            ("diagnose basic, every candidate ({n}), hidden-glauert record, 256 Hz",
             _best(lambda: diagnose(fast, "basic"))),
            ("diagnose basic, every candidate ({n}), hidden-glauert record, 256 Hz, "
             "coloured noise (2 Hz)", _best(lambda: diagnose(coloured, "basic"))),
            ("diagnose glauert (no missing effect), {n} candidates",
             _best(lambda: diagnose(rec, "glauert"))),
            ("ladder basic -> glauert (3 effects found)", _best(lambda: ladder(rec, "basic"), 2)),
            ("ladder basic on the nonlinear truth", _best(lambda: ladder(nl, "basic"), 2))]
    print("| measurement | best time [s] | result |")
    print("| --- | --- | --- |")
    for name, (t, out) in rows:
        res = (out.missing_effect if hasattr(out, "missing_effect")
               else " -> ".join(r.added or r.structure.name for r in out.rungs))
        n = len(out.candidates) if hasattr(out, "candidates") else ""
        print(f"| {name.format(n=n)} | {t:.2f} | {res} |")


if __name__ == "__main__":
    sys.exit(main())
