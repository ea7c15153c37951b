"""The HTML report of ``inflowsim frf``: Bode plots per input, the pairs' table."""
from __future__ import annotations

import numpy as np


def summary_lines(fr) -> list[str]:
    """One line per pair: coherent points, their span, median random error."""
    import numpy as np
    from ..identify.frf import COHERENCE_OK
    lines = [f"records: {', '.join(fr.sources)}",
             f"windows [s]: {', '.join(f'{w:.3g}' for w in fr.windows_s)} (Hann, "
             f"{fr.overlap:.0%} overlap); effective averages "
             f"{', '.join(f'{n:.3g}' for n in fr.n_averages)}",
             f"band {fr.band_hz[0]:.4g}-{fr.band_hz[1]:.4g} Hz, "
             f"{fr.frequency_hz.size} frequencies; coherent: gamma^2 >= {COHERENCE_OK:g}",
             f"{'output':<8}{'input':<9}{'coherent':>10}{'from [Hz]':>11}{'to [Hz]':>9}"
             f"{'eps med [%]':>13}"]
    valid = fr.valid()
    f = fr.frequency_hz
    for o, out in enumerate(fr.outputs):
        for i, inp in enumerate(fr.inputs):
            v = valid[o, i]
            if v.any():
                lines.append(f"{out:<8}{inp:<9}{int(v.sum()):>6}/{f.size:<3}"
                             f"{f[v].min():>11.3g}{f[v].max():>9.3g}"
                             f"{100 * float(np.median(fr.random_error[o, i][v])):>13.3g}")
            else:
                lines.append(f"{out:<8}{inp:<9}{0:>6}/{f.size:<3}{'-':>11}{'-':>9}{'-':>13}")
    lines += [f"note: {n}" for n in fr.notes]
    return lines


def frf_report(fr, models=None, unwrap: bool = True, title=None):
    """A :class:`~inflowsim.report.document.Report` of a
    :class:`~inflowsim.identify.frf.FrequencyResponse`.

    ``models``: mapping of label to complex responses shaped like ``fr.h``, drawn
    over the measurements, with Tischler's cost ``J`` per pair in the table
    (:func:`~inflowsim.identify.frf.tischler_cost`).
    """
    from ..identify.frf import COHERENCE_OK, tischler_cost
    from .document import Report
    from .frf_plots import BAND_SIGMA, frequency_response_plot
    rep = Report(title or "Frequency responses", "records " + ", ".join(fr.sources))
    rep.paragraph(
        "Composite non-parametric responses: Hann windows of "
        + ", ".join(f"{w:.3g}" for w in fr.windows_s)
        + f" s overlapping {fr.overlap:.0%}, combined at each frequency with weights "
        "inverse to their random-error variance; each output's response to each input "
        "conditioned on the other inputs (H = Gxx^-1 Gxy). Coherence is the partial "
        "coherence (the ordinary one with a single input); points with coherence below "
        f"{COHERENCE_OK:g} are grey. Bands: +-{BAND_SIGMA:g} times the stated error "
        "sqrt(eps^2 + bias^2), eps Bendat and Piersol's normalised random error, bias "
        "the spread of the windows' estimates. Phases are "
        + ("unwrapped." if unwrap else "wrapped to +-180 deg."))
    for inp in fr.inputs:
        fig = frequency_response_plot(fr, pairs=[(o, inp) for o in fr.outputs],
                                      models=models, unwrap=unwrap,
                                      title=f"Responses to {inp}")
        rep.figure(fig, f"bode_{inp}", f"Responses of {', '.join(fr.outputs)} to {inp}")
    rows = []
    valid = fr.valid()
    for o, out in enumerate(fr.outputs):
        for i, inp in enumerate(fr.inputs):
            v = valid[o, i]
            row = [out, inp, int(v.sum()),
                   float(np.median(fr.random_error[o, i][v])) * 100 if v.any() else None]
            for label, h in (models or {}).items():
                row.append(tischler_cost(fr, h, out, inp))
            rows.append(row)
    header = ["output", "input", "coherent points", "median eps [%]"] + \
        [f"J {label}" for label in (models or {})]
    rep.table(rows, header, caption="Response pairs (J: Tischler's cost, <= 100 "
              "acceptable, <= 50 good)" if models else "Response pairs")
    rep.preformatted("\n".join(summary_lines(fr)))
    return rep


__all__ = ["summary_lines", "frf_report"]
