"""The noise floor of the diagnosis under white and coloured sensor noise (issue #9).

The floor above the band is right for white noise and far too low for noise
louder in the band (a low-pass in the data system); the local polynomial method
(:mod:`inflowsim.diagnose.lpm`) estimates the in-band noise from the record
alone, and the diagnosis reports a channel whose noise is coloured.  Checked against synthetic spectra of known noise (an independent route:
numpy's generator, a smooth frequency response and a transient written here) and
against the records' own expected noise spectrum (``noise_psd``).
"""
import numpy as np
import pytest

from conftest import TWO_AXES
from inflowsim.diagnose.failures import residual_analysis, spectrum_failures
from inflowsim.diagnose.rule import DEFAULT_RULE
from inflowsim.diagnose.lpm import in_band_noise, local_polynomial_noise
from inflowsim.identify import DEFAULT_BAND, identify
from inflowsim.model.build import build_model
from inflowsim.flighttest.virtual import VirtualTest, noise_psd, virtual_record


def test_local_polynomial_noise_is_unbiased_whatever_the_response():
    """Two inputs through a resonant response, a transient and complex noise of
    known power per bin: the estimates average to that power (the response and
    transient do not leak in), for each of 40 seeds."""
    nf = 400
    f = np.linspace(0.1, 10.0, nf)
    H = np.column_stack([3 / (1 + 0.4j * f - (f / 4) ** 2), 1 / (1 + 1j * f / 2)])
    means = []
    for seed in range(40):
        rng = np.random.default_rng(seed)
        U = rng.normal(size=(nf, 2)) + 1j * rng.normal(size=(nf, 2))
        transient = 0.5 / (1 + 1j * f)
        power = 0.01 * (1 + f / 10)               # coloured: doubles over the range
        noise = np.sqrt(power / 2) * (rng.normal(size=nf) + 1j * rng.normal(size=nf))
        Z = (np.sum(H * U, axis=1) + transient + noise)[:, None]
        est = local_polynomial_noise(Z, U)[:, 0]
        ok = np.isfinite(est)
        means.append(np.mean(est[ok] / power[ok]))
    # each seed's mean rests on the ~380 bins' noise (overlapping windows share
    # it): scatter ~5 %; over the 40 seeds ~0.8 %
    assert np.all(np.abs(np.array(means) - 1) < 0.2), means
    assert abs(np.mean(means) - 1) < 0.025, np.mean(means)


def _fitted_analysis(colour, noise, rate=64):
    rec = virtual_record(VirtualTest(structure="glauert", dt=1 / rate, seed=1,
                                     manoeuvres=TWO_AXES, noise_flap=noise,
                                     noise_color_hz=colour))
    fit = identify(rec, "glauert")
    m = build_model(fit.structure, fit.parameters, rec.constants)
    return rec, m, residual_analysis(rec, m, fit=fit.data[0])


def _coloured_reports(ra):
    return [f for f in spectrum_failures(ra)
            if f.kind == "coloured-noise" and "in_band_over_floor" in f.detail]


@pytest.mark.parametrize("rate", [64, 256])
def test_white_noise_is_not_reported_coloured(rate):
    rec, m, ra = _fitted_analysis(None, 1e-4, rate)
    assert len(ra.in_band_over_floor) == 3
    assert all(k < DEFAULT_RULE.coloured for k in ra.in_band_over_floor)
    assert not _coloured_reports(ra)
    expected = len(rec) * noise_psd(1e-4, rec.dt, ra.f_hz)
    assert np.allclose(ra.floor.mean(axis=1) / expected.mean(), 1, atol=0.3)


@pytest.mark.parametrize("rate", [64, 256])
def test_coloured_noise_is_measured_in_the_band_and_reported(rate):
    """2 Hz first-order low-pass noise: 6-40 times the white level in the band and
    far less above it, so the floor above the band is about 46 (64 Hz) and 540
    (256 Hz) times below the noise in the band.  The in-band estimate is within
    35 % of the truth in each channel, and each channel is reported coloured."""
    rec, m, ra = _fitted_analysis(2.0, 1e-4, rate)
    expected = len(rec) * noise_psd(1e-4, rec.dt, ra.f_hz, 2.0)
    inside = in_band_noise(rec, m.inputs, DEFAULT_BAND, None, ra.f_hz)
    ratio = inside.mean(axis=1) / expected.mean()
    assert np.all(np.abs(ratio - 1) < 0.35), ratio
    assert all(k > DEFAULT_RULE.coloured for k in ra.in_band_over_floor)
    msgs = [f.message for f in _coloured_reports(ra)]
    assert [t[:7] for t in msgs] == ["beta0: ", "beta1c:", "beta1s:"]
    assert "coloured" in msgs[0] and "overstate the model error" in msgs[0]
