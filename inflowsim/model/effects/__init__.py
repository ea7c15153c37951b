"""The catalogue of effects: each a small, self-contained module.

An :class:`Effect` names its parameters, their theory (neutral) values, and how
it edits the structured equations or the measurement.  A structure is the base
model plus a set of these; they are always applied in catalogue order so a
structure is a set, not a sequence.  To add an effect: write one module that
defines ``EFFECT`` and append its import to ``_MODULES`` below.
"""
from __future__ import annotations

from ._effect import Effect
from . import (separate_time_constants, hub_velocity_coupling, glauert, azimuth_bias,
               time_delay)

_MODULES = (separate_time_constants, hub_velocity_coupling, glauert, azimuth_bias,
            time_delay)
from . import flap_inertia, skewed_wake, advance_ratio_perturbation  # noqa: E402
from . import time_shifts  # noqa: E402
_MODULES += (flap_inertia, skewed_wake, advance_ratio_perturbation)

#: Effects by name, in the order they are applied.
CATALOGUE: dict[str, Effect] = {m.EFFECT.name: m.EFFECT for m in _MODULES}
CATALOGUE.update({e.name: e for e in time_shifts.EFFECTS})


def register(effect: Effect) -> Effect:
    """Add an effect to the catalogue (used by effect modules outside this package)."""
    CATALOGUE[effect.name] = effect
    return effect


__all__ = ["Effect", "CATALOGUE", "register"]
