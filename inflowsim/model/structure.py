"""Model structures: the base momentum model plus a set of effects.

Text form: a base or preset, then ``+effect`` terms, e.g. ``glauert``,
``basic+separate-time-constants``, ``empirical+time-delay``.
"""
from __future__ import annotations

from dataclasses import dataclass

from .effects import CATALOGUE, load_missing
from .equations import FLAP, FLAP_RATE, INFLOW, INPUTS, INPUTS_AZ, N_BASE_INPUTS
from ..errors import InputError

BASE_PARAMETERS = ("lambda_beta2", "n_beta", "tau")

PRESETS = {
    "basic": (),
    "empirical": ("separate-time-constants", "hub-velocity-coupling", "azimuth-bias"),
    "glauert": ("separate-time-constants", "glauert", "azimuth-bias"),
}


def unknown_effect(name: str) -> str:
    """One short line for an effect name not in the catalogue: the closest names,
    not the whole catalogue (issue #37: a line of 513 characters)."""
    import difflib
    close = difflib.get_close_matches(str(name), list(CATALOGUE), n=3, cutoff=0.5)
    hint = (f"did you mean {' or '.join(close)}?" if close else
            "docs/workflow.md lists the effects")
    return f"unknown effect {name!r} ({hint})"


@dataclass(frozen=True)
class Structure:
    """A base model plus a set of effects (kept in catalogue order).

    Attributes
    ----------
    effects : tuple of str
        The effects added to the basic model (catalogue names).
    """

    effects: tuple = ()

    def __post_init__(self):
        load_missing(self.effects)     # an installed package's effects, once
        for name in self.effects:
            if name not in CATALOGUE:
                raise InputError(unknown_effect(name))
        ordered = tuple(n for n in CATALOGUE if n in set(self.effects))
        object.__setattr__(self, "effects", ordered)
        for name in ordered:
            for alt in CATALOGUE[name].alternatives:
                if alt in ordered:
                    raise InputError(f"effects {name} and {alt} are alternatives and "
                                     "cannot be combined (the information matrix would "
                                     "be singular)")

    @classmethod
    def parse(cls, text: "str | Structure") -> "Structure":
        """``"glauert"``, ``"basic+time-delay"``, ``"empirical+time-delay"`` ..."""
        if isinstance(text, Structure):
            return text
        parts = [p.strip() for p in str(text).split("+")]
        base = parts[0]
        if base not in PRESETS:
            raise InputError(f"unknown model {base!r} (a preset: {', '.join(PRESETS)}; "
                             "then +effect terms)")
        terms = parts[1:]
        twice = next((e for i, e in enumerate(terms) if e in terms[:i]), None)
        if twice is not None:
            raise InputError(f"structure {text!r}: effect {twice} is given twice")
        return cls(PRESETS[base] + tuple(terms))

    def with_effect(self, name: str) -> "Structure":
        if name in self.effects:
            raise InputError(f"effect {name} is already in the structure {self.name}")
        return Structure(self.effects + (name,))

    def without_effect(self, name: str) -> "Structure":
        return Structure(tuple(e for e in self.effects if e != name))

    @property
    def name(self) -> str:
        """Preset name where it is one, else ``basic+effect+...``."""
        for preset, eff in PRESETS.items():
            if set(eff) == set(self.effects):
                return preset
        best = max((p for p, e in PRESETS.items() if set(e) <= set(self.effects)),
                   key=lambda p: len(PRESETS[p]))
        extra = [e for e in self.effects if e not in PRESETS[best]]
        return "+".join([best, *extra])

    @property
    def parameters(self) -> tuple:
        removed = {r for e in self.effects for r in CATALOGUE[e].removes}
        names = [p for p in BASE_PARAMETERS if p not in removed]
        for e in self.effects:
            names.extend(CATALOGUE[e].parameters)
        return tuple(names)

    @property
    def uses_inplane(self) -> bool:
        return any(CATALOGUE[e].uses_inplane for e in self.effects)

    @property
    def second_order(self) -> bool:
        return any(CATALOGUE[e].second_order for e in self.effects)

    @property
    def n_inputs(self) -> int:
        return len(INPUTS) if self.uses_inplane else N_BASE_INPUTS

    @property
    def inputs(self) -> tuple:
        """Input names in SI units (record columns)."""
        return INPUTS[: self.n_inputs]

    @property
    def inputs_az(self) -> tuple:
        return INPUTS_AZ[: self.n_inputs]

    @property
    def states(self) -> tuple:
        """Flap, inflow, the flap rates with ``flap-inertia``, then each effect's
        appended states (:attr:`Effect.states`) in catalogue order."""
        extra = tuple(x for e in self.effects for x in CATALOGUE[e].states)
        return FLAP + INFLOW + (FLAP_RATE if self.second_order else ()) + extra

    @property
    def replaced_inputs(self) -> dict:
        """``{input: state}``: recorded inputs the base equations see through a state
        (a servo actuator's output pitch)."""
        return {i: x for e in self.effects for i, x in CATALOGUE[e].replaces_inputs}

    def __str__(self) -> str:
        return self.name


def needs_trim(structures) -> bool:
    """Some structure of ``structures`` (names or parsed) has an effect linearised
    about the trim state (:attr:`~inflowsim.model.effects.Effect.about_trim`).

    Parameters
    ----------
    structures : iterable of str or Structure
        The structures.
    """
    return any(CATALOGUE[e].about_trim for st in structures
               for e in Structure.parse(st).effects if e in CATALOGUE)


__all__ = ["BASE_PARAMETERS", "PRESETS", "Structure", "needs_trim"]
