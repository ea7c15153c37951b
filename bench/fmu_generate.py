"""What an FMU of a structure costs to make, and its model to build.

    python bench/fmu_generate.py STRUCTURE [STRUCTURE ...] [--builds N]

Per structure: ``build_fmu`` (FMI 2, no binary cache: ``INFLOWSIM_CACHE_DIR=""``)
as process CPU of its Python (tracing the model on symbols, printing the C) and of
the compiler (child processes), the size of the generated ``inflow_equations.c``;
then ``build_model`` at ``tests/test_fmu_structures.py``'s parameters and trim,
one parameter changed every build (``n_beta``: every memo of the lag's trim
coefficients missed), process CPU per build, best of 7 blocks of ``N`` (default 100).
Say the load (``uptime``) beside the figures.
"""
from __future__ import annotations

import os
import resource
import sys
import tempfile
import time
from pathlib import Path

os.environ["INFLOWSIM_CACHE_DIR"] = ""          # every build compiles
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))


def _cpu(who):
    r = resource.getrusage(who)
    return r.ru_utime + r.ru_stime


def fmu_cost(structure):
    """``(python CPU [s], compiler CPU [s], inflow_equations.c [bytes])``."""
    from inflowsim.fmu import build_fmu
    from inflowsim.fmu.build import description_for
    from inflowsim.fmu.generate import generated_files
    s0, c0 = _cpu(resource.RUSAGE_SELF), _cpu(resource.RUSAGE_CHILDREN)
    with tempfile.TemporaryDirectory() as d:
        build_fmu(Path(d) / "x.fmu", model=structure)
    s1, c1 = _cpu(resource.RUSAGE_SELF), _cpu(resource.RUSAGE_CHILDREN)
    size = len(generated_files(description_for(structure))["inflow_equations.c"])
    return s1 - s0, c1 - c0, size


def build_cost(structure, n=100):
    """Process CPU of one ``build_model`` [s], ``n_beta`` changed every build."""
    from test_fmu_structures import constants_for, parameters
    from inflowsim.model import build_model
    p, k = parameters(structure), constants_for(structure)
    build_model(structure, p, k)
    count = 0
    best = float("inf")
    for _ in range(7):
        t = time.process_time()
        for _ in range(n):
            count += 1
            build_model(structure, dict(p, n_beta=p["n_beta"] * (1 + 1e-9 * count)), k)
        best = min(best, (time.process_time() - t) / n)
    return best


def main(argv):
    n = 100
    if "--builds" in argv:
        i = argv.index("--builds")
        n = int(argv[i + 1])
        argv = argv[:i] + argv[i + 2:]
    from inflowsim.fmu.codegen import n_states
    print("| structure | NX | Python [s] | compiler [s] | inflow_equations.c [kB] | "
          "build_model [ms] |")
    print("| --- | --- | --- | --- | --- | --- |")
    for s in argv:
        py, cc, size = fmu_cost(s)
        print(f"| `{s}` | {n_states([s])} | {py:.1f} | {cc:.1f} | {size / 1e3:.0f} | "
              f"{build_cost(s, n) * 1e3:.2f} |", flush=True)
    print(f"load average {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main(sys.argv[1:])
