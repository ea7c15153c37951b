"""Physics of the base matrices: every entry against numerical quadrature.

An independent route to ``inflowsim.physics.loads`` and ``inflowsim.physics.flapping``: the
blade-element integrals of model.md section 3 and the single-blade flap equation
are evaluated on a grid (Gauss-Legendre over ``r``, a uniform rule over ``psi``,
both exact for these polynomial / trigonometric integrands), with one unit
perturbation at a time.  No closed-form coefficient is written here.

Single-blade flap equation (flap hinge at the centre, spring in ``lambda_beta2``,
``gamma/2 = 4 n_beta``)::

    beta'' + lambda_beta2 beta = 4 n_beta int_0^1 r (theta U_T^2 + U_P U_T) dr
                                 + 2 (pbar cos psi - qbar sin psi)
                                 + qbar' cos psi + pbar' sin psi

(the last line: gyroscopic and hub-acceleration moments of the rotating blade).
Multiblade rows: ``(1/2pi) int d psi``, ``(1/pi) int cos psi d psi``,
``(1/pi) int sin psi d psi`` of the residual; no further normalisation, since the
single-blade ``beta''`` then projects with unit coefficient on each row (``m2 = I``).
"""
import numpy as np
import pytest

from inflowsim.physics import flapping as fl
from inflowsim.physics import loads as ld
MUS = [0.1, 0.2, 0.249, 0.35, 0.5]
ATOL = 1e-12

_X, _W = np.polynomial.legendre.leggauss(8)
R = 0.5 * (_X + 1.0)           # radius nodes on [0, 1]
WR = 0.5 * _W
PSI = 2 * np.pi * np.arange(64) / 64
RR, PP = np.meshgrid(R, PSI, indexing="ij")   # (n_r, n_psi)
COS, SIN = np.cos(PP), np.sin(PP)


def single_blade(mb, mb_rate, mb_acc):
    """Single-blade angle and its first two azimuth derivatives on the grid, from
    multiblade coordinates and their rates (product rule, d/dpsi)."""
    b0, bc, bs = mb
    d0, dc, ds = mb_rate
    a0, ac, as_ = mb_acc
    b = b0 + bc * COS + bs * SIN
    db = d0 + dc * COS + ds * SIN - bc * SIN + bs * COS
    ddb = (a0 + ac * COS + as_ * SIN - 2 * dc * SIN + 2 * ds * COS
           - bc * COS - bs * SIN)
    return b, db, ddb


def integrand(mu, state, mux=0.0, muy=0.0):
    """``F = theta U_T^2 + U_P U_T`` on the grid, and the single-blade flap."""
    beta, dbeta, ddbeta = single_blade(state["beta"], state["dbeta"], state["ddbeta"])
    th = state["theta"][0] + state["theta"][1] * COS + state["theta"][2] * SIN
    lam = state["lam"][0] + state["lam"][1] * RR * COS + state["lam"][2] * RR * SIN
    muz, qbar, pbar = state["nu"]
    ut = RR + (mu + mux) * SIN + muy * COS
    up = (muz - lam - RR * dbeta - (mu + mux) * beta * COS + muy * beta * SIN
          + RR * (pbar * SIN + qbar * COS))
    return th * ut**2 + up * ut, (beta, dbeta, ddbeta)


def radial(f, power):
    return np.einsum("r,rp->p", WR * R**power, f)


def avg(g):
    return g.mean(axis=-1)


def loads_quad(mu, state, **kw):
    """``(C_T, C_mc, C_ms)/(a0 s)`` by quadrature (model.md section 3)."""
    f, _ = integrand(mu, state, **kw)
    return np.array([0.5 * avg(radial(f, 0)),
                     -0.5 * avg(radial(f * COS, 1)),
                     -0.5 * avg(radial(f * SIN, 1))])


def flap_residual_quad(mu, n_beta, lambda_beta2, state, **kw):
    """Multiblade projections of the single-blade flap residual."""
    f, (beta, _, ddbeta) = integrand(mu, state, **kw)
    qdot, pdot = state["eta"]
    _, qbar, pbar = state["nu"]
    psi = PSI
    hub = 2 * (pbar * np.cos(psi) - qbar * np.sin(psi)) + qdot * np.cos(psi) + pdot * np.sin(psi)
    res = ddbeta[0] + lambda_beta2 * beta[0] - 4 * n_beta * radial(f, 1) - hub
    return np.array([avg(res), 2 * avg(res * np.cos(psi)), 2 * avg(res * np.sin(psi))])


