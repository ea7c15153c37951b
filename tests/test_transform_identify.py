"""Transforms and the exact sampled-data frequency model behind identification."""
import numpy as np
import pytest

from inflowsim import PUMA, build_model, preset_parameters
from inflowsim.discrete import lifted_replay, zoh
from inflowsim.errors import InputError, RecordError
from inflowsim.identify import record_spectra, snap_band
from inflowsim.identify.freqmodel import flap_response
from inflowsim.identify.transform import Spectra, dft
from inflowsim.record import find_trim
from inflowsim.simulator import Simulator
from inflowsim.virtual import VirtualTest, virtual_record


def test_band_snaps_to_the_paper_grid():
    k, band = snap_band(2660, 0.01, (0.2256, 1.58))
    assert k[0] == 6 and k[-1] == 42
    assert band == pytest.approx((6 / 26.6, 42 / 26.6))
    assert band[1] == pytest.approx(1.5789, abs=1e-4)


def test_band_with_too_few_bins_is_refused():
    with pytest.raises(InputError, match="fewer than 3"):
        snap_band(2660, 0.01, (0.30, 0.33))


@pytest.mark.parametrize("structure, delay, on_grid", [
    ("glauert", None, True), ("basic", None, False),
    ("glauert+time-delay", 0.0437, True),     # fractional delay: partial-step maps
    ("glauert+time-delay", 0.03, True),       # whole steps
    ("empirical+time-delay", 0.0437, False),  # chosen grid off the DFT bins
])
def test_frequency_model_is_exact_for_the_zoh_replay(structure, delay, on_grid):
    """Transform of the simulator's replay (random inputs and initial state) equals
    the frequency model with the true end-effect states, to rounding."""
    rng = np.random.default_rng(3)
    p = preset_parameters(structure)
    if delay is not None:
        p["delay"] = delay
    m = build_model(structure, p, PUMA)
    n, dt = 400, 0.01
    u = 0.01 * rng.standard_normal((n, m.b.shape[1]))
    x0 = 0.01 * rng.standard_normal(m.a.shape[0])
    y = Simulator(m, dt).replay(u, x0=x0)[:, :3]
    f = np.arange(3, 40) / (n * dt) if on_grid else np.linspace(0.2, 3.1, 17)
    sp = Spectra("t", PUMA, dt, n, f, on_grid, m.inputs, dft(u, dt, f, on_grid),
                 dft(y, dt, f, on_grid), u, y, {}, "")
    y_u, y_nu, q = flap_response(m, sp)
    phi, gam = zoh(m.a, m.b, dt)
    xs = lifted_replay(phi, gam, np.vstack([u, np.zeros((1, u.shape[1]))]), x0)
    pred = y_u + y_nu @ np.concatenate([x0, xs[n - q]])
    assert np.max(np.abs(sp.Z)) > 1e-3
    np.testing.assert_allclose(pred, sp.Z, atol=1e-12 * np.max(np.abs(sp.Z)))


def test_continuous_response_is_not_exact_for_sampled_data():
    """Why the default model is the sampled-data one: the continuous H(jw) misses
    the half-sample hold delay, an error far above the 1e-6 recovery target."""
    m = build_model("glauert", preset_parameters("glauert"), PUMA)
    f = np.array([1.0])
    z = np.exp(2j * np.pi * f * 0.01)
    phi, gam = zoh(m.a, m.b, 0.01)
    hd = m.c[:3] @ np.linalg.solve(z[0] * np.eye(6) - phi, gam)
    hc = m.frequency_response(f)[:3, :, 0]
    assert np.max(np.abs(hd - hc)) / np.max(np.abs(hc)) > 1e-3


def test_spectra_are_of_perturbations_about_trim():
    rec = virtual_record(VirtualTest(noise_flap=0.0))
    sp = record_spectra(rec, ("theta1s", "mux"), (0.2256, 1.58))
    trim = find_trim(rec)
    assert sp.f_hz[0] == pytest.approx(6 / 26.6)
    x = np.fft.rfft(rec["beta1c"] - trim.values["beta1c"])[6:43]
    np.testing.assert_allclose(sp.Z[:, 1], x, rtol=1e-12)
    assert "before the first control movement" in sp.trim_method


def test_band_beyond_nyquist_or_record_is_refused():
    rec = virtual_record(VirtualTest(noise_flap=0.0))
    with pytest.raises(RecordError, match="Nyquist"):
        record_spectra(rec, ("theta1s",), (0.3, 80.0))
    with pytest.raises(RecordError, match="too short"):
        record_spectra(rec, ("theta1s",), (0.001, 1.0))
