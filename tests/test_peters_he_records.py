"""The diagnosis on records with Peters-He inflow hidden, made without the library's
model: the direct construction of the whole Peters-He rotor in forward flight
(``tests/peters_he_direct.py``: its own shape functions, gain by quadrature and the
skewed wake's couplings at ``X = tan(chi/2)`` of its own trim inflow, pressure and flap
integrals) integrated by scipy's DOP853 with a smooth 3-2-1-1 and doublets, or log
sweeps on one or both cyclics, body rates through a first-order filter of the cyclic,
sampled at 64 to 256 Hz, or every input held over each sample (``# hold: zoh``),
white or coloured noise drawn here, written as a CSV record and read back; the Puma,
or the hingeless rotor of ``bench/detection.py``.

``peters-he-6`` is offered by default (the catalogue's pool), and the
diagnosis names it first, no ``time-delay`` (a lead) instead, the ladder ends
``explained`` and ``k_ph`` is within 3 sigma of 1.  On a record of the three-state
model (the same route with the Gram gain, the present model's) nothing is named.
The study of every kind, five seeds each: ``bench/peters_he_detection.py``
(``bench/rotor-physics.md``)."""
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy import signal
from scipy.integrate import solve_ivp

from inflowsim.data.record import read_record
from inflowsim.diagnose import diagnose
from inflowsim.diagnose.rule import offered_effects
from inflowsim.diagnose.search import ladder
from inflowsim.flighttest.virtual import VirtualTest, virtual_record

sys.path.insert(0, str(Path(__file__).parent))
import peters_he_direct as direct  # noqa: E402

DURATION = 30.0
NOISE = 1e-4                          # [rad], standard deviation per sample
T_BODY, K_Q, K_P = 0.6, -1.5, 1.2     # body-rate filter [s], [1/s per rad]
LB2, NB = 1.06, 0.95                  # the rotor's flap frequency and inertia number
BASE = "basic+separate-time-constants"


