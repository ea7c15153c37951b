"""``peters-he-6``, ``peters-he-10``, ``peters-he-15``: Peters-He finite-state inflow of
higher order, appended to the present three inflow states (``model.md`` section 9.4).

The present model's ``lambda0, lambda1c, lambda1s`` are the lowest Peters-He states
``sqrt(3) alpha_1^0, sqrt(15/2) alpha_2^1, sqrt(15/2) beta_2^1`` (the radial shape
functions ``sqrt(3)`` and ``sqrt(15/2) r``).  Each effect appends the states of the
truncation by highest radial power ``P = 2, 3, 4`` beyond these three (3, 7, 12
states: 6, 10, 15 inflow states in all), with the Peters-He apparent mass ``K_n^m``
and inflow gain ``L(X)`` of Peters & He's forward flight (``X = tan(chi/2)``, the wake
skew of the record's trim: the couplings between harmonics of the skewed wake, the
lowest three states' among them), forced by the blade-element pressure integrals of
:mod:`inflowsim.physics.peters_he`.

In ``alpha`` (all states, the first three the base)::

    K alpha' + V L^-1 alpha = tau / 2,   tau = a0 s w_m Q(beta, beta', theta, nu, alpha)

with ``w_m = 1/2`` for ``m = 0`` and 1 otherwise.  The base rows keep the present
model's own form (its time constants and the local-momentum ``L``, which is the
three-state Pitt-Peters gain); the effect adds, scaled by ``k_ph``:

- to the base inflow rows, the difference between the ``N``-state ``L^-1`` and the
  three-state one on the base states, the coupling ``L^-1`` to the higher states and
  the loads of the higher states' inflow (``p_lambda`` and ``l_x``);
- to the flap rows, the flap moments of the higher states' inflow (``f_x``);
- to the recorded ``lambda0, lambda1c, lambda1s``, the least-squares projection of the
  higher states' inflow on ``(1, r cos psi, r sin psi)`` (``to_output``);
- to the loads, the higher states' thrust and moments (:attr:`Effect.loads`).

``k_ph = 0`` is the present three-state structure exactly (the higher states still
move, but nothing sees them); ``k_ph = 1`` is Peters-He of that order.  The higher
states' own rows are Peters-He's unscaled.

The wake skew: ``X = tan(chi/2) = mu / (sqrt(mu^2 + w^2) + w)``, ``w = lambda0 - muz``
the trim flow down through the disc (``tan chi = mu / w``), with the structure's trim
inflow (:func:`.advance_ratio_perturbation.true_trim`, as ``lead-lag``'s): the effects
are linearised about the trim (``about_trim``; the FMU takes the trim as parameters and
computes ``X`` and ``L(X)`` in its C, and ``L(X)^-1`` by a run-time LU solve declared
here, :func:`_runtime`).  ``skewed-wake`` is an alternative: its
Pitt-Peters pair is the three-state part of the skew ``L(X)`` already carries (scaled
by ``k_ph`` with the rest), so the two are never combined (no skew counted twice).

Parameter ``k_ph`` [-]: theory 1, neutral 0.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ._effect import Effect, RuntimeLinear
from .advance_ratio_perturbation import true_trim
from ..equations import StateBlock, rotation
from ..params import ParameterSpec
from ...physics import loads as ld
from ...physics import peters_he as ph

#: Effect name -> highest radial power of its truncation.
POWERS = {"peters-he-6": 2, "peters-he-10": 3, "peters-he-15": 4}
#: Highest radial power -> effect name.
NAMES = {pw: n for n, pw in POWERS.items()}
#: The base states in Peters-He's variables: lambda_b = S alpha_b.
S_BASE = np.array([math.sqrt(3.0), math.sqrt(7.5), math.sqrt(7.5)])
#: The present model's (three-state Pitt-Peters) L^-1 in alpha: V L^-1 alpha = tau/2
#: gives lambda0 = C_T/(2V), (lambda1c, lambda1s) = -2 (C_mc, C_ms)/V.
LINV_BASE = np.array([1.5, 15.0 / 8.0, 15.0 / 8.0])
#: The base load rows from the pressure integrals: Q_b = T c/(a0 s).
T_BASE = np.array([math.sqrt(3.0), -math.sqrt(7.5), -math.sqrt(7.5)])


@lru_cache(maxsize=None)
def layout(power: int):
    """``(states, mass, w)`` of the truncation: states (``physics.peters_he``), the
    apparent masses, the ``tau`` weights."""
    states = ph.truncation(power)
    mass = np.array([ph.apparent_mass(m, n) for _, m, n in states])
    w = np.array([0.5 if m == 0 else 1.0 for _, m, _ in states])
    return states, mass, w


@lru_cache(maxsize=64)
def _linv_number(power: int, x: float) -> np.ndarray:
    out = np.linalg.inv(ph.gain_matrix(layout(power)[0], x))
    out.flags.writeable = False
    return out


def gain_inverse(power: int, x, numeric=None) -> np.ndarray:
    """``L(X)^-1`` of the truncation by ``power`` at wake skew ``X = tan(chi/2)`` [-]:
    LAPACK's for a number.  Traced on symbols for the FMU (``numeric``, the
    constants' ``k.numeric``), a run-time call: the generated C solves ``L(X) Y = I``
    by LU (:func:`_runtime`), its entries symbols of the call's result, so that the
    C holds ``L(X)``'s polynomials, not its inverse's rational functions."""
    if numeric is not None:
        n = len(layout(power)[0])
        return numeric(NAMES[power], (x,), ((n, n),))[0]
    return _linv_number(power, float(x))


def _runtime(power: int):
    """What the FMU computes at run time (:class:`RuntimeLinear`, one argument ``X``):
    ``L(X)^-1`` as the solution of ``L(X) Y = I``, ``L(X)`` the polynomial of
    :func:`inflowsim.physics.peters_he.gain_matrix`."""
    states = layout(power)[0]
    return RuntimeLinear(n_args=1, matrix=lambda arg: ph.gain_matrix(states, arg[0]),
                         rhs=lambda arg: np.eye(len(states)))


def wake_skew(p, k):
    """``X = tan(chi/2)`` [-] of constants ``k`` (its trim; one line naming the effect
    without one) and the structure's parameters ``p`` (the azimuth bias rotates the
    recorded trim, ``momentum-speed``'s ``k_V`` moves the trim inflow)."""
    theta, beta, muz, lam = true_trim(k, p.get("azimuth_bias", 0.0), p.get("k_V"))
    return ph.wake_skew_x(k.mu, lam[0] - muz)


