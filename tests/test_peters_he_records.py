"""The diagnosis on records with Peters-He inflow hidden, made without the library's
model: the direct construction of the whole Peters-He rotor in forward flight
(``tests/peters_he_direct.py``: its own shape functions, gain by quadrature and the
skewed wake's couplings at ``X = tan(chi/2)`` of its own trim inflow, pressure and flap
integrals) integrated by scipy's DOP853 with a smooth 3-2-1-1 and a doublet,
body rates through a first-order filter of the cyclic, sampled at 128 or 200 Hz, white
or coloured noise drawn here, written as a CSV record and read back.

``peters-he-6`` is offered by default (the catalogue's pool), and the
diagnosis names it first, no ``time-delay`` (a lead) instead, the ladder ends
``explained`` and ``k_ph`` is within 3 sigma of 1.  On a record of the three-state
model (the same route with the Gram gain, the present model's) nothing is named."""
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


def _pilot(t, amp_deg, single_axis):
    a = np.radians(amp_deg)
    th1s = a * (_switch(t, 3) - 2 * _switch(t, 4.5) + 2 * _switch(t, 5.5)
                - 2 * _switch(t, 6) + _switch(t, 6.5))
    th1c = 0 * t if single_axis else a * (_switch(t, 15) - 2 * _switch(t, 16)
                                          + _switch(t, 17))
    th0 = 0.4 * a * (_switch(t, 22) - 2 * _switch(t, 23) + _switch(t, 24))
    return th1s, th1c, th0


def make_record(path, power, rate, colour_hz, seed, mu=None, single_axis=False,
                amp_deg=1.0, constants=None, lb2=LB2, nb=NB):
    """A CSV record of the Peters-He rotor with ``power`` (1: the three-state model,
    Pitt-Peters' axial gain), read back.  ``amp_deg``: the pilot's cyclic amplitude
    [deg].  The Peters-He rotor's gain is the skewed wake's at the record's trim (the
    written trim totals, ``muz = 0``).  ``constants`` (default the Puma's), ``lb2``,
    ``nb``: another rotor (its hub written in the record's header)."""
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
        th1s, th1c, th0 = _pilot(t, amp_deg, single_axis)
        qd, pd = (K_Q * th1s - q) / T_BODY, (K_P * th1c - pp) / T_BODY
        u = {"theta0": th0, "theta1s": th1s, "theta1c": th1c, "q": q, "p": pp,
             "qdot": qd, "pdot": pd}
        return u, np.array([u.get(x, 0.0 * t) for x in names])

    def rhs(t, z):
        u, uv = inputs(t, z[n], z[n + 1])
        return np.concatenate([a @ z[:n] + b @ uv, [u["qdot"], u["pdot"]]])

    t = np.arange(int(DURATION * rate)) / rate
    z = solve_ivp(rhs, (0, t[-1]), np.zeros(n + 2), method="DOP853", t_eval=t,
                  rtol=1e-11, atol=1e-14, max_step=0.05).y.T
    u, _ = inputs(t, z[:, n], z[:, n + 1])
    y = z[:, :n] @ c[:3].T
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
        [f"# hub: {k.hub}"] if constants is not None else []) + [",".join(cols)]
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
