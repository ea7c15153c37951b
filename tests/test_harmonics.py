"""The blades' 2/rev flap (``second-harmonic-flap``, issue #9): every coefficient of
:mod:`inflowsim.physics.harmonics` against two independent routes.

1. Quadrature: the single-blade flap equation and the loads of ``model.md``
   (the same integrands as ``tests/test_quadrature.py``) on a Gauss-Legendre x
   uniform-azimuth grid, exact for these trigonometric polynomials, with the blade
   flap written to its second harmonic; one unit perturbation at a time.
2. The individual-blade truth's own right-hand side, averaged over the azimuth
   (:func:`inflowsim.flighttest.averaging.averaged_system`, finite differences):
   the effect's structure must be that system with the 2/rev flap quasi-steady,
   entry by entry, and close to the dynamic one over the identification band.
"""
import dataclasses

import numpy as np
import pytest

from inflowsim.channels import input_scale
from inflowsim.flighttest.averaging import averaged_system, condense
from inflowsim.flighttest.bladesim import BladeRotor, RotorSpec
from inflowsim.model.build import build_model
from inflowsim.model.params import PUMA
from inflowsim.physics import harmonics as hm

MUS = [0.1, 0.249, 0.35, 0.5]
ATOL = 1e-12
_X, _W = np.polynomial.legendre.leggauss(8)
R, WR = 0.5 * (_X + 1.0), 0.5 * _W
PSI = 2 * np.pi * np.arange(64) / 64
RR, PP = np.meshgrid(R, PSI, indexing="ij")
HARM = [np.ones_like(PSI), np.cos(PSI), np.sin(PSI), np.cos(2 * PSI), np.sin(2 * PSI)]
DHARM = [np.zeros_like(PSI), -np.sin(PSI), np.cos(PSI), -2 * np.sin(2 * PSI),
         2 * np.cos(2 * PSI)]
D2HARM = [np.zeros_like(PSI), -np.cos(PSI), -np.sin(PSI), -4 * np.cos(2 * PSI),
          -4 * np.sin(2 * PSI)]
SIZES = {"beta": 5, "dbeta": 5, "ddbeta": 5, "theta": 3, "lam": 3, "u": 5}


def blade(s):
    """Single-blade flap and its azimuth derivatives from five harmonics."""
    b, d, a = s["beta"], s["dbeta"], s["ddbeta"]
    beta = sum(b[i] * HARM[i] for i in range(5))
    dbeta = sum(d[i] * HARM[i] + b[i] * DHARM[i] for i in range(5))
    ddbeta = sum(a[i] * HARM[i] + 2 * d[i] * DHARM[i] + b[i] * D2HARM[i] for i in range(5))
    return beta, dbeta, ddbeta


def integrand(mu, s):
    beta, dbeta, _ = blade(s)
    c, sn = np.cos(PP), np.sin(PP)
    th = s["theta"][0] + s["theta"][1] * c + s["theta"][2] * sn
    lam = s["lam"][0] + RR * (s["lam"][1] * c + s["lam"][2] * sn)
    muz, qbar, pbar = s["u"][:3]
    ut = RR + mu * sn
    up = muz - lam - RR * dbeta - mu * beta * c + RR * (qbar * c + pbar * sn)
    return th * ut**2 + up * ut


def residual(mu, n_beta, lambda_beta2, s):
    """The single-blade flap equation's residual projected on ``1, 2 cos, 2 sin,
    2 cos 2, 2 sin 2`` of the azimuth."""
    beta, _, ddbeta = blade(s)
    _, qbar, pbar, qdot, pdot = s["u"]
    hub = 2 * (pbar * np.cos(PSI) - qbar * np.sin(PSI)) + qdot * np.cos(PSI) \
        + pdot * np.sin(PSI)
    moment = 4 * n_beta * np.einsum("r,rp->p", WR * R, integrand(mu, s))
    res = ddbeta + lambda_beta2 * beta - moment - hub
    return np.array([np.mean(res * h) * (1 if i == 0 else 2) for i, h in enumerate(HARM)])


def loads(mu, s):
    f = integrand(mu, s)
    c, sn = np.cos(PP), np.sin(PP)
    return np.array([0.5 * np.mean(np.einsum("r,rp->p", WR, f)),
                     -0.5 * np.mean(np.einsum("r,rp->p", WR * R, f * c[0])),
                     -0.5 * np.mean(np.einsum("r,rp->p", WR * R, f * sn[0]))])


def columns(fun, var, idx):
    out = []
    for j in idx:
        s = {k: np.zeros(n) for k, n in SIZES.items()}
        s[var][j] = 1.0
        out.append(fun(s))
    return np.column_stack(out)


