"""Tables, text and the HTML report of a validation (what ``inflowsim validate``
prints and writes)."""
from __future__ import annotations

from ..data.record import FLAP_COLUMNS
from ..simulate.sampled import HOLD_TEXT


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
        rep.table(fit_rows(r), header=FIT_HEADER, caption=f"Fit of {r.structure}")
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
