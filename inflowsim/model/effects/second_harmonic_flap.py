"""``second-harmonic-flap``: the blades' 2/rev flapping, condensed into Eq. (1).

The multiblade model (1) keeps each blade's flap to its first harmonic.  But each
blade's equation has periodic coefficients (``U_T = r + mu sin psi``, ``- mu beta
cos psi`` in ``U_P``): the cyclic flap, inflow and pitch force a 2/rev flap
``beta2c, beta2s`` at order ``mu``, and that flap forces the rows of Eq. (1) and
the loads of Eq. (4) back at order ``mu`` (:mod:`inflowsim.physics.harmonics`).
The round trip changes the tip-path-plane response by order ``mu^2``: about 1 %
at ``mu = 0.25``, well above the noise of a 256 Hz record.

The 2/rev flap's own modes lie near 1/rev and 3/rev in the fixed frame
(``C2 beta2' + D2 beta2``, ``D2 ~ lambda_beta2 - 4``), above the band the model is
used in, so it is condensed quasi-statically: ``D2 beta2 = F_dbeta beta' +
F_beta beta + F_lambda lambda + F_u u``, substituted into

* the flap rows: ``C -= k N D2^-1 F_dbeta``, ``D -= k N D2^-1 F_beta``,
  ``H_lambda += k N D2^-1 F_lambda``, ``H_u += k N D2^-1 F_u``;
* the inflow forcing, through the loads: ``P_x += k L G_beta2 D2^-1 F_x``.

The state does not grow (six states, nine with ``flap-inertia``), so every tool,
the FMU included, runs it unchanged.  Measured on the individual-blade truth
(``bench/harmonic_flap.py``, mu = 0.249, 256 Hz): the constant-coefficient model
leaves 2.0e-5 to 5.0e-5 of the flap power in the band; with the 2/rev flap
condensed, 4.8e-7 to 2.0e-6; kept as two more states, 3e-8 to 1e-7.

Parameter ``k_beta2`` [-]: a scale on all the condensed terms, theory 1 (the
harmonic balance), neutral 0 (the paper's first-harmonic flap), so the test of
the effect is nested with one degree of freedom.
"""
import numpy as np

from ._effect import Effect
from ...physics import harmonics as hm
from ...physics import loads as ld
from ..equations import rotation
from ..params import ParameterSpec

NAME = "second-harmonic-flap"


def _inverse2(m):
    """The inverse of a 2 x 2 array, written out so it also runs on symbols (the
    FMU's C is generated from this code)."""
    det = m[0, 0] * m[1, 1] - m[0, 1] * m[1, 0]
    return np.array([[m[1, 1], -m[0, 1]], [-m[1, 0], m[0, 0]]]) / det


def condensed(mu, n_beta, lambda_beta2):
    """``(S_dbeta, S_beta, S_lambda, S_u)``: the quasi-steady 2/rev flap,
    ``beta2 = S_dbeta beta' + S_beta beta + S_lambda lambda + S_u u`` (shapes
    (2, 3), (2, 3), (2, 3), (2, 8))."""
    d2inv = _inverse2(hm.flap2_d(n_beta, lambda_beta2))
    return tuple(d2inv @ f for f in hm.flap2_forcing(mu, n_beta))


def quasi_steady(p, k):
    """:func:`condensed` for parameters ``p`` (by name) and constants ``k``, its
    pitch columns acting on the recorded cyclic pitch where the structure has
    ``azimuth-bias`` (the blades feel the true one; azimuth-bias rotates the other
    pitch columns the same way)."""
    s_db, s_b, s_l, s_u = condensed(k.mu, p["n_beta"], p["lambda_beta2"])
    if "azimuth_bias" in p:
        s_u = np.hstack([s_u[:, :1], s_u[:, 1:3] @ rotation(-p["azimuth_bias"]),
                         s_u[:, 3:]])
    return s_db, s_b, s_l, s_u


def in_loads(p, k):
    """``k_beta2 G_beta2 [S_dbeta, S_beta, S_lambda, S_u]``, shape (3, 17): the
    quasi-steady 2/rev flap's term in ``c = (C_T, C_mc, C_ms)/(a0 s)`` of Eq. (4),
    by ``beta'``, ``beta``, ``lambda`` and the eight inputs in azimuth units
    (:mod:`inflowsim.model.loads` and the FMU's loads add it)."""
    g, _ = hm.flap2_into_loads(k.mu)
    return np.hstack([p["k_beta2"] * g @ s for s in quasi_steady(p, k)])


def _equations(eq, p, k):
    s_db, s_b, s_l, s_u = quasi_steady(p, k)
    n, _ = hm.flap2_into_flap(k.mu, p["n_beta"])
    g, _ = hm.flap2_into_loads(k.mu)
    nk = p["k_beta2"] * n
    lg = p["k_beta2"] * (ld.momentum_l(k.mu, k.a0s, k.flow_speed) @ g)
    nu = s_u.shape[1]
    return eq.with_(
        c=eq.c - nk @ s_db, d=eq.d - nk @ s_b, h_lambda=eq.h_lambda + nk @ s_l,
        h_u=np.hstack([eq.h_u[:, :nu] + nk @ s_u, eq.h_u[:, nu:]]),
        p_dbeta=eq.p_dbeta + lg @ s_db, p_beta=eq.p_beta + lg @ s_b,
        p_lambda=eq.p_lambda + lg @ s_l,
        p_u=np.hstack([eq.p_u[:, :nu] + lg @ s_u, eq.p_u[:, nu:]]))


EFFECT = Effect(
    name=NAME,
    physics="The blades' 2/rev flapping: each blade's periodic coefficients turn the "
            "cyclic flap, inflow and pitch into a 2/rev flap that acts back on the "
            "tip-path plane and the hub loads (order mu^2), which the first-harmonic "
            "multiblade flap drops.",
    paper="extension: Eq. (1) truncates each blade's flap at its first harmonic",
    parameters=("k_beta2",),
    theory=lambda k: {"k_beta2": 1.0},
    neutral=lambda k: {"k_beta2": 0.0},
    equations=_equations,
    specs=(ParameterSpec("k_beta2", "-", "scale of the 2/rev blade flap's coupling "
                         "with the multiblade flap and the loads (theory 1, neutral 0)",
                         -10.0, 10.0,
                         plausible=(0.5, 1.5, "the harmonic balance of the blade "
                                              "equation: theory 1")),),
)


__all__ = ["NAME", "condensed", "quasi_steady", "in_loads", "EFFECT"]
