"""``momentum-speed``: Eq. (14)'s speed through the disc, linearised exactly about the
trim over the whole disc (:mod:`inflowsim.physics.momentum_speed`).

The paper's Glauert augmentation (Eqs. 16-20) keeps two parts of Eq. (14)'s
perturbations: the first-harmonic blade normal velocity ``nu_lambda`` and the
in-plane speed, with free gains.  Linearised without those approximations at the
trim (flap, pitch and ``muz`` from the record's trim, the trim inflow solved with
Eq. 14's speed), Eq. (14) also changes the mass flow of every inflow harmonic,
couples the mean inflow to the mean normal velocity (``muz``, ``theta0``,
``beta0'``), and the harmonics to each other.  At ``mu = 0.10`` on the virtual Puma
the mean row's ``muz`` and ``theta0`` terms are 15-30 % of the basic model's,
the cyclic self-terms 0.16 against 1: a model without them fits the
individual-blade truth with ``n_beta`` 24 % and ``tau0`` 50 % off.

One parameter: ``k_V`` scales the whole linearised term (theory 1, neutral 0, the
paper's ``V = mu``), so the test is nested with one degree of freedom.  An
alternative to ``glauert`` (the same physics, approximated).  Not offered to the
diagnosis by default: ask for it by name (``--model ...+momentum-speed``).

The base model's speed through the disc (``k.flow_speed``) is the one whose gain the
coupling takes out, so with the mass-flow speed the effect reaches hover.  The FMU
runs it: the coupling is computed in its generated C when the matrices are built,
generated from the effect's declaration of the computation (:func:`_runtime`, the
same integrand, quadrature and Newton steps; :mod:`inflowsim.fmu.codegen`).
"""
from functools import lru_cache

import numpy as np

from ._effect import Effect, RuntimeSolve
from ._trim import true_trim_state
from ...physics import momentum_speed as ms
from ..equations import rotation
from ..params import ParameterSpec

NAME = "momentum-speed"


@lru_cache(maxsize=256)
def _coupling(mu, a0s, v, theta, beta, muz):
    lam = ms.eq14_trim_inflow(mu, a0s, theta, beta, muz, v=v)
    a, b = ms.speed_coupling(mu, a0s, theta, beta, muz, lam, v=v)
    lam = np.array(lam, dtype=float).reshape(3, 1)
    for x in (a, b, lam):
        x.flags.writeable = False
    return a, b, lam


def _linearised(k, azimuth_bias: float = 0.0):
    """``(A (3, 9), B (3, 10), lambda (3, 1))``: :func:`coupling` and the trim inflow
    it is linearised about, one computation (one run-time call in the FMU)."""
    theta, beta, muz = true_trim_state(k, azimuth_bias, NAME)
    args = (k.mu, k.a0s, k.flow_speed, *theta, *beta, muz)
    numeric = getattr(k, "numeric", None)
    if numeric is not None:
        return numeric(NAME, args, ((3, 9), (3, 10), (3, 1)))
    return _coupling(*map(float, args[:3]), tuple(map(float, theta)),
                     tuple(map(float, beta)), float(muz))


def coupling(k, azimuth_bias: float = 0.0):
    """``(A (3, 9), B (3, 10))`` the effect adds at ``k_V = 1`` (states ``beta,
    beta', lambda``; inputs ``INPUTS_AZ``, pitch true), at the trim of ``k`` with
    the base model's speed through the disc (``k.flow_speed``).

    Traced for the FMU's C (``k.numeric``, :mod:`inflowsim.fmu.codegen`), the
    coupling is a function call at run time: its arguments are the expressions here,
    its results symbols."""
    a, b, _ = _linearised(k, azimuth_bias)
    return a, b


def trim_inflow(k, azimuth_bias: float = 0.0):
    """The trim inflow ``(lambda0, lambda1c, lambda1s)`` [-] the effect linearises
    about: Eq. (14)'s momentum balance at the trim of ``k``
    (:func:`inflowsim.physics.momentum_speed.eq14_trim_inflow`).  The other effects
    linearised about the trim take it from here when the structure has this effect
    (``advance-ratio-perturbation``), so one structure has one trim."""
    return _linearised(k, azimuth_bias)[2][:, 0]


