"""The input-correlated excess (:mod:`inflowsim.diagnose.excess`): the measure of
the candidate tests under coloured noise.  Checked on synthetic residuals made
here (numpy's generator): its mean for noise alone is the F law's, whatever the
noise level, and a smooth response error raises it."""
from types import SimpleNamespace

import numpy as np

from inflowsim.diagnose.excess import (expected_for_noise, input_excess, noise_levels,
                                       project, smooth_input_basis)


def _analysis(rng, nf=37, colour=True, error_gain=0.0):
    f = np.linspace(0.2256, 1.58, nf)
    # two doublets (1 s a side) starting at 3 s and at 12 s
    doublet = (1 - np.exp(-2j * np.pi * f)) ** 2 / (2j * np.pi * f)
    U = np.column_stack([np.exp(-6j * np.pi * f) * doublet, np.exp(-24j * np.pi * f) * doublet])
    # coloured: a 2 Hz first-order low-pass, 1.6 times from the band's bottom to top
    level = 1e-6 / (1 + (f / 2) ** 2) if colour else np.full(nf, 1e-6)
    e = np.sqrt(level / 2) * (rng.normal(size=(3, nf)) + 1j * rng.normal(size=(3, nf)))
    dH = error_gain * np.array([[1.0, 0.3j], [0.5, 1.0], [0.2j, 0.7]])     # (3, 2)
    e = e + (U @ (dH * (1 + 0.3 * f.mean())).T).T * np.sqrt(1e-6)
    return SimpleNamespace(f_hz=f, U=U, error=e)


def test_noise_alone_gives_the_f_law_mean_white_or_low_pass():
    """(The F law assumes one level over the band; the low-pass here changes it
    1.6 times across the band, within the 5 % tolerance.)"""
    for colour in (False, True):
        vals = []
        for seed in range(300):
            ra = _analysis(np.random.default_rng(seed), colour=colour)
            Q = smooth_input_basis(ra)
            vals.append(input_excess(ra, Q, noise_levels(ra, Q)))
        expected = expected_for_noise(37, Q.shape[1])
        assert Q.shape[1] == 9                     # 3 polynomials x (1 + 2 inputs)
        # the mean of 300 draws, each with standard deviation ~6 (1000 draws: 6.3)
        assert abs(np.mean(vals) / expected - 1) < 0.05, (colour, np.mean(vals), expected)


def test_a_response_error_raises_it_and_its_removal_restores_it():
    rng = np.random.default_rng(7)
    ra = _analysis(rng, error_gain=6.0)
    Q = smooth_input_basis(ra)
    lv = noise_levels(ra, Q)
    with_error = input_excess(ra, Q, lv)
    assert with_error > 10 * expected_for_noise(37, Q.shape[1])
    clean = SimpleNamespace(f_hz=ra.f_hz, U=ra.U,
                            error=ra.error - project(ra.error, Q))
    assert input_excess(clean, Q, lv) < 1e-20
