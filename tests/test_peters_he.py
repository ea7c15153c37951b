"""Peters-He finite-state inflow (``peters-he-6/10/15``, ``model.md`` section 9.4).

Independent routes: the closed-form gain against adaptive quadrature of the
pressure functions (scipy's associated Legendre functions) and against BladeAD's
numbers; the skewed wake's gain (``X = tan(chi/2) > 0``) against a first-principles
quadrature of Kinner's pressure potential integrated upstream along the skewed free
stream (``tests/peters_he_potential.py``) and BladeAD's; the effects' models against a
second, direct construction of the whole Peters-He rotor in its own variables
(``tests/peters_he_direct.py``, its own trim inflow and skew); the lowest three
states against this project's three-state model and Pitt-Peters' skewed gain; the
axial-flow limit of many states against local momentum theory (the exact actuator
disc in axial flow)."""
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
import peters_he_potential as potential  # noqa: E402

#: A trim (totals) the effects are linearised about: the wake skew X = tan(chi/2)
#: of the Puma at 100 kt with it is 0.856 (chi = 81.3 deg).
TRIM = {"theta0": 0.17, "theta1c": 0.012, "theta1s": -0.05, "beta0": 0.06,
        "beta1c": 0.011, "beta1s": -0.004, "muz": -0.02}
K = ifs.PUMA.with_trim(TRIM)
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
        assert set(CATALOGUE[name].alternatives) == set(EFFECTS) - {name} | {"skewed-wake"}


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
    linear inflow responses equal the direct construction of the whole Peters-He rotor
    in forward flight (its gain at the skew of its own trim inflow)."""
    k = K.with_mu(mu)
    s = ifs.Structure.parse("basic+separate-time-constants+" + name)
    p = truth_parameters(s, k) | CATALOGUE["separate-time-constants"].theory(k)
    p |= {"lambda_beta2": 1.08, "n_beta": 0.91, "k_ph": 1.0}
    m = ifs.build_model(s, p, k)
    x = direct.trim_skew(mu, k.a0s, k.flow_speed, [TRIM[c] for c in ("theta0", "theta1c", "theta1s")],
                         [TRIM[c] for c in ("beta0", "beta1c", "beta1s")], TRIM["muz"])
    assert eff.wake_skew(p, k) == pytest.approx(x, abs=1e-12)
    assert 0.7 < x < 0.95                                 # chi 70-87 deg: a strong skew
    d = direct.model(EFFECTS[name], mu, 0.91, 1.08, k.a0s, k.flow_speed, k.omega,
                     gain=direct.gain(EFFECTS[name], x))
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
        mu, v, a0s, nb, kp, x = sympy.symbols("mu v a0s nb kp x")
        # the skew a symbol, L(x)^-1 a run-time call's results (the FMU's route;
        # tests/test_fmu_structures.py runs them): put in, the effect's numbers
        n = len(eff.layout(power)[0])
        linv = np.array([[sympy.Symbol(f"y{i}_{j}") for j in range(n)] for i in range(n)])
        calls = []

        def numeric(effect, args, shapes):
            calls.append((effect, args, shapes))
            return (linv,)

        t = eff.parts(power, mu, v, a0s, nb, kp, x=x, numeric=numeric)
        assert calls == [(name, (x,), ((n, n),))]
        num = eff.parts(power, 0.2, 0.21, 0.5, 0.9, 0.7, x=0.83)
        subs = {mu: 0.2, v: 0.21, a0s: 0.5, nb: 0.9, kp: 0.7, x: 0.83}
        subs |= {y: val for y, val in zip(linv.ravel(), eff.gain_inverse(power, 0.83).ravel())}
        for key in ("a", "a_z", "b", "f_x", "l_x", "p_lambda", "to_output", "loads"):
            got = np.array(sympy.Matrix(np.atleast_2d(t[key])).xreplace(subs).evalf(),
                           dtype=float)
            np.testing.assert_allclose(got, num[key], rtol=1e-12, atol=1e-14)


def test_axial_limit_is_the_block_diagonal_gain():
    """``X = 0``: the forward-flight gain is the axial ``Gamma_jn^mm``, block-diagonal
    by harmonic and kind, exactly; and the effect's terms are those of the axial L."""
    st = ph.truncation(4)
    want = np.zeros((15, 15))
    for a, (ka, r, j) in enumerate(st):
        for b, (kb, m, n) in enumerate(st):
            if ka == kb and r == m:
                want[a, b] = ph.gamma(m, j, n)
    np.testing.assert_array_equal(ph.gain_matrix(st, 0.0), want)
    np.testing.assert_array_equal(eff.gain_inverse(4, 0.0), np.linalg.inv(want))


