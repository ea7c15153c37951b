"""Loads out (issue #10 part 1): Eq. (4) thrust and hub moments and the flap springs'
hub moments, against blade-element quadrature and the flap equation's moment balance."""
import math

import numpy as np
import pytest

from inflowsim.errors import InputError
from inflowsim.model.build import build_model
from inflowsim.model.loads import dimensional_loads, load_matrices
from inflowsim.model.params import PUMA
from inflowsim.model.presets import preset_parameters, truth_parameters
from inflowsim.simulate.simulator import Simulator
from test_quadrature import loads_quad

STRUCTURES = ["basic", "empirical", "glauert", "glauert+time-delay",
              "basic+flap-inertia", "glauert+skewed-wake"]


def model_of(structure, source="paper", mu=PUMA.mu):
    k = PUMA.with_mu(mu)
    base = structure.split("+")[0]
    if structure == base:
        p = preset_parameters(structure, k, source)
    else:
        p = truth_parameters(structure, k)
    return build_model(structure, p, k)


def random_point(model, seed):
    rng = np.random.default_rng(seed)
    x = rng.normal(scale=0.01, size=model.a.shape[0])
    u = rng.normal(scale=0.01, size=model.b.shape[1])
    return x, u


@pytest.mark.parametrize("structure", STRUCTURES)
@pytest.mark.parametrize("seed", [1, 2])
def test_aerodynamic_loads_against_quadrature(structure, seed):
    """Eq. (4) rows against the blade-element integrals of model.md section 3, at a
    random state and input, with the flap rate from the model's own dynamics."""
    m = model_of(structure)
    x, u = random_point(m, seed)
    loads = load_matrices(m)(x, u)
    k = m.constants
    om = k.omega
    st = list(m.states)
    xdot = m.a @ x + m.b @ u
    beta = x[[st.index(c) for c in ("beta0", "beta1c", "beta1s")]]
    dbeta = xdot[[st.index(c) for c in ("beta0", "beta1c", "beta1s")]] / om
    lam = x[[st.index(c) for c in ("lambda0", "lambda1c", "lambda1s")]]
    ui = {n: u[i] for i, n in enumerate(m.inputs)}
    bias = m.measurement.azimuth_bias
    c, s = math.cos(bias), math.sin(bias)
    # true pitch from recorded: rotate back by the azimuth bias
    th_c = c * ui["theta1c"] + s * ui["theta1s"]
    th_s = -s * ui["theta1c"] + c * ui["theta1s"]
    state = {"beta": beta, "dbeta": dbeta, "ddbeta": np.zeros(3), "lam": lam,
             "theta": (ui["theta0"], th_c, th_s),
             "nu": (ui["muz"], ui["q"] / om, ui["p"] / om), "eta": (0.0, 0.0)}
    want = k.a0 * k.solidity * loads_quad(k.mu, state)
    np.testing.assert_allclose(loads[:3], want, rtol=0, atol=1e-14)


@pytest.mark.parametrize("structure", ["basic", "empirical", "glauert",
                                       "basic+flap-inertia"])
@pytest.mark.parametrize("source", ["paper", "theory"])
def test_steady_aerodynamic_moment_equals_the_spring_moment(structure, source):
    """In steady flight the flap equation balances the aerodynamic hub moment against
    the centre spring (model.md section 2): the two load outputs must agree."""
    if "+" in structure and source == "paper":
        pytest.skip("the paper has no values for this structure")
    m = model_of(structure, source)
    for j in range(3):                      # each pilot control in turn
        u = np.zeros(m.b.shape[1])
        u[j] = 0.01
        x = -np.linalg.solve(m.a, m.b @ u)
        loads = load_matrices(m)(x, u)
        np.testing.assert_allclose(loads[1:3], loads[3:5], rtol=1e-9, atol=1e-15)
        assert abs(loads[3]) + abs(loads[4]) > 1e-6


def test_spring_moment_hand_value():
    """lambda_beta2 - 1 of stiffness over 16 n_beta: Puma paper basic values."""
    m = model_of("basic")
    lm = load_matrices(m)
    x = np.zeros(m.a.shape[0])
    x[1] = 0.01                           # beta1c
    p = m.parameters
    want = -PUMA.a0 * PUMA.solidity * (p["lambda_beta2"] - 1) / (16 * p["n_beta"]) * 0.01
    assert lm(x, np.zeros(m.b.shape[1]))[3] == pytest.approx(want, rel=1e-15)


