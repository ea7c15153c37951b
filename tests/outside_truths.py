"""Records whose truth lies outside the catalogue (issue #36), made here.

A plain module the tests and ``bench/outside.py`` import.  Each record is the
Puma's ``basic`` model at its truth parameters (the only library call:
:func:`inflowsim.build_model`, for the continuous matrices a measured rotor's
physics would give) with one term no catalogue effect offers, integrated by
scipy's DOP853 with smooth pilot inputs (raised-cosine switches, 0.12 s), body
rates from a first-order filter of the cyclic pitch integrated with them, noise
drawn here (white, or through a second-order Butterworth low-pass), written as a
CSV record and read back.

The kinds of truth (:data:`TRUTHS`), each a term ``k`` times something added to
the azimuth-time descriptor ``E x' = A x + B u`` of the flap and inflow (states
``beta0, beta1c, beta1s, lambda0, lambda1c, lambda1s``), or to the recorded flap:

``cyclic-entry``
    ``A[beta1c, beta1s] += k``: one matrix entry, a term ``k beta1s`` on the
    right-hand side of the ``beta1c`` flap equation only.
``cyclic-stiffness``
    ``A[beta1c, beta1c] -= k``, ``A[beta1s, beta1s] -= k``: a stiffness in the
    cyclic flap rows only (the coning row keeps the shared ``lambda_beta2``: the
    case where the shared flap-frequency parameter absorbs the cyclic error).
``pitch-lag``
    torsion: an extra state per cyclic, ``tau_t th_e' + th_e = -k beta1(c,s)``
    [s], the elastic pitch ``th_e`` lagging the cyclic flap load and adding to
    the blade's cyclic pitch (``B``'s pitch columns: the flap and inflow rows).
``rotor-speed``
    an extra state ``w = dOmega / Omega``, ``tau_w w' + w = -g lambda0`` (the
    torque the induced inflow draws, through the governor's lag [s]), acting on
    the coning equation, ``A[beta0, w] = k`` (the forcing that does not scale
    with ``Omega^2``).
``cross-sensor``
    the recorded ``beta1c`` is ``beta1c + k beta1s`` (cross-axis coupling of the
    flap sensor's resolver; the recorded ``beta1s`` is clean: not an azimuth
    offset, which rotates both).

Each :class:`Truth` records as data where its term acts, for the map check:
``equations`` ``((block, equation), ...)`` and ``variables`` (names of
:mod:`inflowsim.channels`: the flap, flap rates, inflow or inputs the term is
proportional to or driven by); :meth:`Truth.acts_at` says whether a map entry
lies there.

Not here: the effects of issue #35 (lead-lag, servo actuators, wake distortion,
Peters-He).

Use::

    rec, truth = outside_record(tmp_path / "r.csv", "pitch-lag", seed=3,
                                rate=64, axes="both", colour_hz=None)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import signal
from scipy.integrate import solve_ivp

import inflowsim as ifs
from inflowsim.data.record import read_record
from inflowsim.flighttest.virtual import VirtualTest, virtual_record
from inflowsim.model.presets import truth_parameters

__all__ = ["Truth", "TRUTHS", "KINDS", "AXES", "outside_record", "NOISE", "DURATION"]

DURATION = 30.0       # [s]
NOISE = 1e-4          # [rad], standard deviation per sample of the recorded flap
T_BODY, K_Q, K_P = 0.6, -1.5, 1.2      # body-rate filter [s], [1/s per rad]
#: Which cyclic the pilot moves: both (a 3-2-1-1 on theta1s from 3 s, a doublet
#: on theta1c from 15 s), or one (its 3-2-1-1 from 3 s and a doublet from 15 s).
AXES = ("both", "theta1s", "theta1c")

_FLAP_ROWS = ("beta0", "beta1c", "beta1s")
_RATES = tuple(f"{c}_prime" for c in _FLAP_ROWS)


@dataclass(frozen=True)
class Truth:
    """One kind of truth outside the catalogue (see the module docstring).

    ``strength`` its default gain ``k``; ``lag`` its extra state's time constant
    [s] (``None``: no extra state); ``gain`` what drives the extra state.
    """

    kind: str
    physics: str
    equations: tuple            # ((block, equation), ...) where the term acts
    variables: tuple            # what it is proportional to, or driven by
    strength: float
    lag: float | None = None
    gain: float = 0.0

    def acts_at(self, block: str, equation: str, variable: str, lag=None) -> bool:
        """Whether a map entry (``block``, ``equation``, ``variable``) lies in the
        equations and variables where this truth's term acts.  A lagged entry
        (``lag`` [s]: a slow state driven by ``variable``) is driven by its
        variable: it lies there alike."""
        return (block, equation) in self.equations and variable in self.variables

    def places(self, entries) -> bool:
        """Whether the map's first group ``entries`` (``((block, equation, variable[,
        lag]), ...)``: the entries the record cannot tell apart, most often one)
        places this truth's term: one of them lies where it acts (:meth:`acts_at`)."""
        return any(self.acts_at(*e) for e in entries)

    def to_json(self) -> dict:
        return {"kind": self.kind, "physics": self.physics,
                "equations": [list(e) for e in self.equations],
                "variables": list(self.variables), "strength": self.strength,
                "lag": self.lag, "gain": self.gain}


