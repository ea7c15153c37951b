"""``inflowsim ladder``: add the missing effect, refit, repeat; or climb given structures.

Without ``--structures``: from ``--model``, diagnose, add what the rule accepts
(``inflowsim.diagnose.rule``: an effect, a part of one, or a pair), and diagnose
again until nothing is accepted; the last line is the verdict.  With
``--structures basic empirical glauert``: fit each (the paper's Tables 1 -> 2 -> 3).
Prints the table of parameters with bounds side by side; ``--report DIR`` adds
the plot of the error falling.
"""
from __future__ import annotations

from ..defaults import MAX_STEPS
from ._common import (add_effect_arguments, add_record_arguments, add_search_arguments,
                      check_search_arguments, emit, pool_with, progress, read_records)

HELP = "add the missing effect and refit until none is left, or climb given structures"


def add_arguments(p):
    p.add_argument("record", nargs="+", metavar="RECORD", help="flight-test record(s) (CSV)")
    add_effect_arguments(p)
    p.add_argument("--model", "-m", default="basic", help="starting structure (default basic)")
    p.add_argument("--structures", nargs="+", metavar="M",
                   help="climb these structures instead of searching")
    p.add_argument("--max-steps", type=int, default=MAX_STEPS,
                   help=f"effects to add at most (default {MAX_STEPS})")
    add_search_arguments(p)
    add_record_arguments(p)


def run(args) -> int:
    from ..flighttest.advice import standard_manoeuvres
    from ..diagnose.search import explicit_ladder, ladder
    from ..errors import InputError
    from ..report.ladder import ladder_markdown, ladder_report
    check_search_arguments(args)
    if args.max_steps < 0:
        raise InputError("--max-steps must be >= 0")
    recs = read_records(args.record, args)
    if args.structures:
        lad = explicit_ladder(recs, args.structures, tuple(args.band), progress=progress,
                              hold=args.hold, manoeuvres=standard_manoeuvres)
    else:
        lad = ladder(recs, args.model, tuple(args.band), max_steps=args.max_steps,
                     pool=pool_with(args.candidates, args.also), alpha=args.alpha,
                     progress=progress,
                     hold=args.hold, manoeuvres=standard_manoeuvres)
    emit("ladder", args, lad, lambda r: ladder_report(r, record=recs[0]), ladder_markdown,
         protect=args.record)
    return 0