def test_loads_vanish_at_trim_and_are_linear():
    m = model_of("glauert")
    lm = load_matrices(m)
    zero = lm(np.zeros(m.a.shape[0]), np.zeros(m.b.shape[1]))
    assert not np.any(zero)
    x1, u1 = random_point(m, 3)
    x2, u2 = random_point(m, 4)
    np.testing.assert_allclose(lm(x1 + 2 * x2, u1 + 2 * u2),
                               lm(x1, u1) + 2 * lm(x2, u2), rtol=1e-13, atol=1e-18)


def test_simulator_loads_follow_the_state_and_held_input():
    m = model_of("glauert")
    sim = Simulator(m, 0.01)
    lm = load_matrices(m)
    assert not np.any(sim.loads())
    u = np.zeros(sim.m)
    u[2] = math.radians(1.0)
    for _ in range(30):
        sim.step(u)
    np.testing.assert_allclose(sim.loads(), lm(sim.state, u), rtol=1e-15)
    # a 1 deg longitudinal cyclic step: thrust and pitch moment respond, nose down
    for _ in range(2000):
        sim.step(u)
    x_ss = -np.linalg.solve(m.a, m.b @ u)
    np.testing.assert_allclose(sim.loads(), lm(x_ss, u), rtol=1e-6)
    sim.set_mu(0.3)                        # the load matrices follow the model
    np.testing.assert_allclose(sim.loads(), load_matrices(sim.model)(sim.state, u))


def test_dimensional_loads():
    cf = np.array([0.001, 1e-4, -2e-4, 1e-4, -2e-4])
    d = dimensional_loads(cf, PUMA, density=1.225)
    q = 1.225 * math.pi * 7.5**2 * (27.5 * 7.5) ** 2
    assert d["T"] == pytest.approx(0.001 * q, rel=1e-15)
    assert d["M_pitch"] == pytest.approx(1e-4 * q * 7.5, rel=1e-15)
    assert d["M_roll_hub"] == pytest.approx(-2e-4 * q * 7.5, rel=1e-15)
    with pytest.raises(InputError, match="radius"):
        dimensional_loads(cf, PUMA.__class__(mu=0.249, a0=5.73, solidity=0.0917,
                                             omega=27.5), 1.225)
    with pytest.raises(InputError, match="density"):
        dimensional_loads(cf, PUMA, 1225.0)


@pytest.mark.parametrize("mu", [0.15, 0.249, 0.4])
def test_loads_equal_the_individual_blades_at_small_amplitude(mu):
    """An independent route: the nonlinear individual-blade rotor's own blade-element
    loads (flighttest.bladesim, each blade in the rotating frame, Gauss-Legendre along
    the span), differentiated at trim by a central difference, equal the linear loads
    of Eq. (4) for a random small perturbation; eight blades make them independent of
    the azimuth, as the multiblade model assumes."""
    from inflowsim.flighttest.bladesim import BladeRotor, RotorSpec
    from inflowsim.physics import loads as ld
    from inflowsim.physics.multiblade import blade_angles
    rotor = BladeRotor(RotorSpec(constants=PUMA.with_mu(mu), n_blades=8))
    rng = np.random.default_rng(11)
    b, db, lam = rng.normal(size=(3, 3))
    th, nu = rng.normal(size=3), rng.normal(size=3)
    want = (ld.g_dbeta(mu) @ db + ld.g_beta(mu) @ b + ld.g_theta(mu) @ th
            + ld.g_nu(mu) @ nu + ld.g_lambda(mu) @ lam)

    def blade_loads(eps, psi):
        rate_mb = eps * np.array([db[0], db[1] + b[2], db[2] - b[1]])
        x = np.concatenate([blade_angles(eps * b, psi, 8), blade_angles(rate_mb, psi, 8),
                            eps * lam])
        u = (*(eps * th), *(eps * nu), 0.0, 0.0, mu, 0.0)
        return rotor.blade_terms(psi, x, u)[1]

    h = 1e-5
    for psi in (0.0, 0.3):
        got = (blade_loads(h, psi) - blade_loads(-h, psi)) / (2 * h)
        np.testing.assert_allclose(got, want, rtol=1e-7, atol=1e-9)
