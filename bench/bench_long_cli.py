"""Long records from the command line (issue #38): CPU time and peak memory of
``inflowsim identify`` and ``inflowsim diagnose`` on records of 2, 20 and 120
minutes at 64 Hz, each beside the same command of a peer tree in the same run.

Run::

    git archive HEAD~N inflowsim | tar -x -C /tmp/old          # the peer tree
    OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1 \\
        python bench/bench_long_cli.py --baseline /tmp/old --minutes 2 20 120 --repeat 2

The records are written once as CSV into ``--dir`` (``bench_long.py``'s record:
one 2-minute chunk of the linear ``glauert`` truth repeated, white flap noise over
the whole).  Every measurement is a fresh ``/usr/bin/time -v`` process running the
installed command's code against one tree (``PYTHONPATH``): user + system CPU time
and the maximum resident set.  The trees alternate in ABBA order within every
repetition (this tree, the peer, the peer, this tree), so a change of the
machine's load falls on both alike; the best of the repetitions is kept for each
(the machine is shared: the least is the one least disturbed).  The load average
is printed with every row.  The figures that travel are the ratios to the peer
and the growth with length.

``--records A.csv B.csv --model basic`` times the same commands on given records
instead (the default 26.6 s flight tests: ``diagnose --model basic``, ``identify
--json``'s start-up)::

    python bench/bench_long_cli.py --baseline /tmp/old --records default.csv \
        --model basic --repeat 3
"""
from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "bench"))

MAIN = "import sys; from inflowsim.cli import main; sys.exit(main())"
COMMANDS = {"identify": ["identify", "--json"], "diagnose": ["diagnose", "--json"]}


def write_records(folder: Path, minutes) -> dict:
    """``{minutes: path}``: the records as CSV, made once (kept between runs)."""
    folder.mkdir(parents=True, exist_ok=True)
    out, chunk = {}, None
    for m in minutes:
        path = folder / f"long_{m:g}min.csv"
        if not path.exists():
            from bench_long import CHUNK_S, chunk_record, repeated
            from inflowsim.data.record import write_record
            chunk = chunk if chunk is not None else chunk_record()
            write_record(repeated(chunk, int(round(m * 60 / CHUNK_S)), 2), path)
        out[m] = path
    return out


def run_once(tree: Path, args, cwd: Path):
    """``(cpu [s], max RSS [MB])`` of one command in a fresh process."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    p = subprocess.run(["/usr/bin/time", "-v", sys.executable, "-c", MAIN, *args],
                       env=env, cwd=cwd, stdout=subprocess.DEVNULL,
                       stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        raise RuntimeError(f"{args}: exit {p.returncode}\n{p.stderr[-2000:]}")
    user = float(re.search(r"User time \(seconds\): ([\d.]+)", p.stderr).group(1))
    sys_ = float(re.search(r"System time \(seconds\): ([\d.]+)", p.stderr).group(1))
    rss = float(re.search(r"Maximum resident set size \(kbytes\): (\d+)", p.stderr).group(1))
    return user + sys_, sys_, rss / 1024.0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--minutes", type=float, nargs="+", default=[2, 20, 120])
    ap.add_argument("--commands", nargs="+", default=list(COMMANDS), choices=list(COMMANDS))
    ap.add_argument("--model", default="glauert", help="the structure fitted (default glauert)")
    ap.add_argument("--records", type=Path, nargs="+", default=None,
                    help="time these CSV records instead of the long ones (--minutes unused)")
    ap.add_argument("--baseline", type=Path, default=None,
                    help="the peer tree (a copy of another commit's inflowsim/)")
    ap.add_argument("--repeat", type=int, default=2, help="ABBA repetitions (best kept)")
    ap.add_argument("--dir", type=Path, default=Path("/tmp/inflowsim_long"),
                    help="where the long records are written (kept) and the commands run")
    ap.add_argument("--out", default=None, help="also write the table here (markdown)")
    args = ap.parse_args(argv)
    if args.records:
        recs = {p.name: p.resolve() for p in args.records}
    else:
        recs = {f"{m:g} min": p for m, p in write_records(args.dir, args.minutes).items()}
    trees = [("this", ROOT)] + ([("peer", args.baseline.resolve())] if args.baseline else [])
    order = [trees[0], trees[-1], trees[-1], trees[0]] if len(trees) > 1 else trees
    rows = []
    for cmd in args.commands:
        for m, path in recs.items():
            best = {}
            loads = []
            for _ in range(args.repeat):
                for tag, tree in order:
                    loads.append(os.getloadavg()[0])
                    cpu, sys_, mb = run_once(tree, [*COMMANDS[cmd], "--model", args.model,
                                                    str(path)], args.dir)
                    old = best.get(tag)
                    best[tag] = (min(cpu, old[0]), min(sys_, old[1]), min(mb, old[2])) \
                        if old else (cpu, sys_, mb)
                    print(f"{cmd:9s} {m:12s} {tag:5s} {cpu:7.1f} s CPU ({sys_:.1f} sys) "
                          f"{mb:6.0f} MB  load {loads[-1]:.1f}", file=sys.stderr)
            rows.append((cmd, m, best, min(loads), max(loads)))
    head = "| command | record | CPU [s] | of which system | peak RSS [MB] |"
    sep = "|---|---|---:|---:|---:|"
    if len(trees) > 1:
        head += " peer CPU [s] | peer peak RSS [MB] | CPU / peer | RSS / peer |"
        sep += "---:|---:|---:|---:|"
    lines = [head + " load (1 min) |", sep + "---|"]
    for cmd, m, best, lo, hi in rows:
        c, s, r = best["this"]
        line = f"| {cmd} --model {args.model} | {m} | {c:.2f} | {s:.2f} | {r:.0f} |"
        if "peer" in best:
            pc, _, pr = best["peer"]
            line += f" {pc:.2f} | {pr:.0f} | {c / pc:.2f} | {r / pr:.2f} |"
        lines.append(line + f" {lo:.1f}-{hi:.1f} |")
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        Path(args.out).write_text(text)


if __name__ == "__main__":
    main()
