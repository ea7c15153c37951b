"""Records of a rotor with servo actuators, written without the effect's code.

The servos are integrated here as their own ODE (``T^2 th'' + 2 zeta T th' + th =
command`` on each of the three controls, in seconds) feeding the blade pitch of the
truth's servo-free continuous matrices (``build_model`` of the base structure, as a
measured rotor's physics would come from the rotor); scipy's DOP853 integrates body,
servos and rotor together with smooth pilot inputs (raised-cosine switches) on one
or both cyclics (doublets, a 3-2-1-1, or a frequency sweep), then the record is
sampled, noise added (white, or through a Butterworth low-pass) and written as CSV.
"""
from __future__ import annotations

import numpy as np
from scipy import signal
from scipy.integrate import solve_ivp

import inflowsim as ifs
from inflowsim.flighttest.virtual import VirtualTest, virtual_record
from inflowsim.model.presets import truth_parameters
from csv_records import flap_noise, write_csv

NOISE = 1e-4                      # [rad] per sample
T_BODY, K_Q, K_P = 0.6, -1.5, 1.2   # body-rate filter [s], [1/s per rad]


def _switch(t, t0, rise=0.12):
    x = np.clip((t - t0) / rise, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(np.pi * x)


def pilot(kind, t, amplitude=np.radians(1.0)):
    """``(theta1s, theta1c)`` command perturbations [rad] of a manoeuvre ``kind``:
    ``two-axis`` (3-2-1-1 on theta1s from 3 s, doublet on theta1c from 15 s),
    ``theta1s`` / ``theta1c`` (one doublet and a 3-2-1-1 on that axis alone),
    ``sweep`` (0.1-3 Hz log sweep on theta1s, 4-24 s, faded in and out)."""
    a = amplitude
    s3211 = a * (_switch(t, 3) - 2 * _switch(t, 4.5) + 2 * _switch(t, 5.5)
                 - 2 * _switch(t, 6) + _switch(t, 6.5))
    dbl = a * (_switch(t, 15) - 2 * _switch(t, 16) + _switch(t, 17))
    if kind == "two-axis":
        return s3211, dbl
    if kind == "theta1s":
        return s3211 + dbl, 0 * t
    if kind == "theta1c":
        return 0 * t, s3211 + dbl
    if kind == "sweep":
        tt = np.clip(t - 4.0, 0.0, 20.0)
        ph = signal.chirp(tt, f0=0.1, t1=20.0, f1=3.0, method="logarithmic")
        fade = _switch(t, 4.0, 1.0) * (1 - _switch(t, 23.0, 1.0))
        return 0.6 * a * fade * ph, 0 * t
    raise ValueError(kind)


def record(path, base, servo_tau, servo_zeta, *, kind="two-axis", rate=128,
           colour_hz=None, seed=0, duration=30.0, constants=None):
    """Write and read back a record of ``base`` (a catalogue structure) behind servos
    ``servo_tau`` [s], ``servo_zeta`` [-]; returns ``(record, truth parameters)``
    (the base's truth values and the servos')."""
    k = constants or virtual_record(VirtualTest(duration=1.0)).constants
    s = ifs.Structure.parse(base)
    p = {n: v for n, v in truth_parameters(s, k).items() if n in s.parameters}
    m = ifs.build_model(s, p, k)
    names, n = list(m.inputs), m.a.shape[0]
    wn, z = 1.0 / servo_tau, servo_zeta
    fine = np.arange(0.0, duration, 1e-3)
    c1s, c1c = pilot(kind, fine)
    cmd = (lambda t: np.interp(t, fine, c1s), lambda t: np.interp(t, fine, c1c))

    def rhs(t, w):
        x, q, pp = w[:n], w[n], w[n + 1]
        th = w[n + 2:n + 4]            # servo outputs (theta1s, theta1c)
        thd = w[n + 4:n + 6]
        c = np.array([cmd[0](t), cmd[1](t)])
        thdd = wn * wn * (c - th) - 2 * z * wn * thd
        qd, pd = (K_Q * th[0] - q) / T_BODY, (K_P * th[1] - pp) / T_BODY
        u = {"theta1s": th[0], "theta1c": th[1], "q": q, "p": pp, "qdot": qd, "pdot": pd}
        uv = np.array([u.get(c_, 0.0) for c_ in names])
        return np.concatenate([m.a @ x + m.b @ uv, [qd, pd], thd, thdd])

    t = np.arange(int(duration * rate)) / rate
    w = solve_ivp(rhs, (0, t[-1]), np.zeros(n + 6), method="DOP853", t_eval=t,
                  rtol=1e-10, atol=1e-13, max_step=2e-3).y.T
    q, pp, th = w[:, n], w[:, n + 1], w[:, n + 2:n + 4]
    qd, pd = (K_Q * th[:, 0] - q) / T_BODY, (K_P * th[:, 1] - pp) / T_BODY
    y = w[:, :n] @ m.c[:3].T
    y = y + flap_noise(seed, len(t), rate, colour_hz, NOISE)
    c1s, c1c = pilot(kind, t)
    tr = k.trim
    cols = {"t": t, "theta0": tr["theta0"] + 0 * t, "theta1c": tr["theta1c"] + c1c,
            "theta1s": tr["theta1s"] + c1s, "muz": 0 * t, "p": pp, "q": q,
            "pdot": pd, "qdot": qd, "mux": tr["mux"] + 0 * t, "muy": 0 * t,
            "beta0": tr["beta0"] + y[:, 0], "beta1c": tr["beta1c"] + y[:, 1],
            "beta1s": tr["beta1s"] + y[:, 2]}
    return write_csv(path, k, cols), p | {"servo_tau": servo_tau, "servo_zeta": servo_zeta}