def names(power: int) -> tuple:
    return ph.state_names(layout(power)[0][3:])


def parts(power, mu, v, a0s, n_beta, k_ph, n_inputs=10, azimuth_bias=None, x=0.0,
          numeric=None):
    """Every term of the effect (azimuth time), on numbers or sympy symbols, at wake
    skew ``x = tan(chi/2)`` [-] (0: axial flow); ``numeric`` (traced for the FMU)
    makes ``L(x)^-1`` a run-time call (:func:`gain_inverse`).

    Returns ``dict`` with ``p_lambda`` (3x3 added to the base's), ``block`` (the
    :class:`StateBlock` fields ``e, a, a_z, b, f_x, l_x, to_output``) and ``loads``
    (3 x m, over ``a0 s``)."""
    states, mass, w = layout(power)
    linv = gain_inverse(power, x, numeric)
    q = ph.forces(states).at(mu)                    # (n, 12 + n)
    fl = ph.flap_forces(states).at(mu)              # (3, 12 + n)
    sinv = 1.0 / S_BASE
    b_, h_ = slice(0, 3), slice(3, None)
    col = 12                                        # first state column of q
    half = (a0s / 2.0) * w[:, None]                 # tau/2 = (a0 s/2) w Q
    qz = half * q                                   # (n, 12 + n)
    # higher rows: K_h alpha_h' = -V Linv_h alpha + tau_h/2
    e = np.diag(mass[h_])
    a = -v * linv[h_, h_] + qz[h_, col + 3:]
    a_lam = (-v * linv[h_, b_] + qz[h_, col:col + 3]) * sinv[None, :]
    a_z = np.hstack([qz[h_, 0:3], a_lam, qz[h_, 3:6]])
    b = np.hstack([qz[h_, 6:12], np.zeros((len(states) - 3, max(n_inputs - 6, 0)))])
    if azimuth_bias is not None:
        # the model takes recorded pitch: the true pitch drives the rotor (model.md 6)
        b = np.hstack([b[:, :1], b[:, 1:3] @ rotation(-azimuth_bias), b[:, 3:]])
    # base rows in the present model's form: multiply by S (V Linv_base)^-1
    dv = (S_BASE / LINV_BASE)[:, None]              # D V
    p_lambda = -k_ph * dv * (linv[b_, b_] - np.diag(LINV_BASE)) * sinv[None, :]
    l_x = -k_ph * dv * (linv[b_, h_] - (qz[b_, col + 3:]) / v)
    f_x = k_ph * 4.0 * n_beta * fl[:, col + 3:]
    proj = ph.linear_projection(states)[:, 3:]
    to_output = np.vstack([np.zeros((3, len(states) - 3)), k_ph * proj])
    # loads of the higher states' inflow; the base states are the recorded inflow
    # (to_output is a change of variables), so the base rows' G_lambda lambda counts
    # the projection once too many
    loads = k_ph * (q[b_, col + 3:] / T_BASE[:, None] - ld.g_lambda(mu) @ proj)
    return {"p_lambda": p_lambda, "e": e, "a": a, "a_z": a_z, "b": b, "f_x": f_x,
            "l_x": l_x, "to_output": to_output, "loads": loads}


