"""Every effect of the catalogue, automatically: a new effect module is tested by
adding it (issue #12).  Facts declared by the effect itself (parameters with unit,
allowed and plausible range, description; theory and neutral values), nesting
(its neutral values reproduce the structure without it), and a stable model with
its theory values.

User effects are tested the same way (issue #24): the worked examples under
``examples/effects/`` always, and any file named in the environment variable
``INFLOWSIM_EFFECT_FILES`` (paths separated by ``os.pathsep``), each registered for
its own tests only::

    INFLOWSIM_EFFECT_FILES=my_effect.py python -m pytest tests/test_effect_catalogue.py
"""
import os
from pathlib import Path

import numpy as np
import pytest

from inflowsim import PUMA, Structure, build_model, theory_parameters
from inflowsim.model.effects import CATALOGUE
from inflowsim.model.effects.user import USER_EFFECTS, load_effect_file, unregister
from inflowsim.model.params import SPECS
from inflowsim.flighttest.virtual import PUMA_TRIM

K = PUMA.with_trim(PUMA_TRIM)
F = np.linspace(0.2, 1.6, 9)
USER_FILES = sorted(str(p) for p in (Path(__file__).resolve().parents[1] / "examples" /
                                      "effects").glob("*.py")) + [
    f for f in os.environ.get("INFLOWSIM_EFFECT_FILES", "").split(os.pathsep) if f]


@pytest.fixture(params=list(CATALOGUE) + [f"file:{f}" for f in USER_FILES])
def name(request):
    """A catalogue effect's name, or a user effect file's effect registered for the
    test (and removed after it, so no other test sees it)."""
    if not request.param.startswith("file:"):
        yield request.param
        return
    before = set(USER_EFFECTS)
    (eff,) = load_effect_file(request.param[5:])
    try:
        yield eff.name
    finally:
        for n in set(USER_EFFECTS) - before:
            unregister(n)


def base_for(effect):
    """The smallest preset the effect may join."""
    for base in ("basic", "glauert", "empirical"):
        try:
            Structure.parse(base).with_effect(effect)
            return base
        except Exception:
            continue
    raise AssertionError(effect)


def test_effect_declares_its_facts(name):
    eff = CATALOGUE[name]
    assert eff.physics.endswith(".") and eff.paper
    assert {s.name for s in eff.specs} == set(eff.parameters)
    theory = eff.theory(K)
    neutral = eff.neutral_values(K)
    assert set(theory) == set(eff.parameters) == set(neutral)
    for s in eff.specs:
        assert SPECS[s.name] is s and s.unit and s.description
        assert s.check(theory[s.name]) == theory[s.name]
        assert s.check(neutral[s.name]) == neutral[s.name]
        rng = s.plausible_range(K.omega)
        assert rng is not None and rng[2]
        lo, hi, _ = rng
        assert lo <= theory[s.name] <= hi


def test_neutral_values_nest_the_structure_without_it(name):
    """The start of a candidate refit reproduces the base fit: at its neutral
    values the effect changes nothing (flap-inertia: its first-order limit)."""
    eff = CATALOGUE[name]
    base = Structure.parse(base_for(name))
    with_ = base.with_effect(name)
    p = theory_parameters(with_, K)
    p.update(eff.neutral_values(K))
    p0 = theory_parameters(base, K)
    p0.update({n: v for n, v in p.items() if n in base.parameters})
    if eff.removes:                 # tau0 = tau_cs = tau: the superseded parameter
        for n in eff.parameters:
            p[n] = p0[eff.removes[0]]
    m1 = build_model(with_, p, K)
    m0 = build_model(base, p0, K)
    h1 = m1.frequency_response(F)[:3, : m0.b.shape[1]]
    h0 = m0.frequency_response(F)[:3]
    tol = 1e-4 if eff.boundary else 1e-12
    assert np.abs(h1 - h0).max() <= tol * np.abs(h0).max()
    if m1.b.shape[1] > m0.b.shape[1]:          # the in-plane inputs it adds do nothing
        extra = m1.frequency_response(F)[:3, m0.b.shape[1]:]
        assert np.abs(extra).max() <= tol * np.abs(h0).max() or name in (
            "delay-mux", "delay-muy")


def test_theory_values_give_a_stable_model(name):
    s = Structure.parse(base_for(name)).with_effect(name)
    m = build_model(s, theory_parameters(s, K), K)
    assert m.is_stable() and np.all(np.isfinite(m.a))