def _switch(t, t0, rise=0.12):
    x = np.clip((t - t0) / rise, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(np.pi * x)


def _log_sweep(t, t0, length, f0=0.15, f1=3.0, fade=1.0):
    """A logarithmic sweep from ``f0`` to ``f1`` [Hz] over ``length`` [s] from ``t0``,
    unit peak, faded in and out over ``fade`` [s] by raised-cosine switches (written
    here: not the library's ``log_sweep``)."""
    tau = np.clip(t - t0, 0.0, length)
    r = np.log(f1 / f0)
    ph = 2 * np.pi * f0 * length / r * np.expm1(tau * r / length)
    return np.sin(ph) * _switch(t, t0, fade) * (1 - _switch(t, t0 + length - fade, fade))


def _pilot(t, amp_deg, single_axis, sweep=False):
    """``(theta1s, theta1c, theta0)`` perturbations [rad].  Doublets: a 3-2-1-1 on
    ``theta1s`` from 3 s, a doublet on ``theta1c`` from 15 s (or none:
    ``single_axis``), a collective doublet from 22 s.  ``sweep``: 0.15-3 Hz log
    sweeps, on ``theta1s`` 2-14.5 s then ``theta1c`` 15.5-28 s, or (``single_axis``)
    on ``theta1s`` alone 2-28 s; nothing on the collective."""
    a = np.radians(amp_deg)
    if sweep:
        if single_axis:
            return a * _log_sweep(t, 2.0, 26.0), 0 * t, 0 * t
        return a * _log_sweep(t, 2.0, 12.5), a * _log_sweep(t, 15.5, 12.5), 0 * t
    th1s = a * (_switch(t, 3) - 2 * _switch(t, 4.5) + 2 * _switch(t, 5.5)
                - 2 * _switch(t, 6) + _switch(t, 6.5))
    th1c = 0 * t if single_axis else a * (_switch(t, 15) - 2 * _switch(t, 16)
                                          + _switch(t, 17))
    th0 = 0.4 * a * (_switch(t, 22) - 2 * _switch(t, 23) + _switch(t, 24))
    return th1s, th1c, th0


def _held(a, b, t, rate, inputs):
    """The truth with every input held over each sample (a digital controller's
    record, ``# hold: zoh``): the pilot sampled at ``t`` and held, the body rates
    through their first-order filter of the held cyclic (its exact step), sampled and
    held with their derivatives; the rotor ``x' = a x + b u_k`` on ``[t_k, t_k+1)``.
    Its flow over one sample (``Phi``, ``Gamma``: the state's and each held input's,
    integrated by DOP853 over ``1/rate`` from the identity and from zero) carries the
    state from sample to sample.  Returns ``(x at t, the inputs' dict)``."""
    dt = 1.0 / rate
    n, m = b.shape
    decay = np.exp(-dt / T_BODY)
    pilot, _ = inputs(t, 0 * t, 0 * t)
    q, pp = np.zeros(len(t)), np.zeros(len(t))
    for k in range(len(t) - 1):
        q[k + 1] = decay * q[k] + (1 - decay) * K_Q * pilot["theta1s"][k]
        pp[k + 1] = decay * pp[k] + (1 - decay) * K_P * pilot["theta1c"][k]
    u, uv = inputs(t, q, pp)
    forcing = np.hstack([np.zeros((n, n)), b])

    def rhs(_, z):                    # d/dt [X, G] = a [X, G] + [0, b]
        return (a @ z.reshape(n, n + m) + forcing).ravel()

    z0 = np.hstack([np.eye(n), np.zeros((n, m))]).ravel()
    end = solve_ivp(rhs, (0.0, dt), z0, method="DOP853", rtol=1e-12,
                    atol=1e-15).y[:, -1].reshape(n, n + m)
    phi, gam = end[:, :n], end[:, n:]
    x = np.zeros((len(t), n))
    for k in range(len(t) - 1):
        x[k + 1] = phi @ x[k] + gam @ uv[:, k]
    return x, u


def make_record(path, power, rate, colour_hz, seed, mu=None, single_axis=False,
                amp_deg=1.0, constants=None, lb2=LB2, nb=NB, sweep=False,
                hold="continuous"):
    """A CSV record of the Peters-He rotor with ``power`` (1: the three-state model,
    Pitt-Peters' axial gain), read back.  ``amp_deg``: the pilot's cyclic amplitude
    [deg].  The Peters-He rotor's gain is the skewed wake's at the record's trim (the
    written trim totals, ``muz = 0``).  ``constants`` (default the Puma's), ``lb2``,
    ``nb``: another rotor (its hub written in the record's header).  ``sweep``: log
    sweeps instead of doublets (:func:`_pilot`).  ``hold``: ``continuous`` (smooth
    inputs, the whole record integrated by DOP853, then sampled) or ``zoh`` (every
    input held over each sample, :func:`_held`; the header says ``# hold: zoh``)."""
    if hold not in ("continuous", "zoh"):
        raise ValueError(f"hold {hold!r}: continuous or zoh")
    k = virtual_record(VirtualTest(duration=1.0, constants=constants)
                       if constants is not None else VirtualTest(duration=1.0)).constants
    mu = k.mu if mu is None else mu
    tr = k.trim
    if power == 1:
        gain = np.diag([2 / 3, 8 / 15, 8 / 15])         # the Gram gain: local momentum
    else:
        x = direct.trim_skew(mu, k.a0s, mu, [tr[c] for c in ("theta0", "theta1c", "theta1s")],
                             [tr[c] for c in ("beta0", "beta1c", "beta1s")], 0.0)
        gain = direct.gain(power, x)
    desc = direct.model(power, mu, nb, lb2, k.a0s, mu, k.omega, gain=gain)
    a, b, c = direct.state_space(desc, k.omega)
    n = a.shape[0]
    names = ("theta0", "theta1c", "theta1s", "muz", "q", "p", "qdot", "pdot")

    def inputs(t, q, pp):
        th1s, th1c, th0 = _pilot(t, amp_deg, single_axis, sweep)
        qd, pd = (K_Q * th1s - q) / T_BODY, (K_P * th1c - pp) / T_BODY
        u = {"theta0": th0, "theta1s": th1s, "theta1c": th1c, "q": q, "p": pp,
             "qdot": qd, "pdot": pd}
        return u, np.array([u.get(x, 0.0 * t) for x in names])

    def rhs(t, z):
        u, uv = inputs(t, z[n], z[n + 1])
        return np.concatenate([a @ z[:n] + b @ uv, [u["qdot"], u["pdot"]]])

    t = np.arange(int(DURATION * rate)) / rate
    if hold == "zoh":
        x, u = _held(a, b, t, rate, inputs)
    else:
        z = solve_ivp(rhs, (0, t[-1]), np.zeros(n + 2), method="DOP853", t_eval=t,
                      rtol=1e-11, atol=1e-14, max_step=0.05).y.T
        u, _ = inputs(t, z[:, n], z[:, n + 1])
        x = z[:, :n]
    y = x @ c[:3].T
    noise = np.random.default_rng(seed).normal(size=(len(t), 3))
    if colour_hz:
        bb, aa = signal.butter(2, colour_hz / (rate / 2))
        noise = signal.lfilter(bb, aa, noise, axis=0)
        noise /= noise.std(axis=0)
    y = y + NOISE * noise
    cols = {"t": t, "theta0": tr["theta0"] + u["theta0"],
            "theta1c": tr["theta1c"] + u["theta1c"], "theta1s": tr["theta1s"] + u["theta1s"],
            "muz": 0 * t, "p": u["p"], "q": u["q"], "pdot": u["pdot"], "qdot": u["qdot"],
            "mux": mu + 0 * t, "muy": 0 * t,
            "beta0": tr["beta0"] + y[:, 0], "beta1c": tr["beta1c"] + y[:, 1],
            "beta1s": tr["beta1s"] + y[:, 2]}
    lines = [f"# omega: {k.omega}", f"# mu: {mu}", f"# a0: {k.a0}",
             f"# solidity: {k.solidity}"] + (
        [f"# hub: {k.hub}"] if constants is not None else []) + (
        ["# hold: zoh"] if hold == "zoh" else []) + [",".join(cols)]
    lines += [",".join(f"{cols[x][i]:.12g}" for x in cols) for i in range(len(t))]
    path.write_text("\n".join(lines) + "\n")
    return read_record(path)


POOL = offered_effects()


def test_peters_he_6_alone_is_offered():
    # the lowest order since its detection study (bench/rotor-physics.md); the
    # higher ones are asked for by name
    assert "peters-he-6" in POOL
    assert "peters-he-10" not in POOL and "peters-he-15" not in POOL


def _check(rec):
    """The ladder (its first rung is the diagnosis of the base): peters-he-6 named
    first, no time-delay, k_ph within 3 sigma of 1, ends explained."""
    lad = ladder(rec, BASE, pool=POOL)
    d = lad.rungs[0].diagnosis
    assert d.missing_effect == "peters-he-6", [(c.effect, c.reason) for c in d.candidates]
    assert "time-delay" not in d.decision.effects
    est, sigma = d.candidates[0].added["k_ph"]
    assert abs(est - 1.0) < 3 * sigma, (est, sigma)
    assert "peters-he-6" in lad.final.structure.effects
    assert "time-delay" not in lad.final.structure.effects
    assert lad.verdict.status == "explained", lad.verdict.to_json()
    return lad


def test_hidden_peters_he_6_is_named_and_explains(tmp_path):
    _check(make_record(tmp_path / "r.csv", 2, 200, None, 5))


@pytest.mark.slow
def test_no_alarm_on_the_three_state_rotor(tmp_path):
    rec = make_record(tmp_path / "r.csv", 1, 128, 3.0, 6)
    d = diagnose(rec, BASE, pool=POOL)
    assert d.missing_effect is None, [(c.effect, c.reason) for c in d.candidates]
    assert not any(c.accepted for c in d.candidates)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [21, 22, 23, 24, 25])
