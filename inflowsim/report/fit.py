"""The report of an identification (``inflowsim identify --report``): one
:class:`~.document.Report`, like every report of the package: ``index.html`` with
the parameter table (the paper's Tables 1-3: estimate, Cramer-Rao,
coloured-residual and robust bounds, theory value, and whether the estimates are
conditional on an incomplete structure), the per-channel fit, the warnings, the
frequency-domain fit and the time-domain reconstruction of every record, and
``table.md`` and ``fit.json`` beside it."""
from __future__ import annotations

from ..identify.tables import markdown_table, table_rows
from ..fileio import json_text
from .document import Report
from .fit_plots import band_study_plot, fit_plot, reconstruction_plot

PARAMETER_HEADER = ["parameter", "estimate", "1-sigma", "1-sigma (coloured)",
                    "1-sigma (robust)", "theory", "note"]
FIT_HEADER = ["channel", "magnitude error (RMS dB)", "phase error (RMS deg)", "fit [%]"]


def fit_report(result, rep: Report | None = None) -> Report:
    """The :class:`Report` of a :class:`~inflowsim.identify.FitResult`."""
    rep = rep or Report(f"Identification of {result.structure.name}",
                        ", ".join(result.records))
    rep.paragraph(f"Band {result.band_hz[0]:.4g}-{result.band_hz[1]:.4g} Hz "
                  f"({result.n_freq} frequencies), cost (12) {result.cost:.4f}, "
                  f"{'converged' if result.converged else 'NOT converged'} in "
                  f"{result.iterations} iterations.")
    from .units import parameter_label, parameter_value
    rows = []
    for n, v, s, sc, sr, th, note in table_rows(result):
        free = n not in result.fixed
        rows.append([parameter_label(n), parameter_value(n, v),
                     parameter_value(n, s) if free else "",
                     parameter_value(n, sc) if free else "",
                     parameter_value(n, sr) if free else "", parameter_value(n, th),
                     note or ("not determined" if free and s is None else "")])
    rep.table(rows, PARAMETER_HEADER, caption="Estimates with 1-sigma bounds (angles in "
              "degrees, time constants in azimuth units)")
    if getattr(result, "conditional", None):
        rep.paragraph(f"Every estimate is {result.conditional}.")
    rep.table([[ch, f["mag_rms_db"], f["phase_rms_deg"], f["fit_percent"]]
               for ch, f in result.fit.items()], FIT_HEADER, caption="Fit per channel")
    for w in result.warnings:
        rep.paragraph(f"Warning: {w}")
    for i, d in enumerate(result.data):
        k = i or ""
        rep.figure(fit_plot(result, None, i), f"fit_frequency{k}",
                   f"{d.source}: measured and predicted flap transforms.")
        rep.figure(reconstruction_plot(result, None, i), f"fit_time{k}",
                   f"{d.source}: time-domain reconstruction from the estimated initial "
                   "state.")
    rep.attach("table.md", markdown_table(result), "the tables in Markdown")
    rep.attach("fit.json", json_text(result.to_json()),
               "the fit: a parameter file simulate, validate and the FMU read")
    return rep


def write_report(result, folder, force=False, protect=()):
    """Write :func:`fit_report` into ``folder``; return the ``index.html`` path.
    (``force`` is kept for callers; a report replaces only its own earlier files.)"""
    return fit_report(result).write(folder, protect=protect)


def band_study_report(study, rep: Report | None = None) -> Report:
    """The :class:`Report` of a band study (the paper's Figure 6): estimates with
    1-sigma bars against the lower band limit, and ``bandstudy.json``."""
    rep = rep or Report(f"Band study of {study.structure}",
                        f"upper band limit {study.upper_hz:.4g} Hz")
    rep.figure(band_study_plot(study), "bandstudy",
               "Estimates with 1-sigma bounds against the lower frequency limit.")
    rep.attach("bandstudy.json", json_text(study.to_json()),
               "the estimates and bounds")
    return rep


__all__ = ["PARAMETER_HEADER", "FIT_HEADER", "fit_report", "write_report",
           "band_study_report"]