TRUTHS = {t.kind: t for t in (
    Truth("cyclic-entry", "a term k beta1s in the beta1c flap equation (one entry of A)",
          (("flap", "beta1c"),), ("beta1s",), 0.12),
    Truth("cyclic-stiffness", "a flap stiffness k in the cyclic rows only (not coning)",
          (("flap", "beta1c"), ("flap", "beta1s")), ("beta1c", "beta1s"), 0.12),
    Truth("pitch-lag", "torsion: elastic cyclic pitch lagging the cyclic flap by tau_t",
          tuple(("flap", e) for e in _FLAP_ROWS)
          + tuple(("inflow", e) for e in ("lambda0", "lambda1c", "lambda1s"))
          + (("pitch", "theta1"),),
          ("beta1c", "beta1s") + _RATES[1:] + ("beta1", "beta1_prime"), 0.15, lag=0.01),
    Truth("rotor-speed", "rotor-speed variation: w = dOmega/Omega lags the inflow's "
          "torque and forces the coning equation",
          (("flap", "beta0"),), ("lambda0",), 2.0, lag=0.8, gain=4.0),
    Truth("cross-sensor", "the recorded beta1c contains k beta1s (sensor cross-axis "
          "coupling)", (("measurement", "beta1c"),), ("beta1s",), 0.06),
)}
KINDS = tuple(TRUTHS)


