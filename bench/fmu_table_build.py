"""The FMU's one-time cost of a new flight condition: its first ``mu`` change builds
the ``mu`` table (the exact matrices at every table node), which for a structure with
``momentum-speed`` includes the disc quadrature and Newton solve of its coupling at
each node.

    python bench/fmu_table_build.py [--rounds R] [--structures S ...]

For each structure (Puma, the trim below, theory parameters), an FMI 2 FMU is built,
then in each of R rounds a fresh instance is initialised and timed: the first step
after a new ``mu`` (the table's build and one step) and the next 2,000 steps, each
with a new ``mu`` (the table's evaluation), through fmpy.  Rounds alternate between
the structures so the machine's load hits them alike; best and median are printed.
"""
from __future__ import annotations

import argparse
import statistics
import tempfile
import time

DEFAULT = ("basic+separate-time-constants+flap-inertia+advance-ratio-perturbation",
           "basic+separate-time-constants+flap-inertia+advance-ratio-perturbation"
           "+momentum-speed")
TRIM = {"theta0": 0.17, "theta1c": 0.012, "theta1s": -0.05, "beta0": 0.06,
        "beta1c": 0.011, "beta1s": -0.004, "muz": -0.02}


def _instance(structure):
    from fmpy import extract
    from inflowsim.fmu import build_fmu, description_for
    from inflowsim.fmu.generate import guid
    from inflowsim.model import build_model
    from inflowsim.model.params import PUMA
    from inflowsim.model.presets import truth_parameters
    k = PUMA.with_trim(TRIM)
    m = build_model(structure, truth_parameters(structure, k), k)
    d = tempfile.mkdtemp()
    path = build_fmu(d + "/s.fmu", model=m)
    desc = description_for(m)
    return extract(str(path), d + "/x"), desc, guid(desc)


def _round(unzipped, desc, gid, n):
    from fmpy.fmi2 import FMU2Slave
    s = FMU2Slave(guid=gid, unzipDirectory=unzipped, modelIdentifier="inflowsim",
                  instanceName="s")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    vr = [desc.vr["mu"]]
    t0 = time.perf_counter()
    s.setReal(vr, [0.15])
    s.doStep(0.0, 0.01)
    first = time.perf_counter() - t0
    t0 = time.perf_counter()
    for i in range(n):
        s.setReal(vr, [0.15 + 0.2 * (i + 1) / n])
        s.doStep((i + 1) * 0.01, 0.01)
    rest = (time.perf_counter() - t0) / n
    s.terminate()
    s.freeInstance()
    return first, rest


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--structures", nargs="+", default=list(DEFAULT))
    args = ap.parse_args(argv)
    built = {s: _instance(s) for s in args.structures}
    times = {s: [] for s in args.structures}
    for _ in range(args.rounds):
        for s in args.structures:
            times[s].append(_round(*built[s], args.steps))
    print("| structure | first new mu (table build + step) [ms], best / median | "
          "each later new mu + step through fmpy [us], best / median |")
    print("| --- | --- | --- |")
    for s, t in times.items():
        first, rest = [x[0] for x in t], [x[1] for x in t]
        print(f"| `{s}` | {min(first) * 1e3:.2f} / {statistics.median(first) * 1e3:.2f} "
              f"| {min(rest) * 1e6:.2f} / {statistics.median(rest) * 1e6:.2f} |")


if __name__ == "__main__":
    main()
