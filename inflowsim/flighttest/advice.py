"""Standard manoeuvres for identifiability advice: which one would determine what a
record cannot (:func:`inflowsim.identify.identifiability.identifiability`).

Each is a 1 deg pilot input from 2 s on one control, a doublet, a 3-2-1-1 or a log
sweep (0.15-3 Hz, as long as the record allows, up to 20 s), flown
on the project's virtual airframe (:class:`~inflowsim.flighttest.body.BodyModel`,
which turns the controls into the hub motion ``p, q, mux, muy ...`` a real aircraft
gives) over the same length and step as the record judged.
"""
from __future__ import annotations

import numpy as np

from ..channels import CONTROLS
from .body import BodyModel
from .virtual import Manoeuvre, pilot_controls

#: (shape, control) of the manoeuvres tried.
STANDARD = tuple((shape, ch) for shape in ("doublet", "3211", "sweep") for ch in CONTROLS)


def standard_manoeuvres(n_samples: int, dt: float, constants, shapes=STANDARD):
    """``(label, {column: perturbation (n_samples,)})`` for each of ``shapes``, one
    at a time (a generator: a 2-hour record's nine manoeuvres held together were
    330 MB): the controls and the airframe's hub motion [SI]."""
    t = np.arange(n_samples) * dt
    omega_r = constants.omega * (constants.radius or 7.5)
    for shape, ch in shapes:
        # made and handed over unnamed: the generator holds no reference to them,
        # so the consumer can free them while it works with what it made of them
        yield f"{shape} on {ch}", _columns(t, dt, omega_r, constants.mu, shape, ch)


def _columns(t, dt, omega_r, mu, shape, ch):
    """``{column: perturbation}`` of one manoeuvre: its controls and the hub motion."""
    length = min(20.0, max(t[-1] - 4.0, 1.0))
    controls = pilot_controls(t, (Manoeuvre(channel=ch, shape=shape, length=length),))
    hub = BodyModel().response(controls, dt, omega_r, mu)
    return {c: controls[:, i] for i, c in enumerate(CONTROLS)} | hub


__all__ = ["STANDARD", "standard_manoeuvres"]
