"""Where the package keeps a hand version of what a library does, it computes what
the library does (issue #39): the coloured sensor noise is ``scipy.signal.lfilter``,
the log sweep ``scipy.signal.chirp``, the spectral matrices ``scipy.signal.csd``
on the FFT bins.  (The hand versions stay because importing scipy.signal costs
seconds on paths that load nothing else of it; see the comments beside them.)"""
import numpy as np
import pytest

scipy_signal = pytest.importorskip("scipy.signal")


def test_coloured_noise_is_lfilter():
    from inflowsim.flighttest.virtual import sensor_noise
    n, sigma, dt, fc = 5000, 1e-4, 0.01, 2.0
    got = sensor_noise(np.random.default_rng(5), n, sigma, dt, fc)
    w = np.random.default_rng(5).standard_normal(n)
    rho = float(np.exp(-2 * np.pi * fc * dt))
    e = np.empty(n)
    e[0] = w[0]
    e[1:], _ = scipy_signal.lfilter([np.sqrt(1 - rho * rho)], [1.0, -rho], w[1:],
                                    zi=[rho * w[0]])
    assert np.array_equal(got, sigma * e)              # the same doubles


def test_log_sweep_is_chirp():
    from inflowsim.data.inputs import fade, log_sweep
    t = np.arange(0.0, 30.0, 0.01)
    got = log_sweep(t, 2.0, 25.0, 0.15, 3.0, 0.01, 1.0)
    tau = np.clip(t - 2.0, 0.0, 25.0)
    want = 0.01 * fade(t, 2.0, 25.0, 1.0) * scipy_signal.chirp(
        tau, 0.15, 25.0, 3.0, method="logarithmic", phi=-90)
    assert np.max(np.abs(got - want)) < 1e-14 * 0.01 * 100


def test_spectral_matrices_are_csd_on_the_bins():
    from inflowsim.identify.frf import _spectra
    x = np.random.default_rng(0).standard_normal((3000, 3))
    dt, length, overlap = 0.01, 512, 0.5
    hop = int(round(length * (1 - overlap)))
    f = np.arange(1, length // 2) / (length * dt)
    G, _ = _spectra([x], dt, length, overlap, f)
    for i in range(3):
        for j in range(3):
            _, P = scipy_signal.csd(x[:, i], x[:, j], fs=1 / dt, window="hann",
                                    nperseg=length, noverlap=length - hop, detrend=False)
            P = P[1:length // 2]
            assert np.max(np.abs(G[:, i, j] - P)) < 1e-12 * np.max(np.abs(P))
