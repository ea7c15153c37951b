"""Defaults and choices that the command line shows in its help, apart from the
modules that compute with them.

``inflowsim --help`` and each command's ``--help`` must answer without importing
NumPy, SciPy or Matplotlib (issue #27: start-up): the values live here, in a module
that imports nothing, and the computing modules re-export them (one definition).
"""

#: The paper's band (model.md section 7), Hz: the one default of identification,
#: validation and diagnosis (bins 6..42 at 26.6 s).
DEFAULT_BAND = (0.2256, 1.58)

#: Intersample behaviour of a record's inputs (record-format.md, ``# hold:``).
HOLDS = ("continuous", "zoh", "foh")

#: The diagnosis's one significance level: ``Rule.alpha``'s default
#: (:mod:`inflowsim.diagnose.rule`), the level of each test the diagnosis makes.
ALPHA = 1e-3

#: Rungs a ladder adds at most (and atoms it removes at most): ``Rule.max_steps``'s
#: default.
MAX_STEPS = 6


__all__ = ["DEFAULT_BAND", "HOLDS", "ALPHA", "MAX_STEPS"]
