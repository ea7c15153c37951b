"""``inflowsim frf``: non-parametric frequency responses of the records (composite
multi-window, multi-input conditioned, with coherence and random error).

Prints one line per response pair (coherent points, their band, the median
random error), or with ``--json`` the document of ``interface.md`` (``{"responses":
[{"input", "output", "frequency_hz", "real", "imag", "coherence",
"random_error", ...}], ...}``); ``--report DIR`` writes Bode plots and
``DIR/index.html``.
"""
from __future__ import annotations

from ._checks import finite_float, fraction, positive_float
from ..channels import FLAP, INPUTS
from ..errors import InputError
from ._common import (add_band_option, add_json_option, add_report_option,
                      add_trim_window_option, check_finite, emit, read_records)

HELP = "frequency responses of records: composite, conditioned, with coherence and errors"



def add_arguments(p):
    p.add_argument("record", nargs="+", metavar="RECORD",
                   help="flight-test record(s) of one flight condition (CSV)")
    p.add_argument("--inputs", nargs="+", metavar="CH",
                   help="input channels (default: the controls that move)")
    p.add_argument("--outputs", nargs="+", metavar="CH", default=list(FLAP),
                   help="output channels (default beta0 beta1c beta1s)")
    add_band_option(p, what="band [Hz] of the log-spaced grid", default_text="0.1 5")
    p.add_argument("--windows", nargs="+", type=positive_float, metavar="S",
                   help="window lengths [s] of the composite (default: five from half "
                        "the shortest record down)")
    p.add_argument("--overlap", type=fraction, default=0.75, metavar="R",
                   help="overlap of consecutive windows (default 0.75)")
    add_trim_window_option(p)
    p.add_argument("--unwrap", action="store_true", default=True,
                   help="report plots: the phase unwrapped (the default)")
    p.add_argument("--wrap", dest="unwrap", action="store_false",
                   help="report plots: the phase wrapped to +-180 deg")
    add_report_option(p, "Bode plots")
    add_json_option(p)


def _check(args):
    for name in ("inputs", "outputs"):
        for c in getattr(args, name) or ():
            if c not in INPUTS and c not in FLAP and c not in ("lambda0", "lambda1c",
                                                               "lambda1s"):
                raise InputError(f"--{name} {c}: not a record channel (inputs "
                                 f"{', '.join(INPUTS)}; flap {', '.join(FLAP)})")
    check_finite(args, "band", "overlap")


def run(args) -> int:
    _check(args)
    if args.report:
        from ..report.document import check_report_folder
        check_report_folder(args.report, protect=args.record)
    from ..identify.frf import DEFAULT_FRF_BAND, frequency_response
    recs = read_records(args.record, args)
    for rec in recs:                 # a dead sensor has no response to measure
        rec.require_measured([c for c in args.outputs if c in rec.channels])
    fr = frequency_response(recs, inputs=args.inputs, outputs=args.outputs,
                            band_hz=tuple(args.band or DEFAULT_FRF_BAND),
                            windows_s=args.windows,
                            overlap=args.overlap)
    from ..report.frf_report import frf_report, summary_lines
    emit("frf", args, fr, lambda r: frf_report(r, unwrap=args.unwrap),
         lambda r: "\n".join(summary_lines(r)), protect=args.record)
    return 0
