"""Servo actuators (``servo-actuators``) and the appended-state core (``model.md`` 9).

Independent routes: the structure's frequency response equals the structure
without servos times the servo's own transfer function ``1/(T^2 s^2 + 2 zeta T s
+ 1)`` on the control columns (and nothing elsewhere); its steady state, loads
and end states are the servo-free model's; python-control's ``ss`` gives the same
poles as the descriptor."""
import numpy as np
import pytest

import inflowsim as ifs
from inflowsim.model.loads import load_matrices
from inflowsim.model.presets import truth_parameters

K = ifs.PUMA
F = np.array([0.05, 0.3, 1.0, 3.0, 8.0])


@pytest.mark.parametrize("base", ["basic", "glauert", "glauert+flap-inertia+azimuth-bias",
                                  "basic+advance-ratio-perturbation"])
@pytest.mark.parametrize("tau, zeta", [(0.02, 0.7), (0.045, 0.35), (0.01, 1.3)])
def test_the_servo_filters_each_control_and_nothing_else(base, tau, zeta):
    s0 = ifs.Structure.parse(base)
    s = s0.with_effect("servo-actuators")
    k = K.with_trim({"theta0": 0.17, "theta1c": 0.01, "theta1s": -0.05, "beta0": 0.06,
                     "beta1c": 0.01, "beta1s": -0.004, "muz": -0.02})
    p = truth_parameters(s, k) | {"servo_tau": tau, "servo_zeta": zeta}
    if "azimuth_bias" in p:
        p["azimuth_bias"] = 0.15
    m = ifs.build_model(s, p, k)
    m0 = ifs.build_model(s0, {n: p[n] for n in s0.parameters}, k)
    assert m.a.shape[0] == m0.a.shape[0] + 6
    sv = 2j * np.pi * F
    g = 1.0 / ((tau * sv) ** 2 + 2 * zeta * tau * sv + 1.0)
    h, h0 = m.frequency_response(F), m0.frequency_response(F)
    scale = np.abs(h0).max()
    np.testing.assert_allclose(h[:, :3], h0[:, :3] * g, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(h[:, 3:], h0[:, 3:], rtol=0, atol=1e-12 * scale)
    # steady state, loads and end states: the servo passes a constant command
    u = np.linspace(0.01, 0.02, m.b.shape[1])
    x = -np.linalg.solve(m.a, m.b @ u)
    x0 = -np.linalg.solve(m0.a, m0.b @ u)
    np.testing.assert_allclose(x[:6], x0[:6], rtol=0, atol=1e-12)
    np.testing.assert_allclose(x[-6:-3], u[:3], rtol=0, atol=1e-12)
    np.testing.assert_allclose(load_matrices(m)(x, u), load_matrices(m0)(x0, u),
                               rtol=0, atol=1e-13)
    np.testing.assert_allclose(m.end_state(x0[:6], u), x, rtol=0, atol=1e-12)


def test_the_servo_states_and_poles():
    s = ifs.Structure.parse("glauert+servo-actuators")
    p = truth_parameters(s, K) | {"servo_tau": 0.025, "servo_zeta": 0.6}
    m = ifs.build_model(s, p, K)
    assert s.states[-6:] == ("theta0_a", "theta1c_a", "theta1s_a", "theta0_a_prime",
                             "theta1c_a_prime", "theta1s_a_prime")
    # the servo's own poles, three times: -zeta/T +- j sqrt(1 - zeta^2)/T
    want = (-0.6 + 1j * np.sqrt(1 - 0.36)) / 0.025
    ev = m.eigenvalues()
    assert np.sum(np.abs(ev - want) < 1e-6 * abs(want)) == 3
    sys = m.to_control()
    np.testing.assert_allclose(np.sort_complex(np.linalg.eigvals(sys.A)), np.sort_complex(ev),
                               rtol=1e-10)


def test_the_servo_tends_to_the_direct_structure_at_its_floor():
    from inflowsim.model.effects.servo_actuators import FLOOR
    s0 = ifs.Structure.parse("glauert")
    s = s0.with_effect("servo-actuators")
    p = truth_parameters(s, K) | {"servo_tau": FLOOR}
    h = ifs.build_model(s, p, K).frequency_response(F[:4])
    h0 = ifs.build_model(s0, {n: p[n] for n in s0.parameters}, K).frequency_response(F[:4])
    assert np.abs(h - h0).max() < 1e-4 * np.abs(h0).max()
