"""Flight-condition and step changes in a Python simulator loop (issue #27 item 3).

    OPENBLAS_NUM_THREADS=1 python bench/simulator_mu.py [--rounds R] [--calls N]

Times, in alternating rounds of the same run (best and median of R rounds of N
calls each, so the machine's load hits every case alike), on the glauert preset
(Puma, 6 states, 10 inputs) at dt = 1 ms:

- ``step``: ``Simulator.step`` alone (the loop's floor);
- ``set_mu + step``: a new ``mu`` every call (0.249 + 1e-4 (k mod 100)), from the
  table in ``mu`` (``inflowsim.simulate.mutable``);
- ``old path: build_model + expm + step``: the same ``mu`` sequence by an exact
  rebuild every call (``set_model(model.with_mu(mu))``, what ``set_mu`` did before);
- ``set_dt + step``: a new step every call (1 ms +- 2 %), stored Taylor series;
- ``old path: expm + step``: the same steps by ``scipy.linalg.expm``.

The one-time costs (building the mu table, the Taylor series) are timed apart.
Prints a Markdown table; results and method are kept in ``bench/simulator.md``.
"""
from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

from inflowsim.model.build import build_model
from inflowsim.model.params import PUMA
from inflowsim.model.presets import preset_parameters
from inflowsim.simulate.discrete import zoh
from inflowsim.simulate.simulator import Simulator

DT = 1e-3


def cases(calls):
    model = build_model("glauert", preset_parameters("glauert", PUMA, "paper"), PUMA)
    u = np.full(10, 1e-3)
    mus = [0.249 + 1e-4 * (k % 100) for k in range(calls)]
    dts = [DT * (1 + 0.02 * ((k * 37) % 101 - 50) / 50) for k in range(calls)]

    floor = Simulator(model, DT)

    def step():
        for _ in range(calls):
            floor.step(u)

    fast = Simulator(model, DT)
    t0 = time.perf_counter()
    fast.set_mu(0.3)
    fast.set_mu(0.31)                  # the second change builds the table
    table_s = time.perf_counter() - t0

    def set_mu_step():
        for mu in mus:
            fast.set_mu(mu)
            fast.step(u)

    old = Simulator(model, DT)

    def old_mu():
        for mu in mus:
            old.set_model(model.with_mu(mu))
            old.step(u)

    vdt = Simulator(model, DT)
    t0 = time.perf_counter()
    vdt.set_dt(0.0011)                 # builds the stored series
    series_s = time.perf_counter() - t0

    def set_dt_step():
        for h in dts:
            vdt.set_dt(h)
            vdt.step(u)

    ref = Simulator(model, DT)
    xu = np.zeros(16)

    def old_dt():
        for h in dts:
            phi, gam = zoh(model.a, model.b, h)
            xu[:6] = ref.state
            ref.state = np.hstack([phi, gam]) @ np.concatenate([xu[:6], u])

    return {"step": step, "set_mu + step (table)": set_mu_step,
            "old path: build_model + expm + step": old_mu,
            "set_dt + step (Taylor series)": set_dt_step,
            "old path: expm + step": old_dt}, table_s, series_s


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--calls", type=int, default=2000)
    args = ap.parse_args(argv)
    runs, table_s, series_s = cases(args.calls)
    times = {k: [] for k in runs}
    for _ in range(args.rounds):
        for name, f in runs.items():
            t0 = time.perf_counter()
            f()
            times[name].append((time.perf_counter() - t0) / args.calls * 1e6)
    print(f"load average at the end: {os.getloadavg()[0]:.2f}; {args.rounds} rounds of "
          f"{args.calls} calls; one-time: mu table {table_s * 1e3:.0f} ms, Taylor series "
          f"{series_s * 1e6:.0f} us")
    print("| case | best [us/call] | median [us/call] | median / step |")
    print("| --- | --- | --- | --- |")
    base = statistics.median(times["step"])
    for name, ts in times.items():
        med = statistics.median(ts)
        print(f"| {name} | {min(ts):.2f} | {med:.2f} | {med / base:.1f}x |")


if __name__ == "__main__":
    main()
