"""Long records (issue #26): time and peak memory of ``identify`` and ``diagnose`` on
a 2-hour record at 64 Hz, beside the same on a 2-minute peer in the same run.

Run::

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python bench/bench_long.py [--hours 2] [--out bench/long.md]

The record: one 2-minute continuous-time chunk of the linear ``glauert`` truth
(:func:`inflowsim.flighttest.virtual.virtual_record`, no noise: a cyclic doublet
on each axis and a collective 3-2-1-1, each dying out within the chunk) repeated
back to back, then white flap noise (1e-4 rad, one seed) over the whole record;
the chunk starts and ends in trim, so the repetition is the truth's response to
the repeated inputs.  Made in chunks because the adaptive ODE solver over two
hours is itself the slowest part.  The 2-minute peer is one chunk with its own
noise.

Each measurement runs in a fresh process (the record is pickled to it): wall
time of the call (``time.perf_counter``) and the process's peak resident set
(``resource.getrusage(RUSAGE_SELF).ru_maxrss``, the interpreter and the record
included); the load average of the machine is printed with every line, since
the machine is shared: the ratio to the peer is the figure that travels.
"""
from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import resource
import sys
import time

import numpy as np

CHUNK_S = 120.0
DT = 1.0 / 64
NOISE = 1e-4


def chunk_record():
    from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record
    man = (Manoeuvre(channel="theta1s", t_start=5.0),
           Manoeuvre(channel="theta1c", t_start=35.0),
           Manoeuvre(channel="theta0", shape="3211", t_start=65.0, width=0.5))
    return virtual_record(VirtualTest(structure="glauert", manoeuvres=man, duration=CHUNK_S,
                                      dt=DT, noise_flap=0.0), include_truth=False)


def repeated(chunk, reps: int, seed: int):
    """``chunk`` back to back ``reps`` times with fresh white flap noise."""
    from inflowsim.data.record import FLAP_COLUMNS, Record
    n = len(chunk) * reps
    rng = np.random.default_rng(seed)
    cols = {}
    for k, v in chunk.channels.items():
        cols[k] = np.tile(v, reps)
        if k in FLAP_COLUMNS:
            cols[k] += NOISE * rng.standard_normal(n)
    return Record.from_arrays(np.arange(n) * DT, cols, dict(chunk.meta),
                              source=f"<{reps * CHUNK_S / 60:g} min>")


def _work(what, rec, q):
    from inflowsim.diagnose import diagnose
    from inflowsim.identify import identify
    t = time.perf_counter()
    if what == "identify":
        out = identify(rec, "glauert").n_freq
    else:
        out = diagnose(rec, "glauert").missing_effect
    dt = time.perf_counter() - t
    q.put((dt, resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0, out))


def measure(what, rec):
    ctx = mp.get_context("fork")
    q = ctx.Queue()
    p = ctx.Process(target=_work, args=(what, rec, q))
    p.start()
    res = q.get()
    p.join()
    return res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--hours", type=float, default=2.0)
    ap.add_argument("--out", default=None, help="also write the table here (markdown)")
    args = ap.parse_args(argv)
    t = time.perf_counter()
    chunk = chunk_record()
    reps = int(round(args.hours * 3600 / CHUNK_S))
    peer, long = repeated(chunk, 1, 1), repeated(chunk, reps, 2)
    print(f"records made in {time.perf_counter() - t:.1f} s ({len(long)} samples)",
          file=sys.stderr)
    rows = []
    for what in ("identify", "diagnose"):
        for name, rec in (("2 min", peer), (f"{args.hours:g} h", long), ("2 min", peer)):
            load = os.getloadavg()[0]
            sec, mb, out = measure(what, rec)
            rows.append((what, name, sec, mb, load, out))
            print(f"{what:9s} {name:6s} {sec:8.1f} s {mb:7.0f} MB  load {load:.1f}  ({out})",
                  file=sys.stderr)
    lines = ["| call | record | wall [s] | peak RSS [MB] | load (1 min) | result |",
             "|---|---|---:|---:|---:|---|"]
    lines += [f"| {w} | {n} | {s:.1f} | {m:.0f} | {ld:.1f} | {o} |"
              for w, n, s, m, ld, o in rows]
    for what in ("identify", "diagnose"):
        r = [x for x in rows if x[0] == what]
        peer_s = 0.5 * (r[0][2] + r[2][2])
        lines.append(f"\n{what}: the {args.hours:g}-hour record took {r[1][2] / peer_s:.1f} "
                     f"times the 2-minute peer's time (mean of the peer before and after), "
                     f"peak memory {r[1][3] / max(r[0][3], r[2][3]):.1f} times the peer's.")
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        with open(args.out, "w") as fh:
            fh.write(text)


if __name__ == "__main__":
    main()
