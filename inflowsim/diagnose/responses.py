"""Models on top of measured frequency responses (issue #25, item 2).

A model's response is put through the same estimator as the measurements: its
predicted flap (the record's measured inputs replayed, :func:`validate`) is
analysed with the measured inputs, the same inputs, windows and grid
(:func:`inflowsim.identify.frf.response_of_series`).  What the overlay shows is
then what the measurement would have been had the model been the aircraft, hub
motion and conditioning included, and the difference is the model's error, not
the estimator's.
"""
from __future__ import annotations

import numpy as np

from ..channels import CONTROLS, FLAP


def validation_responses(results, labels=None, inputs=None, band_hz=None):
    """Measured responses and each model's, from validations of one record.

    Parameters
    ----------
    results : sequence of ValidationResult
        Models on the same record (:func:`~inflowsim.diagnose.validation.validate`).
    labels : sequence of str, optional
        One per model (default the structures).
    inputs : sequence of str, optional
        Default: the controls that move.
    band_hz : (float, float), optional
        Default :data:`~inflowsim.identify.frf.DEFAULT_FRF_BAND`.

    Returns
    -------
    (FrequencyResponse, dict)
        The measured responses and ``{label: h}`` with ``h`` shaped like theirs.
    """
    from ..identify.frf import DEFAULT_FRF_BAND, response_of_series
    res = list(results)
    r0 = res[0]
    labels = list(labels or [r.structure for r in res])
    dt = float(r0.t[1] - r0.t[0])
    if inputs is None:
        inputs = [c for c in CONTROLS if c in r0.inputs
                  and np.ptp(r0.u[:, r0.inputs.index(c)]) > 0]
    cols = [r0.inputs.index(c) for c in inputs]
    band = band_hz or DEFAULT_FRF_BAND
    band = (band[0], min(band[1], 0.45 / dt))
    meas = response_of_series([np.hstack([r0.u[:, cols], r0.measured])], dt, inputs,
                              FLAP, band, sources=(r0.source,))
    models = {}
    for lab, r in zip(labels, res):
        fr = response_of_series([np.hstack([r0.u[:, cols], r.predicted])], dt, inputs,
                                FLAP, band, windows_s=meas.windows_s,
                                overlap=meas.overlap, sources=(r0.source,))
        models[lab] = fr.h
    return meas, models


__all__ = ["validation_responses"]
