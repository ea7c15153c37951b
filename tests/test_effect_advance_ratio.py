"""``advance-ratio-perturbation``: closed-form coefficients against quadrature and
finite differences of the blade-element integrals; the model blocks it edits."""
import numpy as np
import pytest

from inflowsim import PUMA, Structure, build_model, descriptor, preset_parameters
from inflowsim.physics import bladeelement as be
from inflowsim.physics import loads as ld
from inflowsim.model.effects import CATALOGUE
from inflowsim.model.equations import assemble, rotation
from inflowsim.model import base_equations
from inflowsim.errors import InputError
from inflowsim.flighttest.virtual import PUMA_TRIM, VirtualTest, virtual_record

from test_quadrature import (COS, RR, SIN, avg, flap_residual_quad, loads_quad, radial,
                             single_blade, zero_state)

MUS = [0.1, 0.249, 0.4]
EFFECT = "advance-ratio-perturbation"
K = PUMA.with_trim(PUMA_TRIM)
MU_PUMA = PUMA.mu


def random_trim(seed):
    rng = np.random.default_rng(seed)
    theta = np.array([0.17, 0.01, -0.05]) + 0.05 * rng.normal(size=3)
    beta = np.array([0.06, 0.01, -0.002]) + 0.03 * rng.normal(size=3)
    return theta, beta, 0.02 * rng.normal(), 0.02 * rng.normal(size=3)


def trim_dict(theta, beta, muz, lam):
    s = zero_state()
    s.update(theta=theta, beta=beta, nu=np.array([muz, 0.0, 0.0]), lam=lam)
    return s


def central(fun, h=1e-3):
    # the integrands are quadratic in mux, muy: a central difference is exact
    return np.column_stack([(fun(mux=h) - fun(mux=-h)) / (2 * h),
                            (fun(muy=h) - fun(muy=-h)) / (2 * h)])


@pytest.mark.parametrize("mu", MUS)
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_load_derivatives_against_finite_difference_of_quadrature(mu, seed):
    theta, beta, muz, lam = random_trim(seed)
    s = trim_dict(theta, beta, muz, lam)
    fd = central(lambda **kw: loads_quad(mu, s, **kw))
    np.testing.assert_allclose(be.inplane_load_derivatives(mu, theta, beta, muz, lam), fd,
                               rtol=0, atol=1e-11)


@pytest.mark.parametrize("mu", MUS)
@pytest.mark.parametrize("seed", [0, 3])
def test_flap_derivatives_against_finite_difference_of_quadrature(mu, seed):
    theta, beta, muz, lam = random_trim(seed)
    s = trim_dict(theta, beta, muz, lam)
    n_beta = 0.9
    # forcing is minus the residual's derivative
    fd = -central(lambda **kw: flap_residual_quad(mu, n_beta, 1.06, s, **kw)) / n_beta
    np.testing.assert_allclose(be.inplane_flap_derivatives(mu, theta, beta, muz, lam), fd,
                               rtol=0, atol=1e-10)


@pytest.mark.parametrize("mu", MUS)
def test_derivatives_against_quadrature_of_the_differentiated_integrand(mu):
    # the other route: d F/d mux = 2 theta U_T sin - beta cos U_T + U_P sin, etc.
    theta, beta, muz, lam = random_trim(7)
    b, db, _ = single_blade(beta, np.zeros(3), np.zeros(3))
    th = theta[0] + theta[1] * COS + theta[2] * SIN
    ut = RR + mu * SIN
    up = muz - (lam[0] + lam[1] * RR * COS + lam[2] * RR * SIN) - RR * db - mu * b * COS
    dfx = 2 * th * ut * SIN - b * COS * ut + up * SIN
    dfy = 2 * th * ut * COS + b * SIN * ut + up * COS
    cos, sin = COS[0], SIN[0]
    for col, df in enumerate((dfx, dfy)):
        dc = [0.5 * avg(radial(df, 0)), -0.5 * avg(radial(df * COS, 1)),
              -0.5 * avg(radial(df * SIN, 1))]
        m = radial(df, 1)
        dh = 4 * np.array([avg(m), 2 * avg(m * cos), 2 * avg(m * sin)])
        np.testing.assert_allclose(be.inplane_load_derivatives(mu, theta, beta, muz, lam)[:, col],
                                   dc, rtol=0, atol=1e-12)
        np.testing.assert_allclose(be.inplane_flap_derivatives(mu, theta, beta, muz, lam)[:, col],
                                   dh, rtol=0, atol=1e-12)