@pytest.mark.parametrize("rate, colour_hz, mu, single_axis, amp_deg", [
    (200, None, None, False, 1.0),     # white noise, two-axis
    (128, 3.0, None, False, 2.0),      # coloured noise (at 1 deg: see below)
    (200, None, None, True, 1.0),      # single-axis 3-2-1-1 on theta1s
    (128, None, 0.33, False, 1.0),     # another advance ratio
])
def test_hidden_peters_he_6_study(tmp_path, seed, rate, colour_hz, mu, single_axis,
                                  amp_deg):
    _check(make_record(tmp_path / "r.csv", 2, rate, colour_hz, seed, mu, single_axis,
                       amp_deg))


@pytest.mark.slow
@pytest.mark.parametrize("seed", [21, 22, 23, 24, 25])
def test_hidden_peters_he_6_small_inputs_coloured_noise(tmp_path, seed):
    """At 1 deg under coloured noise (128 Hz, 3 Hz low-pass) the effect is near the
    detection threshold (measured on the axial-flow truth before the skewed gain:
    named on 3 of these 5 seeds, the other two at p = 0.007 and 0.0013 against the
    rule's 0.001; not recounted on the skewed truth, which passes): it is named, or
    nothing is; never another effect in its place."""
    rec = make_record(tmp_path / "r.csv", 2, 128, 3.0, seed)
    d = diagnose(rec, BASE, pool=POOL)
    assert d.missing_effect in ("peters-he-6", None), [(c.effect, c.reason)
                                                       for c in d.candidates]
    assert set(d.decision.effects) <= {"peters-he-6"}, d.decision.effects