def inputs_u(fun):
    """Columns ``theta0, theta1c, theta1s, muz, qbar, pbar, qbar', pbar'``."""
    return np.hstack([columns(fun, "theta", range(3)), columns(fun, "u", range(5))])


@pytest.mark.parametrize("mu", MUS)
@pytest.mark.parametrize("n_beta, lambda_beta2", [(0.987, 1.06), (0.6, 1.3)])
def test_second_harmonic_rows_against_quadrature(mu, n_beta, lambda_beta2):
    res = lambda s: residual(mu, n_beta, lambda_beta2, s)[3:]  # noqa: E731
    np.testing.assert_allclose(columns(res, "ddbeta", [3, 4]), np.eye(2), atol=ATOL)
    np.testing.assert_allclose(columns(res, "dbeta", [3, 4]), hm.flap2_c(n_beta),
                               atol=ATOL)
    np.testing.assert_allclose(columns(res, "beta", [3, 4]),
                               hm.flap2_d(n_beta, lambda_beta2), atol=ATOL)
    f_dbeta, f_beta, f_lambda, f_u = hm.flap2_forcing(mu, n_beta)
    # forcing moves to the right-hand side: residual columns are -F
    np.testing.assert_allclose(-columns(res, "dbeta", range(3)), f_dbeta, atol=ATOL)
    np.testing.assert_allclose(-columns(res, "beta", range(3)), f_beta, atol=ATOL)
    np.testing.assert_allclose(-columns(res, "lam", range(3)), f_lambda, atol=ATOL)
    np.testing.assert_allclose(-inputs_u(res), f_u, atol=ATOL)
    # the first-harmonic accelerations do not enter the 2/rev rows
    np.testing.assert_allclose(columns(res, "ddbeta", range(3)), 0.0, atol=ATOL)


@pytest.mark.parametrize("mu", MUS)
def test_second_harmonic_in_the_rows_of_eq1_and_the_loads(mu):
    n_beta = 0.987
    res = lambda s: residual(mu, n_beta, 1.06, s)[:3]  # noqa: E731
    n, n_dot = hm.flap2_into_flap(mu, n_beta)
    np.testing.assert_allclose(-columns(res, "beta", [3, 4]), n, atol=ATOL)
    np.testing.assert_allclose(-columns(res, "dbeta", [3, 4]), n_dot, atol=ATOL)
    np.testing.assert_allclose(columns(res, "ddbeta", [3, 4]), 0.0, atol=ATOL)
    g, g_dot = hm.flap2_into_loads(mu)
    ld_ = lambda s: loads(mu, s)  # noqa: E731
    np.testing.assert_allclose(columns(ld_, "beta", [3, 4]), g, atol=ATOL)
    np.testing.assert_allclose(columns(ld_, "dbeta", [3, 4]), g_dot, atol=ATOL)
    # the route is sensitive: a term of order mu, and at mu^2 in the thrust
    assert abs(g[0, 1]) > 1e-3 and abs(n[1, 0]) > 1e-2


@pytest.fixture(scope="module", params=[0.15, 0.249])
def truth(request):
    """The Puma truth with ``V = mu`` (linear), 16 blades, and its averaged systems
    with the flap to harmonics 1 and 2."""
    k = dataclasses.replace(PUMA, mu=request.param)
    spec = RotorSpec(constants=k, speed="mu", n_blades=16)
    rotor = BladeRotor(spec)
    par = dict(lambda_beta2=spec.lambda_beta2, n_beta=spec.n_beta, tau0=spec.tau0,
               tau_cs=spec.tau_cs, flap_inertia=1.0)
    return k, par, averaged_system(rotor, 1), averaged_system(rotor, 2)


#: the model's state order (beta, lambda, beta') in the averaged order (b, b', lambda)
PERM = [0, 1, 2, 6, 7, 8, 3, 4, 5]
STRUCTURE = "basic+flap-inertia+separate-time-constants"


def averaged_model(structure, par, k):
    m = build_model(structure, par, k)
    scale = input_scale(k.omega)[:8]
    return m.a[np.ix_(PERM, PERM)] / k.omega, m.b[PERM, :8] / k.omega / scale


