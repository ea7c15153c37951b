"""The blade truth's lead-lag (``RotorSpec(nu_zeta=...)``, ``flighttest --add lead-lag``)
against the linear ``lead-lag`` effect (``model.md`` 9.1 and "The blade truth's
lead-lag").

The independent route: the truth's right-hand side (each blade's flap and lag
equations from Lagrange's equations and blade-element lift and in-plane force,
nothing of the effect's matrices) differentiated by central differences in
multiblade coordinates and averaged over the azimuth (16 blades), against the
effect's descriptor built by the library.
"""
import numpy as np
import pytest

import inflowsim as ifs
from inflowsim.channels import INPUTS_AZ
from inflowsim.errors import InputError
from inflowsim.flighttest.bladesim import BladeRotor, RotorSpec, multiblade_derivatives
from inflowsim.flighttest.nonlinear import trim_inputs
from inflowsim.model.effects import lead_lag
from inflowsim.model.effects.advance_ratio_perturbation import true_trim

STATES = ("beta0", "beta1c", "beta1s", "beta0_prime", "beta1c_prime", "beta1s_prime",
          "lambda0", "lambda1c", "lambda1s", "zeta0", "zeta1c", "zeta1s", "zeta0_prime",
          "zeta1c_prime", "zeta1s_prime")


def _effect(mu, th_t, b_t, nu, zl, theta=None, beta=None):
    """The effect's ``(A, B)`` rows ``(beta'', lambda', zeta'')`` in the truth's state
    and input order, the trim inflow it is linearised about, the spec, the
    steady lag it holds and the trim's 2/rev flap (an axisymmetric trim ``th_t, b_t``, or the trim's pitch
    ``theta`` and flap ``beta``)."""
    theta = (th_t, 0.0, 0.0) if theta is None else theta
    beta = (b_t, 0.0, 0.0) if beta is None else beta
    k = ifs.PUMA.with_mu(mu).with_trim({"theta0": theta[0], "theta1c": theta[1],
                                        "theta1s": theta[2], "beta0": beta[0],
                                        "beta1c": beta[1], "beta1s": beta[2], "muz": 0.0})
    spec = RotorSpec(constants=k, n_blades=16, speed="mu", nu_zeta=nu, zeta_lag=zl)
    p = {"lambda_beta2": spec.lambda_beta2, "n_beta": spec.n_beta, "tau0": spec.tau0,
         "tau_cs": spec.tau_cs, "flap_inertia": 1.0, "nu_zeta": nu, "zeta_lag": zl,
         "k_flap_lag": 1.0}
    m = ifs.build_model("basic+separate-time-constants+flap-inertia+lead-lag", p, k)
    ei = np.linalg.inv(m.E)
    a, b = ei @ m.A, ei @ m.B
    names = list(m.states)
    idx = [names.index(s) for s in STATES]
    rows = idx[3:9] + idx[12:15]
    bm = np.zeros((9, len(INPUTS_AZ)))
    for j, name in enumerate(m.inputs_az):
        bm[:, INPUTS_AZ.index(name)] = b[rows, j]
    # the trim inflow and the steady lag the effect is linearised about: the basic
    # model's trim inflow moved by the steady lag's share of the trim's loads
    zt, *_, lam = lead_lag.coefficients(p, k)
    assert np.abs(lam - true_trim(k, 0.0, None)[3]).max() < 0.003
    return a[np.ix_(rows, idx)], bm, lam, spec, zt, lead_lag.trim_flap2(p, k)


