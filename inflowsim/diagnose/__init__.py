"""Diagnosis layer: compare a model with measurements (:mod:`.validation`), see where
it fails (:mod:`.failures`), which effect is missing (the rule, :mod:`.rule`, on the lattice of :mod:`.candidates`), and the
ladder that adds it and ranks again (:mod:`.search`).

``inflowsim.diagnose`` was a module before the package was split into layers; its
public names are kept here.
"""
from .search import (Diagnosis, Ladder, Rung, analyses_of, diagnose, explicit_ladder,
                     failures_of, ladder)

__all__ = ["Diagnosis", "Ladder", "Rung", "diagnose", "ladder", "explicit_ladder",
           "failures_of", "analyses_of"]
