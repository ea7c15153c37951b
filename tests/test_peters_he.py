"""Peters-He finite-state inflow (``peters-he-6/10/15``, ``model.md`` section 9.4).

Independent routes: the closed-form gain against adaptive quadrature of the
pressure functions (scipy's associated Legendre functions) and against BladeAD's
numbers; the effects' models against a second, direct construction of the whole
Peters-He rotor in its own variables (``tests/peters_he_direct.py``); the lowest three
states against this project's three-state model; the axial-flow limit of many
states against local momentum theory (the exact actuator disc in axial flow)."""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import inflowsim as ifs
from inflowsim.model.effects import CATALOGUE
from inflowsim.model.effects import peters_he as eff
from inflowsim.model.loads import load_matrices
from inflowsim.model.presets import truth_parameters
from inflowsim.physics import flapping as fl
from inflowsim.physics import loads as ld
from inflowsim.physics import peters_he as ph
from inflowsim.physics.theory import pitt_peters_time_constants

sys.path.insert(0, str(Path(__file__).parent))
import peters_he_direct as direct  # noqa: E402

K = ifs.PUMA
P = np.polynomial.polynomial


def _integral(c):
    """``int_0^1`` of the polynomial with coefficients ``c``."""
    return P.polyval(1.0, P.polyint(c))

F = np.array([0.05, 0.3, 1.0, 3.0, 8.0])
EFFECTS = {"peters-he-6": 2, "peters-he-10": 3, "peters-he-15": 4}


def test_truncations_count_6_10_15_states():
    assert [len(ph.truncation(p)) for p in (1, 2, 3, 4)] == [3, 6, 10, 15]
    for name, power in EFFECTS.items():
        assert len(CATALOGUE[name].states) == len(ph.truncation(power)) - 3
        assert set(CATALOGUE[name].alternatives) == set(EFFECTS) - {name}


def test_shape_functions_are_legendre_over_nu():
    r = np.linspace(0.0, 0.98, 11)
    for _, m, n in ph.truncation(4):
        np.testing.assert_allclose(ph.phi(m, n, r), direct.shape(m, n, r), rtol=0,
                                   atol=1e-11)


def test_closed_form_gain_is_the_pressure_projection():
    """``Gamma_jn^mm = int_0^1 P_j^m P_n^m r dr`` (adaptive quadrature, scipy's
    Legendre functions) for every pair of the 15-state truncation."""
    st = ph.truncation(4)
    np.testing.assert_allclose(ph.gain_matrix(st), direct.gain(4), rtol=0, atol=1e-11)


#: BladeAD (github LSDOlab/BladeAD, BladeAD/core/peters_he/peters_he_inflow.py,
#: ``compute_L(4, 4, x=0)`` and ``compute_phi``), run here on numpy on 2026-11-27:
#: the axial-flow gain's non-zero blocks (harmonic m, radial indices) and the shape
#: functions at r = 0.1, 0.35, 0.6, 0.85, 0.99.
BLADEAD_L = {
    0: ((1, 3, 5), [[0.75, 0.19094065395649334, -0.02991959711738556],
                    [0.19094065395649334, 0.65625, 0.20566322782950286],
                    [-0.02991959711738556, 0.20566322782950286, 0.64453125]]),
    1: ((2, 4), [[0.625, 0.19136638615493579], [0.19136638615493579, 0.6328125]]),
    2: ((3, 5), [[0.546875, 0.1813779182225609], [0.1813779182225609, 0.6015624999999999]]),
    3: ((4,), [[0.4921875]]),
    4: ((5,), [[0.45117187499999994]]),
}
BLADEAD_R = (0.1, 0.35, 0.6, 0.85, 0.99)
BLADEAD_PHI = {
    (0, 3): (2.5796075282879753, 1.8354899720510598, 0.26457513110645925,
             -2.133136994545825, -3.837000838871422),
    (0, 5): (3.0870728970529266, 0.8645585761127765, -1.656322420303487,
             0.17677351021282367, 5.651507345888665),
    (1, 4): (0.6590810363680629, 1.844546450064436, 1.4892212730148604,
             -1.5074592024563411, -4.749564349950984),
    (2, 5): (0.11835380618087452, 1.2014488376806602, 1.9897858176195753,
             -0.7270573442513548, -5.536723405138778),
    (4, 5): (5.202913847066854e-04, 7.807622591754694e-02, 6.742976345798640e-01,
             2.715953546380441e+00, 4.997898281866169e+00),
}


def test_gain_and_shapes_equal_bladead():
    for m, (js, want) in BLADEAD_L.items():
        got = [[ph.gamma(m, j, n) for n in js] for j in js]
        np.testing.assert_allclose(got, want, rtol=1e-14, atol=0)
    for (m, n), want in BLADEAD_PHI.items():
        np.testing.assert_allclose(ph.phi(m, n, np.array(BLADEAD_R)), want, rtol=1e-13)


