"""``glauert``: Glauert augmentation ``F nu_lambda + G mu_xy``, Eqs. (14)-(20).

``nu_lambda = (p* - lambda1s, q* - lambda1c)`` with
``p* = pbar + beta1c - beta1s' + theta1s`` and ``q* = qbar - beta1s - beta1c' + theta1c``;
``F = [[ks, kc], [0, k0], [k0, 0]]``, ``G = [[c1, c2], [-c3, c4], [c4, c3]]``.
``k0`` is parameterised as ``k0p = k0 + a0 s/(8 mu)`` (``model.md`` section 5).
"""
import numpy as np

from ._effect import Effect, ParameterSpec

_LARGE = (-5.0, 5.0, "a Glauert gain this large is not physical")

NAMES = ("c1", "c2", "c3", "c4", "k0p", "kc", "ks")
# state / input column indices
B1C, B1S, L1C, L1S = 1, 2, 1, 2
TH1C, TH1S, QBAR, PBAR, MUX, MUY = 1, 2, 4, 5, 8, 9


def f_matrix(p, a0s, v):
    """``F`` of Eq. (19); ``v`` the speed through the disc of the momentum gains."""
    k0 = p["k0p"] - a0s / (8 * v)
    return np.array([[p["ks"], p["kc"]], [0.0, k0], [k0, 0.0]])


def g_matrix(p):
    return np.array([[p["c1"], p["c2"]], [-p["c3"], p["c4"]], [p["c4"], p["c3"]]])


def _equations(eq, p, k):
    f = f_matrix(p, k.a0s, k.flow_speed)
    fp, fq = f[:, 0], f[:, 1]          # columns multiplying p* - l1s and q* - l1c
    p_dbeta, p_beta, p_lambda, p_u = (eq.p_dbeta.copy(), eq.p_beta.copy(),
                                      eq.p_lambda.copy(), eq.p_u.copy())
    # beta' terms: -beta1s' in p*, -beta1c' in q*
    p_dbeta[:, B1S] -= fp
    p_dbeta[:, B1C] -= fq
    p_beta[:, B1C] += fp
    p_beta[:, B1S] -= fq
    p_lambda[:, L1S] -= fp
    p_lambda[:, L1C] -= fq
    p_u[:, TH1S] += fp
    p_u[:, PBAR] += fp
    p_u[:, TH1C] += fq
    p_u[:, QBAR] += fq
    p_u[:, MUX:MUY + 1] += g_matrix(p)
    return eq.with_(p_dbeta=p_dbeta, p_beta=p_beta, p_lambda=p_lambda, p_u=p_u)


def _theory(k):
    t = dict.fromkeys(NAMES, 0.0)
    t["k0p"] = k.a0s / (8 * k.flow_speed)      # neutral: k0 = 0, not k0p = 0
    return t


EFFECT = Effect(
    name="glauert",
    physics="The blade's own normal velocity (flap, pitch and hub rates) enters the "
            "speed through the disc, so the cyclic inflow is forced by p*, q* and by "
            "the in-plane velocity (Glauert-type augmentation).",
    paper="Eqs. (14)-(20)",
    parameters=NAMES,
    theory=_theory,
    equations=_equations,
    specs=(*(ParameterSpec(f"c{i}", "-", f"Glauert G coefficient c{i} (Eq. 19)",
                           plausible=_LARGE) for i in range(1, 5)),
           ParameterSpec("k0p", "-", "k0 + a0 s/(8 mu), Glauert F (Eq. 19)",
                         plausible=(-1.0, 2.0, "k0 + a0 s/(8 mu) lies near a0 s/(8 mu)")),
           ParameterSpec("kc", "-", "Glauert F coefficient kc (Eq. 19)", plausible=_LARGE),
           ParameterSpec("ks", "-", "Glauert F coefficient ks (Eq. 19)", plausible=_LARGE)),
    uses_inplane=True,
    alternatives=("hub-velocity-coupling",),
    # F nu_lambda (flap, pitch and hub rates) and G mu_xy (in-plane velocities) are
    # two terms of Eq. (19): a record without in-plane motion still tests F
    parts=(("k0p", "kc", "ks"), ("c1", "c2", "c3", "c4")),
)


__all__ = ["NAMES", "f_matrix", "g_matrix", "EFFECT"]
