"""Report sections: measured frequency responses with the models on top, Tischler's
cost per response pair, and the parameters' Cramer-Rao and insensitivity percent
(issue #25, item 2).  Used by the ``validate``, ``ladder`` and ``demo`` reports."""
from __future__ import annotations

import numpy as np


def cost_rows(fr, models: dict):
    """Rows ``output, input, coherent points, J per model`` and the overall row
    (the mean over the pairs with coherent points), with the guideline verdict."""
    from ..identify.frf import J_ACCEPTABLE, J_GOOD, tischler_cost
    rows, per_model = [], {k: [] for k in models}
    valid = fr.valid()
    for o, out in enumerate(fr.outputs):
        for i, inp in enumerate(fr.inputs):
            row = [out, inp, int(valid[o, i].sum())]
            for label, h in models.items():
                j = tischler_cost(fr, h, out, inp)
                row.append(None if np.isnan(j) else j)
                if np.isfinite(j):
                    per_model[label].append(j)
            rows.append(row)
    overall = ["overall", "", int(valid.sum())]
    verdict = ["guideline", "", ""]
    for label in models:
        js = per_model[label]
        m = float(np.mean(js)) if js else None
        overall.append(m)
        verdict.append("-" if m is None else "good" if m <= J_GOOD else
                       "acceptable" if m <= J_ACCEPTABLE else "poor")
    return rows + [overall, verdict]


def accuracy_row(a) -> list:
    """A :class:`~inflowsim.identify.accuracy.ParameterAccuracy` row as reports show
    it: the parameter with its unit, estimate and bound in that unit (degrees for
    angles)."""
    from .units import parameter_label, parameter_value
    name, est, sigma, *rest = a.as_row()
    return [parameter_label(name), parameter_value(name, est),
            parameter_value(name, sigma), *rest]


def model_frf_section(rep, results, labels=None, fits=None, prefix="frf", heading=None):
    """Add to ``rep``: Bode plots per input (measured with coherence and error
    bands, the models of ``results`` on top), Tischler's ``J`` per pair and
    overall, and for each of ``fits`` (``{label: FitResult}``) the CR% and
    insensitivity% table.  ``results``: validations of the models on one record."""
    from ..diagnose.responses import validation_responses
    from ..identify.accuracy import CR_LIMIT, HEADER, INSENSITIVITY_LIMIT, parameter_accuracy
    from ..identify.frf import J_ACCEPTABLE, J_GOOD
    from .frf_plots import BAND_SIGMA, frequency_response_plot
    from ..errors import InputError
    res = list(results)
    labels = list(labels or [r.structure for r in res])
    try:
        fr, models = validation_responses(res, labels)
    except InputError as exc:
        rep.paragraph(f"No frequency responses: {exc}.")
        return None, {}
    rep.heading(heading or "Frequency responses: the models on the measurements")
    rep.paragraph(
        "Measured responses of the flap to each control that moves, each conditioned on "
        "the other controls (composite of Hann windows "
        + ", ".join(f"{w:.3g}" for w in fr.windows_s)
        + f" s; +-{BAND_SIGMA:g} stated-error bands; grey: coherence below 0.6). The "
        "models' responses are their predicted flap through the same estimator, so "
        "hub motion and conditioning are the same on both sides. Phases wrapped to "
        "+-180 deg.")
    for inp in fr.inputs:
        fig = frequency_response_plot(fr, pairs=[(o, inp) for o in fr.outputs],
                                      models=models, title=f"Responses to {inp}: "
                                      + ", ".join(labels))
        rep.figure(fig, f"{prefix}-bode-{inp}",
                   f"Flap responses to {inp}: measured (markers, bands) and "
                   + ", ".join(labels) + " (lines).")
    rep.table(cost_rows(fr, models), ["output", "input", "coherent points"] +
              [f"J {lab} [-]" for lab in labels],
              caption=f"Tischler's cost J per response pair over the coherent points, "
                      f"a pure number (magnitude errors in dB weighted 1 per dB^2, "
                      f"phase errors in deg weighted 0.01745 per deg^2; J <= "
                      f"{J_GOOD:g} good, <= "
                      f"{J_ACCEPTABLE:g} acceptable)")
    for lab, fit in (fits or {}).items():
        rep.table([accuracy_row(a) for a in parameter_accuracy(fit)], HEADER,
                  caption=f"{lab}: Cramer-Rao and insensitivity percent (guidelines: CR "
                          f"<= {CR_LIMIT:g} %, insensitivity <= {INSENSITIVITY_LIMIT:g} %;"
                          " angles in degrees)")
    return fr, models