@pytest.mark.parametrize("mu", MUS)
def test_mux_column_is_the_mu_derivative_of_the_base_loads(mu):
    # consistency with the base matrices: a change of mux is a change of mu
    theta, beta, muz, lam = random_trim(4)
    h = 1e-4

    def c(m):
        return (ld.g_theta(m) @ theta + ld.g_beta(m) @ beta + ld.g_nu(m)[:, 0] * muz
                + ld.g_lambda(m) @ lam)
    fd = (c(mu + h) - c(mu - h)) / (2 * h)
    np.testing.assert_allclose(be.inplane_load_derivatives(mu, theta, beta, muz, lam)[:, 0], fd,
                               rtol=0, atol=1e-10)


@pytest.mark.parametrize("mu", MUS)
def test_trim_inflow_is_the_momentum_balance(mu):
    theta, beta, muz, _ = random_trim(5)
    lam = be.trim_inflow(mu, PUMA.a0s, theta, beta, muz)
    c = loads_quad(mu, trim_dict(theta, beta, muz, lam))
    # lambda0 = C_T/(2 mu), and the cyclic rows of lambda = L c
    np.testing.assert_allclose(lam, ld.momentum_l(mu, PUMA.a0s) @ c, rtol=0, atol=1e-13)
    assert np.isclose(lam[0], PUMA.a0s * c[0] / (2 * mu), rtol=1e-12)


def _params(structure, k=K, **over):
    p = preset_parameters(structure, k, "theory")
    p.update(over)
    return p


def test_descriptor_columns_entry_by_entry():
    s = "basic+" + EFFECT
    p = _params(s, k_mu=0.7, n_beta=0.95)
    e, a, b = descriptor(s, p, K)
    e0, a0, b0 = descriptor("basic", {k: v for k, v in p.items() if k != "k_mu"}, K)
    np.testing.assert_array_equal(e, e0)
    np.testing.assert_array_equal(a, a0)
    np.testing.assert_array_equal(b[:, :8], b0)
    theta = np.array([PUMA_TRIM[n] for n in ("theta0", "theta1c", "theta1s")])
    beta = np.array([PUMA_TRIM[n] for n in ("beta0", "beta1c", "beta1s")])
    lam = be.trim_inflow(K.mu, K.a0s, theta, beta, PUMA_TRIM["muz"])
    hmu = be.inplane_flap_derivatives(K.mu, theta, beta, PUMA_TRIM["muz"], lam)
    dc = be.inplane_load_derivatives(K.mu, theta, beta, PUMA_TRIM["muz"], lam)
    np.testing.assert_allclose(b[:3, 8:], 0.7 * 0.95 * hmu, rtol=1e-14, atol=0)
    np.testing.assert_allclose(b[3:, 8:], 0.7 * ld.momentum_l(K.mu, K.a0s) @ dc,
                               rtol=1e-14, atol=0)
    assert np.abs(b[:3, 8:]).min() > 1e-3   # every flap entry is forced


def test_neutral_value_is_the_structure_without_it():
    p = _params("glauert+" + EFFECT, k_mu=0.0)
    m = build_model("glauert+" + EFFECT, p, K)
    m0 = build_model("glauert", {k: v for k, v in p.items() if k != "k_mu"}, K)
    for name in ("E", "A", "B", "a", "b", "c"):
        np.testing.assert_array_equal(getattr(m, name), getattr(m0, name), err_msg=name)


@pytest.mark.parametrize("structure", ["basic", "empirical", "glauert"])
def test_stable_with_theory_values_for_the_puma(structure):
    s = f"{structure}+{EFFECT}"
    assert build_model(s, _params(s), K).is_stable()
    p = preset_parameters(s, K, "paper")
    assert p["k_mu"] == 1.0
    assert build_model(s, p, K).is_stable()


def test_parse_and_parameters():
    s = Structure.parse("glauert+" + EFFECT)
    assert s.parameters[-1] == "k_mu" and "k_mu" in s.parameters
    assert s.uses_inplane and s.inputs[-2:] == ("mux", "muy")
    # neither the Glauert nor the empirical in-plane terms exclude it
    Structure.parse("empirical+" + EFFECT)


def test_refuses_without_trim_in_one_line():
    s = "glauert+" + EFFECT
    with pytest.raises(InputError, match="trim") as err:
        build_model(s, _params(s, k=PUMA), PUMA)
    assert "\n" not in str(err.value) and "beta0" in str(err.value)
    partial = PUMA.with_trim({"theta0": 0.17})
    with pytest.raises(InputError, match="muz"):
        build_model(s, _params(s), partial)


def test_azimuth_bias_rotates_the_recorded_trim_cyclics():
    s = "glauert+" + EFFECT
    dpsi = 0.3
    b = build_model(s, _params(s, azimuth_bias=dpsi, k_mu=1.0), K).B
    b0 = build_model(s, _params(s, azimuth_bias=dpsi, k_mu=0.0), K).B
    trim = dict(PUMA_TRIM)
    r = rotation(-dpsi)
    trim["theta1c"], trim["theta1s"] = r @ [PUMA_TRIM["theta1c"], PUMA_TRIM["theta1s"]]
    trim["beta1c"], trim["beta1s"] = r @ [PUMA_TRIM["beta1c"], PUMA_TRIM["beta1s"]]
    kt = PUMA.with_trim(trim)
    b_true = build_model(s, _params(s, k=kt, k_mu=1.0), kt).B
    np.testing.assert_allclose(b[:, 8:] - b0[:, 8:], b_true[:, 8:] - b0[:, 8:],
                               rtol=1e-12, atol=1e-14)


