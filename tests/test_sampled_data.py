"""Intersample behaviour (issue #9): identification is exact for the record's hold.

Continuous records come from the independent route of
:func:`inflowsim.flighttest.virtual.virtual_record`: body and rotor integrated together by
an adaptive ODE solver (DOP853, rtol 1e-12) with smooth pilot inputs, then
sampled, at 64 and 256 Hz; no sampled-data code is on that route.  Held records
come from the exact ZOH replay; linear-input records from scipy's ``lsim``.
The truths are moved away from every start value the estimator tries.
"""
from functools import lru_cache
from types import MappingProxyType

import numpy as np
import pytest
from scipy import signal

import inflowsim as ifs
from conftest import TWO_AXES
from inflowsim import PUMA, build_model, preset_parameters
from inflowsim.identify import identify
from inflowsim.data.record import FLAP_COLUMNS, INPUT_COLUMNS, Record
from inflowsim.simulate.sampled import HOLDS, gregory_weights, shift_taps
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record

THREE = TWO_AXES + (Manoeuvre(channel="theta0", t_start=18.0),)


def moved(structure, **extra):
    """Paper values moved by 7 % (no start of the estimator sits on them)."""
    p = {n: v * 1.07 for n, v in preset_parameters(structure, PUMA, "paper").items()}
    p.update(extra)
    return p


@lru_cache(maxsize=None)
def noise_free(structure, extra=(), rate=64, hold="continuous"):
    """``(record, truth)``: the noise-free record of ``moved(structure, **extra)``
    (``extra`` as sorted items), made once a session: records are frozen, and a
    continuous one is an adaptive ODE solve (the convention test reads the recovery
    test's glauert record)."""
    truth = moved(structure, **dict(extra))
    rec = virtual_record(VirtualTest(structure=structure, parameters=truth, dt=1 / rate,
                                     noise_flap=0.0, manoeuvres=THREE, hold=hold))
    return rec, MappingProxyType(truth)


def rel_error(fit, truth):
    return max(abs(fit.parameters[n] - v) / max(abs(v), 1e-3) for n, v in truth.items())


CASES = [
    ("glauert", {}),
    ("glauert+time-delay", {"delay": 0.0437}),
    ("empirical+time-delay", {"delay": -0.0213}),                 # a lead
    ("basic+delay-theta1s+delay-beta1c", {"delay_theta1s": 0.017, "delay_beta1c": -0.011}),
    ("basic+flap-inertia", {"flap_inertia": 1.0}),
    ("glauert+flap-inertia+second-harmonic-flap", {"flap_inertia": 1.0, "k_beta2": 1.3}),
]


@pytest.mark.parametrize("structure, extra, rate", [
    *((s, e, 64) for s, e in CASES), (*CASES[0], 256),
    *(pytest.param(s, e, 256, marks=pytest.mark.slow) for s, e in CASES[1:])])
def test_continuous_records_are_recovered_to_1e6(structure, extra, rate):
    rec, truth = noise_free(structure, tuple(sorted(extra.items())), rate, "continuous")
    assert rec.hold == "continuous" and "hold" in rec.meta
    fit = identify(rec, structure)
    assert fit.converged
    assert rel_error(fit, truth) < 1e-6, {n: fit.parameters[n] - v for n, v in truth.items()}


@pytest.mark.parametrize("structure, extra", CASES[:3])
def test_held_records_are_recovered_exactly(structure, extra):
    rec, truth = noise_free(structure, tuple(sorted(extra.items())), 64, "zoh")
    assert rec.hold == "zoh"
    fit = identify(rec, structure)
    assert rel_error(fit, truth) < 1e-9


@pytest.mark.parametrize("kind, wrong", [("continuous", "zoh"), ("continuous", "foh"),
                                         ("zoh", "continuous")])
def test_the_wrong_sampled_data_convention_fails(kind, wrong):
    """What the estimator assumes between samples matters far above 1e-6: the
    recovery tests above would fail with the wrong convention."""
    rec, truth = noise_free("glauert", (), 64, kind)
    assert rec.hold == kind
    assert rel_error(identify(rec, "glauert"), truth) < 1e-6
    assert rel_error(identify(rec, "glauert", hold=wrong), truth) > 1e-3


