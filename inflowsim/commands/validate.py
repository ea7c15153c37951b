"""``inflowsim validate``: compare a model with a record's measured flap.

Prints per-channel fit figures (RMS error, Theil inequality coefficient, fit
percent, RMS magnitude and phase errors of the measured responses, each conditioned
on the other moving controls, against the model's analytic ones where coherence >=
0.6) and Tischler's cost per response pair and overall, or with ``--json`` the
document of ``interface.md`` (``{"channels": {channel: {"rms", "tic",
"fit_percent", ...}}, "responses": [...], "cost": {...}, ...}``); ``--report DIR``
writes plots and ``DIR/index.html`` (:func:`validation_report`).
"""
from __future__ import annotations

from ..defaults import DEFAULT_BAND
from ._common import (add_band_option, add_json_option, add_model_arguments,
                      add_record_arguments, add_report_option, emit, load_model,
                      read_records)

HELP = "compare a model with the measured flap: per-channel figures, plots, report"


def add_arguments(p):
    p.add_argument("record", metavar="RECORD", help="flight-test record (CSV)")
    add_model_arguments(p)
    add_band_option(p, default_text=f"{DEFAULT_BAND[0]:g} {DEFAULT_BAND[1]:g}, snapped "
                                    "to the record's transform grid")
    add_record_arguments(p)
    add_report_option(p)
    add_json_option(p)


def run(args) -> int:
    from ..diagnose.validation import validate
    from ..report.document import check_report_folder
    from ..report.validation import format_table, validation_report
    if args.report:
        check_report_folder(args.report, protect=[q for q in (args.record, args.params) if q])
    rec = read_records([args.record], args)[0]
    model = load_model(args, rec.constants)
    result = validate(rec, model, band_hz=args.band, hold=args.hold)
    emit("validate", args, result, validation_report, format_table,
         protect=[q for q in (args.record, args.params) if q])
    return 0
