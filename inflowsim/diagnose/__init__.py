"""Diagnosis layer: compare a model with measurements (:mod:`.validation`), see where
it fails (:mod:`.failures`), which effect is missing (the selection, one rule with one
settings object :class:`Rule`: :mod:`.rule`; its per-atom view :mod:`.candidates`), and
the ladder that adds it and selects again (:mod:`.search`).

``inflowsim.diagnose`` was a module before the package was split into layers; its
public names are kept here.
"""
from .rule import DEFAULT_RULE, Rule
from .search import (Diagnosis, Ladder, Rung, analyses_of, diagnose, explicit_ladder,
                     failures_of, ladder)

__all__ = ["Diagnosis", "Ladder", "Rung", "diagnose", "ladder", "explicit_ladder",
           "failures_of", "analyses_of", "Rule", "DEFAULT_RULE"]