def test_lowest_three_states_are_the_present_model():
    """``lambda0 = sqrt(3) alpha_1^0``, ``lambda1c, lambda1s = sqrt(15/2) (alpha_2^1,
    beta_2^1)``: the pressure integrals of the three lowest shapes are the project's
    blade-element loads (``G_*`` of Eq. 4), their flap integrals the flap equation's
    ``H_lambda``, the apparent masses with the three-state gain give the Pitt-Peters
    time constants of ``separate-time-constants``; and the three-state gain is the
    Galerkin projection with the inflow shapes as test functions (the Gram matrix)."""
    mu, nb = 0.27, 0.93
    low = ph.truncation(1)
    q = ph.forces(low).at(mu)
    g = q / eff.T_BASE[:, None]
    for cols, want in ((slice(0, 3), ld.g_beta(mu)), (slice(3, 6), ld.g_dbeta(mu)),
                       (slice(6, 9), ld.g_theta(mu)), (slice(9, 12), ld.g_nu(mu))):
        np.testing.assert_allclose(g[:, cols], want, rtol=0, atol=1e-15)
    np.testing.assert_allclose(g[:, 12:] / eff.S_BASE, ld.g_lambda(mu), rtol=0, atol=1e-15)
    f = 4 * nb * ph.flap_forces(low).at(mu)
    np.testing.assert_allclose(f[:, 12:] / eff.S_BASE, fl.flap_h_lambda(mu, nb), rtol=0,
                               atol=1e-15)
    np.testing.assert_allclose(f[:, 6:9], fl.flap_h_theta(mu, nb), rtol=0, atol=1e-15)
    # time constants: tau = K / (V L^-1)
    for v in (0.1, 0.249, 0.4):
        kk = np.array([ph.apparent_mass(m, n) for _, m, n in low])
        tau = kk / (v * eff.LINV_BASE)
        want = pitt_peters_time_constants(v)
        np.testing.assert_allclose(tau, [want[0], want[1], want[1]], rtol=1e-14)
        sc = CATALOGUE["separate-time-constants"].theory(K.with_mu(v))
        np.testing.assert_allclose(tau[:2], [sc["tau0"], sc["tau_cs"]], rtol=1e-14)
    # three-state gain: the inverse Gram matrix of the lowest shapes (least squares)
    gram = [_integral(P.polymul([0, 1], P.polymul(ph.phi_coefficients(m, n),
                                                   ph.phi_coefficients(m, n))))
            for _, m, n in low]
    np.testing.assert_allclose(gram, eff.LINV_BASE, rtol=1e-14)
    # Peters-He's own three-state gain differs by its Petrov-Galerkin weighting:
    # Gamma_11^00 = 3/4 against 2/3, Gamma_22^11 = 5/8 against 8/15
    assert ph.gamma(0, 1, 1) == pytest.approx(9 / 8 * 2 / 3, abs=1e-15)
    assert ph.gamma(1, 2, 2) == pytest.approx(75 / 64 * 8 / 15, abs=1e-15)


def test_three_state_galerkin_route_is_the_base_model():
    """The direct construction with the three lowest states and the Gram gain is the
    project's ``basic+separate-time-constants`` with Pitt-Peters time constants."""
    s = ifs.Structure.parse("basic+separate-time-constants")
    p = truth_parameters(s, K) | CATALOGUE["separate-time-constants"].theory(K)
    m = ifs.build_model(s, p, K)
    d = direct.model(1, K.mu, p["n_beta"], p["lambda_beta2"], K.a0s, K.flow_speed,
                     K.omega, gain=np.diag(1.0 / eff.LINV_BASE))
    h, hd = m.frequency_response(F), direct.frequency_response(d, F, K.omega)
    assert np.abs(h - hd).max() <= 1e-12 * np.abs(h).max()


@pytest.mark.parametrize("name", list(EFFECTS))
@pytest.mark.parametrize("mu", [0.15, 0.249, 0.35])
def test_the_effect_is_the_direct_peters_he_rotor(name, mu):
    """At ``k_ph = 1`` with Pitt-Peters time constants the structure's flap and recorded
    linear inflow responses equal the direct construction of the whole Peters-He rotor."""
    k = K.with_mu(mu)
    s = ifs.Structure.parse("basic+separate-time-constants+" + name)
    p = truth_parameters(s, k) | CATALOGUE["separate-time-constants"].theory(k)
    p |= {"lambda_beta2": 1.08, "n_beta": 0.91, "k_ph": 1.0}
    m = ifs.build_model(s, p, k)
    d = direct.model(EFFECTS[name], mu, 0.91, 1.08, k.a0s, k.flow_speed, k.omega)
    h, hd = m.frequency_response(F), direct.frequency_response(d, F, k.omega)
    assert np.abs(h - hd).max() <= 1e-12 * np.abs(h).max()
    # and the loads: at a steady state (no flap rate) the structure's aerodynamic
    # loads are the direct quadrature's of the whole inflow
    u = np.array([0.01, -0.005, 0.008, 0.003, 0.02, -0.01, 0.0, 0.0])
    x = -np.linalg.solve(m.a, m.b @ u)
    a_d, b_d, _ = direct.state_space(d, k.omega)
    xd = -np.linalg.solve(a_d, b_d @ u)
    want = direct.steady_loads(d, xd, u, EFFECTS[name], mu, k.a0s, k.omega)
    np.testing.assert_allclose(load_matrices(m)(x, u)[:3], want, rtol=0,
                               atol=1e-12 * np.abs(want).max())


