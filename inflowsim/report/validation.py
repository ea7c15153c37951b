"""Tables, text and the HTML report of a validation (what ``inflowsim validate``
prints and writes)."""
from __future__ import annotations

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


def format_table(result) -> str:
    lines = [f"model {result.structure} on {result.source}",
             f"trim: {result.trim.describe()}",
             f"band {result.band_hz[0]:.4g}-{result.band_hz[1]:.4g} Hz "
             f"({result.frequency.f_hz.size} frequencies), responses to "
             f"{result.frequency.reference_input}",
             f"{'channel':<8}{'rms [deg]':>12}{'TIC':>8}{'fit [%]':>9}"
             f"{'|H| [dB]':>10}{'phase [deg]':>13}"]
    undefined = False
    for c, rms, tic, fit, mag, ph in fit_rows(result):
        undefined |= not (np.isfinite(mag) and np.isfinite(ph))
        lines.append(f"{c:<8}{rms:>12.4g}{tic:>8.4f}{fit:>9.2f}{_cell(mag, 3):>10}"
                     f"{_cell(ph, 2):>13}")
    if undefined:
        lines.append(f"{NO_RESPONSE}: {NO_RESPONSE_TEXT}")
    return "\n".join(lines)


#: The table's mark of a response error that no band frequency defines.
NO_RESPONSE = "none"
NO_RESPONSE_TEXT = ("no response above noise to compare: at no band frequency do the "
                    "input and both responses have power")


def _cell(v, digits):
    return f"{v:.{digits}f}" if np.isfinite(v) else NO_RESPONSE


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
    from ..report.plots import (coherence_plot, error_spectrum_plot,
                                frequency_response_plot, time_response_plot)
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
        rows = [row[:4] + [v if np.isfinite(v) else NO_RESPONSE for v in row[4:]]
                for row in fit_rows(r)]
        rep.table(rows, header=FIT_HEADER, caption=f"Fit of {r.structure}")
        if any(NO_RESPONSE in row for row in rows):
            rep.paragraph(f"{NO_RESPONSE}: {NO_RESPONSE_TEXT}.")
    rep.paragraph(f"Fit [%] is 100 (1 - |Z - Y| / |Z|) over the band's transforms "
                  f"({r0.band_hz[0]:.4g}-{r0.band_hz[1]:.4g} Hz), the figure identify "
                  "and the ladder report; the time plots show the whole record, "
                  "including what lies outside the band (trim drift, slow modes).")
    rep.figure(time_response_plot(res, show_inputs=True), "time",
               "Time-domain reconstruction: measured and predicted multiblade flap, "
               "and the pilot inputs that drove them.")
    rep.figure(coherence_plot(res), "coherence",
               "Coherence of the measured flap with the reference input: frequencies "
               "where it is low carry noise or other inputs, not this response.")
    rep.figure(frequency_response_plot(res), "frequency",
               "Frequency responses: measured (markers) and model (lines).")
    rep.figure(error_spectrum_plot(res), "errors",
               "Measured over model response, magnitude and phase, across the band.")
    from .model_frf import model_frf_section
    model_frf_section(rep, res)
    return rep
