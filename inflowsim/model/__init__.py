"""Model layer: named parameters and constants, the effect catalogue, structures,
the structured equations and their assembly into descriptor and state space
(:mod:`.build`), presets and parameter files.

``inflowsim.model`` was a module before the package was split into layers; its
public names are kept here.
"""
from .build import FLAP, Model, base_equations, build_model, descriptor, equations
from .effects import user as _user_effects  # noqa: F401  (plugs installed effects in)

__all__ = ["Model", "build_model", "descriptor", "equations", "base_equations", "FLAP"]