@pytest.mark.slow
@pytest.mark.parametrize("seed", [31, 32, 33, 34, 35])
@pytest.mark.parametrize("rate, colour_hz", [(200, None), (128, 3.0)])
def test_no_alarm_study(tmp_path, seed, rate, colour_hz):
    rec = make_record(tmp_path / "r.csv", 1, rate, colour_hz, seed)
    d = diagnose(rec, BASE, pool=POOL)
    assert d.missing_effect is None, [(c.effect, c.reason) for c in d.candidates]


#: The hingeless rotor of ``bench/detection.py`` (``ROTORS["hingeless"]``): a Bo 105-size
#: rotor at 100 kt, its flap frequency squared and Lock-number ratio.
HINGELESS = ({"mu": 0.236, "a0": 5.7, "solidity": 0.07, "omega": 44.4, "radius": 4.91,
              "hub": "hingeless"}, 1.25, 0.65)


def _check_within_floor(rec, rate, colour_hz, lb2=LB2, nb=NB):
    """:func:`_check`, and the ladder's final fit within 1.5 times the noise floor on
    every flap channel, every scaling of the truth within 3 sigma: ``k_ph`` 1, the
    rotor's flap frequency and inertia number, the Pitt-Peters time constants."""
    from inflowsim.model.effects import CATALOGUE
    from test_lead_lag_records import floor_ratio
    lad = _check(rec)
    fit = lad.final.fit
    ratio = floor_ratio(fit, rec, rate, colour_hz)
    assert ratio.max() < 1.5, ratio
    truth = {"lambda_beta2": lb2, "n_beta": nb, "k_ph": 1.0} | CATALOGUE[
        "separate-time-constants"].theory(rec.constants)
    z = {n: (fit.parameters[n] - v) / fit.sigma[n] for n, v in truth.items()}
    assert all(abs(v) < 3 for v in z.values()), z


@pytest.mark.slow
@pytest.mark.parametrize("rate, colour_hz, single_axis, amp_deg, hold, rotor", [
    (256, None, False, 1.0, "continuous", "puma"),   # log sweeps on both cyclics
    (64, 3.0, True, 2.0, "continuous", "puma"),      # one cyclic's sweep, coloured
    (64, 3.0, True, 2.0, "continuous", "hingeless"),
], ids=["sweep-two-axis", "sweep-single-axis", "hingeless-sweep-single-axis"])
def test_hidden_peters_he_6_in_sweeps(tmp_path, rate, colour_hz, single_axis, amp_deg,
                                      hold, rotor):
    """Log sweeps (0.15-3 Hz) instead of doublets, one seed of the study's
    (``bench/peters_he_detection.py wider``)."""
    from dataclasses import replace
    from inflowsim.model.params import PUMA
    k, lb2, nb = ((replace(PUMA, **HINGELESS[0]),) + HINGELESS[1:]
                  if rotor == "hingeless" else (None, LB2, NB))
    rec = make_record(tmp_path / "r.csv", 2, rate, colour_hz, 61, single_axis=single_axis,
                      amp_deg=amp_deg, constants=k, lb2=lb2, nb=nb, sweep=True, hold=hold)
    _check_within_floor(rec, rate, colour_hz, lb2, nb)


