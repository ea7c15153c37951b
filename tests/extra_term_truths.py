"""Records whose truth has a term outside the fitted structure (issue #36, bounds).

The truth is a catalogue structure's continuous matrices (``build_model``, the only
thing taken from the library, as a measured rotor's physics would come from the
rotor) with one term added that no catalogue effect offers:

- ``"coupling"``: a cross-coupling ``K`` [1/s] between the two cyclic flap states
  in the cyclic flap rows only (``A[b1c, b1s] += K``, ``A[b1s, b1c] -= K``);
- ``"pitch-lag"``: the cyclic pitch reaches the blades through a first-order
  servo of time constant ``T`` [s] (two extra states), the record holding the
  commanded pitch.

``None`` is the truth without a term (the fitted structure is then right).  The
record is integrated by scipy's DOP853 (``solve_ivp``, as
``test_independent_records.py`` does), a smooth 3-2-1-1 on the longitudinal cyclic
and, for ``axes=2``, a doublet on the lateral one (raised-cosine switches), body
rates from a first-order filter of the cyclic pitch integrated with them, white
noise drawn here, written as a CSV record and read back.
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

import inflowsim as ifs
from inflowsim.flighttest.virtual import VirtualTest, virtual_record
from inflowsim.model.presets import truth_parameters
from csv_records import flap_noise, write_csv

DURATION = 30.0
RATE = 100.0               # [Hz]
NOISE = 1e-4               # [rad], standard deviation per flap sample
T_BODY, K_Q, K_P = 0.6, -1.5, 1.2      # body-rate filter [s], [1/s per rad]
#: The size of each kind's extra term: coupling [1/s], servo lag [s].
SIZE = {"coupling": 2.0, "pitch-lag": 0.05}


def _switch(t, t0, rise=0.12):
    x = np.clip((t - t0) / rise, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(np.pi * x)


def _pilot(t, axes):
    """(theta1s, theta1c) perturbations [rad]: a 3-2-1-1 from 3 s; with two axes a
    doublet on theta1c from 15 s."""
    a = np.radians(1.0)
    th1s = a * (_switch(t, 3) - 2 * _switch(t, 4.5) + 2 * _switch(t, 5.5)
                - 2 * _switch(t, 6) + _switch(t, 6.5))
    th1c = a * (_switch(t, 15) - 2 * _switch(t, 16) + _switch(t, 17)) if axes == 2 \
        else 0.0 * t
    return th1s, th1c


def truth_model(structure="basic"):
    """``(model, parameters, constants)`` of the catalogue truth (Puma, trim totals)."""
    k = virtual_record(VirtualTest(duration=1.0)).constants
    s = ifs.Structure.parse(structure)
    p = {n: v for n, v in truth_parameters(s, k).items() if n in s.parameters}
    return ifs.build_model(s, p, k), p, k


def write_record(path, kind=None, seed=0, axes=2, structure="basic", size=None,
                 noise=NOISE):
    """Write and read back a record of ``structure``'s truth with the ``kind`` of
    extra term (``None``: none); returns ``(record, truth parameters)``."""
    m, p, k = truth_model(structure)
    size = SIZE.get(kind) if size is None else size
    names, n = list(m.inputs), m.a.shape[0]
    a = np.array(m.a, dtype=float)
    st = list(m.states)
    if kind == "coupling":
        i, j = st.index("beta1c"), st.index("beta1s")
        a[i, j] += size
        a[j, i] -= size
    elif kind not in (None, "pitch-lag"):
        raise ValueError(kind)
    lag = kind == "pitch-lag"
    ic, is_ = names.index("theta1c"), names.index("theta1s")

    def inputs(t, z):
        th1s, th1c = _pilot(t, axes)
        q, pp = z[n], z[n + 1]
        qd, pd = (K_Q * th1s - q) / T_BODY, (K_P * th1c - pp) / T_BODY
        u = {"theta1s": th1s, "theta1c": th1c, "q": q, "p": pp, "qdot": qd, "pdot": pd}
        return u, np.array([u.get(c, 0.0 * t) for c in names])

    def rhs(t, z):
        u, uv = inputs(t, z)
        extra = []
        if lag:                          # the blades see the servo's output
            uv = uv.copy()
            uv[is_], uv[ic] = z[n + 2], z[n + 3]
            extra = [(u["theta1s"] - z[n + 2]) / size, (u["theta1c"] - z[n + 3]) / size]
        return np.concatenate([a @ z[:n] + m.b @ uv, [u["qdot"], u["pdot"]], extra])

    t = np.arange(int(DURATION * RATE)) / RATE
    nz = n + 2 + (2 if lag else 0)
    z = solve_ivp(rhs, (0, t[-1]), np.zeros(nz), method="DOP853", t_eval=t,
                  rtol=1e-10, atol=1e-14, max_step=0.05).y.T
    u, uv = inputs(t, z.T)
    y = z[:, :n] @ m.c[:3].T + uv.T @ np.asarray(m.d)[:3].T
    y = y + flap_noise(seed, len(t), RATE, None, noise)
    tr = k.trim
    cols = {"t": t, "theta0": tr["theta0"] + 0 * t, "theta1c": tr["theta1c"] + u["theta1c"],
            "theta1s": tr["theta1s"] + u["theta1s"], "muz": 0 * t, "p": u["p"], "q": u["q"],
            "pdot": u["pdot"], "qdot": u["qdot"], "mux": tr["mux"] + 0 * t, "muy": 0 * t,
            "beta0": tr["beta0"] + y[:, 0], "beta1c": tr["beta1c"] + y[:, 1],
            "beta1s": tr["beta1s"] + y[:, 2]}
    return write_csv(path, k, cols), p
