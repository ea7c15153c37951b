"""``inflowsim bandstudy``: estimates and bounds against the lower band limit
(the paper's Figure 6), with a plot."""
from __future__ import annotations

from ._checks import finite_float, positive_float
from ._common import (add_record_arguments, parse_fix, print_json, progress, read_records,
                      structure_of)

HELP = "estimates and 1-sigma bounds against the lower frequency limit (Figure 6)"


def add_arguments(p):
    p.add_argument("record", metavar="RECORD", help="flight-test record (CSV)")
    p.add_argument("--model", "-m", required=True,
                   help="structure: basic, empirical, glauert, then +effect terms")
    p.add_argument("--add", action="append", default=[], metavar="EFFECT",
                   help="add an effect to the structure (repeatable)")
    p.add_argument("--upper", type=positive_float, default=1.58, metavar="F",
                   help="upper band limit [Hz] (default 1.58)")
    p.add_argument("--lower", nargs="+", type=positive_float, metavar="F",
                   help="lower limits [Hz] (default: ten from 2/T)")
    p.add_argument("--fix", action="append", default=[], metavar="NAME[=VALUE]",
                   help="hold a parameter fixed")
    add_record_arguments(p)
    p.add_argument("--out", metavar="DIR", help="write bandstudy.png and bandstudy.json")
    p.add_argument("--json", action="store_true", help="one JSON document on stdout")
    p.add_argument("--force", action="store_true", help="overwrite existing outputs")


def run(args) -> int:
    from ..identify import band_study
    from ..report.document import check_report_folder
    from ..report.fit import band_study_report
    s = structure_of(args)
    if args.out:                     # refuse before the fits
        check_report_folder(args.out, ("bandstudy.png", "bandstudy.json"), (args.record,))
    rec = read_records([args.record], args)[0]
    study = band_study(rec, s, upper_hz=args.upper, lowers_hz=args.lower,
                       fixed=parse_fix(args.fix), progress=progress, hold=args.hold)
    doc = study.to_json()
    if args.out:
        path = band_study_report(study).write(args.out, protect=(args.record,))
        progress(f"wrote {path} with bandstudy.png and bandstudy.json")
    if args.json:
        print_json(doc)
    else:
        names = list(study.estimates)
        print("lower [Hz]  cost        " + "  ".join(f"{n:>12}" for n in names))
        for i, f in enumerate(study.lower_hz):
            print(f"{f:9.4f}  {study.cost[i]:10.3f}  " + "  ".join(
                f"{study.estimates[n][i]:12.5g}" for n in names))
    return 0
