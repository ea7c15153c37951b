"""The parsimony test and the part variants of :func:`inflowsim.diagnose.candidates.try_effect`,
on stub fits whose costs are set by hand (the record cases are in
``tests/test_nonlinear_ladder.py`` and ``bench/README.md``)."""
from types import SimpleNamespace

import numpy as np
import pytest

from inflowsim.diagnose.rule import DEFAULT_RULE

import inflowsim as ifs
from inflowsim.diagnose import candidates
from inflowsim.diagnose.candidates import try_effect
from inflowsim.model.presets import theory_parameters
from inflowsim.flighttest.virtual import VirtualTest, virtual_record

K = virtual_record(VirtualTest(duration=1.0)).constants
BASE = ifs.Structure.parse("basic")
NF = 37
LN_N = np.log(6 * NF)
BASE_FIT = SimpleNamespace(structure=BASE, cost=100.0, fixed=(), n_freq=NF,
                           parameters=theory_parameters(BASE, K), constants=(K,))


def _fit_fn(cost_of):
    """Stub fits: ``cost_of(frozenset of the effect's held names)`` sets the cost;
    every free parameter gets a bound."""
    def fit_fn(records, s, band_hz, start, fixed=None):
        fixed = dict(fixed or {})
        return SimpleNamespace(structure=s, cost=cost_of(frozenset(fixed)), fixed=tuple(fixed),
                               n_freq=NF, parameters=dict(start),
                               sigma={n: (None if n in fixed else 0.01) for n in start})
    return fit_fn


@pytest.mark.parametrize("margin, worth", [(1.0, False), (3.0, True)])
def test_a_significant_effect_must_be_worth_its_parameters(margin, worth):
    """Six free gains with ``2 dJ = 6 ln n + margin``: significant (p ~ 1e-5) either
    way; worth it only above positive evidence, a Schwarz gain of 2."""
    stat = 6 * LN_N + margin
    c = try_effect(None, BASE_FIT, "hub-velocity-coupling", (0.2, 1.6),
                   _fit_fn(lambda held: 100.0 - stat / 2))
    assert c.significant and c.schwarz_gain == pytest.approx(margin)
    assert ("not worth its 6 parameters: Schwarz gain 1.0 <= 2" in c.reason) is not worth
    assert DEFAULT_RULE.schwarz_min == 2.0


F_PART, G_PART = frozenset({"k0p", "kc", "ks"}), frozenset({"c1", "c2", "c3", "c4"})


def test_an_effect_is_tried_with_each_part_alone_and_the_best_schwarz_kept():
    """The nonlinear truth at 256 Hz, seed 7: all seven Glauert gains lose 2.1,
    ``F`` alone gains 10.4, ``G`` alone loses 14.3 (``bench/README.md``)."""
    gains = {frozenset(): -2.1, G_PART: 10.4, F_PART: -14.3}
    dofs = {frozenset(): 7, G_PART: 3, F_PART: 4}
    costs = {k: 100.0 - (g + dofs[k] * LN_N) / 2 for k, g in gains.items()}
    c = try_effect(None, BASE_FIT, "glauert", (0.2, 1.6), _fit_fn(costs.__getitem__))
    assert c.held == ("c1", "c2", "c3", "c4") and c.dof == 3
    assert c.schwarz_gain == pytest.approx(10.4)
    assert "not worth their parameters beside the effect's other part" in c.reason


def test_the_whole_effect_is_kept_when_it_is_worth_more_than_a_part():
    gains = {frozenset(): 30.0, G_PART: 10.4, F_PART: -14.3}
    dofs = {frozenset(): 7, G_PART: 3, F_PART: 4}
    costs = {k: 100.0 - (g + dofs[k] * LN_N) / 2 for k, g in gains.items()}
    c = try_effect(None, BASE_FIT, "glauert", (0.2, 1.6), _fit_fn(costs.__getitem__))
    assert c.held == () and c.dof == 7 and c.schwarz_gain == pytest.approx(30.0)