def test_the_effect_is_the_truths_2rev_flap_quasi_steady(truth):
    k, par, (a1, b1), (a2, b2) = truth
    a, b = averaged_model(STRUCTURE + "+second-harmonic-flap", par | {"k_beta2": 1.0}, k)
    ac, bc = condense(a2, b2, [3, 4, 8, 9])
    np.testing.assert_allclose(a, ac, rtol=0, atol=1e-9)
    np.testing.assert_allclose(b, bc, rtol=0, atol=1e-9)
    # without it the model is the first-harmonic average, and that differs
    a0, b0 = averaged_model(STRUCTURE, par, k)
    np.testing.assert_allclose(a0, a1, rtol=0, atol=1e-9)
    np.testing.assert_allclose(b0, b1, rtol=0, atol=1e-9)
    assert np.abs(ac - a1).max() > 1e-3


def test_quasi_steady_2rev_flap_is_the_dynamic_one_in_the_band(truth):
    """The 2/rev flap's own modes lie near 1/rev; over the identification band
    (to 1.58 Hz, 0.36/rev at the Puma's 27.5 rad/s) the quasi-steady form carries
    most of the effect: its error is a fraction of what the effect changes."""
    k, par, (a1, b1), (a2, b2) = truth
    a, b = averaged_model(STRUCTURE + "+second-harmonic-flap", par | {"k_beta2": 1.0}, k)
    a0, b0 = averaged_model(STRUCTURE, par, k)
    w = 2 * np.pi * np.linspace(0.2256, 1.58, 25) / k.omega      # per azimuth rad

    def resp(a, b, flap):
        return np.array([np.linalg.solve(1j * wi * np.eye(len(a)) - a, b[:, :3])[flap]
                         for wi in w])

    dyn = resp(a2, b2, [0, 1, 2])
    effect = np.abs(dyn - resp(a0, b0, [0, 1, 2])).max()
    error = np.abs(dyn - resp(a, b, [0, 1, 2])).max()
    assert error < 0.35 * effect, (error, effect)
    assert effect > 1e-3 * np.abs(dyn).max()


def test_recorded_pitch_is_rotated_to_the_true_one_under_azimuth_bias():
    """With ``azimuth-bias`` the model takes the recorded cyclic pitch; every
    pitch column, the 2/rev flap's included, must act on the true one."""
    k = PUMA
    par = dict(lambda_beta2=1.06, n_beta=0.987, tau=1.0, k_beta2=1.0)
    m0 = build_model("basic+second-harmonic-flap", par, k)
    m1 = build_model("basic+azimuth-bias+second-harmonic-flap",
                     par | {"azimuth_bias": 0.3}, k)
    r = np.array([[np.cos(0.3), np.sin(0.3)], [-np.sin(0.3), np.cos(0.3)]])  # R(-0.3)
    np.testing.assert_allclose(m1.b[:, 1:3], m0.b[:, 1:3] @ r, rtol=0, atol=1e-12)
    np.testing.assert_allclose(m1.a, m0.a, rtol=0, atol=1e-12)


def test_loads_carry_the_2rev_flap_as_the_truth_does(truth):
    """The loads out (:func:`inflowsim.model.loads.load_matrices`) against the
    blade loads the averaged truth feeds its inflow states: ``c = M lambda' +
    L^-1 lambda`` from its inflow rows, with and without the 2/rev flap."""
    from inflowsim.model.loads import load_matrices
    k, par, (a1, b1), (a2, b2) = truth
    rotor = BladeRotor(RotorSpec(constants=k, speed="mu", n_blades=16))
    m_mat = np.linalg.inv(rotor.minv)
    scale = input_scale(k.omega)[:8]

    def blade_loads(a, b):
        lam = np.zeros((3, a.shape[0]))
        lam[:, 6:9] = np.eye(3)
        return m_mat @ a[6:9] + rotor.linv @ lam, m_mat @ b[6:9]

    for structure, extra, (a, b) in ((STRUCTURE, {}, (a1, b1)),
                                     (STRUCTURE + "+second-harmonic-flap", {"k_beta2": 1.0},
                                      condense(a2, b2, [3, 4, 8, 9]))):
        lm = load_matrices(build_model(structure, par | extra, k))
        cx, cu = blade_loads(a, b)
        a0s = k.a0 * k.solidity                   # the truth's c is per a0 s
        np.testing.assert_allclose(lm.c[:3][:, PERM] / a0s, cx, rtol=0, atol=1e-9,
                                   err_msg=structure)
        np.testing.assert_allclose(lm.d[:3, :8] / scale / a0s, cu, rtol=0, atol=1e-9,
                                   err_msg=structure)
    # and the 2/rev flap's term is there to be seen
    assert np.abs(blade_loads(a1, b1)[0]
                  - blade_loads(*condense(a2, b2, [3, 4, 8, 9]))[0]).max() > 1e-5
