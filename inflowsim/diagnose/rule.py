"""The settings of the diagnosis's acceptance rule, as data passed as an argument.

The rule itself is stated in :mod:`inflowsim.diagnose.candidates` (the tests a
candidate passes) and :mod:`inflowsim.diagnose.rivals` (naming one among rivals);
its numbers live here, in one frozen object that :func:`~inflowsim.diagnose.diagnose`,
:func:`~inflowsim.diagnose.ladder` and the pieces they call take as ``rule=``.  A
study varies a setting by passing ``Rule(...)`` (``dataclasses.replace``), never by
patching a module.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..defaults import ALPHA
from ..errors import InputError
from .failures import COLOURED

#: Every test a candidate can be put to, in the order they are stated.
TESTS = ("significant", "parsimonious", "plausible", "material", "whiter", "unrivalled")
#: What the material and whiter tests measure on a white-noise record.
WHITE_MEASURES = ("level", "deviance")


@dataclass(frozen=True)
class Rule:
    """Settings of the acceptance rule.

    Attributes
    ----------
    alpha : float
        Significance level of each likelihood-ratio test [-].
    schwarz_min : float
        Schwarz gain a candidate must exceed: 2 is "positive evidence" (Kass and
        Raftery, JASA 90, 1995).
    plausible_sigmas : float
        Estimates within this many sigma of their plausible range are plausible.
    material : float
        Share of the base residual's excess over the noise floor a candidate must
        explain [-].
    tests : tuple of str
        The tests applied (:data:`TESTS`; a study may narrow them).
    white_measure : {"level", "deviance"}
        The measure of the material and whiter tests on white-noise records: the
        level deviance, or the per-bin deviance (kept for studies).
    coloured : float
        A record whose in-band sensor noise is this many times the floor or more
        is judged on the residual's input-correlated excess instead (0: every
        record; :data:`inflowsim.diagnose.failures.COLOURED`).
    pair_min_dof : int
        A candidate with this many parameters or more is tested against pairs of
        smaller ones.
    max_pairs, max_part_pairs : int
        Pairs of candidates, and of a candidate with a part of a whole effect,
        tried at most.
    max_rounds : int
        Rounds of displacement among rivals, per candidate, at most.
    """

    alpha: float = ALPHA
    schwarz_min: float = 2.0
    plausible_sigmas: float = 3.0
    material: float = 0.10
    tests: tuple = TESTS
    white_measure: str = "level"
    coloured: float = COLOURED
    pair_min_dof: int = 3
    max_pairs: int = 3
    max_part_pairs: int = 3
    max_rounds: int = 3

    def __post_init__(self):
        if not 0 < self.alpha < 1:
            raise InputError(f"alpha = {self.alpha:g}: give a level between 0 and 1")
        bad = [t for t in self.tests if t not in TESTS]
        if bad:
            raise InputError(f"rule test {bad[0]!r}: choose from {', '.join(TESTS)}")
        if self.white_measure not in WHITE_MEASURES:
            raise InputError(f"white_measure {self.white_measure!r}: choose "
                             f"{' or '.join(WHITE_MEASURES)}")
        object.__setattr__(self, "tests", tuple(self.tests))

    def uses(self, test: str) -> bool:
        return test in self.tests


#: The rule as the library applies it by default.
DEFAULT_RULE = Rule()


def rule_with(rule: Rule | None, alpha: float | None = None) -> Rule:
    """``rule`` (default :data:`DEFAULT_RULE`) with ``alpha`` where one is given."""
    from dataclasses import replace
    rule = rule or DEFAULT_RULE
    return rule if alpha is None or alpha == rule.alpha else replace(rule, alpha=alpha)