@pytest.mark.slow
def test_hidden_peters_he_6_held_inputs_256_hz_coloured(tmp_path):
    """Every input held over each sample (``# hold: zoh``), 256 Hz, coloured noise."""
    rec = make_record(tmp_path / "r.csv", 2, 256, 3.0, 61, amp_deg=2.0, hold="zoh")
    assert rec.hold == "zoh"
    _check_within_floor(rec, 256, 3.0)


@pytest.mark.slow
def test_hidden_peters_he_6_hingeless_held(tmp_path):
    """The hingeless rotor, inputs held, 64 Hz, coloured noise."""
    from dataclasses import replace
    from inflowsim.model.params import PUMA
    rec = make_record(tmp_path / "r.csv", 2, 64, 3.0, 61, amp_deg=2.0,
                      constants=replace(PUMA, **HINGELESS[0]), lb2=HINGELESS[1],
                      nb=HINGELESS[2], hold="zoh")
    _check_within_floor(rec, 64, 3.0, *HINGELESS[1:])


@pytest.mark.slow
@pytest.mark.parametrize("rate, colour_hz, single_axis, sweep, hold", [
    (256, None, False, True, "continuous"),
    (64, 3.0, True, True, "continuous"),
    (256, 3.0, False, False, "zoh"),
])
def test_no_alarm_sweeps_and_held_inputs(tmp_path, rate, colour_hz, single_axis, sweep,
                                         hold):
    """The three-state rotor under the sweeps and held inputs: nothing named."""
    rec = make_record(tmp_path / "r.csv", 1, rate, colour_hz, 71, single_axis=single_axis,
                      amp_deg=2.0 if colour_hz else 1.0, sweep=sweep, hold=hold)
    d = diagnose(rec, BASE, pool=POOL)
    assert d.missing_effect is None, [(c.effect, c.reason) for c in d.candidates]
    assert not any(c.accepted for c in d.candidates)


def test_held_records_flow_equals_the_ode_from_sample_to_sample():
    """The held-input route (:func:`_held`) equals DOP853 integrating the truth over
    each sample with that sample's inputs held (a short stretch of a sweep at 64 Hz)."""
    from inflowsim.flighttest.virtual import VirtualTest, virtual_record
    k = virtual_record(VirtualTest(duration=1.0)).constants
    a, b, _ = direct.state_space(direct.model(1, k.mu, NB, LB2, k.a0s, k.mu, k.omega),
                                 k.omega)
    names = ("theta0", "theta1c", "theta1s", "muz", "q", "p", "qdot", "pdot")

    def inputs(t, q, pp):
        th1s, th1c, th0 = _pilot(t + 2.0, 1.0, False, True)
        u = {"theta0": th0, "theta1s": th1s, "theta1c": th1c, "q": q, "p": pp,
             "qdot": (K_Q * th1s - q) / T_BODY, "pdot": (K_P * th1c - pp) / T_BODY}
        return u, np.array([u.get(x, 0.0 * t) for x in names])

    t = np.arange(24) / 64.0
    x, u = _held(a, b, t, 64.0, inputs)
    _, uv = inputs(t, u["q"], u["p"])
    z = np.zeros(a.shape[0])
    for i in range(len(t) - 1):
        z = solve_ivp(lambda _, s: a @ s + b @ uv[:, i], (t[i], t[i + 1]), z,
                      method="DOP853", rtol=1e-12, atol=1e-15).y[:, -1]
    np.testing.assert_allclose(z, x[-1], rtol=0, atol=1e-12 * np.abs(x).max())
    assert np.abs(x).max() > 1e-4