def test_skewed_gain_is_the_pressure_potentials():
    """First principles: Kinner's pressure potential of each ``P_n^m cos (sin) m psi``
    integrated upstream along the skewed free stream and projected on the pressure
    functions (``tests/peters_he_potential.py``) is the closed-form ``L(X)`` pair by
    pair, the couplings between harmonics (``X^|m-r| +- (-1)^min X^(m+r)``, the
    ``r + m`` odd ``Gamma``) included, at wake skew 30 and 60 deg (quadrature accurate
    to about 1e-4; the couplings are up to 0.6)."""
    st = ph.truncation(2)
    for chi in (30.0, 60.0):
        x = math.tan(math.radians(chi) / 2)
        got = potential.gain(st, math.radians(chi))
        want = ph.gain_matrix(st, x)
        assert np.abs(got - want).max() < 2e-4, (chi, np.abs(got - want).max())
        # and the skew is there: without it the difference is O(X)
        assert np.abs(got - ph.gain_matrix(st, 0.0)).max() > 0.25


@pytest.mark.slow
@pytest.mark.parametrize("chi", [30.0, 60.0, 75.0])
def test_skewed_gain_is_the_pressure_potentials_15_states(chi):
    """All 15 states (harmonics 0-4) at a finer quadrature: within 1e-4 (measured
    2e-5, 5e-5, 8e-5 at 30, 60, 75 deg)."""
    st = ph.truncation(4)
    got = potential.gain(st, math.radians(chi), nr=28, npsi=48, ns=120)
    want = ph.gain_matrix(st, math.tan(math.radians(chi) / 2))
    assert np.abs(got - want).max() < 1e-4


#: BladeAD (github LSDOlab/BladeAD, commit 56370f9581a5f0f531588cff86b96a55bccc35fa,
#: BladeAD/core/peters_he/peters_he_inflow.py, ``compute_L(4, 4, x, "cos"/"sin")``),
#: run here on numpy on 2026-11-27: entries ``(kind, r, j, m, n): L_jn^rm`` between
#: harmonics with ``r + m`` even (the odd ones below), at X = 0.27, 0.58, 0.91.
BLADEAD_SKEW = {
    0.27: {
        ('c', 0, 1, 0, 1): 0.75,
        ('c', 0, 1, 0, 3): 0.19094065395649334,
        ('c', 0, 1, 2, 3): 0.012706774152986275,
        ('c', 1, 2, 0, 1): 0.1385153816574813,
        ('c', 1, 2, 1, 2): 0.5794375,
        ('c', 1, 2, 0, 3): 0.08904560249409514,
        ('c', 1, 2, 2, 3): -0.03768065462206976,
        ('s', 1, 2, 1, 2): 0.6705625,
        ('s', 1, 2, 2, 3): -0.04360648726568724,
        ('c', 0, 3, 0, 1): 0.19094065395649334,
        ('c', 0, 3, 0, 3): 0.65625,
        ('c', 0, 3, 2, 3): 0.04367231579607598,
        ('c', 2, 3, 0, 1): 0.02541354830597255,
        ('c', 2, 3, 0, 3): 0.08734463159215196,
        ('c', 2, 3, 2, 3): 0.54978131796875,
        ('s', 2, 3, 2, 3): 0.54396868203125,
        ('c', 0, 1, 4, 5): -0.0001330331326365696,
        ('c', 2, 3, 4, 5): 0.01151183299771737,
        ('c', 4, 5, 2, 3): 0.01151183299771737,
        ('s', 1, 2, 3, 4): 0.01320019036689997,
        ('s', 4, 5, 2, 3): 0.011390122615785413,
        ('c', 0, 3, 2, 5): 0.014484468522149532,
    },
    0.58: {
        ('c', 0, 1, 0, 1): 0.75,
        ('c', 0, 1, 0, 3): 0.19094065395649334,
        ('c', 0, 1, 2, 3): 0.05863592352626313,
        ('c', 1, 2, 0, 1): 0.29755156059755244,
        ('c', 1, 2, 1, 2): 0.41474999999999995,
        ('c', 1, 2, 0, 3): 0.19128314609842656,
        ('c', 1, 2, 2, 3): -0.05793786197573151,
        ('s', 1, 2, 1, 2): 0.83525,
        ('s', 1, 2, 2, 3): -0.11667896133870943,
        ('c', 0, 3, 0, 1): 0.19094065395649334,
        ('c', 0, 3, 0, 3): 0.65625,
        ('c', 0, 3, 2, 3): 0.20152766850205703,
        ('c', 2, 3, 0, 1): 0.11727184705252626,
        ('c', 2, 3, 0, 3): 0.40305533700411406,
        ('c', 2, 3, 2, 3): 0.6087620874999999,
        ('s', 2, 3, 2, 3): 0.4849879125,
        ('c', 0, 1, 4, 5): -0.0028328053600478863,
        ('c', 2, 3, 4, 5): 0.05882075017345066,
        ('c', 4, 5, 2, 3): 0.05882075017345066,
        ('s', 1, 2, 3, 4): 0.07587275866797139,
        ('s', 4, 5, 2, 3): 0.04686125076457862,
        ('c', 0, 3, 2, 5): 0.06683916612964474,
    },
    0.91: {
        ('c', 0, 1, 0, 1): 0.75,
        ('c', 0, 1, 0, 3): 0.19094065395649334,
        ('c', 0, 1, 2, 3): 0.1443412849943475,
        ('c', 1, 2, 0, 1): 0.4668481381789185,
        ('c', 1, 2, 1, 2): 0.10743749999999996,
        ('c', 1, 2, 0, 3): 0.3001166602578762,
        ('c', 1, 2, 2, 3): -0.02354753021918506,
        ('s', 1, 2, 1, 2): 1.1425625,
        ('s', 1, 2, 2, 3): -0.2504202442914033,
        ('c', 0, 3, 0, 1): 0.19094065395649334,
        ('c', 0, 3, 0, 3): 0.65625,
        ('c', 0, 3, 2, 3): 0.49609114829534323,
        ('c', 2, 3, 0, 1): 0.288682569988695,
        ('c', 2, 3, 0, 3): 0.9921822965906865,
        ('c', 2, 3, 2, 3): 0.9218943179687501,
        ('s', 2, 3, 2, 3): 0.17185568203124993,
        ('c', 0, 1, 4, 5): -0.017166048314414182,
        ('c', 2, 3, 4, 5): 0.21927589744895515,
        ('c', 4, 5, 2, 3): 0.21927589744895515,
        ('s', 1, 2, 3, 4): 0.25549132236447575,
        ('s', 4, 5, 2, 3): 0.04087649546656821,
        ('c', 0, 3, 2, 5): 0.16453482007122122,
    },
}


