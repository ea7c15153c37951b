"""The nonlinear individual-blade truth (inflowsim.flighttest.bladesim)."""
import numpy as np
import pytest

from inflowsim.flighttest.bladesim import BladeRotor, RotorSpec, multiblade_derivatives
from inflowsim.model.equations import assemble
from inflowsim.errors import InputError
from inflowsim.model import equations
from inflowsim.physics.multiblade import multiblade
from inflowsim.model.params import PUMA

U_TRIM = np.array([0.17, 0.01, -0.05, 0.0, 0.0, 0.0, 0.0, 0.0, 0.249, 0.0])


def _state(rot, rng):
    nb = rot.nb
    return np.concatenate([0.1 + 0.05 * rng.standard_normal(nb),
                           0.05 * rng.standard_normal(nb),
                           [0.02, -0.004, 0.006]])


def _inputs(rng):
    u = U_TRIM + 0.01 * rng.standard_normal(10)
    return tuple(u)


def _fd_jacobian(f, w0, eps=1e-6):
    cols = []
    for j in range(len(w0)):
        dw = np.zeros(len(w0))
        dw[j] = eps
        cols.append((f(w0 + dw) - f(w0 - dw)) / (2 * eps))
    return np.array(cols).T


def _jacobian(speed, at="mu"):
    """Jacobian of the azimuth-averaged multiblade equations at the trim of ``at``."""
    rot = BladeRotor(RotorSpec(n_blades=16, speed=speed))    # 16 blades: averaged
    tr = BladeRotor(RotorSpec(n_blades=16, speed=at)).periodic_trim(U_TRIM)
    w0 = np.concatenate([tr.beta, np.zeros(3), tr.lam, U_TRIM])
    return _fd_jacobian(lambda w: multiblade_derivatives(rot, 0.3, w[:9], w[9:]), w0)


def _linear_second_order(spec):
    """``basic`` + separate time constants with the multiblade ``beta''`` kept."""
    p = {"lambda_beta2": spec.lambda_beta2, "n_beta": spec.n_beta, "tau0": spec.tau0,
         "tau_cs": spec.tau_cs}
    _, _, eq, _ = equations("basic+separate-time-constants", p, PUMA)
    e, a, b = assemble(eq.with_(m2=np.eye(3)), True)
    ea, eb = np.linalg.solve(e, a), np.linalg.solve(e, b)
    rows, cols = [6, 7, 8, 3, 4, 5], [0, 1, 2, 6, 7, 8, 3, 4, 5]   # -> (beta'', lambda')
    return np.hstack([ea[np.ix_(rows, cols)], eb[rows, :]])


def test_linearised_multiblade_equations_are_eq1_and_eq2_when_v_is_mu():
    # the basic model's every coefficient (states and the eight base inputs)
    # comes out of the blade-element truth; mux, muy columns are extra physics
    jac = _jacobian("mu")
    lin = _linear_second_order(RotorSpec())
    np.testing.assert_allclose(jac[:, :17], lin[:, :17], atol=1e-8)
    assert np.max(np.abs(jac[:, 17:])) > 0.1       # advance-ratio perturbation


def test_eq14_speed_gives_glauert_structure():
    # the speed-dependent part of the inflow equations has the paper's Eq. (19)
    # structure: q* = qbar - beta1s - beta1c' + theta1c and p* = pbar + beta1c -
    # beta1s' + theta1s enter together, F = [[ks, kc], [0, k0], [k0, 0]]
    d = _jacobian("eq14", at="eq14") - _jacobian("mu", at="eq14")
    assert np.max(np.abs(d[:3])) < 1e-8              # flap equations untouched
    b1c, b1s, db1c, db1s, th1c, th1s, qb, pb = 1, 2, 4, 5, 10, 11, 13, 14
    # exact: the rates enter only through the blade normal velocity
    np.testing.assert_allclose(d[3:, db1c], -d[3:, qb], atol=1e-9)
    np.testing.assert_allclose(d[3:, db1s], -d[3:, pb], atol=1e-9)
    # up to the mux products of T1, T2, theta0* (Eq. 15): a few per cent
    k0_c, k0_s = d[4, qb], d[5, pb]
    np.testing.assert_allclose(d[4, [b1s, th1c]], [-k0_c, k0_c], rtol=0.05)
    np.testing.assert_allclose(d[5, [b1c, th1s]], [k0_s, k0_s], rtol=0.1)
    assert abs(k0_c) > 1e-2 and k0_c == pytest.approx(k0_s, rel=0.2)
    assert abs(d[4, pb]) < abs(k0_c) / 20 and abs(d[5, qb]) < abs(k0_s) / 20  # F zeros