def _with_second_lag(rot, psi, w, b2=(0.0, 0.0)):
    """The truth's multiblade accelerations ``(beta'', lambda', zeta'')`` (9) and its
    second-harmonic lag's ``(zeta2c'', zeta2s'')`` (2) at ``w = (z (15), u (10),
    zeta2c, zeta2s)``: the blades' lag gains ``zeta2c cos 2psi_i + zeta2s sin 2psi_i``
    at rest in the fixed frame (its rate ``2 (zeta2s cos - zeta2c sin) 2psi_i``), and
    the lag accelerations are projected on ``(2 cos 2psi_i, 2 sin 2psi_i) / Nb`` too
    (``zeta2c'' = P2c + 4 zeta2c`` with the coordinates' rates zero); the blades'
    flap also has the trim's 2/rev part ``b2`` (at rest in the fixed frame)."""
    z, u, (z2c, z2s) = w[:15], w[15:25], w[25:]
    nb = rot.nb
    a2 = 2 * (psi + rot.offsets)
    c2, s2 = np.cos(a2), np.sin(a2)
    zeta2, dzeta2 = z2c * c2 + z2s * s2, 2 * (z2s * c2 - z2c * s2)
    beta2, dbeta2 = b2[0] * c2 + b2[1] * s2, 2 * (b2[1] * c2 - b2[0] * s2)
    # the first harmonics' blades from multiblade_derivatives' own transformation
    from inflowsim.physics.multiblade import blade_angles
    rates = [z[12], z[13] + z[11], z[14] - z[10]]
    x = np.concatenate([blade_angles(z[0:3], psi, nb) + beta2,
                        blade_angles([z[3], z[4] + z[2], z[5] - z[1]], psi, nb) + dbeta2,
                        z[6:9],
                        blade_angles(z[9:12], psi, nb) + zeta2,
                        blade_angles(rates, psi, nb) + dzeta2])
    f = rot.rhs(psi, x, tuple(float(v) for v in u))
    lag_acc = f[3 * nb + 3:]
    from inflowsim.physics.multiblade import multiblade
    pb, pz = multiblade(f[nb:2 * nb], psi), multiblade(lag_acc, psi)
    out = np.concatenate([
        [pb[0], pb[1] - 2 * z[5] + z[1], pb[2] + 2 * z[4] + z[2]], f[2 * nb:2 * nb + 3],
        [pz[0], pz[1] - 2 * z[14] + z[10], pz[2] + 2 * z[13] + z[11]],
        [2 * (lag_acc @ c2) / nb + 4 * z2c, 2 * (lag_acc @ s2) / nb + 4 * z2s]])
    return out


def _truth_jacobian(spec, z0, u0, z2=(0.0, 0.0), b2=(0.0, 0.0), n_psi=4, eps=1e-6):
    """The truth's averaged Jacobian of ``(beta'', lambda', zeta'')`` per ``(z, u)``
    (9 x 25) with its second-harmonic lag quasi-static: differenced with
    ``zeta2c, zeta2s`` as two more columns and rows (about the trim's 2/rev lag
    ``z2`` and 2/rev flap ``b2``), and those condensed, ``zeta2 = -J22^-1 J2w w`` (the effect's
    :func:`inflowsim.physics.lead_lag.second_harmonic` by another route: the blades'
    own equations, numbers only)."""
    rot = BladeRotor(spec)
    w0 = np.concatenate([z0, u0, z2])
    jac = np.zeros((11, w0.size))
    # without the second harmonic, the library's multiblade transformation
    np.testing.assert_allclose(_with_second_lag(rot, 0.1, w0 * (np.arange(w0.size) < 25))[:9],
                               multiblade_derivatives(rot, 0.1, z0, u0), rtol=0, atol=1e-13)
    for psi in np.linspace(0, 2 * np.pi / rot.nb, n_psi, endpoint=False):
        for j in range(w0.size):
            d = np.zeros(w0.size)
            d[j] = eps
            jac[:, j] += (_with_second_lag(rot, psi, w0 + d, b2)
                          - _with_second_lag(rot, psi, w0 - d, b2)) / (2 * eps)
    jac /= n_psi
    return jac[:9, :25] - jac[:9, 25:] @ np.linalg.solve(jac[9:, 25:], jac[9:, :25])


@pytest.mark.parametrize("mu, b_t, nu, zl", [(0.249, 0.06, 0.25, 0.2),
                                             (0.15, 0.02, 0.65, 0.05)])