@pytest.mark.parametrize("name", list(EFFECTS))
def test_k_ph_zero_is_the_three_state_structure(name):
    s0 = ifs.Structure.parse("glauert+flap-inertia+azimuth-bias")
    s = s0.with_effect(name)
    p = truth_parameters(s, K) | {"k_ph": 0.0}
    m, m0 = ifs.build_model(s, p, K), ifs.build_model(s0, {n: p[n] for n in s0.parameters}, K)
    h, h0 = m.frequency_response(F), m0.frequency_response(F)
    assert np.abs(h - h0).max() <= 1e-13 * np.abs(h0).max()
    u = np.linspace(0.01, 0.02, m.b.shape[1])
    x, x0 = -np.linalg.solve(m.a, m.b @ u), -np.linalg.solve(m0.a, m0.b @ u)
    np.testing.assert_allclose(load_matrices(m)(x, u), load_matrices(m0)(x0, u),
                               rtol=0, atol=1e-13)
    # at theory the higher states matter: the response moves by several per cent
    p1 = p | {"k_ph": 1.0}
    h1 = ifs.build_model(s, p1, K).frequency_response(F)
    assert np.abs(h1 - h0).max() > 0.02 * np.abs(h0).max()


def test_higher_harmonics_reach_the_flap_only_through_mu():
    """States of harmonic 2 drive the first-harmonic flap only through ``mu`` (and
    ``phi_5^2`` not at all: it is orthogonal to the flap's radial weight); harmonics 3
    and 4 never (their flap integrals vanish: ``U_T`` shifts a harmonic by one)."""
    st = ph.truncation(4)
    for mu in (0.0, 0.2, 0.4):
        f = ph.flap_forces(st).at(mu)
        for i, (_, m, n) in enumerate(st):
            col = np.abs(f[:, 12 + i]).max()
            if m >= 3 or (m == 2 and (mu == 0.0 or n == 5)):
                assert col < 1e-15
            elif m == 2:
                assert col == pytest.approx(15 / 64 * math.sqrt(56 / 15) * mu, rel=1e-13)


def test_axial_flow_converges_to_local_momentum():
    """Published limit: in axial flow Peters-He's steady inflow of a pressure
    distribution tends, as radial states are added, to the actuator disc's exact
    ``Delta p / (2 V)`` (each annulus alone); the elliptic pressure ``P_1^0``
    gives ``lambda = (3/4) C_T nu / V`` with the momentum mean ``C_T / (2 V)``."""
    v, ct = 0.05, 0.006
    r = np.linspace(0.0, 0.9, 10)
    exact = 0.75 * ct * np.sqrt(1 - r ** 2) / v
    errs, means = [], []
    for power in (0, 2, 4, 6, 8, 10):
        js = list(range(1, power + 2, 2))
        gam = np.array([[ph.gamma(0, j, n) for n in js] for j in js])
        tau = np.zeros(len(js))
        tau[0] = math.sqrt(3) / 2 * ct                 # tau_1^0 of the thrust
        alpha = gam @ tau / (2 * v)                    # V L^-1 alpha = tau / 2
        lam = sum(a * ph.phi(0, j, r) for a, j in zip(alpha, js))
        errs.append(np.abs(lam - exact).max() / exact.max())
        means.append(sum(a * 2 * _integral(P.polymul([0, 1], ph.phi_coefficients(0, j)))
                         for a, j in zip(alpha, js)))
    assert all(b < a for a, b in zip(errs, errs[1:])), errs
    assert errs[-1] < 0.03
    assert abs(means[-1] - ct / (2 * v)) < 0.01 * ct / (2 * v)
    assert means[0] == pytest.approx(9 / 8 * ct / (2 * v), rel=1e-14)   # one state: 9/8


def test_theory_model_is_stable_and_symbol_safe():
    import sympy
    for name, power in EFFECTS.items():
        s = ifs.Structure.parse("glauert+flap-inertia+" + name)
        assert ifs.build_model(s, truth_parameters(s, K), K).is_stable()
        mu, v, a0s, nb, kp = sympy.symbols("mu v a0s nb kp")
        t = eff.parts(power, mu, v, a0s, nb, kp)
        num = eff.parts(power, 0.2, 0.21, 0.5, 0.9, 0.7)
        subs = {mu: 0.2, v: 0.21, a0s: 0.5, nb: 0.9, kp: 0.7}
        for key in ("a", "a_z", "b", "f_x", "l_x", "p_lambda", "to_output", "loads"):
            got = np.array(sympy.Matrix(np.atleast_2d(t[key])).subs(subs).evalf(),
                           dtype=float)
            np.testing.assert_allclose(got, num[key], rtol=1e-12, atol=1e-14)