def test_momentum_loads_with_v_mu_are_exactly_l_inverse_lambda():
    rng = np.random.default_rng(1)
    rot = BladeRotor(RotorSpec())
    for _ in range(5):
        x, u = _state(rot, rng), _inputs(rng)
        c_mom = rot.momentum_loads(0.4, x, u, speed="mu")
        np.testing.assert_allclose(c_mom, rot.linv @ x[-3:], rtol=1e-13, atol=1e-16)
    # hence D_tau lambda' + lambda = L c_blade
    rot_mu = BladeRotor(RotorSpec(speed="mu"))
    x, u = _state(rot_mu, rng), _inputs(rng)
    _, c_blade = rot_mu.blade_terms(0.4, x, u)
    tau = np.array([rot_mu.spec.tau0, rot_mu.spec.tau_cs, rot_mu.spec.tau_cs])
    lhs = tau * rot_mu.rhs(0.4, x, u)[-3:] + x[-3:]
    np.testing.assert_allclose(lhs, rot_mu.spec.l_matrix @ c_blade, rtol=1e-12)


def test_eq14_momentum_loads_match_a_direct_disc_evaluation():
    rng = np.random.default_rng(2)
    spec = RotorSpec(n_disc_psi=10, n_disc_r=5)
    rot = BladeRotor(spec)
    x, u = _state(rot, rng), _inputs(rng)
    th0, th1c, th1s, muz, qb, pb, _, _, mux, muy = u
    psi, nb = 0.9, rot.nb
    bmb = multiblade(x[:nb], psi)
    dmb = multiblade(x[nb:2 * nb], psi)          # harmonics of the blade rates
    lam = x[-3:]
    r, w = np.polynomial.legendre.leggauss(5)
    r, w = (r + 1) / 2, w / 2
    acc = np.zeros(3)
    for ps in 2 * np.pi * np.arange(10) / 10:
        c, s = np.cos(ps), np.sin(ps)
        for ri, wi in zip(r, w):
            lam_i = lam[0] + ri * (lam[1] * c + lam[2] * s)
            beta = bmb[0] + bmb[1] * c + bmb[2] * s
            dbeta = dmb[0] + dmb[1] * c + dmb[2] * s
            theta = th0 + th1c * c + th1s * s
            ut = ri + mux * s + muy * c
            up = (muz - lam_i - ri * dbeta - beta * (mux * c - muy * s)
                  + ri * (pb * s + qb * c))
            v = np.sqrt(mux**2 + muy**2 + (up + theta * ut) ** 2)
            acc += wi * ri * lam_i * v * np.array([1, -ri * c, -ri * s])
    expect = 4 / PUMA.a0s * acc / 10
    np.testing.assert_allclose(rot.momentum_loads(psi, x, u), expect, rtol=1e-12)


def test_span_quadrature_is_exact_and_disc_quadrature_converges():
    rng = np.random.default_rng(3)
    x, u = _state(BladeRotor(RotorSpec()), rng), _inputs(rng)
    f3 = BladeRotor(RotorSpec(n_span=3)).rhs(0.2, x, u)
    f9 = BladeRotor(RotorSpec(n_span=9)).rhs(0.2, x, u)
    np.testing.assert_allclose(f3, f9, rtol=1e-12, atol=1e-15)   # polynomial lift
    fine = BladeRotor(RotorSpec(n_disc_psi=64, n_disc_r=16)).rhs(0.2, x, u)[-3:]
    default = BladeRotor(RotorSpec()).rhs(0.2, x, u)[-3:]
    coarse = BladeRotor(RotorSpec(n_disc_psi=6, n_disc_r=3)).rhs(0.2, x, u)[-3:]
    err_d, err_c = np.abs(default - fine).max(), np.abs(coarse - fine).max()
    assert err_d < 1e-3 * np.abs(fine).max() and err_d < err_c


def test_rk4_converges_at_fourth_order():
    rot = BladeRotor(RotorSpec())
    tr = rot.periodic_trim(U_TRIM)
    u = np.tile(U_TRIM, (12, 1))
    u[2:6, 2] += 0.01                                # a cyclic step of 4 samples
    dpsi = 27.5 * 0.01
    ends = [rot.integrate(tr.x, 0.0, u, dpsi, max_step=np.radians(d))[0][-1]
            for d in (16, 8, 4, 1)]
    e1, e2, e3 = (np.abs(ends[i] - ends[3]).max() for i in range(3))
    assert e2 < e1 / 10 and e3 < e2 / 10 and e3 < 1e-7     # ratios ~16 = 2^4


def test_periodic_trim_is_periodic_and_blades_are_identical():
    rot = BladeRotor(RotorSpec())
    tr = rot.periodic_trim(U_TRIM)
    n = 73
    x, _, _ = rot.integrate(tr.x, 0.0, np.tile(U_TRIM, (n, 1)), 2 * np.pi / (n - 1))
    np.testing.assert_allclose(x[-1], tr.x, atol=1e-9)          # one revolution
    # blade 1 is a quarter revolution ahead of blade 0 (18 of 72 steps)
    np.testing.assert_allclose(x[:54, 1], x[18:72, 0], atol=1e-9)
    assert tr.beta[0] > 0 and tr.lam[0] > 0 and tr.c[0] > 0


def test_bad_spec_is_refused_with_one_line():
    for kw in ({"n_blades": 2}, {"n_beta": -1.0}, {"speed": "fast"}, {"n_span": 1}):
        with pytest.raises(InputError) as exc:
            BladeRotor(RotorSpec(**kw))
        assert "\n" not in str(exc.value)
