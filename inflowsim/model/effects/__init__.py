"""The catalogue of effects: each a small, self-contained module.

An :class:`Effect` names its parameters, their theory (neutral) values, and how
it edits the structured equations or the measurement.  A structure is the base
model plus a set of these; they are always applied in catalogue order so a
structure is a set, not a sequence.  To add an effect: write one module that
defines ``EFFECT`` and append its import to ``_MODULES`` below.  Effects written
outside the package (a file, ``--effect-file``, or an installed package's
``inflowsim.model.effects`` entry point) are checked and registered by :mod:`.user`.
"""
from __future__ import annotations

from ._effect import Effect, ParameterSpec, RuntimeSolve
from ..params import register as register_spec
from . import (separate_time_constants, hub_velocity_coupling, glauert, azimuth_bias,
               time_delay)

_MODULES = (separate_time_constants, hub_velocity_coupling, glauert, azimuth_bias,
            time_delay)
from . import flap_inertia, skewed_wake, advance_ratio_perturbation  # noqa: E402
from . import second_harmonic_flap  # noqa: E402
from . import momentum_speed  # noqa: E402
from . import wake_distortion, wake_distortion_lag  # noqa: E402
from . import time_shifts  # noqa: E402
from . import servo_actuators  # noqa: E402
from . import lead_lag  # noqa: E402
from . import peters_he  # noqa: E402
_MODULES += (flap_inertia, skewed_wake, advance_ratio_perturbation, second_harmonic_flap,
             momentum_speed, wake_distortion, wake_distortion_lag, servo_actuators,
             lead_lag)

#: Effects by name, in the order they are applied.
CATALOGUE: dict[str, Effect] = {}


def register(effect: Effect) -> Effect:
    """Add an effect to the catalogue, and its parameters' facts to
    :data:`inflowsim.model.params.SPECS` (used by effect modules outside this
    package too).

    Parameters
    ----------
    effect : Effect
        The effect (its name, parameters with their units and ranges, and equations).
    """
    for spec in effect.specs:
        register_spec(spec)
    CATALOGUE[effect.name] = effect
    return effect


for _e in [m.EFFECT for m in _MODULES] + list(time_shifts.EFFECTS) + list(peters_he.EFFECTS):
    register(_e)


def needs_trim(structures) -> bool:
    """Some structure of ``structures`` (names or parsed) has an effect linearised
    about the trim state (:attr:`Effect.about_trim`).

    Parameters
    ----------
    structures : iterable of str or Structure
        The structures.
    """
    from ..structure import Structure
    return any(CATALOGUE[e].about_trim for st in structures
               for e in Structure.parse(st).effects if e in CATALOGUE)


from .user import (load_effect_file, load_effect_files, load_installed,  # noqa: E402
                   registered, unregister, USER_EFFECTS)

__all__ = ["Effect", "ParameterSpec", "RuntimeSolve", "CATALOGUE", "register", "needs_trim",
           "load_effect_file", "load_effect_files",
           "load_installed", "registered", "unregister", "USER_EFFECTS"]
