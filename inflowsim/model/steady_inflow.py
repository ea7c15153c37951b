"""The model's steady (trim) induced inflow at given loads: the inflow equations of
the paper, Eqs. (2), (19), and the ``skewed-wake`` extension, with ``lambda' = 0``.

The loads are given, not computed from blade pitch: ``c = (C_T, C_mc, C_ms)/(a0 s)``
with the measured thrust and the hub moments of the run (zero for a rotor trimmed to
zero first-harmonic flapping: in steady flight the flap equation makes the
aerodynamic and the spring hub moments equal, ``model.md``, Loads out).  ``a0 s``
then cancels from ``L c``.  Every function returns ``(lambda0, lambda1c, lambda1s)``
of Eq. (6), over ``Omega R``, down positive.

These are what the model says at trim, for comparison with a measured inflow
(``inflowsim.identify.inflow_survey``); a perturbation model identified about one
trim (the paper's Tables) is here applied to the totals of another rotor, which is
an extrapolation the comparison is there to judge.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from ..errors import InputError
from ..physics import bladeelement as be
from ..physics import loads as ld
from .effects.glauert import f_matrix
from .effects.skewed_wake import skew_l
from .params import PUMA
from .presets import paper_table

#: The theories compared, in the order they are reported.
THEORIES = ("momentum", "momentum-mass-flow", "momentum-tilt", "skewed-wake",
            "glauert-table3")
LABELS = {
    "momentum": "momentum, V ~ mu (Eq. 2)",
    "momentum-mass-flow": "momentum, mass-flow V",
    "momentum-tilt": "momentum, trim root with shaft tilt",
    "skewed-wake": "skewed wake (Pitt-Peters)",
    "glauert-table3": "Glauert, Table 3 (Eq. 19)",
}


@dataclass(frozen=True)
class SteadyInflow:
    """One theory's trim inflow.

    ``harmonics`` ``(lambda0, lambda1c, lambda1s)`` [-]; ``sigma`` their 1-sigma
    bounds propagated from the paper's bounds where the theory has identified
    parameters (Table 3), else zeros; ``gains`` the theory's own numbers (``chi``
    [rad], ``k_skew``, ``V`` ...); ``note`` what was assumed.
    """

    theory: str
    harmonics: tuple[float, float, float]
    sigma: tuple[float, float, float] = (0.0, 0.0, 0.0)
    gains: tuple[tuple[str, float], ...] = ()
    note: str = ""

    @property
    def label(self) -> str:
        return LABELS.get(self.theory, self.theory)

    @property
    def lambda0(self) -> float:
        return self.harmonics[0]

    @property
    def lambda1c(self) -> float:
        return self.harmonics[1]

    @property
    def lambda1s(self) -> float:
        return self.harmonics[2]


def _loads(ct, c_mc, c_ms) -> np.ndarray:
    # a0 s = 1: L c is independent of a0 s once the loads are given
    return np.array([ct, c_mc, c_ms], dtype=float)


def momentum_inflow(mu, ct, c_mc=0.0, c_ms=0.0, v=None) -> np.ndarray:
    """Local momentum, Eq. (2) at steady state: ``lambda = L c`` [-].

    ``L = diag(1/(2V), -2/V, -2/V)`` per ``a0 s`` (:func:`inflowsim.physics.loads.
    momentum_l`); ``v`` the speed through the disc, default the paper's ``V ~ mu``.
    """
    return ld.momentum_l(mu, 1.0, v) @ _loads(ct, c_mc, c_ms)


def momentum_inflow_tilted(mu, muz, ct) -> float:
    """Glauert's momentum trim root with a through-flow: ``lambda0 = C_T / (2
    sqrt(mu^2 + (lambda0 - muz)^2))`` [-] (``muz`` down positive, negative for a
    shaft tilted forward).  The project's :func:`inflowsim.physics.loads.
    momentum_inflow` is the level-flight case ``muz = 0``."""
    def f(lam):
        return 2.0 * lam * math.hypot(mu, lam - muz) - ct
    hi = math.sqrt(ct / 2.0) + abs(muz)
    if not (f(0.0) < 0.0 < f(hi)):
        raise InputError(f"momentum trim root: no single root for mu = {mu:g}, "
                         f"muz = {muz:g}, ct = {ct:g}")
    return float(brentq(f, 0.0, hi, xtol=1e-14))


def skewed_wake_inflow(mu, muz, ct, c_mc=0.0, c_ms=0.0):
    """Momentum with the ``skewed-wake`` coupling at its Pitt-Peters theory value.

    ``lambda = (L + dL) c`` with ``dL = k_skew (1/mu) [[0,1,0],[1,0,0],[0,0,0]]``
    per ``a0 s`` (:func:`inflowsim.model.effects.skewed_wake.skew_l`), ``k_skew =
    15 pi/64 tan(chi/2)`` and the wake skew ``tan chi = mu/(lambda0 - muz)`` from the
    momentum ``lambda0 = C_T/(2 mu)``: ``lambda1c/lambda0 = 15 pi/32 tan(chi/2)``.

    Returns
    -------
    harmonics : ndarray (3,)
    chi : float
        Wake skew angle [rad].
    k_skew : float
    """
    c = _loads(ct, c_mc, c_ms)
    lam0 = momentum_inflow(mu, ct, c_mc, c_ms)[0]
    chi = be.wake_skew_angle(mu, lam0, muz)
    k = be.pitt_peters_skew_gain(chi)
    return (ld.momentum_l(mu, 1.0) + skew_l(k, mu, 1.0)) @ c, chi, k


def glauert_inflow(mu, ct, theta1c, theta1s, beta1c=0.0, beta1s=0.0, c_mc=0.0, c_ms=0.0,
                   params=None):
    """The Glauert-augmented inflow, Eq. (19), at steady state with Table 3's gains.

    ``lambda = L c + F nu_lambda`` with ``nu_lambda = (p* - lambda1s, q* - lambda1c)``,
    at trim ``p* = beta1c + theta1s``, ``q* = theta1c - beta1s`` (no hub rates, no flap
    rates) and ``G mu_xy = 0`` (``mu_xy`` are perturbations of the in-plane velocity,
    ``model.md`` section 1).  Solved as ``(I + F S) lambda = L c + F (p*, q*)``.

    ``F = [[ks, kc], [0, k0], [k0, 0]]``: Table 3's ``kc``, ``ks`` are the mean-inflow
    row's gains on ``q* - lambda1c`` and ``p* - lambda1s``, not Glauert's gradient
    ``lambda1c / lambda0``; ``k0 = k0p - a0 s/(8 mu)`` with the Puma's ``a0 s`` and
    ``mu`` at which ``k0p`` was identified (the given loads already hold the
    ``-a0 s/(8 mu)`` self-term of ``L G_lambda``).

    Returns
    -------
    harmonics : ndarray (3,)
    sigma : ndarray (3,)
        1-sigma from Table 3's bounds on ``kc, ks, k0p`` (first-order, taken
        independent: the paper gives no correlations).
    """
    if params is None:
        _, params, sig = paper_table(3)
    else:
        sig = {}
    ps = np.array([beta1c + theta1s, theta1c - beta1s])
    c = _loads(ct, c_mc, c_ms)
    sel = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]])   # lambda -> (l1s, l1c)

    def solve(p):
        f = f_matrix(p, PUMA.a0s, PUMA.mu)
        return np.linalg.solve(np.eye(3) + f @ sel, momentum_inflow(mu, ct, c_mc, c_ms)
                               + f @ ps)

    lam = solve(params)
    var = np.zeros(3)
    for name in ("kc", "ks", "k0p"):
        if sig.get(name):
            h = 1e-6
            d = (solve({**params, name: params[name] + h}) - lam) / h
            var += (d * sig[name]) ** 2
    return lam, np.sqrt(var)


def steady_inflow_predictions(mu, muz, ct, theta1c, theta1s, beta1c=0.0, beta1s=0.0,
                              c_mc=0.0, c_ms=0.0) -> tuple[SteadyInflow, ...]:
    """Every theory of :data:`THEORIES` at one run condition.

    Parameters
    ----------
    mu : float
        In-plane advance ratio [-].
    muz : float
        Hub velocity normal to the disc over ``Omega R``, down positive [-].
    ct : float
        Measured thrust coefficient [-].
    theta1c, theta1s : float
        Cyclic pitch, model convention [rad] (Glauert's ``p*, q*``).
    beta1c, beta1s : float
        Trim first-harmonic flap [rad]; 0 for a rotor trimmed to zero flapping.
    c_mc, c_ms : float
        Hub pitch and roll moment coefficients [-]; 0 with zero flapping.
    """
    assumed = ("loads given: C_T measured, C_mc = {:g}, C_ms = {:g}".format(c_mc, c_ms))
    mom = momentum_inflow(mu, ct, c_mc, c_ms)
    v = ld.mass_flow_parameter(mu, ct)
    mf = momentum_inflow(mu, ct, c_mc, c_ms, v=v)
    tilt = momentum_inflow_tilted(mu, muz, ct)
    sw, chi, k = skewed_wake_inflow(mu, muz, ct, c_mc, c_ms)
    gl, gsig = glauert_inflow(mu, ct, theta1c, theta1s, beta1c, beta1s, c_mc, c_ms)
    _, t3, _ = paper_table(3)
    k0 = t3["k0p"] - PUMA.a0s / (8 * PUMA.mu)
    return (
        SteadyInflow("momentum", tuple(map(float, mom)), note=assumed),
        SteadyInflow("momentum-mass-flow", tuple(map(float, mf)), gains=(("V", v),),
                     note=assumed + "; V the level-flight mass-flow parameter"),
        SteadyInflow("momentum-tilt", (tilt, float(mom[1]), float(mom[2])),
                     gains=(("muz", muz),),
                     note="lambda0 = C_T/(2 sqrt(mu^2 + (lambda0 - muz)^2))"),
        SteadyInflow("skewed-wake", tuple(map(float, sw)),
                     gains=(("chi", chi), ("k_skew", k)),
                     note=assumed + "; k_skew = 15 pi/64 tan(chi/2)"),
        SteadyInflow("glauert-table3", tuple(map(float, gl)), tuple(map(float, gsig)),
                     gains=(("kc", t3["kc"]), ("ks", t3["ks"]), ("k0", k0),
                            ("p*", float(beta1c + theta1s)), ("q*", float(theta1c - beta1s))),
                     note=assumed + "; G mu_xy = 0 at trim; Table 3 identified on the "
                          "Puma at mu 0.249"),
    )


__all__ = ["THEORIES", "LABELS", "SteadyInflow", "momentum_inflow", "momentum_inflow_tilted",
           "skewed_wake_inflow", "glauert_inflow", "steady_inflow_predictions"]