def test_the_blade_truths_lag_linearised_is_the_lead_lag_effect(mu, b_t, nu, zl):
    """About an axisymmetric trim (collective, coning, and the trim inflow and the
    steady lag the effect finds there: the drag holds the blades aft, and in
    forward flight the lag moment's 1/rev parts a cyclic lag) every coefficient of
    the effect's flap, inflow and lag rows, states and the eight base inputs, comes
    out of the blade truth.  Tolerance: the truth's inertia is Lagrange's exact in the
    flap (``sin beta cos beta``, ``cos^2 beta``), the effect's linear in
    ``beta_t``: they differ by ``(2/3) beta_t^2`` relative in the Coriolis terms and
    ``beta_t^2`` in the lag rows (0.36 % at ``beta_t = 0.06``): each entry within
    ``2 beta_t^2`` of itself, plus 1e-7 for the differences' rounding and the square
    of the cyclic steady lag the effect keeps to first order.  The lag rows' flap
    columns also hold the derivative of the exact ``1/cos^2 beta`` times the lag
    moment at this point: within ``4 tan beta_t max|Z_t|`` (7e-4 at the Puma's
    coning)."""
    th_t = 0.17
    a, b, lam, spec, zt, b2 = _effect(mu, th_t, b_t, nu, zl)
    u0 = np.array([th_t, 0, 0, 0, 0, 0, 0, 0, mu, 0])
    z0 = np.concatenate([[b_t, 0, 0], np.zeros(3), lam, zt[:3], np.zeros(3)])
    lam0 = lam[0]
    # the drag holds the blades aft by a few degrees; the cyclic steady lag is small
    assert 0.005 < zt[0] < 0.2 and np.abs(zt[1:]).max() < zt[0]
    # the truth linearised about the effect's steady lag and flap, their 2/rev parts
    # included
    jac = _truth_jacobian(spec, z0, u0, zt[3:], b2)
    rel, atol = 2 * b_t ** 2, 1e-7 + np.abs(zt[1:]).max() ** 2
    rot = BladeRotor(spec)
    x0 = np.concatenate([np.full(16, b_t), np.zeros(16), [lam0, 0, 0], np.zeros(32)])
    z_t = max(np.abs(rot.lag_terms(p, x0, tuple(u0))[1]).max()
              for p in np.linspace(0, 2 * np.pi, 8, endpoint=False))
    slack = np.zeros_like(a)
    slack[6:, :9] = 4 * np.tan(b_t) * z_t
    assert 1e-4 < z_t < 0.02
    assert np.all(np.abs(jac[:, :15] - a) <= rel * np.abs(a) + slack + atol)
    tol = rel * np.abs(a).max() + atol
    # the base inputs; the lag rows' hub angular accelerations (pbar', qbar') are
    # the truth's own (sin beta cos beta, inertial; the effect has no such term),
    # mux, muy act on the blades as advance-ratio-perturbation's do
    base = [INPUTS_AZ.index(c) for c in INPUTS_AZ[:8]]
    d = jac[:, 15:][:, base] - b[:, base]
    sc = np.sin(b_t) * np.cos(b_t)
    qd, pd = INPUTS_AZ.index("qbar_prime"), INPUTS_AZ.index("pbar_prime")
    np.testing.assert_allclose(d[7:, [qd, pd]], [[0, sc], [-sc, 0]], atol=tol)
    d[7:, [qd, pd]] = 0
    assert np.all(np.abs(d) <= rel * np.abs(b[:, base]) + atol)
    # the lag matters: its columns of the flap and inflow rows and the flap columns
    # of its rows are far above the tolerance
    assert np.abs(a[:6, 9:]).max() > 3 * tol and np.abs(a[6:, :9]).max() > 3 * tol
    # a collective lag turns the whole rotor: about an axisymmetric trim it would
    # leave the hub moments (inflow rows) unchanged, but in forward flight the trim's
    # cyclic steady lag is not axisymmetric, and the effect has what the truth has
    assert np.abs(jac[4:6, 9]).max() > 1e-5
    np.testing.assert_allclose(a[4:6, 9], jac[4:6, 9], rtol=0.05)


@pytest.mark.slow
@pytest.mark.parametrize("mu, nu, zl", [(0.249, 0.25, 0.2), (0.1, 0.65, 0.05),
                                        (0.15, 0.25, 0.2)])
