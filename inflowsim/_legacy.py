"""Import paths of the package before it was split into layers (0.1.0).

``inflowsim.record``, ``inflowsim.simulator``, ``inflowsim.effects.glauert`` ...
keep working (``inflowsim.model``, ``inflowsim.diagnose``, ``inflowsim.flighttest``
and ``inflowsim.report`` are packages now that re-export what the modules had): each name below resolves to the module that now holds the code (the
same module object, so ``isinstance`` and monkeypatching behave).  New code uses
the layered paths; an old path warns (``DeprecationWarning``) naming its
replacement.
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

#: Old path under ``inflowsim`` -> new path (a prefix maps its submodules too).
ALIASES = {
    "flapping": "physics.flapping", "loads": "physics.loads",
    "bladeelement": "physics.bladeelement", "theory": "physics.theory",
    "multiblade": "physics.multiblade",
    "params": "model.params", "equations": "model.equations",
    "structure": "model.structure", "presets": "model.presets",
    "paramfile": "model.paramfile", "effects": "model.effects",
    "discrete": "simulate.discrete", "sampled": "simulate.sampled",
    "simulator": "simulate.simulator", "replay": "simulate.replay",
    "record": "data.record", "inputs": "data.inputs",
    "failures": "diagnose.failures", "candidates": "diagnose.candidates",
    "validation": "diagnose.validation",
    "body": "flighttest.body", "bladesim": "flighttest.bladesim",
    "virtual": "flighttest.virtual",
    "plots": "report.plots",
    "ladder_report": "report.ladder", "identify.plots": "report.fit_plots",
}


def target(name: str) -> str | None:
    """The new absolute name for an old absolute ``inflowsim.*`` name, or ``None``."""
    if not name.startswith("inflowsim."):
        return None
    rest = name[len("inflowsim."):]
    for old, new in ALIASES.items():
        if rest == old or rest.startswith(old + "."):
            return "inflowsim." + new + rest[len(old):]
    return None


class _AliasFinder(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    def find_spec(self, fullname, path, target_=None):
        if target(fullname) is None:
            return None
        return importlib.util.spec_from_loader(fullname, self)

    def create_module(self, spec):
        new = target(spec.name)
        warnings.warn(f"{spec.name} is an old import path: use {new} (inflowsim 0.2; "
                      "the old paths will be removed)", DeprecationWarning, stacklevel=2)
        module = importlib.import_module(new)
        self._specs[spec.name] = module.__spec__
        sys.modules[spec.name] = module
        return module

    def exec_module(self, module):
        # the import system has stamped the alias spec on the module: give it back
        # its own, so it stays what it is under its real name
        for name, spec in list(self._specs.items()):
            if sys.modules.get(name) is module:
                module.__spec__ = spec

    def __init__(self):
        self._specs = {}


def install():
    if not any(isinstance(f, _AliasFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, _AliasFinder())
