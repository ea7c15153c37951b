"""The diagnosis on records no generator of the project made (issue #9).

Each record is written here: the linear truth's continuous matrices integrated by
scipy's DOP853 with a smooth 3-2-1-1 on the longitudinal cyclic and a doublet on
the lateral one (raised-cosine switches, 0.12 s), body rates from a first-order
filter of the cyclic pitch integrated with them, sampled at rates the detection
study does not use (128 and 200 Hz), with noise drawn here (white, or through a
second-order Butterworth low-pass), written as a CSV record and read back.  Only
the truth's matrices come from the library (``build_model``), as a measured
rotor's physics would come from the rotor.
"""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import inflowsim as ifs
from inflowsim.diagnose import diagnose
from inflowsim.model.presets import truth_parameters
from inflowsim.flighttest.virtual import VirtualTest, virtual_record
from csv_records import flap_noise, write_csv

DURATION = 30.0
NOISE = 1e-4          # [rad], standard deviation per sample
T_BODY, K_Q, K_P = 0.6, -1.5, 1.2      # body-rate filter [s], [1/s per rad]


def _switch(t, t0, rise=0.12):
    x = np.clip((t - t0) / rise, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(np.pi * x)


def _pilot(t):
    """(theta1s, theta1c) perturbations [rad]: a 3-2-1-1 from 3 s, a doublet from 15 s."""
    a = np.radians(1.0)
    th1s = a * (_switch(t, 3) - 2 * _switch(t, 4.5) + 2 * _switch(t, 5.5)
                - 2 * _switch(t, 6) + _switch(t, 6.5))
    th1c = a * (_switch(t, 15) - 2 * _switch(t, 16) + _switch(t, 17))
    return th1s, th1c


def _record(path, structure, rate, colour_hz, seed):
    k = virtual_record(VirtualTest(duration=1.0)).constants      # Puma, trim totals
    s = ifs.Structure.parse(structure)
    p = truth_parameters(s, k) | ({"tau": 5.0} if "tau" in s.parameters else {})
    p = {n: v for n, v in p.items() if n in s.parameters}
    m = ifs.build_model(s, p, k)
    names, n = list(m.inputs), m.a.shape[0]

    def inputs(t, q, pp):
        th1s, th1c = _pilot(t)
        qd, pd = (K_Q * th1s - q) / T_BODY, (K_P * th1c - pp) / T_BODY
        u = {"theta1s": th1s, "theta1c": th1c, "q": q, "p": pp, "qdot": qd, "pdot": pd}
        return u, np.array([u.get(c, 0.0 * t) for c in names])

    def rhs(t, z):
        u, uv = inputs(t, z[n], z[n + 1])
        return np.concatenate([m.a @ z[:n] + m.b @ uv, [u["qdot"], u["pdot"]]])

    t = np.arange(int(DURATION * rate)) / rate
    z = solve_ivp(rhs, (0, t[-1]), np.zeros(n + 2), method="DOP853", t_eval=t,
                  rtol=1e-11, atol=1e-14, max_step=0.05).y.T
    u, uv = inputs(t, z[:, n], z[:, n + 1])
    y = z[:, :n] @ m.c[:3].T + uv.T @ np.asarray(m.d)[:3].T
    y = y + flap_noise(seed, len(t), rate, colour_hz, NOISE)
    tr = k.trim
    cols = {"t": t, "theta0": tr["theta0"] + 0 * t, "theta1c": tr["theta1c"] + u["theta1c"],
            "theta1s": tr["theta1s"] + u["theta1s"], "muz": 0 * t, "p": u["p"], "q": u["q"],
            "pdot": u["pdot"], "qdot": u["qdot"], "mux": tr["mux"] + 0 * t, "muy": 0 * t,
            "beta0": tr["beta0"] + y[:, 0], "beta1c": tr["beta1c"] + y[:, 1],
            "beta1s": tr["beta1s"] + y[:, 2]}
    return write_csv(path, k, cols), p


@pytest.mark.parametrize("truth, effect, parameter, rate, colour_hz, seed", [
    ("basic+second-harmonic-flap", "second-harmonic-flap", "k_beta2", 200, None, 11),
    ("basic+skewed-wake", "skewed-wake", "k_skew", 128, 3.0, 13),
])
def test_the_hidden_effect_is_named_with_the_truth_within_its_bound(
        tmp_path, truth, effect, parameter, rate, colour_hz, seed):
    rec, p = _record(tmp_path / "rec.csv", truth, rate, colour_hz, seed)
    assert rec.hold == "continuous"
    d = diagnose(rec, "basic", assess=False)          # the decision only (no map)
    assert d.missing_effect == effect, [(c.effect, c.reason) for c in d.candidates]
    named = d.candidates[0]
    assert named.measure == ("input-correlated excess" if colour_hz else "level deviance")
    est, sigma = named.added[parameter]
    assert abs(est - p[parameter]) < 3 * sigma, (est, sigma, p[parameter])


def test_no_alarm_on_the_true_structure_under_coloured_noise(tmp_path):
    rec, _ = _record(tmp_path / "rec.csv", "glauert", 200, 3.0, 12)
    d = diagnose(rec, "glauert", assess=False)        # the decision only (no map)
    assert d.missing_effect is None, [(c.effect, c.reason) for c in d.candidates]
    assert not any(c.accepted for c in d.candidates)
    assert [f for f in d.failures if f.kind == "coloured-noise"
            and "in_band_over_floor" in f.detail]