def _information_conditioning(effects, params, k):
    """Smallest / largest singular value of the column-normalised sensitivity of
    the flap frequency responses (all ten inputs, the paper's band) to the
    parameters.  Built from the catalogue directly, so that combinations a
    Structure refuses can be measured too."""
    w_az = 2 * np.pi * 0.0376 * np.arange(6, 43) / k.omega
    names = [n for n in params]

    def response(p):
        eq = base_equations(p, k)
        for e in effects:
            eq = CATALOGUE[e].equations(eq, p, k)
        e_, a_, b_ = assemble(eq, second_order=False)
        return np.stack([np.linalg.solve(1j * w * e_ - a_, b_)[:3] for w in w_az])

    cols = []
    for n in names:
        h = 1e-6 * max(1.0, abs(params[n]))
        d = (response({**params, n: params[n] + h})
             - response({**params, n: params[n] - h})).ravel() / (2 * h)
        cols.append(np.concatenate([d.real, d.imag]))
    j = np.column_stack(cols)
    j /= np.linalg.norm(j, axis=0)
    sv = np.linalg.svd(j, compute_uv=False)
    return sv[-1] / sv[0]


def _paper(structure):
    s = Structure.parse(structure)
    return s.effects, preset_parameters(s, K, "paper")


@pytest.mark.parametrize("structure", ["glauert", "empirical"])
def test_not_an_alternative_information_matrix_is_regular(structure):
    effects, p = _paper(f"{structure}+{EFFECT}")
    assert _information_conditioning(effects, p, K) > 1e-2


def test_information_measure_sees_the_declared_alternatives():
    # glauert + hub-velocity-coupling (refused by Structure) is singular by this
    # same measure.  The free K of `empirical` spans every inflow-row mux, muy
    # entry, so there only the flap rows of k_mu keep the combination regular.
    effects, p = _paper("glauert")
    p.update(dict.fromkeys(("k01", "k02", "k11", "k12", "k21", "k22"), 0.1))
    effects = effects + ("hub-velocity-coupling",)
    assert _information_conditioning(effects, p, K) < 1e-7


def test_virtual_record_carries_the_trim_it_needs():
    rec = virtual_record(VirtualTest(duration=4.0))
    k = rec.constants
    s = "glauert+" + EFFECT
    m = build_model(s, preset_parameters(s, k, "paper"), k)
    assert m.is_stable()
    assert np.isclose(k.trim["theta0"], PUMA_TRIM["theta0"], atol=1e-9)


def test_columns_match_the_nonlinear_individual_blade_truth():
    # a third route: the team's individual-blade rotor (8 blades, speed = mu so the
    # inflow has no Glauert terms), differentiated in the total mux, muy at trim
    bladesim = pytest.importorskip("inflowsim.flighttest.bladesim")
    spec = bladesim.RotorSpec(n_blades=8, speed="mu")
    rotor = bladesim.BladeRotor(spec)
    theta = np.array([PUMA_TRIM[n] for n in ("theta0", "theta1c", "theta1s")])
    beta = np.array([PUMA_TRIM[n] for n in ("beta0", "beta1c", "beta1s")])
    lam = be.trim_inflow(MU_PUMA, PUMA.a0s, theta, beta, 0.0)
    z = np.concatenate([beta, np.zeros(3), lam])

    def rhs(psi, mx, my):
        u = np.array([*theta, 0.0, 0, 0, 0, 0, MU_PUMA + mx, my])
        return bladesim.multiblade_derivatives(rotor, psi, z, u)
    h = 1e-4
    jac = np.mean([np.column_stack([(rhs(psi, h, 0) - rhs(psi, -h, 0)) / (2 * h),
                                    (rhs(psi, 0, h) - rhs(psi, 0, -h)) / (2 * h)])
                   for psi in (0.0, 0.3)], axis=0)
    want_flap = spec.n_beta * be.inplane_flap_derivatives(MU_PUMA, theta, beta, 0.0, lam)
    d_tau = np.diag([spec.tau0, spec.tau_cs, spec.tau_cs])
    want_inflow = np.linalg.solve(d_tau, ld.momentum_l(MU_PUMA, PUMA.a0s)
                                  @ be.inplane_load_derivatives(MU_PUMA, theta, beta, 0.0, lam))
    np.testing.assert_allclose(jac[:3], want_flap, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(jac[3:], want_inflow, rtol=1e-6, atol=1e-9)
