"""The catalogue of effects: each a small, self-contained module.

An :class:`Effect` names its parameters, their theory (neutral) values, and how
it edits the structured equations or the measurement.  A structure is the base
model plus a set of these; they are always applied in catalogue order so a
structure is a set, not a sequence.  To add an effect: write one module that
defines ``EFFECT`` and append its import to ``_MODULES`` below.  Effects written
outside the package (a file, ``--effect-file``, or an installed package's
``inflowsim.model.effects`` entry point) are checked and registered by :mod:`.user`,
which needs the structures and equations that read this catalogue: it sits above
them and plugs its loader of installed effects in here (:data:`LOADERS`), so this
module imports none of them (no import circle, issue #40).
"""
from __future__ import annotations

from ._effect import Effect, ParameterSpec, RuntimeLinear, RuntimePolynomials, RuntimeSolve
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


#: Callables that register effects from outside the package when a name is not in
#: the catalogue (:func:`load_missing`); :mod:`.user` adds its loader of installed
#: packages' effects.
LOADERS: list = []


def load_missing(names) -> None:
    """Where a name of ``names`` is not in the catalogue, run the :data:`LOADERS`
    (an installed package's effects, registered once).

    Parameters
    ----------
    names : iterable of str
        Effect names a structure asks for.
    """
    if any(n not in CATALOGUE for n in names):
        for load in LOADERS:
            load()


#: Names this package exported before the user effects and ``needs_trim`` moved to
#: the modules that own them: name -> module, resolved on first use (the one table
#: of moved names; new code imports them from their module).
MOVED = {"load_effect_file": "inflowsim.model.effects.user",
         "load_effect_files": "inflowsim.model.effects.user",
         "load_installed": "inflowsim.model.effects.user",
         "registered": "inflowsim.model.effects.user",
         "unregister": "inflowsim.model.effects.user",
         "USER_EFFECTS": "inflowsim.model.effects.user",
         "needs_trim": "inflowsim.model.structure"}


def __getattr__(name):
    if name in MOVED:
        import importlib
        return getattr(importlib.import_module(MOVED[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["Effect", "ParameterSpec", "RuntimeSolve", "RuntimeLinear", "RuntimePolynomials",
           "CATALOGUE", "register", "LOADERS", "load_missing", "MOVED"]