def _runtime():
    """The coupling as the FMU computes it at run time (:class:`RuntimeSolve`,
    arguments ``mu, a0 s, V, theta (3), beta (3), muz`` as :func:`_linearised` passes
    them): the same steps as :mod:`inflowsim.physics.momentum_speed`.  The unknowns
    are the trim inflow, from the base model's (``(I - L G_lambda) lambda = L
    blade``); Newton's method on Eq. (14)'s momentum balance ``blade + G_lambda
    lambda = c_mom`` (its step count and tolerance) with ``c_mom`` the disc
    quadrature of :func:`~inflowsim.physics.momentum_speed.speed_integrand`
    (``4/(a0 s) (sum w0 q, -sum c w1 q, -sum s w1 q)``); then ``-J`` with ``J = L
    dc_mom/d(z, u) - [0 0 I 0]`` and the trim inflow."""
    from ...physics import loads as ld
    pc, ps, pr, w0, w1 = ms.disc_points()

    def blade(arg):
        mu, theta, beta = arg[0], np.asarray(arg[3:6]), np.asarray(arg[6:9])
        return ld.g_theta(mu) @ theta + ld.g_beta(mu) @ beta + ld.g_nu(mu)[:, 0] * arg[9]

    def start(arg):
        lm = ld.momentum_l(arg[0], arg[1], arg[2])
        return np.eye(3) - lm @ ld.g_lambda(arg[0]), lm @ blade(arg)

    def w_of(arg, x):
        # z = (beta, beta' = 0, lambda), u = (theta, muz, 0, 0, 0, 0, mux = mu, 0)
        return [arg[6], arg[7], arg[8], 0, 0, 0, x[0], x[1], x[2], arg[3], arg[4],
                arg[5], arg[9], 0, 0, 0, 0, arg[0], 0]

    def outputs(arg, x, f, df):
        j = ld.momentum_l(arg[0], arg[1], arg[2]) @ np.asarray(df).reshape(3, 19)
        j[:, 6:9] -= np.eye(3)
        return -j[:, :9], -j[:, 9:], np.asarray(x).reshape(3, 1)

    return RuntimeSolve(
        n_args=10, shapes=((3, 9), (3, 10), (3, 1)), n_unknowns=3, n_w=19,
        integrand=lambda w, c, s, r, sqrt: ms.speed_integrand(w[:9], w[9:], c, s, r,
                                                               sqrt=sqrt),
        points=(pc, ps, pr), weights=np.array([w0, -(pc * w1), -(ps * w1)]),
        scale=lambda arg: 4.0 / arg[1], w_of=w_of, start=start,
        residual=lambda arg, x, f: blade(arg) + ld.g_lambda(arg[0]) @ np.asarray(x)
        - np.asarray(f),
        outputs=outputs, steps=ms.NEWTON_STEPS, tol=ms.NEWTON_TOL)


def _equations(eq, p, k):
    dpsi = p.get("azimuth_bias", 0.0)
    a, b = coupling(k, dpsi)
    s = p["k_V"]
    b = b.copy()
    # azimuth-bias is applied before this effect: the pitch columns are per
    # recorded pitch, the coupling's per true pitch R(-dpsi) theta_recorded
    b[:, 1:3] = b[:, 1:3] @ rotation(-dpsi)
    return eq.with_(p_beta=eq.p_beta + s * a[:, 0:3], p_dbeta=eq.p_dbeta + s * a[:, 3:6],
                    p_lambda=eq.p_lambda + s * a[:, 6:9], p_u=eq.p_u + s * b)


EFFECT = Effect.of_one(
    name=NAME,
    physics="The speed through the disc of Eq. (14) moves with the blade normal "
            "velocity and the inflow itself: linearised over the whole disc it changes "
            "the mass flow of every inflow harmonic and couples the mean inflow to "
            "collective, climb and coning rate, beyond the paper's Glauert terms.",
    paper="Eq. (14), linearised without the approximations of Eqs. (16)-(18)",
    theory=1.0,
    neutral=0.0,
    equations=_equations,
    uses_inplane=True,
    about_trim=True,
    runtime=_runtime,
    alternatives=("glauert",),
    offered=False,
    spec=ParameterSpec("k_V", "-", "scale of Eq. (14)'s linearised speed terms "
                       "(theory 1, neutral 0: the paper's V = mu)", -5.0, 5.0,
                       plausible=(0.5, 1.5, "the linearisation is exact for small "
                                            "perturbations: theory 1")),
)


__all__ = ["NAME", "coupling", "trim_inflow", "EFFECT"]