def _effect(name: str, power: int) -> Effect:
    state_names = names(power)

    def equations(eq, p, k):
        t = parts(power, k.mu, k.flow_speed, k.a0s, p["n_beta"], p["k_ph"],
                  eq.h_u.shape[1], p.get("azimuth_bias"), wake_skew(p, k),
                  getattr(k, "numeric", None))
        bl = StateBlock(effect=name, states=state_names, e=t["e"], a=t["a"],
                        a_z=t["a_z"], b=t["b"], f_x=t["f_x"], l_x=t["l_x"],
                        to_output=t["to_output"])
        return eq.with_(p_lambda=eq.p_lambda + t["p_lambda"], blocks=eq.blocks + (bl,))

    def loads(p, k):
        return parts(power, k.mu, k.flow_speed, k.a0s, p["n_beta"], p["k_ph"])["loads"]

    n_total = len(state_names) + 3
    return Effect.of_one(
        name=name,
        physics=f"The induced inflow has more radial and harmonic shape than the linear "
                f"lambda0 + r (lambda1c cos + lambda1s sin): Peters-He finite-state "
                f"inflow with {n_total} states (highest radial power {power}) and the "
                "skewed wake's couplings between its harmonics, its higher states and "
                "skew coupled to flap and the recorded inflow by k_ph.",
        paper="extension (Peters & He 1991, 1995 finite-state inflow)",
        theory=1.0,
        neutral=0.0,
        equations=equations,
        spec=SPEC,
        alternatives=tuple(n for n in POWERS if n != name) + ("skewed-wake",),
        # the lowest order only: its detection study (bench/rotor-physics.md) named it
        # first and raised no alarm; higher orders are asked for by name
        offered=(power == min(POWERS.values())),
        about_trim=True,
        states=state_names,
        loads=loads,
        runtime=lambda: _runtime(power),
    )


SPEC = ParameterSpec("k_ph", "-", "coupling of the higher Peters-He inflow states (1: "
                     "Peters-He, 0: the three-state model)", -1.0, 5.0,
                     plausible=(0.3, 2.0, "the higher inflow states' coupling within a "
                                "factor of about 3 of Peters-He's"))

EFFECTS = tuple(_effect(n, pw) for n, pw in POWERS.items())


__all__ = ["POWERS", "NAMES", "S_BASE", "LINV_BASE", "T_BASE", "layout", "gain_inverse", "wake_skew",
           "names", "parts", "SPEC", "EFFECTS"]