def test_about_the_truths_own_periodic_trim_the_effect_is_the_truth(mu, nu, zl):
    """In forward flight the trim is not axisymmetric: cyclic pitch, flap and inflow,
    and a steady lag (collective and cyclic) held by the drag and the cyclic flap's
    Coriolis moment.  The truth's periodic trim (the given controls, four blades)
    against the effect built from what a record gives (the controls and the mean
    flap; the inflow its own trim's): the effect's steady lag is the truth's
    (measured within 1 % and 5e-5 rad; its 2/rev part within 1e-5 rad of the
    truth's blade, the trim's 2/rev flap within 1.6e-4 rad), and the truth's averaged
    Jacobian about its trim (16 blades) is the effect's, every coefficient within 5 %
    of the largest lag coupling (measured 0.0034, 0.0043, 0.0020 against 0.15;
    before the trim's 2/rev flap and lag 0.0036, 0.0043, 0.0046; linearised
    about an axisymmetric trim without steady lag the effect was 0.29 off at mu =
    0.249): what is left is Lagrange's exact inertia (``cos^2 beta``, the coning's
    0.1-0.12 rad) and the trim's higher harmonics, the averaging's own level."""
    u0 = trim_inputs(mu)
    rotor = RotorSpec(constants=ifs.PUMA.with_mu(mu), speed="mu", nu_zeta=nu, zeta_lag=zl)
    tr = BladeRotor(rotor).periodic_trim(u0)
    a, b, lam, spec, zt, b2 = _effect(mu, None, None, nu, zl, theta=tuple(u0[:3]),
                                  beta=tuple(tr.beta))
    assert abs(zt[0] - tr.zeta[0]) < 0.02 * tr.zeta[0]
    np.testing.assert_allclose(zt[1:3], tr.zeta[1:], atol=1e-4)
    # the trim's 2/rev lag and flap: blade 0's over a revolution of the periodic trim
    rot = BladeRotor(rotor)
    n, x, blade = 360, tr.x, []
    for m in range(n):
        blade.append((x[0], x[2 * rot.nb + 3]))
        x = rot.step(2 * np.pi * m / n, x, tuple(u0), 2 * np.pi / n)
    psi, blade = 2 * np.pi * np.arange(n) / n, np.array(blade)
    second = [[2 * np.mean(blade[:, i] * f(2 * psi)) for f in (np.cos, np.sin)]
              for i in (0, 1)]
    np.testing.assert_allclose(b2, second[0], atol=3e-4)
    np.testing.assert_allclose(zt[3:], second[1], atol=5e-5)
    z0 = np.concatenate([tr.beta, np.zeros(3), tr.lam, tr.zeta, np.zeros(3)])
    jac = _truth_jacobian(spec, z0, u0, zt[3:], b2)
    coupling = max(np.abs(a[:6, 9:]).max(), np.abs(a[6:, :9]).max())
    assert coupling > 0.05
    assert np.abs(jac[:, :15] - a).max() < 0.05 * coupling
    assert np.abs(jac[:, 15:21] - b[:, :6]).max() < 0.05 * coupling


def test_the_lag_truth_trims_periodically_and_the_lag_free_truth_is_unchanged():
    spec = RotorSpec(nu_zeta=0.3, zeta_lag=0.5)    # a firm damper: a short trim
    rot = BladeRotor(spec)
    assert spec.n_states == 4 * 4 + 3 and RotorSpec().n_states == 2 * 4 + 3
    u = np.array([0.17, 0.01, -0.05, 0.0, 0, 0, 0, 0, 0.249, 0.0])
    tr = rot.periodic_trim(u)
    x = tr.x
    for m in range(18):                               # one blade passage
        x = rot.step(m * np.pi / 36, x, tuple(u), np.pi / 36)
    np.testing.assert_allclose(rot.relabel(x), tr.x, atol=1e-10)
    # the drag holds the blades aft (zeta positive aft) by a few degrees
    assert 0.01 < tr.zeta[0] < 0.1 and "zeta0" in tr.as_dict()
    # without the lag the truth's right-hand side is the rigid in-plane blades'
    rigid = BladeRotor(RotorSpec())
    xr = np.concatenate([x[:11]])
    lagged = np.concatenate([x[:11], np.zeros(8)])
    f_lag = BladeRotor(RotorSpec(nu_zeta=0.3)).rhs(0.3, lagged, tuple(u))
    np.testing.assert_allclose(f_lag[:11], rigid.rhs(0.3, xr, tuple(u)), rtol=1e-12,
                               atol=1e-15)
    with pytest.raises(InputError, match="nu_zeta = 2"):
        RotorSpec(nu_zeta=2.0).check()
    with pytest.raises(InputError, match="zeta_lag = -1"):
        RotorSpec(nu_zeta=0.3, zeta_lag=-1.0).check()
    with pytest.raises(InputError, match="takes 15"):
        multiblade_derivatives(rot, 0.0, np.zeros(9), u)


