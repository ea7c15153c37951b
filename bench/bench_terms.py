"""Score map benchmark: CPU time of :func:`inflowsim.diagnose.terms.missing_terms`
on one record; not part of the test run.

Run::

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python bench/bench_terms.py   # bench/terms.md

Goal (issue #24): the score map of one record in at most 1 s CPU.  Measured with
``time.process_time`` (CPU of this process, so other users' load on the machine
inflates it little), the best of ``REPEATS`` runs, beside the peer the map rides
on: the base fit (``identify``) of the same record in the same run.  Records: the
26.6 s virtual Puma record with two cyclic doublets, 64 and 100 Hz, held
(``zoh``) and continuous inputs, bases ``basic`` and ``glauert`` (a larger
structure: more base parameters to project off, azimuth bias, in-plane inputs).
"""
from __future__ import annotations

import platform
import time

from inflowsim.diagnose.terms import missing_terms
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record
from inflowsim.identify import identify

TWO_AXES = (Manoeuvre(), Manoeuvre(channel="theta1c", t_start=12.0))
REPEATS = 3
CASES = [("basic", "zoh", 64), ("basic", "continuous", 64), ("basic", "zoh", 100),
         ("glauert", "zoh", 64), ("glauert", "continuous", 100)]


def cpu(fn, repeats=REPEATS):
    best, out = float("inf"), None
    for _ in range(repeats):
        t = time.process_time()
        out = fn()
        best = min(best, time.process_time() - t)
    return best, out


def main():
    rows = []
    for base, hold, rate in CASES:
        rec = virtual_record(VirtualTest(structure="glauert", seed=1, manoeuvres=TWO_AXES,
                                         dt=1.0 / rate, hold=hold))
        t_fit, fit = cpu(lambda: identify(rec, base), 1)
        t_map, terms = cpu(lambda: missing_terms(rec, fit))
        rows.append((base, hold, rate, fit.n_freq, len(terms.terms), terms.n_tested,
                     t_fit, t_map))
    print(f"python {platform.python_version()}, numpy single-threaded; "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}\n")
    print("| base | hold | rate [Hz] | frequencies | entries | tested | fit CPU [s] | "
          "map CPU [s] | map / fit |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for base, hold, rate, nf, ne, nt, tf, tm in rows:
        print(f"| {base} | {hold} | {rate} | {nf} | {ne} | {nt} | {tf:.3f} | {tm:.3f} | "
              f"{tm / tf:.2f} |")


if __name__ == "__main__":
    main()
