"""Campaign throughput (issue #26): the same small campaign on a local Dask cluster of
1 worker process and of 2, each into a fresh results folder, in one run.

Run::

    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 python bench/bench_campaign.py [--records 4] [--repeat 2] [--out bench/campaign.md]

The campaign: ``--records`` linear-truth records (``glauert``, 16 s at 64 Hz, a
cyclic doublet, held inputs so they are made fast), half at ``mu`` 0.2 and half
at 0.3, diagnosed from ``glauert`` with the candidates ``time-delay`` and
``flap-inertia`` and one ladder step; then the joint fit per condition.  Wall
time of :func:`inflowsim.campaign.engine.run_campaign` including the cluster's
start (a second or two), so the ratio is a lower bound of the workers' own
speed-up.  The runs alternate in ABBA order, ``--repeat`` times (1, 2, 2, 1
workers, then again): each count's runs are placed symmetrically in time, so a
steady drift of the shared machine's load falls on both alike; the ratio is taken
per ABBA block (the mean of its two 1-worker runs over the mean of its two
2-worker runs) and its median over the blocks reported, with the best run of
each count.  The load average is printed with each line.
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path


def make_plan(folder: Path, n: int) -> Path:
    from inflowsim.data.record import write_record
    from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record
    from inflowsim.model.params import PUMA
    for i in range(n):
        mu = 0.2 if i < n // 2 else 0.3
        ch = ("theta1s", "theta1c")[i % 2]
        rec = virtual_record(VirtualTest(structure="glauert", constants=PUMA.with_mu(mu),
                                         dt=1 / 64, duration=16.0, seed=i, hold="zoh",
                                         manoeuvres=(Manoeuvre(channel=ch),)))
        write_record(rec.with_meta(manoeuvre=f"doublet {ch}"), folder / f"r{i:02d}.csv")
    return folder


def main(argv=None):
    from inflowsim.campaign import Settings, read_plan
    from inflowsim.campaign.engine import run_campaign
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--records", type=int, default=4)
    ap.add_argument("--out", help="also write the table here (markdown)")
    ap.add_argument("--repeat", type=int, default=2, help="ABBA blocks")
    args = ap.parse_args(argv)
    tmp = Path(tempfile.mkdtemp(prefix="bench_campaign."))
    try:
        (tmp / "plan").mkdir()
        plan = read_plan(make_plan(tmp / "plan", args.records))
        s = Settings(pool=("time-delay", "flap-inertia"), max_steps=1)
        rows = []
        for r in range(args.repeat):
            for n in (1, 2, 2, 1):
                load = os.getloadavg()[0]
                t = time.perf_counter()
                out = tmp / f"out{len(rows)}"
                res = run_campaign(plan, out, s, workers=n, progress=False)
                sec = time.perf_counter() - t
                shutil.rmtree(out, ignore_errors=True)
                assert res.computed["records"] == args.records
                rows.append((r, n, sec, load))
                print(f"block {r + 1}: {n} worker(s): {sec:.1f} s  load {load:.1f}",
                      file=sys.stderr)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    ratios = []
    for r in range(args.repeat):
        blk = [x for x in rows if x[0] == r]
        one = statistics.mean(x[2] for x in blk if x[1] == 1)
        two = statistics.mean(x[2] for x in blk if x[1] == 2)
        ratios.append(one / two)
    lines = ["| block | workers | wall [s] | load (1 min) |", "|---:|---:|---:|---:|"]
    lines += [f"| {r + 1} | {n} | {sec:.1f} | {ld:.1f} |" for r, n, sec, ld in rows]
    best = {n: min(x[2] for x in rows if x[1] == n) for n in (1, 2)}
    lines.append(f"\n{args.records} records, 2 conditions, {args.repeat} ABBA blocks "
                 f"(1, 2, 2, 1 workers): 2 workers ran {statistics.median(ratios):.2f} "
                 f"times as fast as 1 (median over the blocks of the ratio within each; "
                 f"per block {', '.join(f'{x:.2f}' for x in ratios)}; best runs "
                 f"{best[1]:.1f} s and {best[2]:.1f} s), on {os.cpu_count()} cores.")
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        Path(args.out).write_text(text)


if __name__ == "__main__":
    main()
