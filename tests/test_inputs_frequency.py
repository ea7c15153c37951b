"""Sweeps and multisines (issue #25): the shapes, and ``flighttest --input sweep |
multisine``."""
import json

import numpy as np
import pytest

from inflowsim.data.inputs import (fade, interleaved_harmonics, log_sweep, multisine,
                                   peak_factor, schroeder_phases)
from inflowsim.flighttest.virtual import Manoeuvre, pilot_controls

DT = 0.01


def test_log_sweep_spans_its_range_and_fades():
    t = np.arange(0, 40, DT)
    x = log_sweep(t, 2.0, 30.0, 0.2, 4.0, 0.02, fade_s=1.5)
    assert np.all(x[t < 2.0] == 0) and np.all(x[t > 32.0] == 0)
    assert np.max(np.abs(x)) == pytest.approx(0.02, rel=1e-3)
    # smooth start and end: no jump at either end, the envelope grows from 0
    assert np.max(np.abs(np.diff(x[(t > 1.9) & (t < 2.1)]))) < 0.02 * 0.01
    assert np.max(np.abs(x[(t > 31.9) & (t < 32.1)])) < 0.02 * 0.01
    # instantaneous frequency from the zero crossings: f1 (f2/f1)^(tau/T)
    s = np.flatnonzero(np.diff(np.signbit(x[(t > 4) & (t < 30)])))
    tz = t[(t > 4) & (t < 30)][s]
    f_inst = 0.5 / np.diff(tz)
    tau = 0.5 * (tz[1:] + tz[:-1]) - 2.0
    np.testing.assert_allclose(f_inst, 0.2 * 20 ** (tau / 30), rtol=0.05)
    # power in range: 98 % of the spectrum between f1/1.5 and 1.5 f2
    spec = np.abs(np.fft.rfft(x)) ** 2
    f = np.fft.rfftfreq(t.size, DT)
    assert spec[(f > 0.2 / 1.5) & (f < 4 * 1.5)].sum() > 0.98 * spec.sum()


def test_fade_envelope():
    t = np.linspace(-1, 11, 1201)
    e = fade(t, 0.0, 10.0, 2.0)
    assert e[t < 0].max() == 0 and e[t > 10].max() == 0
    assert np.all(e[(t >= 2) & (t <= 8)] == 1)
    assert np.all(np.diff(e[(t >= 0) & (t <= 2)]) >= 0)
    assert np.max(np.abs(np.diff(e))) < 0.02           # no step anywhere


def test_multisine_channels_orthogonal_low_peak_factor_in_range():
    length, k1, k2 = 20.0, 3, 60
    hs = interleaved_harmonics(3, k1, k2)
    assert sorted(k for h in hs for k in h) == list(range(k1, k2 + 1))
    assert all(set(a).isdisjoint(b) for i, a in enumerate(hs) for b in hs[i + 1:])
    t = np.arange(0, 30, DT)
    xs = [multisine(t, 2.0, length, 1 / length, h, 0.01, fade_s=0.0) for h in hs]
    steady = (t >= 2.0) & (t < 22.0)
    for i in range(3):
        x = xs[i]
        assert np.max(np.abs(x)) == pytest.approx(0.01, rel=1e-3)
        assert peak_factor(x[steady]) < 2.0            # against sqrt(2 x 19) = 6.2 in phase
        # whole periods: the channels are orthogonal to rounding
        for j in range(i + 1, 3):
            assert abs(np.dot(x[steady], xs[j][steady])) < 1e-9 * np.dot(x[steady], x[steady])
        spec = np.abs(np.fft.rfft(x[steady])) ** 2
        lines = np.flatnonzero(spec > 1e-9 * spec.max())
        assert set(lines) == set(hs[i])                 # its own harmonics, nothing else
    zero = sum(np.cos(2 * np.pi * k * t[steady] / length) for k in hs[0])
    assert peak_factor(zero) > 2.5 * peak_factor(xs[0][steady])
    # with fades still nearly orthogonal
    xf = [multisine(t, 2.0, length, 1 / length, h, 0.01, fade_s=1.0) for h in hs]
    c = np.dot(xf[0], xf[1]) / np.sqrt(np.dot(xf[0], xf[0]) * np.dot(xf[1], xf[1]))
    assert abs(c) < 0.05


def test_schroeder_phases_of_unequal_powers():
    p = np.array([1.0, 4.0, 1.0, 0.25, 2.0])
    ph = schroeder_phases(p)
    q = p / p.sum()
    assert ph[0] == 0 and ph[2] == pytest.approx(-2 * np.pi * (2 * q[0] + q[1]))
    with pytest.raises(ValueError):
        interleaved_harmonics(3, 5, 6)


def test_manoeuvre_signal_vector_and_scalar_agree():
    hs = interleaved_harmonics(2, 2, 30)
    ms = (Manoeuvre(channel="theta1c", shape="multisine", length=10.0, harmonics=hs[0]),
          Manoeuvre(channel="theta0", shape="multisine", length=10.0, harmonics=hs[1],
                    weights=tuple(np.linspace(1, 2, len(hs[1])))),
          Manoeuvre(shape="sweep", length=8.0, f_range=(0.3, 3.0)))
    t = np.linspace(0, 14, 397)
    u = pilot_controls(t, ms)
    for k, tk in enumerate(t):
        np.testing.assert_allclose(pilot_controls(tk, ms)[0], u[k], atol=1e-15)


def test_flighttest_sweep_and_multisine(tmp_path, capsys):
    from inflowsim.cli import main
    from inflowsim.data.record import find_trim, read_record
    out = tmp_path / "ms.csv"
    assert main(["flighttest", "--truth", "linear", "--input", "multisine", "--channels",
                 "theta1c", "theta1s", "--sweep-range", "0.3", "2", "--duration", "9",
                 "--start", "1", "--sweep-duration", "7", "--out", str(out), "--json"]) == 0
    truth = json.loads(capsys.readouterr().out)
    man = truth["manoeuvres"]
    assert [m["channel"] for m in man] == ["theta1c", "theta1s"]
    assert [m["harmonics"][0] for m in man] == [3, 4] and man[0]["harmonics"][-1] <= 14
    rec = read_record(out)
    trim = find_trim(rec)
    assert trim.t_movement == pytest.approx(1.0, abs=0.3)
    assert np.ptp(rec["theta0"]) == 0 and np.ptp(rec["theta1c"]) > 0
    assert "multisine" in rec.meta["description"]
    out2 = tmp_path / "sw.csv"
    assert main(["flighttest", "--truth", "linear", "--input", "sweep", "--duration", "8",
                 "--sweep-range", "0.5", "3", "--out", str(out2)]) == 0
    assert np.max(np.abs(read_record(out2)["theta1s"] + 0.05)) == pytest.approx(
        np.radians(1), rel=0.01)
    capsys.readouterr()
    for bad in (["--input", "sweep", "--sweep-range", "3", "1"],
                ["--input", "sweep", "--sweep-range", "0.01", "1"],
                ["--input", "multisine", "--sweep-range", "1", "1.2"],
                ["--input", "doublet", "--channels", "theta0"],
                ["--input", "sweep", "--sweep-duration", "100"]):
        assert main(["flighttest", "--truth", "linear", "--duration", "8", "--out",
                     str(tmp_path / "x.csv"), *bad]) == 2
        assert capsys.readouterr().err.count("\n") == 1