def test_skewed_gain_equals_bladead():
    """Pair by pair at three skews: every ``r + m`` even entry to rounding.  For ``r +
    m`` odd BladeAD's ``compute_gamma`` differs: it keeps the entries with ``|j - 1|
    = 1`` (not ``|j - n| = 1``) and writes ``pi sgn(r-m) / (sqrt(H H) (2n+1)(2j+1))``
    for ``(pi/2) sgn(r-m) / (sqrt(H H) sqrt((2n+1)(2j+1)))``: where both are nonzero
    ours is theirs times ``sqrt((2n+1)(2j+1))/2`` exactly; the pressure potential's
    quadrature (above) decides for the published form."""
    for x, entries in BLADEAD_SKEW.items():
        for (kind, r, j, m, n), want in entries.items():
            got = ph.skew_factor(kind, r, m, x) * ph.gamma_rm(r, m, j, n)
            if (r + m) % 2 == 0:
                assert got == pytest.approx(want, rel=1e-14, abs=1e-16), (x, kind, r, j, m, n)
            else:
                ratio = math.sqrt((2 * n + 1) * (2 * j + 1)) / 2
                assert got == pytest.approx(want * ratio, rel=1e-13), (x, kind, r, j, m, n)


def test_three_state_member_is_pitt_peters():
    """The lowest three states' ``L(X)`` in the recorded inflow and the loads,
    ``lambda = S L W T (C_T, C_mc, C_ms) / (2V)``, has Pitt-Peters' form at every
    skew: ``lambda0`` from ``C_T`` and ``C_mc``, ``lambda1c`` from ``C_T`` and ``C_mc``
    times ``(1 - X^2)``, ``lambda1s`` from ``C_ms`` times ``(1 + X^2)``, the pair
    symmetric; each element is Pitt-Peters' ``(1/V) [[1/2, 15 pi/64 X, 0], [15 pi/64
    X, -2 (1-X^2), 0], [0, 0, -2 (1+X^2)]]`` times 9/8, 8/5, 75/64 (the pressure
    functions as test functions; Pitt-Peters' is the least-squares fit of the inflow,
    the Gram matrix in axial flow).  The moment column is Pitt-Peters' least squares
    exactly: the inflow of the ``P_2^1`` pressure fitted with ``lambda0 + r lambda1c
    cos psi`` by quadrature of the pressure potential has ``lambda0 / lambda1c = -(15
    pi/64) X / (2 (1 - X^2))``."""
    low = ph.truncation(1)
    wt = np.diag([0.5, 1.0, 1.0]) @ np.diag(eff.T_BASE)
    for x in (0.0, 0.2, 0.5, 0.856, 1.0):
        lam = np.diag(eff.S_BASE) @ ph.gain_matrix(low, x) @ wt / 2      # times V
        k = 15 * math.pi / 64 * x
        pp = np.array([[0.5, k, 0.0], [k, -2 * (1 - x * x), 0.0], [0.0, 0.0, -2 * (1 + x * x)]])
        factor = np.array([[9 / 8, 8 / 5, 1], [8 / 5, 75 / 64, 1], [1, 1, 75 / 64]])
        np.testing.assert_allclose(lam, pp * factor, rtol=1e-14, atol=1e-15)
    # the skewed-wake effect's theory gain is this k at the same trim
    from inflowsim.model.effects import skewed_wake
    x = eff.wake_skew({}, K)
    assert skewed_wake.theory_skew(K) == pytest.approx(15 * math.pi / 64 * x, rel=1e-12)
    chi = math.radians(60)
    l0, l1c, _ = potential.least_squares_inflow(("c", 1, 2), chi)
    x = math.tan(chi / 2)
    assert l0 / l1c == pytest.approx(-(15 * math.pi / 64) * x / (2 * (1 - x * x)), rel=3e-4)