def zero_state():
    return {k: np.zeros(n) for k, n in
            (("beta", 3), ("dbeta", 3), ("ddbeta", 3), ("theta", 3), ("lam", 3),
             ("nu", 3), ("eta", 2))}


def columns(fun, var, n):
    """Matrix whose column j is ``fun`` at a unit perturbation of ``var[j]``."""
    cols = []
    for j in range(n):
        s = zero_state()
        s[var][j] = 1.0
        cols.append(fun(s))
    return np.column_stack(cols)


def test_grid_is_exact_for_the_integrands():
    # int_0^1 r^7 dr and avg(cos^6): the highest degrees that occur are lower
    assert np.isclose(np.sum(WR * R**7), 1 / 8, rtol=0, atol=1e-15)
    assert np.isclose(avg(np.cos(PSI) ** 6), 5 / 16, rtol=0, atol=1e-15)


@pytest.mark.parametrize("mu", MUS)
@pytest.mark.parametrize("var, n, want", [
    ("dbeta", 3, ld.g_dbeta), ("beta", 3, ld.g_beta), ("theta", 3, ld.g_theta),
    ("nu", 3, ld.g_nu), ("lam", 3, ld.g_lambda)])
def test_load_matrices_against_quadrature(mu, var, n, want):
    got = columns(lambda s: loads_quad(mu, s), var, n)
    np.testing.assert_allclose(want(mu), got, rtol=0, atol=ATOL)


@pytest.mark.parametrize("mu", MUS)
def test_loads_are_linear_in_the_state(mu):
    # G matrices are exact, not only tangent: a random combined state
    rng = np.random.default_rng(int(mu * 1000))
    s = {k: rng.normal(size=v.size) for k, v in zero_state().items()}
    s["ddbeta"] = np.zeros(3)   # accelerations do not load the rotor
    want = (ld.g_dbeta(mu) @ s["dbeta"] + ld.g_beta(mu) @ s["beta"]
            + ld.g_theta(mu) @ s["theta"] + ld.g_nu(mu) @ s["nu"]
            + ld.g_lambda(mu) @ s["lam"])
    np.testing.assert_allclose(loads_quad(mu, s), want, rtol=0, atol=1e-11)


@pytest.mark.parametrize("mu", MUS)
@pytest.mark.parametrize("n_beta, lambda_beta2", [(0.987, 1.06), (0.6, 1.3)])
def test_flap_matrices_against_quadrature(mu, n_beta, lambda_beta2):
    res = lambda s: flap_residual_quad(mu, n_beta, lambda_beta2, s)  # noqa: E731
    np.testing.assert_allclose(columns(res, "ddbeta", 3), np.eye(3), rtol=0, atol=ATOL)
    np.testing.assert_allclose(columns(res, "dbeta", 3), fl.flap_c(mu, n_beta),
                               rtol=0, atol=ATOL)
    np.testing.assert_allclose(columns(res, "beta", 3),
                               fl.flap_d(mu, n_beta, lambda_beta2), rtol=0, atol=ATOL)
    # forcing moves to the right-hand side: residual columns are -H
    for var, n, h in (("lam", 3, fl.flap_h_lambda(mu, n_beta)),
                      ("theta", 3, fl.flap_h_theta(mu, n_beta)),
                      ("nu", 3, fl.flap_h_nu(mu, n_beta)),
                      ("eta", 2, fl.flap_h_eta())):
        np.testing.assert_allclose(-columns(res, var, n), h, rtol=0, atol=ATOL,
                                   err_msg=var)


def test_quadrature_sees_a_wrong_entry():
    # the route is sensitive: the scan's dropped /2 in G_theta would be caught
    mu = 0.249
    got = columns(lambda s: loads_quad(mu, s), "theta", 3)
    wrong = ld.g_theta(mu).copy()
    wrong[1, 1] = -1 / 8 - mu**2 / 16
    assert np.abs(got - wrong).max() > 1e-2
