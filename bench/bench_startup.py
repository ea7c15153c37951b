"""Start-up of the ``inflowsim`` command line (issue #27 item 2): wall time of
``inflowsim --version``, ``--help`` and each command's ``--help`` beside peers
measured in the same run, round-robin (each round runs every case once, so a change
of the machine's load falls on all of them alike).

Run::

    python bench/bench_startup.py                      # 15 rounds, about 30 s
    python bench/bench_startup.py --rounds 10 --baseline /tmp/old   # also an older tree

Each case is a fresh interpreter, ``python -c CODE ARGS`` where CODE is what the
installed ``inflowsim`` script runs (``from inflowsim.cli import main``), with
``PYTHONPATH`` set to this tree (or to ``--baseline``, a copy of another commit's
files: ``git archive COMMIT inflowsim | tar -x -C /tmp/old``).  Peers: ``python -c
pass`` (the interpreter alone) and ``python -c "import numpy"``.  Printed: the
median and the least of the rounds [s] and the median's ratio to each peer.  Goal:
<= 0.3 s for every command case (issue #27).
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from inflowsim.cli import COMMANDS  # noqa: E402  (the command list of this tree)

MAIN = "import sys; from inflowsim.cli import main; sys.exit(main())"
GOAL_S = 0.3


def cases(tree: Path, tag: str = "", commands=COMMANDS):
    env = {**os.environ, "PYTHONPATH": str(tree)}
    out = [(f"{tag}inflowsim --version", ["--version"]), (f"{tag}inflowsim --help", ["--help"])]
    out += [(f"{tag}inflowsim {c} --help", [c, "--help"]) for c in commands]
    if "fmu" in commands:
        out.append((f"{tag}inflowsim fmu build --help", ["fmu", "build", "--help"]))
    return [(name, [sys.executable, "-c", MAIN, *argv], env) for name, argv in out]


def wall(cmd, env, cwd) -> float:
    t0 = time.perf_counter()
    res = subprocess.run(cmd, env=env, cwd=cwd, stdout=subprocess.DEVNULL,
                         stderr=subprocess.PIPE, check=False)
    dt = time.perf_counter() - t0
    if res.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)}: exit {res.returncode}: {res.stderr.decode()}")
    return dt


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--baseline", type=Path, metavar="TREE",
                    help="also time the cases of another source tree (its inflowsim/)")
    args = ap.parse_args(argv)
    env = dict(os.environ)
    todo = [("python -c pass (peer)", [sys.executable, "-c", "pass"], env),
            ("python -c 'import numpy' (peer)", [sys.executable, "-c", "import numpy"], env)]
    todo += cases(ROOT)
    if args.baseline:
        # a few cases only: a tree that imports everything takes seconds per case
        todo += cases(args.baseline.resolve(), "baseline: ", ("identify",))
    times = {name: [] for name, _, _ in todo}
    # in a folder of its own: ``python -c`` puts the working folder first on the path,
    # which would run this tree's code for the baseline's cases
    with tempfile.TemporaryDirectory() as cwd:
        for _ in range(args.rounds):
            for name, cmd, e in todo:
                times[name].append(wall(cmd, e, cwd))
    med = {n: statistics.median(v) for n, v in times.items()}
    p0, p1 = med["python -c pass (peer)"], med["python -c 'import numpy' (peer)"]
    load = os.getloadavg()
    print(f"{args.rounds} rounds, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, "
          f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f} on {os.cpu_count()} "
          f"cores, Python {sys.version.split()[0]}\n")
    print("| case | median [s] | least [s] | / python -c pass | / import numpy | <= 0.3 s |")
    print("| --- | --- | --- | --- | --- | --- |")
    worst = 0.0
    for name, v in times.items():
        ok = "" if "(peer)" in name else ("yes" if med[name] <= GOAL_S else "no")
        if "(peer)" not in name and not name.startswith("baseline"):
            worst = max(worst, med[name])
        print(f"| {name} | {med[name]:.3f} | {min(v):.3f} | {med[name] / p0:.2f} | "
              f"{med[name] / p1:.2f} | {ok} |")
    print(f"\nslowest command case of this tree: median {worst:.3f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
