"""Tables, text and the HTML report of a validation (what ``inflowsim validate``
prints and writes)."""
from __future__ import annotations

import math

import numpy as np

from ..data.record import FLAP_COLUMNS
from ..simulate.sampled import HOLD_TEXT
from .units import DEG


def fit_rows(result):
    """Table rows ``channel, rms [deg], tic, fit, magnitude error, phase error`` (the
    RMS error in degrees, as the plots show the flap; ``--json`` keeps SI)."""
    return [[c, result.channels[c].rms * DEG, result.channels[c].tic,
             result.channels[c].fit_percent, result.magnitude_rms_db[c],
             result.phase_rms_deg[c]] for c in FLAP_COLUMNS]


FIT_HEADER = ["channel", "rms error [deg]", "TIC [-]", "fit [%]", "|H| error [dB rms]",
              "phase error [deg rms]"]


#: The table's mark of a response error that no point read defines.
NO_RESPONSE = "none"
NO_RESPONSE_TEXT = ("no response above noise to compare: no point of the channel's "
                    "responses has coherence >= 0.6")


def fit_table_rows(result):
    """:func:`fit_rows` for a report table: an undefined response error is
    :data:`NO_RESPONSE` (say :data:`NO_RESPONSE_TEXT` beside the table)."""
    return [row[:4] + [v if np.isfinite(v) else NO_RESPONSE for v in row[4:]]
            for row in fit_rows(result)]


def _cell(v, digits):
    return f"{v:.{digits}f}" if np.isfinite(v) else NO_RESPONSE


def _g(x, fmt):
    return "-" if x is None or not math.isfinite(x) else format(x, fmt)


def format_table(result) -> str:
    from ..diagnose.validation import cost_verdict
    fc = result.frequency
    fr = fc.measured
    cond = ", each conditioned on the other(s)" if len(fr.inputs) > 1 else ""
    lines = [f"model {result.structure} on {result.source}",
             f"trim: {result.trim.describe()}",
             f"band {result.band_hz[0]:.4g}-{result.band_hz[1]:.4g} Hz "
             f"({result.dft_f_hz.size} frequencies); responses to "
             f"{', '.join(fr.inputs)}{cond}"
             + (f"; hub path through {', '.join(fc.paths)}" if fc.paths else ""),
             "response errors over the points with coherence >= 0.6",
             f"{'channel':<8}{'rms [deg]':>12}{'TIC':>8}{'fit [%]':>9}"
             f"{'|H| [dB]':>10}{'phase [deg]':>13}"]
    undefined = False
    for c, rms, tic, fit, mag, ph in fit_rows(result):
        undefined |= not (np.isfinite(mag) and np.isfinite(ph))
        lines.append(f"{c:<8}{rms:>12.4g}{tic:>8.4f}{fit:>9.2f}{_cell(mag, 3):>10}"
                     f"{_cell(ph, 2):>13}")
    if undefined:
        lines.append(f"{NO_RESPONSE}: {NO_RESPONSE_TEXT}")
    lines.append("Tischler's J per response pair (points read):")
    valid = fr.valid()
    for o, out in enumerate(fr.outputs):
        cells = [f"{inp} {_g(fc.cost[(out, inp)], '.3g')} ({int(valid[o, i].sum())})"
                 for i, inp in enumerate(fr.inputs)]
        lines.append(f"  {out:<8}" + "   ".join(cells))
    overall = fc.overall_cost
    lines.append(f"  overall J {_g(overall, '.3g')} ({cost_verdict(overall)}; "
                 "<= 50 good, <= 100 acceptable)")
    for note in fr.notes:
        lines.append(f"note: {note}")
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
        Fit table per model, the time-domain reconstruction, the measured
        frequency responses (conditioned, with coherence and error bands) with the
        models on top, the response errors, the coherence and Tischler's cost; call
        ``.write(DIR)``.
    """
    from ..report.plots import (coherence_plot, error_spectrum_plot,
                                frequency_response_plot, time_response_plot)
    from ..report.document import Report
    from .model_frf import model_frf_section, responses_paragraph
    res = list(results) if isinstance(results, (list, tuple)) else [results]
    r0 = res[0]
    names = ", ".join(r.structure for r in res)
    rep = Report(title or f"Validation: {names}", subtitle or f"record {r0.source}")
    rep.paragraph(
        f"Measured inputs replayed through each model at the record's step "
        f"({r0.t[1] - r0.t[0]:.4g} s) with its intersample behaviour ({r0.hold}: "
        f"{HOLD_TEXT[r0.hold]}); flap compared as "
        f"perturbations about trim, the {r0.trim.describe()}. "
        + responses_paragraph(r0))
    for r in res:
        rows = fit_table_rows(r)
        rep.table(rows, header=FIT_HEADER, caption=f"Fit of {r.structure} (response "
                  "errors over the points with coherence >= 0.6)")
        if any(NO_RESPONSE in row for row in rows):
            rep.paragraph(f"{NO_RESPONSE}: {NO_RESPONSE_TEXT}.")
    rep.paragraph(f"Fit [%] is 100 (1 - |Z - Y| / |Z|) over the band's transforms "
                  f"({r0.band_hz[0]:.4g}-{r0.band_hz[1]:.4g} Hz), the figure identify "
                  "and the ladder report; the time plots show the whole record, "
                  "including what lies outside the band (trim drift, slow modes).")
    rep.figure(time_response_plot(res, show_inputs=True), "time",
               "Time-domain reconstruction: measured and predicted multiblade flap, "
               "and the pilot inputs that drove them.")
    rep.figure(frequency_response_plot(res), "frequency",
               "Frequency responses: measured (markers, +-2 stated-error bands, grey "
               "where coherence < 0.6) and the models' analytic responses (lines); "
               "coherence below.")
    rep.figure(error_spectrum_plot(res), "errors",
               "Measured over model response where the measurement is read, against "
               "the measurement's own error.")
    rep.figure(coherence_plot(res), "coherence",
               "Coherence of the measured flap with each input (partial: the other "
               "inputs' part removed): frequencies where it is low carry noise or "
               "unmeasured inputs, not this response.")
    model_frf_section(rep, res, bode=False, heading="Tischler's cost")
    for note in r0.frequency.measured.notes:
        rep.paragraph(f"Note: {note}")
    return rep


__all__ = ["fit_rows", "FIT_HEADER", "NO_RESPONSE", "NO_RESPONSE_TEXT", "fit_table_rows",
           "format_table", "validation_report"]
