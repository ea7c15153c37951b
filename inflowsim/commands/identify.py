"""``inflowsim identify``: frequency-domain output-error fit with 1-sigma bounds.

Prints the parameter table (or with ``--json`` the ``interface.md`` document);
every estimate is marked conditional on an incomplete structure where the fit's
residual keeps structured excess over the record's noise floor (the diagnosis's
test, :mod:`inflowsim.diagnose.conditional`);
``--out FIT.json`` writes that document, a parameter file that ``simulate``,
``validate`` and the FMU read as it is; ``--report DIR`` writes the tables
(Markdown, HTML), the frequency-domain fit and the time-domain reconstruction
plots.  Progress goes to stderr.
"""
from __future__ import annotations

from ._checks import finite_float
from ..defaults import DEFAULT_BAND
from ._common import (add_effect_arguments, add_record_arguments, parse_fix, parse_ties,
                      print_json, progress, read_parameter_file, read_records, warn,
                      structure_of)

HELP = "estimate a structure's parameters with 1-sigma bounds (frequency-domain output error)"


def add_arguments(p):
    p.add_argument("records", nargs="+", metavar="RECORD",
                   help="flight-test record(s) (CSV); several are fitted together")
    p.add_argument("--model", "-m", required=True,
                   help="structure: basic, empirical, glauert, then +effect terms")
    add_effect_arguments(p)
    p.add_argument("--add", action="append", default=[], metavar="EFFECT",
                   help="add an effect to the structure (repeatable)")
    p.add_argument("--band", nargs=2, type=finite_float, metavar=("F1", "F2"),
                   help=f"frequency band [Hz] (default {DEFAULT_BAND[0]:g} "
                        f"{DEFAULT_BAND[1]:g}, snapped to the "
                        "record's grid 1/T)")
    p.add_argument("--fix", action="append", default=[], metavar="NAME[=VALUE]",
                   help="hold a parameter fixed (at VALUE, or its theory value)")
    p.add_argument("--tie", action="append", default=[], metavar="A=B[=C]",
                   help="estimate one value for several parameters")
    p.add_argument("--start", metavar="FILE",
                   help="parameter file with starting values")
    add_record_arguments(p)
    p.add_argument("--out", metavar="FIT.json", help="write the fit (a parameter file)")
    p.add_argument("--report", metavar="DIR", help="write tables and plots into DIR")
    p.add_argument("--json", action="store_true", help="one JSON document on stdout")
    p.add_argument("--force", action="store_true", help="overwrite existing outputs")


def _check_outputs(out, inputs, force):
    """Refuse before any work: an existing ``out`` without ``force``, or an input."""
    if out is not None:
        from ..fileio import check_output
        check_output(out, force, inputs)


def run(args) -> int:
    from ..identify import identify
    from ..identify.tables import markdown_table
    from ..model.paramfile import write_json
    from ..report.document import check_report_folder
    from ..report.fit import write_report
    s = structure_of(args)
    _check_outputs(args.out, args.records, args.force)
    if args.report:
        check_report_folder(args.report, ("table.md", "fit.json"), args.records)
    recs = read_records(args.records, args)
    start = None
    if args.start:
        ps = read_parameter_file(args.start)
        start = {n: v for n, v in ps.parameters.items() if n in s.parameters}
    band = tuple(args.band) if args.band else DEFAULT_BAND
    result = identify(recs, s, band_hz=band, start=start, fixed=parse_fix(args.fix),
                      ties=parse_ties(args.tie), progress=progress, hold=args.hold)
    from ..diagnose.conditional import marked
    from ..diagnose.search import analyses_of
    # the level and structure tests need no in-band colour estimate (check_colour)
    result = marked(result, analyses_of(recs, result, band, check_colour=False))
    for w in result.warnings:
        warn(w)
    if result.conditional:
        warn(f"every estimate is {result.conditional}")
    doc = result.to_json()
    if args.out:
        write_json(doc, args.out, overwrite=args.force, protect=args.records)
        progress(f"wrote {args.out}")
    if args.report:
        write_report(result, args.report, args.force, protect=args.records)
        progress(f"wrote {args.report}/index.html, table.md, fit.json and plots")
    if args.json:
        print_json(doc)
    else:
        print(markdown_table(result), end="")
    return 0
