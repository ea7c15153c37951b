"""``inflowsim diagnose``: where a model fails and which effect is missing.

Fits ``--model`` (starting from ``--params`` when given), reports where model and
measurement part (per channel and frequency, magnitude or phase), residual
whiteness and correlation with the inputs, implausible or poorly determined
estimates, then applies the diagnosis's rule (``inflowsim.diagnose.rule``: every
candidate effect, or part of one, added alone and in pairs, scored by the Schwarz
gain, the best admissible one accepted when it is worth its parameters and
material), and says how much excess is left (the verdict).
"""
from __future__ import annotations

from ._common import (add_model_arguments, add_record_arguments, add_search_arguments,
                      check_search_arguments, emit, pool_with, progress, read_records,
                      start_values)

HELP = "where a model fails on a record, and the ranked candidate effects"


def add_arguments(p):
    p.add_argument("record", nargs="+", metavar="RECORD", help="flight-test record(s) (CSV)")
    add_model_arguments(p)
    add_search_arguments(p)
    add_record_arguments(p)


def run(args) -> int:
    from ..flighttest.advice import standard_manoeuvres
    from ..diagnose.search import diagnose
    from ..report.ladder import diagnosis_report, format_diagnosis
    check_search_arguments(args)
    recs = read_records(args.record, args)
    start = start_values(args)
    d = diagnose(recs, args.model, tuple(args.band), start=start, pool=pool_with(args.candidates, args.also),
                 alpha=args.alpha, progress=progress, hold=args.hold,
                 manoeuvres=standard_manoeuvres)
    emit("diagnose", args, d, diagnosis_report, format_diagnosis, protect=args.record)
    return 0
