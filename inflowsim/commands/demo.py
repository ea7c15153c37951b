"""``inflowsim demo``: the whole story on a virtual Puma record with a hidden effect
(:mod:`inflowsim.report.demo`); a summary on stdout, everything in ``DIR/index.html``."""
from __future__ import annotations

from ._common import check_seed, print_json, progress

HELP = ("the whole story on a virtual Puma record with a hidden effect: compare, "
        "diagnose, add, refit; HTML report with plots")
DEFAULT_DIR = "inflowsim-demo"


def add_arguments(p):
    p.add_argument("--out", "-o", default=DEFAULT_DIR, metavar="DIR",
                   help=f"report folder (default {DEFAULT_DIR}; created)")
    p.add_argument("--seed", type=int, default=0, help="sensor-noise seed (default 0)")
    p.add_argument("--json", action="store_true", help="one JSON summary on stdout")


def run(args) -> int:
    from ..report.demo import run_demo
    check_seed(args.seed)
    path, summary, lad = run_demo(args.out, args.seed, progress)
    if args.json:
        print_json(summary)
        return 0
    print(f"hidden truth: {summary['truth']}; started from {summary['start']}")
    from ..report.ladder import rung_label
    for r in lad.rungs:
        fits = ", ".join(f"{c} {v['fit_percent']:.1f}%" for c, v in r.fit.fit.items())
        step = rung_label(r)
        print(f"  {step:<28} cost {r.fit.cost:10.2f}   {fits}")
    print(f"final structure: {summary['final']}")
    print(f"report: {path}")
    return 0
