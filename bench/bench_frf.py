"""CPU time of ``frequency_response`` (issue #25: ``frf`` of a 60 s record at 100 Hz
in at most 1 s CPU).

Run::

    OPENBLAS_NUM_THREADS=1 python bench/bench_frf.py      # the table of bench/frf.md

Records: virtual Puma (linear glauert truth, body motion), 60 s at 0.01 s: a sweep on
theta1s (one input) and a multisine on the three controls (three inputs), each
with the three flap outputs.  Timed: ``frequency_response`` on the record in
memory (CPU time of the process, ``time.process_time``, median of 5), and the whole
``inflowsim frf RECORD --json`` command in a fresh interpreter (CPU time of the
child, ``resource.getrusage(RUSAGE_CHILDREN)``: start-up, imports, reading the
CSV included; median of 3).  Peers, same run: one ``scipy.signal.csd`` Welch
estimate (one window length, 75 % overlap) of every input-output pair, the cost of
the textbook single-window ordinary estimate; and for the command, a fresh
interpreter that imports NumPy and reads the same CSV with ``numpy.loadtxt`` (the
least any Python command reading that file costs), median of 3.
"""
from __future__ import annotations

import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy import signal

from inflowsim.data.inputs import interleaved_harmonics
from inflowsim.data.record import find_trim, perturbations, write_record
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record
from inflowsim.identify.frf import frequency_response

CONTROLS = ("theta0", "theta1c", "theta1s")
FLAP = ("beta0", "beta1c", "beta1s")


def records():
    sweep = VirtualTest(manoeuvres=(Manoeuvre(shape="sweep", length=56.0,
                                              f_range=(0.1, 5.0)),), duration=60.0)
    hs = interleaved_harmonics(3, 6, 280)
    ms = VirtualTest(manoeuvres=tuple(Manoeuvre(channel=c, shape="multisine", length=56.0,
                                                harmonics=h) for c, h in zip(CONTROLS, hs)),
                     duration=60.0)
    return {"sweep, 1 input": virtual_record(sweep), "multisine, 3 inputs": virtual_record(ms)}


def cpu(fn, repeat=5):
    out = []
    for _ in range(repeat):
        t = time.process_time()
        fn()
        out.append(time.process_time() - t)
    return statistics.median(out)


def peer(rec, inputs):
    trim = find_trim(rec)
    x = perturbations(rec, trim, inputs)
    y = perturbations(rec, trim, FLAP)
    n = int(round(30.0 / rec.dt))
    for i in range(x.shape[1]):
        for o in range(3):
            signal.csd(x[:, i], y[:, o], fs=1 / rec.dt, window="hann", nperseg=n,
                       noverlap=3 * n // 4)


def child_cpu(argv):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(argv, check=True, stdout=subprocess.DEVNULL, env=dict(os.environ))
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def command_cpu(path):
    return child_cpu([sys.executable, "-m", "inflowsim.cli", "frf", path, "--json"])


def command_peer_cpu(path):
    code = ("import sys, numpy\n"
            "lines = open(sys.argv[1]).read().splitlines()\n"
            "k = next(i for i, ln in enumerate(lines) if ln.startswith('t,'))\n"
            "numpy.loadtxt(lines[k + 1:], delimiter=',')\n")
    return child_cpu([sys.executable, "-c", code, path])


def main():
    rows = []
    with tempfile.TemporaryDirectory() as d:
        for name, rec in records().items():
            fr = frequency_response(rec)
            t_frf = cpu(lambda: frequency_response(rec))
            t_peer = cpu(lambda: peer(rec, fr.inputs))
            path = os.path.join(d, "r.csv")
            write_record(rec, path, overwrite=True)
            t_cmd = statistics.median(command_cpu(path) for _ in range(3))
            t_cpeer = statistics.median(command_peer_cpu(path) for _ in range(3))
            rows.append((name, len(rec), fr.frequency_hz.size, len(fr.windows_s), t_frf,
                         t_peer, t_cmd, t_cpeer))
    print(f"load average {os.getloadavg()[0]:.2f}; OPENBLAS_NUM_THREADS="
          f"{os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}")
    print("| record | samples | frequencies | windows | frequency_response CPU [s] | "
          "peer: scipy csd, 1 window [s] | ratio | `inflowsim frf --json` CPU [s] | "
          "peer: python + numpy.loadtxt of the CSV [s] | ratio |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, n, nf, nw, a, b, c, d in rows:
        print(f"| {name} | {n} | {nf} | {nw} | {a:.3f} | {b:.3f} | {a / b:.1f} | {c:.2f} "
              f"| {d:.2f} | {c / d:.1f} |")


if __name__ == "__main__":
    main()