@pytest.mark.parametrize("name", list(EFFECTS))
def test_the_fmus_run_time_solve_is_the_gain_inverse(name):
    """The FMU solves ``L(X) Y = I`` at run time (the effect's
    :class:`~inflowsim.model.effects.RuntimeLinear`, generated into C): its matrix,
    evaluated on symbols and on numbers, is :func:`gain_matrix`, and its solution is
    the effect's ``L(X)^-1`` (LAPACK's) from axial to edgewise flow."""
    import sympy
    rl = CATALOGUE[name].runtime()
    st = eff.layout(EFFECTS[name])[0]
    x = sympy.Symbol("x")
    sym = rl.matrix((x,))
    for xv in (0.0, 0.4, 0.856, 1.0):
        want = eff.gain_inverse(EFFECTS[name], xv)
        np.testing.assert_allclose(rl.solve((xv,)), want, rtol=0,
                                   atol=1e-14 * np.abs(want).max())
        got = np.array(sympy.Matrix(sym).xreplace({x: xv}), dtype=float)
        np.testing.assert_allclose(got, ph.gain_matrix(st, xv), rtol=1e-15, atol=1e-16)
    assert rl.shape((0.5,)) == (len(st), len(st))


def test_the_traced_structure_calls_the_solve_at_the_trims_skew():
    """Traced for the FMU's C, a Peters-He structure asks for one run-time call whose
    argument is the wake skew of the trim (the FMU's trim parameters, the azimuth
    bias turning it); with the call's results the effect's ``L(X)^-1``, the traced
    E, A, B are build_model's."""
    import sympy
    from inflowsim.fmu.codegen import _trace
    structure = "glauert+azimuth-bias+peters-he-6"
    s = ifs.Structure.parse(structure)
    k = K.with_mu(0.3)
    p = truth_parameters(s, k) | {"azimuth_bias": 0.15, "k_ph": 1.3}
    e, a, b = ifs.descriptor(structure, p, k)
    _, es, as_, bs, _, calls = _trace(structure)
    assert [c[0] for c in calls] == ["peters-he-6"]
    values = {**p, "mu": k.mu, "a0": k.a0, "solidity": k.solidity, "V": k.flow_speed,
              **{f"trim_{c}": v for c, v in TRIM.items()}}
    subs = {sympy.Symbol(n): v for n, v in values.items()}
    x = float(calls[0][1][0].xreplace(subs))
    assert x == pytest.approx(eff.wake_skew(p, k), rel=1e-14)
    linv = eff.gain_inverse(2, x)
    subs |= {sympy.Symbol(f"numeric_0_0[{i}]"): v for i, v in enumerate(linv.ravel())}
    for sym, num in ((es, e), (as_, a), (bs, b[:, : bs.shape[1]])):
        got = np.array([[float(sympy.sympify(v).xreplace(subs)) for v in row]
                        for row in sym])
        np.testing.assert_allclose(got, num, rtol=1e-13, atol=1e-13)


def test_skewed_wake_is_an_alternative():
    """The skew of the three lowest states is in ``L(X)``: with ``skewed-wake``'s pair
    it would be counted twice, so a structure never holds both."""
    for name in EFFECTS:
        with pytest.raises(ifs.InputError, match="alternatives"):
            ifs.Structure.parse(f"basic+skewed-wake+{name}")


def test_refused_without_a_trim():
    s = ifs.Structure.parse("basic+peters-he-6")
    with pytest.raises(ifs.InputError, match="trim"):
        ifs.build_model(s, truth_parameters(s, K), ifs.PUMA)
