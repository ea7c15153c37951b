"""``inflowsim validate``: compare a model with a record's measured flap.

Prints per-channel fit figures (RMS error, Theil inequality coefficient, fit
percent, RMS magnitude and phase errors of the responses over the band), or
with ``--json`` the document of ``interface.md`` (``{"channels": {channel: {"rms",
"tic", "fit_percent", ...}}, ...}``); ``--report DIR`` writes plots and
``DIR/index.html`` (:func:`validation_report`).
"""
from __future__ import annotations

from pathlib import Path

from ..data.record import FLAP_COLUMNS
from ..simulate.sampled import HOLD_TEXT
from ..diagnose.validation import PAPER_BAND_HZ, validate
from ._common import (add_model_arguments, add_record_arguments, load_model, print_json,
                      progress, read_records)

HELP = "compare a model with the measured flap: per-channel figures, plots, report"


def add_arguments(p):
    p.add_argument("record", metavar="RECORD", help="flight-test record (CSV)")
    add_model_arguments(p)
    p.add_argument("--band", nargs=2, type=float, metavar=("F1", "F2"),
                   help=f"frequency band [Hz] (default {PAPER_BAND_HZ[0]:g} "
                        f"{PAPER_BAND_HZ[1]:g}, snapped to the record's transform grid)")
    add_record_arguments(p)
    p.add_argument("--report", metavar="DIR",
                   help="write plots and DIR/index.html (the folder is created)")
    p.add_argument("--json", action="store_true", help="one JSON document on stdout")


def fit_rows(result):
    """Table rows ``channel, rms, tic, fit, magnitude error, phase error``."""
    return [[c, result.channels[c].rms, result.channels[c].tic,
             result.channels[c].fit_percent, result.magnitude_rms_db[c],
             result.phase_rms_deg[c]] for c in FLAP_COLUMNS]


FIT_HEADER = ["channel", "rms error [rad]", "TIC", "fit [%]", "|H| error [dB rms]",
              "phase error [deg rms]"]


def format_table(result) -> str:
    lines = [f"model {result.structure} on {result.source}",
             f"trim: {result.trim.describe()}",
             f"band {result.band_hz[0]:.4g}-{result.band_hz[1]:.4g} Hz "
             f"({result.frequency.f_hz.size} frequencies), responses to "
             f"{result.frequency.reference_input}",
             f"{'channel':<8}{'rms [rad]':>12}{'TIC':>8}{'fit [%]':>9}"
             f"{'|H| [dB]':>10}{'phase [deg]':>13}"]
    for c, rms, tic, fit, mag, ph in fit_rows(result):
        lines.append(f"{c:<8}{rms:>12.4g}{tic:>8.4f}{fit:>9.2f}{mag:>10.3f}{ph:>13.2f}")
    return "\n".join(lines)


def validation_report(results, title=None, subtitle=None):
    """A :class:`~inflowsim.report.Report` comparing one or more models on one record.

    Parameters
    ----------
    results : ValidationResult or sequence of them (same record)
    title, subtitle : str, optional

    Returns
    -------
    Report
        Fit table per model, the time-domain reconstruction, the frequency
        responses and the response errors; call ``.write(DIR)``.
    """
    from ..report.plots import error_spectrum_plot, frequency_response_plot, time_response_plot
    from ..report.document import Report
    res = list(results) if isinstance(results, (list, tuple)) else [results]
    r0 = res[0]
    names = ", ".join(r.structure for r in res)
    rep = Report(title or f"Validation: {names}", subtitle or f"record {r0.source}")
    rep.paragraph(
        f"Measured inputs replayed through each model at the record's step "
        f"({r0.t[1] - r0.t[0]:.4g} s) with its intersample behaviour ({r0.hold}: "
        f"{HOLD_TEXT[r0.hold]}); flap compared as "
        f"perturbations about trim, the {r0.trim.describe()}. Frequency responses are "
        f"DFT ratios to {r0.frequency.reference_input} over "
        f"{r0.band_hz[0]:.4g}-{r0.band_hz[1]:.4g} Hz ({r0.frequency.f_hz.size} "
        "transform frequencies); the model's are its predicted flap over the same "
        "input DFT.")
    for r in res:
        rep.table(fit_rows(r), header=FIT_HEADER, caption=f"Fit of {r.structure}")
    rep.figure(time_response_plot(res, show_inputs=True), "time",
               "Time-domain reconstruction: measured and predicted multiblade flap.")
    rep.figure(frequency_response_plot(res), "frequency",
               "Frequency responses: measured (markers) and model (lines).")
    rep.figure(error_spectrum_plot(res), "errors",
               "Measured over model response, magnitude and phase, across the band.")
    return rep


def run(args) -> int:
    rec = read_records([args.record], args)[0]
    model = load_model(args, rec.constants)
    result = validate(rec, model, band_hz=args.band, hold=args.hold)
    if args.report:
        path = validation_report(result).write(
            args.report, protect=[q for q in (args.record, args.params) if q])
        progress(f"validate: report written to {path}")
    if args.json:
        doc = result.to_json()
        if args.report:
            doc["report"] = str(Path(args.report) / "index.html")
        print_json(doc)
    else:
        print(format_table(result))
    return 0
