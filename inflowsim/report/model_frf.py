"""Report sections: measured frequency responses with the models on top, Tischler's
cost per response pair, and the parameters' Cramer-Rao and insensitivity percent
(issue #25, item 2).  Used by the ``validate``, ``ladder`` and ``demo`` reports.

Everything comes from validations of the models on one record
(:func:`inflowsim.diagnose.validation.validate`): their measured responses (each
conditioned on the other inputs, the same for every model) and each model's
analytic responses and costs.
"""
from __future__ import annotations

import numpy as np


def cost_rows(results, labels=None):
    """Rows ``output, input, points read, J per model`` and the overall row (the
    mean over the pairs with points read), then the guideline verdict."""
    from ..diagnose.validation import cost_verdict
    res = list(results)
    labels = list(labels or [r.structure for r in res])
    fr = res[0].frequency.measured
    valid = fr.valid()
    rows = []
    for o, out in enumerate(fr.outputs):
        for i, inp in enumerate(fr.inputs):
            row = [out, inp, int(valid[o, i].sum())]
            for r in res:
                j = r.frequency.cost[(out, inp)]
                row.append(float(j) if np.isfinite(j) else None)
            rows.append(row)
    overall = ["overall", "", int(valid.sum())]
    verdict = ["guideline", "", ""]
    for r in res:
        m = r.frequency.overall_cost
        overall.append(m if np.isfinite(m) else None)
        verdict.append(cost_verdict(m))
    return rows + [overall, verdict]


def accuracy_row(a) -> list:
    """A :class:`~inflowsim.identify.accuracy.ParameterAccuracy` row as reports show
    it: the parameter with its unit, estimate and bound in that unit (degrees for
    angles)."""
    from .units import parameter_label, parameter_value
    name, est, sigma, *rest = a.as_row()
    return [parameter_label(name), parameter_value(name, est),
            parameter_value(name, sigma), *rest]


def cost_caption() -> str:
    from ..identify.frf import J_ACCEPTABLE, J_GOOD, W_GAIN, W_PHASE
    return (f"Tischler's cost J per response pair over the points read (coherence >= "
            f"0.6), a pure number (magnitude errors in dB weighted {W_GAIN:g} per "
            f"dB^2, phase errors in deg weighted {W_PHASE:g} per deg^2; J <= "
            f"{J_GOOD:g} good, <= {J_ACCEPTABLE:g} acceptable)")


def responses_paragraph(r0) -> str:
    """How the responses were measured and the models' computed (one paragraph)."""
    from .frf_plots import BAND_SIGMA
    fc = r0.frequency
    fr = fc.measured
    cond = (", each conditioned on the other" + ("s" if len(fr.inputs) > 2 else "")
            if len(fr.inputs) > 1 else "")
    hub = (f" The models' hub inputs ({', '.join(fc.paths)}) moved with the controls: "
           "they are closed through their own measured responses to the controls, so "
           "each model is shown as it would have answered with the hub moving as it "
           "did." if fc.paths else "")
    return ("Measured responses of the flap to " + ", ".join(fr.inputs) + cond +
            " (composite of Hann windows " + ", ".join(f"{w:.3g}" for w in fr.windows_s)
            + f" s over {r0.band_hz[0]:.4g}-{r0.band_hz[1]:.4g} Hz; +-{BAND_SIGMA:g} "
            "stated-error bands; grey: coherence below 0.6). The models' responses are "
            "their analytic transfer functions (time shifts and the record's "
            f"intersample behaviour, {r0.hold}, included)." + hub +
            " Phases unwrapped, each model on the measurement's branch.")


def model_frf_section(rep, results, labels=None, fits=None, prefix="frf", heading=None,
                      bode=True):
    """Add to ``rep``: Bode plots per input (measured with coherence and error
    bands, the models of ``results`` on top; unless ``bode`` is false), Tischler's
    ``J`` per pair and overall, and for each of ``fits`` (``{label: FitResult}``)
    the CR% and insensitivity% table.  ``results``: validations of the models on
    one record.  Returns the measured responses."""
    from ..identify.accuracy import CR_LIMIT, HEADER, INSENSITIVITY_LIMIT, parameter_accuracy
    from .frf_plots import frequency_response_plot
    res = list(results)
    labels = list(labels or [r.structure for r in res])
    fr = res[0].frequency.measured
    models = {lab: r.frequency.model for lab, r in zip(labels, res)}
    rep.heading(heading or "Frequency responses: the models on the measurements")
    if bode:
        rep.paragraph(responses_paragraph(res[0]))
        for inp in fr.inputs:
            fig = frequency_response_plot(fr, pairs=[(o, inp) for o in fr.outputs],
                                          models=models, title=f"Responses to {inp}: "
                                          + ", ".join(labels))
            rep.figure(fig, f"{prefix}-bode-{inp}",
                       f"Flap responses to {inp}: measured (markers, bands) and "
                       + ", ".join(labels) + " (lines).")
    rep.table(cost_rows(res, labels), ["output", "input", "points read"] +
              [f"J {lab} [-]" for lab in labels], caption=cost_caption())
    for lab, fit in (fits or {}).items():
        rep.table([accuracy_row(a) for a in parameter_accuracy(fit)], HEADER,
                  caption=f"{lab}: Cramer-Rao and insensitivity percent (guidelines: CR "
                          f"<= {CR_LIMIT:g} %, insensitivity <= {INSENSITIVITY_LIMIT:g} %;"
                          " angles in degrees)")
    return fr


__all__ = ["cost_rows", "accuracy_row", "cost_caption", "responses_paragraph",
           "model_frf_section"]
