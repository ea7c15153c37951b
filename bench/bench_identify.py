"""Identification benchmarks (pytest-benchmark); not part of the default test run.

Run::

    OPENBLAS_NUM_THREADS=1 python -m pytest bench/bench_identify.py --benchmark-only -p no:cacheprovider
    OPENBLAS_NUM_THREADS=1 python bench/bench_identify.py     # timeit table (bench/identify.md)

Goals (issue #4, part 9): a glauert fit of a 26.6 s record at 0.01 s in at most 1 s;
the band study (ten lower limits) in at most 10 s; how the cost grows with record
length and the number of records fitted together.
"""
from __future__ import annotations

import sys
import timeit

import numpy as np
import pytest

from inflowsim.identify import band_study, evaluate, identify
from inflowsim.model.presets import preset_parameters
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record

THREE = (Manoeuvre("theta1s", "doublet", np.radians(1.0), 2.0, 0.4),
         Manoeuvre("theta1c", "doublet", np.radians(1.0), 8.0, 0.4),
         Manoeuvre("theta0", "doublet", np.radians(1.0), 14.0, 0.4))
LENGTHS = (13.3, 26.6, 53.2, 106.4)
COUNTS = (1, 2, 4)


def record(duration=26.6, seed=0, structure="glauert"):
    return virtual_record(VirtualTest(structure=structure, manoeuvres=THREE,
                                      duration=duration, noise_flap=1e-4, seed=seed))


def fit(recs, structure="glauert"):
    r = identify(recs, structure)
    assert r.converged
    return r


@pytest.mark.parametrize("structure", ["glauert", "glauert+time-delay"])
def test_fit_26s(benchmark, structure):
    rec = record(structure=structure)
    benchmark(fit, rec, structure)


def test_band_study(benchmark):
    rec = record()
    benchmark.pedantic(band_study, (rec, "glauert"), rounds=3, iterations=1)


def test_evaluate(benchmark):
    rec = record()
    p = preset_parameters("glauert")
    benchmark(evaluate, rec, "glauert", p)


@pytest.mark.parametrize("duration", LENGTHS)
def test_fit_vs_length(benchmark, duration):
    rec = record(duration)
    benchmark(fit, rec)


@pytest.mark.parametrize("count", COUNTS)
def test_fit_vs_records(benchmark, count):
    recs = [record(seed=k) for k in range(count)]
    benchmark(fit, recs)


def _best(fn, repeat=5):
    return min(timeit.repeat(fn, number=1, repeat=repeat))


def main():
    rows = []
    rec = record()
    rows.append(("glauert fit, 26.6 s", _best(lambda: fit(rec))))
    recd = record(structure="glauert+time-delay")
    rows.append(("glauert+time-delay fit, 26.6 s",
                 _best(lambda: fit(recd, "glauert+time-delay"))))
    p = preset_parameters("glauert")
    rows.append(("evaluate (glauert, 26.6 s)", _best(lambda: evaluate(rec, "glauert", p))))
    rows.append(("band study, 10 lower limits", _best(lambda: band_study(rec, "glauert"), 3)))
    for d in LENGTHS:
        r = record(d)
        rows.append((f"glauert fit, {d} s record", _best(lambda: fit(r))))
    for n in COUNTS:
        rs = [record(seed=k) for k in range(n)]
        rows.append((f"glauert fit, {n} x 26.6 s records", _best(lambda: fit(rs), 3)))
    print("| measurement | best of repeats [s] |\n| --- | ---: |")
    for name, t in rows:
        print(f"| {name} | {t:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