def test_flighttest_add_lead_lag_flies_the_blades_lag(tmp_path, capsys):
    """``flighttest --add lead-lag``: the truth's theory values for the rotor or
    ``--set nu_zeta, zeta_lag``; the record's flap differs from the rigid blades'."""
    import json
    from inflowsim.cli import main
    from inflowsim.data.record import read_record
    common = ["--duration", "2", "--dt", "0.02", "--noise", "0", "--start", "0.2",
              "--speed", "mu", "--no-body"]
    assert main(["flighttest", *common, "--add", "lead-lag", "--set", "nu_zeta=0.3",
                 "--set", "zeta_lag=0.5", "--out", str(tmp_path / "lag.csv"),
                 "--truth-json", str(tmp_path / "lag.json")]) == 0
    assert main(["flighttest", *common, "--out", str(tmp_path / "rigid.csv")]) == 0
    truth = json.loads((tmp_path / "lag.json").read_text())
    assert truth["rotor"]["nu_zeta"] == 0.3 and truth["rotor"]["zeta_lag"] == 0.5
    lag, rigid = read_record(tmp_path / "lag.csv"), read_record(tmp_path / "rigid.csv")
    assert "blade lead-lag nu_zeta 0.3, zeta_lag 0.5" in lag.meta["description"]
    d = lag.channels["beta1s"] - rigid.channels["beta1s"]
    dev = rigid.channels["beta1s"] - rigid.channels["beta1s"][0]
    # the lag's steady deflection moves the trim, its dynamics the response
    assert np.abs(d - d[0]).max() > 0.01 * np.abs(dev).max()
    for argv, words in ((["--add", "lead-lag", "--set", "k_flap_lag=0.5"],
                         "k_flap_lag: the nonlinear truth's flap-lag coupling"),
                        (["--set", "zeta_lag=0.1"], "nu_zeta, zeta_lag with --add lead-lag")):
        capsys.readouterr()
        assert main(["flighttest", *common, *argv, "--out", str(tmp_path / "x.csv")]) == 2
        assert words in capsys.readouterr().err


#: The blade-truth records of the identification: Puma at mu 0.249, the trim mu as
#: the speed through the disc and the hub fixed (the rigid truth is then exactly
#: ``BASE`` linearised), a 3-2-1-1 on theta1s, noise 1e-4 rad, seed 5.
BASE = "basic+separate-time-constants+flap-inertia"
NU, ZL = 0.25, 0.2


@pytest.fixture(scope="module")
def blade_fits():
    from inflowsim.flighttest.nonlinear import FlightTest, nonlinear_flighttest
    from inflowsim.flighttest.virtual import Manoeuvre
    from inflowsim.identify.estimator import identify
    man = (Manoeuvre(channel="theta1s", shape="3211", amplitude=np.radians(1.0),
                     t_start=2.0, width=0.4),)
    out = {}
    for name, lag in (("rigid", {}), ("lag", {"nu_zeta": NU, "zeta_lag": ZL})):
        test = FlightTest(rotor=RotorSpec(speed="mu", **lag), manoeuvres=man, seed=5,
                          body=None)
        rec = nonlinear_flighttest(test).record
        out[name] = {s: identify(rec, s) for s in (BASE, BASE + "+lead-lag")}
    return out


@pytest.mark.slow
def test_lead_lag_is_seen_in_a_blade_truth_record(blade_fits):
    """The rigid truth's record is explained by BASE at its own values; the lagged
    truth's is not, and lead-lag takes most of what BASE leaves (measured: the
    cost falls about 50 times; nu_zeta 0.298 +- 0.003 against 0.25)."""
    rigid, lag = blade_fits["rigid"], blade_fits["lag"]
    assert abs(rigid[BASE].parameters["flap_inertia"] - 1.0) < 3 * \
        rigid[BASE].sigma["flap_inertia"]
    assert lag[BASE].cost > 20 * rigid[BASE].cost
    assert lag[BASE + "+lead-lag"].cost < 0.1 * lag[BASE].cost
    nu = lag[BASE + "+lead-lag"].parameters["nu_zeta"]
    assert abs(nu - NU) < 0.25 * NU


