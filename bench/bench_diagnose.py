"""Diagnose benchmark (pytest-benchmark); not part of the default test run.

Run::

    OPENBLAS_NUM_THREADS=1 python -m pytest bench/bench_diagnose.py --benchmark-only -p no:cacheprovider
    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python bench/bench_diagnose.py   # table for bench/README.md

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
    # one candidate per atom (glauert's two parts are two); the truth's effects only
    assert len(d.candidates) == len(OFFERED) + 1
    assert set(d.missing_effects) <= {"glauert", "azimuth-bias", "separate-time-constants"}


def test_ladder_hidden_glauert(benchmark, rec):
    lad = benchmark.pedantic(ladder, args=(rec, "basic"), rounds=2, iterations=1)
    assert lad.final.structure.name == "glauert"


def _best(f, n=3):
    """(best wall time [s], best CPU time [s], result) of ``n`` calls."""
    wall = cpu = float("inf")
    out = None
    for _ in range(n):
        t, c = time.perf_counter(), time.process_time()
        out = f()
        cpu = min(cpu, time.process_time() - c)
        wall = min(wall, time.perf_counter() - t)
    return wall, cpu, out


def main(argv=None):
    """Each row beside its peer, timed in the same loop: ``identify`` of the row's base
    structure on the same record.  CPU time (``time.process_time``) is the figure to
    compare across runs on a shared machine; the ratio to the peer is the one to quote."""
    import argparse
    import os

    from inflowsim.identify import identify

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="best of N (diagnose rows)")
    ap.add_argument("--no-ladder", action="store_true", help="diagnose rows only")
    args = ap.parse_args(argv)
    n = args.repeat
    load0 = os.getloadavg()
    rec = hidden_glauert()
    fast = hidden_glauert(256.0)
    coloured = hidden_glauert(256.0, colour=2.0)
    rows = [("diagnose basic, every candidate ({n}), hidden-glauert record, 100 Hz",
             rec, "basic", lambda: diagnose(rec, "basic"), n),
            ("diagnose basic, every candidate ({n}), hidden-glauert record, 256 Hz",
             fast, "basic", lambda: diagnose(fast, "basic"), n),
            ("diagnose basic, every candidate ({n}), hidden-glauert record, 256 Hz, "
             "coloured noise (2 Hz)", coloured, "basic", lambda: diagnose(coloured, "basic"), n),
            ("diagnose glauert (no missing effect), {n} candidates",
             rec, "glauert", lambda: diagnose(rec, "glauert"), n)]
    if not args.no_ladder:
        nl = nonlinear_flighttest(FlightTest(seed=1)).record
        rows += [("ladder basic -> glauert (3 effects found)",
                  rec, "basic", lambda: ladder(rec, "basic"), max(1, n - 1)),
                 ("ladder basic on the nonlinear truth",
                  nl, "basic", lambda: ladder(nl, "basic"), max(1, n - 1))]
    print("| measurement | CPU [s] | peer: identify base, CPU [s] | ratio | wall [s] | result |")
    print("| --- | --- | --- | --- | --- | --- |")
    for name, r, base, f, k in rows:
        _, peer, _ = _best(lambda: identify(r, base), k)
        wall, cpu, out = _best(f, k)
        res = (out.missing_effect if hasattr(out, "missing_effect")
               else " -> ".join(x.added or x.structure.name for x in out.rungs))
        m = len(out.candidates) if hasattr(out, "candidates") else ""
        print(f"| {name.format(n=m)} | {cpu:.2f} | {peer:.3f} ({base}) | {cpu / peer:.0f}x "
              f"| {wall:.2f} | {res} |", flush=True)
    load1 = os.getloadavg()
    print(f"\nbest of {n} (ladders {max(1, n - 1)}); load average (1 min) "
          f"{load0[0]:.1f} at the start, {load1[0]:.1f} at the end")


if __name__ == "__main__":
    sys.exit(main())
