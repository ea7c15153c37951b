"""Multiblade extraction as a flight-test system does it (inflowsim.physics.multiblade)."""
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from inflowsim.model.equations import rotation
from inflowsim.errors import InputError
from inflowsim.physics.multiblade import (blade_angles, blade_azimuths, multiblade,
                                  multiblade_rates, reactionless)

finite = st.floats(-0.2, 0.2)


@settings(max_examples=40, deadline=None)
@given(b0=finite, b1c=finite, b1s=finite, psi=st.floats(0, 20), nb=st.integers(3, 7))
def test_exact_on_pure_harmonics(b0, b1c, b1s, psi, nb):
    ang = blade_azimuths(psi, nb)
    blades = b0 + b1c * np.cos(ang) + b1s * np.sin(ang)
    np.testing.assert_allclose(multiblade(blades, psi), [b0, b1c, b1s], atol=1e-15)


@settings(max_examples=40, deadline=None)
@given(b1c=finite, b1s=finite, psi=st.floats(0, 20), bias=st.floats(-1, 1))
def test_azimuth_bias_rotates_the_cyclic_components(b1c, b1s, psi, bias):
    blades = blade_angles([0.05, b1c, b1s], psi, 4)
    m = multiblade(blades, psi + bias)                 # the recorded azimuth
    np.testing.assert_allclose(m[1:], rotation(bias) @ [b1c, b1s], atol=1e-15)
    assert m[0] == pytest.approx(0.05, abs=1e-15)


def test_reactionless_mode_does_not_leak():
    psi = np.linspace(0, 7, 50)
    diff = 0.03 * np.cos(3 * psi)[:, None] * (-1.0) ** np.arange(4)   # beta_d(t)
    base = blade_angles([0.1, -0.02, 0.01], psi, 4)
    np.testing.assert_allclose(multiblade(base + diff, psi),
                               np.tile([0.1, -0.02, 0.01], (50, 1)), atol=1e-15)
    np.testing.assert_allclose(reactionless(base + diff), 0.03 * np.cos(3 * psi),
                               atol=1e-15)
    # a 2/rev blade harmonic is invisible too (it lives in the reactionless mode)
    two = 0.02 * np.cos(2 * blade_azimuths(psi, 4))
    np.testing.assert_allclose(multiblade(two, psi), 0.0, atol=1e-15)
    # but a 3/rev harmonic aliases onto 1/rev for four blades: a real limitation
    three = 0.02 * np.cos(3 * blade_azimuths(psi, 4))
    assert np.max(np.abs(multiblade(three, psi)[:, 1])) > 0.01


def test_multiblade_rates_have_the_rotating_frame_terms():
    psi, h = 0.7, 1e-6
    mb = lambda p: np.array([0.1 + 0.2 * p, -0.03 + 0.1 * p, 0.02 - 0.05 * p])
    blades = lambda p: blade_angles(mb(p), p, 4)
    dblades = (blades(psi + h) - blades(psi - h)) / (2 * h)     # each blade's own rate
    np.testing.assert_allclose(multiblade_rates(mb(psi), dblades, psi),
                               [0.2, 0.1, -0.05], atol=1e-8)


def test_too_few_blades_is_refused():
    with pytest.raises(InputError, match="n_blades"):
        multiblade(np.zeros(2), 0.0)