@pytest.mark.slow
def test_lead_lag_from_a_blade_truth_record_within_3_sigma(blade_fits):
    fit = blade_fits["lag"][BASE + "+lead-lag"]
    for name, truth in (("nu_zeta", NU), ("zeta_lag", ZL)):
        assert abs(fit.parameters[name] - truth) < 3 * fit.sigma[name], name


def test_a_blade_truth_record_names_its_rotors_hub():
    """The record of a hingeless blade truth says so (``# hub: hingeless``), as the
    linear flight test's does: the lag's theory frequency (0.65 per rev, not an
    articulated rotor's 0.25) and the plausible ranges are the hingeless rotor's."""
    from dataclasses import replace
    from inflowsim.flighttest.nonlinear import FlightTest, nonlinear_flighttest
    k = replace(ifs.PUMA, hub="hingeless")
    rec = nonlinear_flighttest(FlightTest(rotor=RotorSpec(constants=k, speed="mu"),
                                          duration=0.5, dt=0.05, body=None,
                                          noise_flap=0.0)).record
    assert rec.meta["hub"] == "hingeless" and rec.constants.hub == "hingeless"
    assert lead_lag.EFFECT.theory(rec.constants)["nu_zeta"] == 0.65


#: The hingeless rotor of ``bench/detection.py`` (flap frequency squared 1.25, Lock
#: number 5.2, mu 0.236) with its theory lag (``nu_zeta`` 0.65, ``zeta_lag`` 0.2).
HINGELESS = {"mu": 0.236, "a0": 5.7, "solidity": 0.07, "omega": 44.4, "radius": 4.91,
             "hub": "hingeless"}


@pytest.fixture(scope="module")
def hingeless_ladders():
    from dataclasses import replace
    from inflowsim.diagnose import ladder
    from inflowsim.flighttest.nonlinear import FlightTest, nonlinear_flighttest
    from inflowsim.flighttest.virtual import Manoeuvre
    man = (Manoeuvre(channel="theta1s", shape="3211", amplitude=np.radians(1.0),
                     t_start=2.0, width=0.4),)
    spec = RotorSpec(constants=replace(ifs.PUMA, **HINGELESS), lambda_beta2=1.25,
                     n_beta=0.65, speed="mu", nu_zeta=0.65, zeta_lag=0.2)
    out = []
    for seed in (5, 6):
        rec = nonlinear_flighttest(FlightTest(rotor=spec, manoeuvres=man, seed=seed,
                                              body=None)).record
        out.append((rec, ladder(rec, BASE)))
    return out


@pytest.mark.slow
def test_the_hingeless_blade_truths_lag_is_named_with_its_second_harmonic_flap(
        hingeless_ladders):
    """The hingeless blade truth's lag (2.7 and 4.1 times the noise in ``beta0``,
    ``beta1s``; seeds 5 and 6): the ladder from the rigid blades' structure names
    ``lead-lag`` first and then (seed 5) ``second-harmonic-flap`` (the rigid truth's own
    2/rev flap: ``k_beta2`` 1.04 +- 0.16 on the lag-free record), nothing else, and ends
    ``explained`` with every channel within 1.5 of the floor; the lag's coupling
    (its frequency and damper at the hingeless theory) and ``k_beta2`` within 3
    sigma of the truth.  Before the lag's second harmonic and the record's hub, the
    ladder named ``azimuth-bias`` and ``peters-he-6`` instead."""
    for rec, lad in hingeless_ladders:
        added = [r.added for r in lad.rungs[1:]]
        assert added[0] == "lead-lag" and set(added) <= {"lead-lag", "second-harmonic-flap"}, \
            added
        assert lad.verdict.status == "explained"
        fit = lad.final.fit
        level = len(rec) * 1e-4 ** 2
        assert max(abs(fit.S[0][i, i]) for i in range(3)) / level < 1.5
        truth = {"k_flap_lag": 1.0, "k_beta2": 1.0, "nu_zeta": 0.65, "zeta_lag": 0.2}
        for n, v in truth.items():
            if fit.sigma.get(n):
                assert abs(fit.parameters[n] - v) < 3 * fit.sigma[n], (n, fit.parameters[n])
        assert fit.parameters["nu_zeta"] == pytest.approx(0.65, abs=3 * (
            fit.sigma.get("nu_zeta") or 0) + 1e-12)
