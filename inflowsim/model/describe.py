"""A structure described for people and scripts: states, inputs, parameters with
their units and ranges, ``E, A, B`` and the eigenvalues (``inflowsim model``,
``interface.md``)."""
from __future__ import annotations

import numpy as np

from .params import SPECS


def eigen_table(model) -> list[dict]:
    """Poles [1/s] with natural frequency [rad/s], damped frequency [Hz], damping."""
    rows = []
    for ev in model.eigenvalues():
        if ev.imag < -1e-12:
            continue                      # one line per conjugate pair
        wn = abs(ev)
        rows.append({"re": float(ev.real), "im": float(ev.imag), "wn_rad_s": float(wn),
                     "f_hz": float(abs(ev.imag) / (2 * np.pi)),
                     "damping": float(-ev.real / wn) if wn > 0 else float("nan")})
    return rows


def describe_model(model, sigma=None) -> dict:
    """The ``model --json`` document of ``model`` (``interface.md``)."""
    sigma = sigma or {}
    params = {}
    for n, v in model.parameters.items():
        spec = SPECS[n]
        d = {"estimate": v}
        if n in sigma:
            d["sigma"] = sigma[n]
        d.update(unit=spec.unit, range=spec.range_text(), description=spec.description)
        params[n] = d
    return {
        "structure": model.structure.name,
        "effects": list(model.structure.effects),
        "states": list(model.states),
        "inputs": list(model.inputs_az),
        "record_inputs": list(model.inputs),
        "constants": model.constants.as_dict(),
        "parameters": params,
        "E": model.E, "A": model.A, "B": model.B,
        "eigenvalues": [[float(e.real), float(e.imag)] for e in model.eigenvalues()],
        "delays_s": dict(zip(model.outputs, model.delays.tolist())),
    }


__all__ = ["eigen_table", "describe_model"]