def test_linear_input_records_are_recovered_exactly():
    """A record of inputs linear between samples (scipy's lsim, interp=True) is
    exact for hold foh: the record says so in its metadata."""
    s = "glauert+time-delay"
    truth = moved(s, delay=0.026)         # 26 steps of the fine grid
    m = build_model(s, truth, PUMA.with_trim({}))
    dt, n = 1 / 50, 1330
    t = np.arange(n) * dt
    rng = np.random.default_rng(4)
    u = np.zeros((n, len(m.inputs)))
    for j in range(len(m.inputs)):       # band-rich inputs, quiet for 2 s
        w = signal.lfilter([0.05], [1, -0.95], rng.standard_normal(n))
        u[:, j] = np.where(t > 2.0, w, 0.0) * (0.01 if j < 4 else 0.001)
    sub = 20
    tf = np.arange((n - 1) * sub + 1) * dt / sub
    uf = np.column_stack([np.interp(tf, t, u[:, j]) for j in range(u.shape[1])])
    sys = signal.StateSpace(m.a, m.b, np.eye(m.a.shape[0]), np.zeros(m.b.shape))
    _, _, x = signal.lsim(sys, uf, tf, interp=True)
    k = int(round(truth["delay"] / (dt / sub)))
    xd = np.vstack([np.zeros((k, x.shape[1])), x])[: len(x)]
    y = xd[::sub] @ m.c[:3].T
    cols = {c: np.zeros(n) for c in INPUT_COLUMNS}
    cols.update({c: u[:, j] for j, c in enumerate(m.inputs)})
    cols.update({c: y[:, i] for i, c in enumerate(FLAP_COLUMNS)})
    meta = {"omega": PUMA.omega, "mu": PUMA.mu, "a0": PUMA.a0, "solidity": PUMA.solidity,
            "hold": "foh"}
    rec = Record.from_arrays(t, cols, meta, "lsim.csv")
    fit = identify(rec, s)
    assert rel_error(fit, truth) < 1e-8
    assert rel_error(identify(rec, s, hold="zoh"), truth) > 1e-3


@pytest.mark.parametrize("rate, hold", [(64, "continuous"), (256, "continuous"),
                                        (64, "zoh")])
def test_noisy_records_truth_within_three_sigma(rate, hold):
    s = "glauert+time-delay"
    truth = moved(s, delay=-0.012)
    rec = virtual_record(VirtualTest(structure=s, parameters=truth, dt=1 / rate,
                                     noise_flap=1e-4, seed=7, manoeuvres=THREE, hold=hold))
    fit = identify(rec, s)
    for n, v in truth.items():
        assert abs(fit.parameters[n] - v) <= 3 * fit.sigma[n], (n, fit.parameters[n], v)


def test_gregory_weights_integrate_polynomials_and_smooth_signals():
    for n in (12, 100, 1001):
        c = gregory_weights(n)
        x = np.linspace(0.0, 1.0, n)
        h = 1.0 / (n - 1)
        for k in range(6 if n > 12 else 3):
            assert h * np.sum(c * x ** k) == pytest.approx(1 / (k + 1), rel=1e-12)
    # a smooth non-periodic signal against its closed-form finite Fourier integral
    t = np.linspace(0.0, 3.0, 301)
    w = 2.0
    g = np.exp(-0.5 * t) * np.exp(-1j * w * t)
    exact = (1 - np.exp(-(0.5 + 1j * w) * 3.0)) / (0.5 + 1j * w)
    h = t[1]
    assert abs(h * np.sum(gregory_weights(301) * g) - exact) < 1e-11
    assert abs(h * np.sum(g) - exact) > 1e-3          # the plain DFT sum is not


def test_shift_taps_compose_like_time():
    """Two half-sample shifts make one sample: taps of d = dt are the taps of
    d = 0 moved by one sample, for every hold."""
    m = build_model("glauert", preset_parameters("glauert"), PUMA)
    dt = 0.01
    for hold in HOLDS:
        phi0, t0 = shift_taps(m.a, m.b, dt, hold)
        phi1, t1 = shift_taps(m.a, m.b, dt, hold, np.full(m.b.shape[1], dt))
        np.testing.assert_allclose(phi0, phi1, rtol=1e-13, atol=1e-15)
        assert sorted(t1) == sorted(o - 1 for o in t0)
        for o, g in t0.items():
            np.testing.assert_allclose(t1[o - 1], g, rtol=1e-11, atol=1e-16)


def test_record_hold_metadata_and_override(tmp_path):
    from inflowsim.errors import RecordError
    from inflowsim.data.record import read_record, write_record
    rec = virtual_record(VirtualTest(duration=4.0, hold="zoh"))
    p = write_record(rec, tmp_path / "r.csv")
    assert "# hold: zoh" in p.read_text() and read_record(p).hold == "zoh"
    bare = rec.with_meta(hold="continuous")
    assert bare.hold == "continuous"
    old = Record.from_arrays(rec.t, rec.channels, {k: v for k, v in rec.meta.items()
                                                   if k != "hold"})
    assert old.hold == "continuous"                  # measured data by default
    assert old.hold_or("foh") == "foh"
    with pytest.raises(RecordError, match="hold"):
        Record.from_arrays(rec.t, rec.channels, dict(rec.meta, hold="cubic"))
    with pytest.raises(RecordError, match="choose continuous, zoh, foh"):
        old.hold_or("sinc")


def test_simulator_refuses_what_it_cannot_step_causally():
    m = build_model("basic+time-delay", preset_parameters("basic") | {"delay": -0.01}, PUMA)
    from inflowsim.simulate.simulator import Simulator
    with pytest.raises(ifs.InputError, match="lead"):
        Simulator(m, 0.01)
    m2 = build_model("basic+delay-theta0", preset_parameters("basic") | {"delay_theta0": 0.02},
                     PUMA)
    with pytest.raises(ifs.InputError, match="time shifts on its inputs"):
        Simulator(m2, 0.01)