def _switch(t, t0, rise=0.12):
    x = np.clip((t - t0) / rise, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(np.pi * x)


def _3211(t, t0, a):
    return a * (_switch(t, t0) - 2 * _switch(t, t0 + 1.5) + 2 * _switch(t, t0 + 2.5)
                - 2 * _switch(t, t0 + 3.0) + _switch(t, t0 + 3.5))


def _doublet(t, t0, a):
    return a * (_switch(t, t0) - 2 * _switch(t, t0 + 1.0) + _switch(t, t0 + 2.0))


def _pilot(t, axes):
    """(theta1s, theta1c) perturbations [rad]."""
    a = np.radians(1.0)
    if axes == "both":
        return _3211(t, 3.0, a), _doublet(t, 15.0, a)
    one = _3211(t, 3.0, a) + _doublet(t, 15.0, a)
    return (one, 0.0 * t) if axes == "theta1s" else (0.0 * t, one)


def _system(truth: Truth, k: float, m, omega):
    """``(a, b, c, n_extra)``: the truth's SI state space, states the base's six
    then its extra ones; ``c`` the recorded flap (3 rows) over all states."""
    n = m.a.shape[0]
    Einv = np.linalg.solve(m.E, np.eye(n))
    i = {s: j for j, s in enumerate(m.states)}
    a, b = np.array(m.a, dtype=float), np.array(m.b, dtype=float)
    c = np.array(m.c, dtype=float)[:3]
    if truth.kind == "cyclic-entry":
        dA = np.zeros((n, n))
        dA[i["beta1c"], i["beta1s"]] = k
        return a + omega * Einv @ dA, b, c, 0
    if truth.kind == "cyclic-stiffness":
        dA = np.zeros((n, n))
        dA[i["beta1c"], i["beta1c"]] = dA[i["beta1s"], i["beta1s"]] = -k
        return a + omega * Einv @ dA, b, c, 0
    if truth.kind == "pitch-lag":
        # states th_ec, th_es: tau th' = -th - k beta1(c,s); they add to the pitch
        jc, js = list(m.inputs).index("theta1c"), list(m.inputs).index("theta1s")
        tau = truth.lag
        big = np.zeros((n + 2, n + 2))
        big[:n, :n] = a
        big[:n, n] = b[:, jc]
        big[:n, n + 1] = b[:, js]
        big[n, n], big[n + 1, n + 1] = -1 / tau, -1 / tau
        big[n, i["beta1c"]], big[n + 1, i["beta1s"]] = -k / tau, -k / tau
        return big, np.vstack([b, np.zeros((2, b.shape[1]))]), \
            np.hstack([c, np.zeros((3, 2))]), 2
    if truth.kind == "rotor-speed":
        tau = truth.lag
        big = np.zeros((n + 1, n + 1))
        big[:n, :n] = a
        col = np.zeros(n)
        col[i["beta0"]] = k
        big[:n, n] = omega * Einv @ col
        big[n, n] = -1 / tau
        big[n, i["lambda0"]] = -truth.gain / tau
        return big, np.vstack([b, np.zeros((1, b.shape[1]))]), \
            np.hstack([c, np.zeros((3, 1))]), 1
    if truth.kind == "cross-sensor":
        c = c.copy()
        c[1] += k * c[2]
        return a, b, c, 0
    raise ValueError(f"unknown truth {truth.kind!r}; choose from {', '.join(KINDS)}")


def outside_record(path, kind: str, seed: int, rate: float = 64.0, axes: str = "both",
                   colour_hz: float | None = None, strength: float | None = None,
                   duration: float = DURATION, noise: float = NOISE):
    """Write a record of truth ``kind`` to ``path`` and read it back.

    Parameters
    ----------
    path : path-like
        The CSV record written.
    kind : str
        One of :data:`KINDS`.
    seed : int
        The noise's seed.
    rate : float
        Sample rate [Hz].
    axes : {"both", "theta1s", "theta1c"}
        Which cyclic the pilot moves (:data:`AXES`).
    colour_hz : float, optional
        Coloured noise: white through a second-order Butterworth low-pass at this
        corner [Hz], rescaled to ``noise``; ``None``: white.
    strength : float, optional
        The term's gain ``k`` (default :attr:`Truth.strength`; 0: the base alone).
    duration, noise : float
        [s], [rad] per sample.

    Returns
    -------
    (Record, dict)
        The record as read back, and ``{"truth": Truth, "parameters": the base's
        true parameters, "strength": k}``.
    """
    truth = TRUTHS[kind]
    if axes not in AXES:
        raise ValueError(f"axes {axes!r}: choose from {', '.join(AXES)}")
    k = truth.strength if strength is None else float(strength)
    const = virtual_record(VirtualTest(duration=1.0)).constants      # Puma, trim totals
    s = ifs.Structure.parse("basic")
    p = {n: v for n, v in truth_parameters(s, const).items() if n in s.parameters}
    m = ifs.build_model(s, p, const)
    a, b, c, _ = _system(truth, k, m, const.omega)
    names, n = list(m.inputs), a.shape[0]

    def inputs(t, q, pp):
        th1s, th1c = _pilot(t, axes)
        qd, pd = (K_Q * th1s - q) / T_BODY, (K_P * th1c - pp) / T_BODY
        u = {"theta1s": th1s, "theta1c": th1c, "q": q, "p": pp, "qdot": qd, "pdot": pd}
        return u, np.array([u.get(col, 0.0 * t) for col in names])

    def rhs(t, z):
        u, uv = inputs(t, z[n], z[n + 1])
        return np.concatenate([a @ z[:n] + b @ uv, [u["qdot"], u["pdot"]]])

    t = np.arange(int(round(duration * rate))) / rate
    z = solve_ivp(rhs, (0, t[-1]), np.zeros(n + 2), method="DOP853", t_eval=t,
                  rtol=1e-10, atol=1e-13, max_step=0.05).y.T
    u, uv = inputs(t, z[:, n], z[:, n + 1])
    y = z[:, :n] @ c.T + uv.T @ np.asarray(m.d)[:3].T
    e = np.random.default_rng(seed).normal(size=(len(t), 3))
    if colour_hz:
        bb, aa = signal.butter(2, colour_hz / (rate / 2))
        e = signal.lfilter(bb, aa, e, axis=0)
        e /= e.std(axis=0)
    y = y + noise * e
    tr = const.trim
    cols = {"t": t, "theta0": tr["theta0"] + 0 * t,
            "theta1c": tr["theta1c"] + u["theta1c"], "theta1s": tr["theta1s"] + u["theta1s"],
            "muz": 0 * t, "p": u["p"], "q": u["q"], "pdot": u["pdot"], "qdot": u["qdot"],
            "mux": tr["mux"] + 0 * t, "muy": 0 * t,
            "beta0": tr["beta0"] + y[:, 0], "beta1c": tr["beta1c"] + y[:, 1],
            "beta1s": tr["beta1s"] + y[:, 2]}
    lines = [f"# omega: {const.omega}", f"# mu: {const.mu}", f"# a0: {const.a0}",
             f"# solidity: {const.solidity}", ",".join(cols)]
    lines += [",".join(f"{cols[col][j]:.12g}" for col in cols) for j in range(len(t))]
    with open(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return read_record(path), {"truth": truth, "parameters": p, "strength": k}
