"""Input shapes and the built-in virtual Puma record generator."""
import numpy as np
import pytest

from inflowsim import PUMA, build_model, preset_parameters
from inflowsim.data.inputs import doublet, input_3211
from inflowsim.data.record import find_trim, model_inputs
from inflowsim.simulate.simulator import Simulator
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record


def test_doublet_and_3211_shapes():
    t = np.arange(0, 3, 0.01)
    d = doublet(t, 0.5, 0.4, 2.0)
    assert np.all(d[t < 0.5 - 1e-9] == 0) and np.all(d[(t >= 0.5) & (t < 0.9 - 1e-9)] == 2)
    assert np.all(d[(t >= 0.9 - 1e-9) & (t < 1.3 - 1e-9)] == -2) and np.all(d[t >= 1.3] == 0)
    assert np.sum(d) == pytest.approx(0.0)
    s = input_3211(t, 0.2, 0.3, 1.0)
    assert [np.sum(s == v) for v in (1.0, -1.0)] == [120, 90]    # 3+1 and 2+1 units of 30
    assert s[t.searchsorted(0.2)] == 1 and s[t.searchsorted(1.25)] == -1


def test_virtual_record_is_seeded_and_replays_its_truth():
    test = VirtualTest(duration=6.0, seed=11)
    a, b = virtual_record(test), virtual_record(test)
    np.testing.assert_array_equal(a["beta1c"], b["beta1c"])
    c = virtual_record(VirtualTest(duration=6.0, seed=12))
    assert not np.array_equal(a["beta1c"], c["beta1c"])
    # noise-free, held inputs: the measured flap is the ZOH replay of the model
    clean = virtual_record(VirtualTest(duration=6.0, noise_flap=0.0, hold="zoh"))
    assert clean.hold == "zoh" and a.hold == "continuous"
    m = build_model("glauert", preset_parameters("glauert", PUMA, "paper"), PUMA)
    trim = find_trim(clean)
    y = Simulator(m, clean.dt).replay(model_inputs(clean, m, trim))
    for i, ch in enumerate(("beta0", "beta1c", "beta1s")):
        np.testing.assert_allclose(clean[ch] - trim.values[ch], y[:, i], atol=1e-14)
    resid = a["beta1c"] - virtual_record(VirtualTest(duration=6.0, noise_flap=0.0))["beta1c"]
    assert np.std(resid) == pytest.approx(1e-4, rel=0.1)


def test_smooth_inputs():
    """The pilot's switches are Gaussian-smoothed steps: 10-90 % rise as asked,
    the same pulse areas as the sharp ones, a spectrum below 1e-12 of its
    peak beyond 40 Hz (nothing to alias at 64 Hz)."""
    t = np.arange(0, 8, 1e-3)
    sharp = doublet(t, 2.0, 0.4, 1.0)
    smooth = doublet(t, 2.0, 0.4, 1.0, rise=0.1)
    assert np.sum(smooth) == pytest.approx(np.sum(sharp), abs=1e-9)
    assert np.max(np.abs(smooth[t < 1.7])) < 1e-9 and np.max(smooth) == pytest.approx(1, rel=1e-6)
    i10, i90 = np.searchsorted(smooth[t < 2.2], [0.1, 0.9])
    assert t[i90] - t[i10] == pytest.approx(0.1, abs=2e-3)
    spec = np.abs(np.fft.rfft(input_3211(t, 1.0, 0.5, 1.0, rise=0.1)))
    f = np.fft.rfftfreq(t.size, 1e-3)
    assert spec[f > 40].max() < 1e-12 * spec.max()


def test_coloured_noise_has_its_spectrum():
    from inflowsim.flighttest.virtual import noise_psd, sensor_noise
    rng = np.random.default_rng(0)
    dt, n = 0.01, 2 ** 16
    e = sensor_noise(rng, n, 1e-4, dt, color_hz=2.0)
    assert np.std(e) == pytest.approx(1e-4, rel=0.05)
    p = np.abs(np.fft.rfft(e)) ** 2 / n
    f = np.fft.rfftfreq(n, dt)
    for band in ((0.2, 1.6), (10.0, 20.0)):
        sel = (f > band[0]) & (f < band[1])
        assert np.mean(p[sel]) == pytest.approx(np.mean(noise_psd(1e-4, dt, f[sel], 2.0)),
                                                rel=0.1)


def test_body_motion_excites_hub_inputs():
    rec = virtual_record(VirtualTest(duration=8.0, noise_flap=0.0,
                                     manoeuvres=(Manoeuvre(channel="theta1c"),)))
    for ch in ("p", "pdot", "muy"):
        assert np.ptp(rec[ch]) > 0
    assert np.ptp(rec["q"]) == 0            # decoupled body model: lateral input only
