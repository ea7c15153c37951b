"""Lead-lag (``lead-lag``, ``model.md`` 9.1) against routes written here.

The blade route: four individual blades, each with its own flap and lag equation in
the rotating frame (the blade-element moments evaluated on a Gauss quadrature of
the full integrand and linearised by a complex step, the inertial terms from the
Lagrangian of a point-mass blade derived here with sympy), the basic inflow driven
by the four blades' summed loads, integrated by scipy's DOP853 with a smooth cyclic
input, then transformed to multiblade coordinates.  Nothing of the library's flap,
lag or load matrices is used: only the model under test is built by the library.
"""
import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

import inflowsim as ifs
from inflowsim.errors import InputError
from inflowsim.model.presets import truth_parameters

N_BLADES = 4
RG, WG = np.polynomial.legendre.leggauss(6)
RG, WG = 0.5 * (RG + 1.0), 0.5 * WG           # radius 0..1
H = 1e-30                                      # complex step


def _coriolis():
    """The linearised inertial terms of a point-mass blade (radius 1, flap ``b`` up,
    lag ``z`` aft against the rotation) about coning ``b0``, azimuth time, from its
    kinetic energy in the inertial frame: ``(flap row, lag row)`` as
    ``{(equation, coordinate rate): coefficient}``."""
    t, b0 = sp.symbols("t b0")
    b, z = sp.Function("b")(t), sp.Function("z")(t)
    ang = t - z                                  # unit rotor speed: psi = t
    pos = sp.Matrix([sp.cos(b) * sp.cos(ang), sp.cos(b) * sp.sin(ang), sp.sin(b)])
    ke = sp.Rational(1, 2) * pos.diff(t).dot(pos.diff(t))
    out = {}
    for q, name in ((b, "flap"), (z, "lag")):
        eq = sp.diff(ke.diff(q.diff(t)), t) - ke.diff(q)
        for r, rname in ((b, "flap"), (z, "lag")):
            c = eq.diff(r.diff(t))
            c = c.subs({r.diff(t): 0 for r in (b, z)}).subs({b: b0, z: 0})
            out[(name, rname)] = sp.trigsimp(c)
    return out, b0


def test_the_coriolis_coupling_from_the_lagrangian():
    """Johnson's Coriolis pair, sign and size: a blade flapping up leads (its lag
    row gains ``+2 beta0 beta'``, lag aft positive), and the flap row's partner is
    ``-2 beta0 zeta'``: skew, as a gyroscopic coupling is."""
    c, b0 = _coriolis()
    for v in (0.05, 0.3, -0.2):
        # sin(2 beta0): 2 beta0 for small coning, as the blade route below has them
        assert abs(float(c[("lag", "flap")].subs(b0, v)) - np.sin(2 * v)) < 1e-14
        assert abs(float(c[("flap", "lag")].subs(b0, v)) + np.sin(2 * v)) < 1e-14
        assert float(c[("flap", "flap")].subs(b0, v)) == 0
        assert float(c[("lag", "lag")].subs(b0, v)) == 0


def _trim_inflow(mu, a0s, v, th, b, muz):
    """The basic inflow model's steady collective inflow at an axisymmetric trim: the
    momentum row ``lambda0 = a0 s c_T / (2 V)`` with the four blades' ``c_T``."""
    def ct(lam0):
        psi = 2 * np.pi * np.arange(N_BLADES) / N_BLADES
        out = 0.0
        for p in np.linspace(0, 2 * np.pi, 64, endpoint=False):
            for ps in psi + p:
                ut = RG + mu * np.sin(ps)
                up = muz - lam0 - mu * b * np.cos(ps)
                out += 0.5 * np.sum(WG * (th * ut**2 + up * ut)) / (N_BLADES * 64)
        return out
    # linear in lambda0
    c0, c1 = ct(0.0), ct(1.0) - ct(0.0)
    return a0s / (2 * v) * c0 / (1 - a0s / (2 * v) * c1)


def _route_trim(k, p, th_t, b_t, muz_t, lam_guess, psi0):
    """The blades' trim: their periodic lag under the trim's drag (one blade's
    nonlinear lag equation, the blade at ``psi - zeta``, its lag rate in ``U_T``;
    the one-revolution map's fixed point) and the trim inflow ``lambda = L c`` with
    the blades' mean loads at that lag (their lift acting at ``psi - zeta``, the
    lag's action scaled by ``k_flap_lag``; Newton's method from ``lam_guess``).
    Returns the trim inflow (3) and ``(zeta, zeta')`` of each of the four blades at
    ``psi0``."""
    from scipy.optimize import fsolve
    mu, nb = k.mu, p["n_beta"]
    nu, zl, kz = p["nu_zeta"], p["zeta_lag"], p["k_flap_lag"]
    dl = 0.01 / k.a0
    v = k.flow_speed
    lmat = np.diag([k.a0s / (2 * v), -2 * k.a0s / v, -2 * k.a0s / v])

    def velocities(psi, z, dz, lam, kz):
        at = psi - kz * z
        ut = RG * (1 - kz * dz) + mu * np.sin(at)
        up = (muz_t - lam[0] - RG * (lam[1] * np.cos(at) + lam[2] * np.sin(at))
              - mu * b_t * np.cos(at))
        return ut, up, at

    def periodic(lam):
        def rhs(psi, y):
            ut, up, _ = velocities(psi, y[0], y[1], lam, 1.0)
            drag = -(th_t * ut * up + up**2) + dl * ut**2
            return [y[1], -nu**2 * y[0] - 2 * zl * nu * y[1] + 4 * nb * (drag * RG) @ WG]

        def period(y0):
            return solve_ivp(rhs, (0, 2 * np.pi), y0, method="DOP853", rtol=1e-12,
                             atol=1e-15, dense_output=True)
        y0 = fsolve(lambda y: period(y).y[:, -1] - y, [0.0, 0.0], xtol=1e-13)
        sol = period(y0)
        assert np.abs(sol.y[:, -1] - y0).max() < 1e-11
        return sol

    def residual(lam):
        sol = periodic(lam)
        psi = np.linspace(0, 2 * np.pi, 128, endpoint=False)
        z, dz = sol.sol(psi)
        c = np.zeros(3)
        for ps, zz, dd in zip(psi, z, dz):
            ut, up, at = velocities(ps, zz, dd, lam, kz)
            lift = th_t * ut**2 + up * ut
            c += 0.5 * np.array([lift @ WG, -(RG * np.cos(at) * lift) @ WG,
                                 -(RG * np.sin(at) * lift) @ WG]) / len(psi)
        return lmat @ c - lam, sol

    lam = np.array([lam_guess, 0.0, 0.0])
    # Newton's method with the first Jacobian: the loads are nearly linear in lam
    # (at hover the guess, the rigid blades' momentum inflow, is the trim: the steady
    # lag turns an axisymmetric rotor and leaves its thrust)
    f0, sol = residual(lam)
    if np.abs(f0).max() > 1e-12:
        jac = np.column_stack([(residual(lam + 1e-6 * e)[0] - f0) / 1e-6
                               for e in np.eye(3)])
    for _ in range(4 if np.abs(f0).max() > 1e-12 else 0):
        lam = lam - np.linalg.solve(jac, f0)
        f0, sol = residual(lam)
        if np.abs(f0).max() < 1e-12:
            break
    assert np.abs(f0).max() < 1e-11
    at = np.mod(psi0 + 2 * np.pi * np.arange(N_BLADES) / N_BLADES, 2 * np.pi)
    return lam, sol.sol(at)


def _blade_route(k, p, th_t, b_t, muz_t, lam_t, inputs, t_end, psi0=0.0):
    """Four blades, rotating frame, integrated; returns ``t`` and the multiblade
    ``(beta0, beta1c, beta1s, lambda0, lambda1c, lambda1s, zeta0, zeta1c, zeta1s)``
    of the perturbations about the trim.

    The trim holds the blades at a steady lag (the drag; periodic in forward
    flight) and the inflow at the blades' mean loads (``lam_t``: a first guess of
    its collective part): each blade's trim lag is integrated with the
    perturbations (two more states a blade, started periodic, :func:`_route_trim`);
    the blades meet the free stream and the inflow and their lift acts on the hub
    at ``psi - zeta``, the trim's lag included, and its lag rate acts in ``U_T``
    and in the Coriolis moments."""
    om, mu, nb = k.omega, k.mu, p["n_beta"]
    lb2, tau = p["lambda_beta2"], p["tau"]
    nu, zl, kf = p["nu_zeta"], p["zeta_lag"], p["k_flap_lag"]
    c_z = 2 * zl * nu
    dl = 0.01 / k.a0
    v = k.flow_speed
    lmat = np.diag([k.a0s / (2 * v), -2 * k.a0s / v, -2 * k.a0s / v])
    off = 2 * np.pi * np.arange(N_BLADES) / N_BLADES
    n_pert = 4 * N_BLADES + 3

    def rhs(psi, y):
        t = psi / om
        th0, th1c, th1s = inputs(t)
        bl = y[:4 * N_BLADES].reshape(N_BLADES, 4)          # beta, beta', zeta, zeta'
        lam = y[4 * N_BLADES:n_pert]
        zt, dzt = y[n_pert:].reshape(N_BLADES, 2).T         # the trim's lag
        dy = np.empty_like(y)
        # all blades at once: rows are blades, columns the Gauss radii
        ps = (psi + psi0 + off)[:, None]
        be, dbe, ze, dze = (bl[:, j, None] for j in range(4))
        # perturbation in the imaginary part: the exact linear part of the moments
        d_the = 1j * H * (th0 + th1c * np.cos(ps) + th1s * np.sin(ps))
        the = th_t + d_the

        def velocities(kz):
            # the lag's action on flap and loads scaled by kz (k_flap_lag): the
            # perturbation's and the trim's
            zc = kz * (zt[:, None] + 1j * H * ze)
            at = ps - zc
            d_lam = 1j * H * (lam[0] + RG * (lam[1] * np.cos(at) + lam[2] * np.sin(at)))
            ut = RG * (1 - kz * (dzt[:, None] + 1j * H * dze)) + mu * np.sin(at)
            up = (muz_t - lam_t[0] - RG * (lam_t[1] * np.cos(at) + lam_t[2] * np.sin(at))
                  - d_lam - RG * 1j * H * dbe - mu * (b_t + 1j * H * be) * np.cos(at))
            return ut, up, at

        ut, up, _ = velocities(1.0)
        drag = -(the * ut * up + up**2) + dl * ut**2
        ut, up, where = velocities(kf)
        lift = the * ut**2 + up * ut
        f_aero = (4 * nb * (lift * RG) @ WG).imag / H
        z_all = 4 * nb * (drag * RG) @ WG
        z_aero = z_all.imag / H
        be, dbe, ze, dze = bl.T
        # inertia: Coriolis pair from the Lagrangian (test above), 2 beta zeta' -
        # beta zeta'^2 in the flap and 2 beta beta' (1 - zeta') in the lag,
        # linearised about the trim's coning and lag rate; springs, damper
        d = np.empty((N_BLADES, 4))
        d[:, 0] = dbe
        d[:, 1] = -lb2 * be + kf * (2 * b_t * dze * (1 - dzt) + be * (2 * dzt - dzt**2)) \
            + f_aero
        d[:, 2] = dze
        d[:, 3] = -nu**2 * ze - c_z * dze - 2 * b_t * dbe * (1 - dzt) + z_aero
        dy[:4 * N_BLADES] = d.ravel()
        # each blade's lift acts on the hub where the blade is, at psi - zeta
        c = np.array([(lift @ WG).imag, -((RG * np.cos(where) * lift) @ WG).imag,
                      -((RG * np.sin(where) * lift) @ WG).imag]).sum(axis=1) * 0.5 / H / N_BLADES
        dy[4 * N_BLADES:n_pert] = (lmat @ c - lam) / tau
        # the trim's own lag (real: the moments at the trim)
        dtr = np.empty((N_BLADES, 2))
        dtr[:, 0] = dzt
        dtr[:, 1] = -nu**2 * zt - c_z * dzt + z_all.real
        dy[n_pert:] = dtr.ravel()
        return dy

    lam_t, lag_t = _route_trim(k, p, th_t, b_t, muz_t, lam_t, psi0)
    y0 = np.zeros(n_pert + 2 * N_BLADES)
    y0[n_pert:] = lag_t.T.ravel()
    psi_end = t_end * om
    ps = np.linspace(0, psi_end, int(t_end * 100) + 1)
    sol = solve_ivp(rhs, (0, psi_end), y0, method="DOP853", t_eval=ps,
                    rtol=1e-10, atol=1e-13)
    y = sol.y.T
    bl = y[:, :4 * N_BLADES].reshape(len(ps), N_BLADES, 4)
    ang = ps[:, None] + psi0 + off[None, :]
    mb = []
    for j in (0, 2):
        q = bl[:, :, j]
        mb.append([q.mean(axis=1), 2 * (q * np.cos(ang)).mean(axis=1),
                   2 * (q * np.sin(ang)).mean(axis=1)])
    out = np.column_stack([*mb[0], y[:, 4 * N_BLADES:n_pert], *mb[1]])
    return ps / om, out


def _pulse(t, t0, width):
    x = np.clip((t - t0) / width, 0.0, 1.0)
    return 0.5 - 0.5 * np.cos(2 * np.pi * x)


def _inputs(t):
    """``(theta0, theta1c, theta1s)`` perturbations [rad]: smooth pulses."""
    a = 0.01
    return (0.3 * a * _pulse(t, 1.2, 0.6), a * (_pulse(t, 0.2, 0.5) - _pulse(t, 0.7, 0.5)),
            -0.7 * a * _pulse(t, 0.4, 0.8))


def _model_route(m, t, lag=True):
    names = list(m.inputs)

    def u(tt):
        th0, th1c, th1s = _inputs(tt)
        return np.array([{"theta0": th0, "theta1c": th1c, "theta1s": th1s}.get(c, 0.0)
                         for c in names])

    n = m.a.shape[0]
    sol = solve_ivp(lambda tt, x: m.a @ x + m.b @ u(tt), (0, t[-1]), np.zeros(n),
                    method="DOP853", t_eval=t, rtol=1e-10, atol=1e-13)
    x = sol.y.T
    st = list(m.states)
    if not lag:
        return x[:, :6]
    return np.column_stack([x[:, :6], x[:, st.index("zeta0")], x[:, st.index("zeta1c")],
                            x[:, st.index("zeta1s")]])


def _hover(ct=0.0075):
    k = ifs.Constants(mu=0.0, a0=5.73, solidity=0.0917, omega=27.5, inflow_speed="mass-flow",
                      ct=ct, hub="articulated")
    trim = {"theta0": 0.16, "theta1c": 0.0, "theta1s": 0.0, "beta0": 0.07, "beta1c": 0.0,
            "beta1s": 0.0, "muz": -0.01}
    return k.with_trim(trim), trim


@pytest.mark.parametrize("nu, zl", [(0.27, 0.15),
                                     pytest.param(0.65, 0.05, marks=pytest.mark.slow)])
def test_the_multiblade_model_is_the_blade_route_in_hover(nu, zl):
    """At mu = 0 the four blades' equations have constant coefficients in multiblade
    coordinates: the effect's model and the blade route agree to the integration
    tolerance, flap, inflow and lag."""
    k, tr = _hover()
    s = ifs.Structure.parse("basic+flap-inertia+lead-lag")
    p = {"lambda_beta2": 1.06, "n_beta": 0.987, "tau": 3.0, "flap_inertia": 1.0,
         "nu_zeta": nu, "zeta_lag": zl, "k_flap_lag": 1.0}
    m = ifs.build_model(s, p, k)
    lam_t = _trim_inflow(0.0, k.a0s, k.flow_speed, tr["theta0"], tr["beta0"], tr["muz"])
    t, blade = _blade_route(k, p, tr["theta0"], tr["beta0"], tr["muz"], lam_t, _inputs, 3.0)
    model = _model_route(m, t)
    scale = np.abs(blade).max(axis=0)
    assert scale[1] > 1e-3 and scale[7] > 1e-4 and scale[6] > 1e-5  # flap, lag move
    np.testing.assert_allclose(model, blade, rtol=0, atol=2e-7 * scale.max())
    # and the lag matters: the structure without it is off by much more
    s0 = ifs.Structure.parse("basic+flap-inertia")
    m0 = ifs.build_model(s0, {n: p[n] for n in s0.parameters}, k)
    x0 = _model_route(m0, t, lag=False)
    # measured 0.7 % and 1.0 % of the largest flap
    assert np.abs(x0[:, :3] - blade[:, :3]).max() > 0.004 * scale[:3].max()


@pytest.mark.slow
def test_forward_flight_to_the_averaged_level():
    """At mu = 0.25 the blades' coefficients are periodic; the multiblade model keeps
    their averages, as the base flap model does.  The lag's share of the response
    (with minus without it) is the blade route's to the same level as the base
    model's own averaging error."""
    k0 = ifs.PUMA
    tr = {"theta0": 0.17, "theta1c": 0.0, "theta1s": 0.0, "beta0": 0.06, "beta1c": 0.0,
          "beta1s": 0.0, "muz": -0.02}
    k = k0.with_trim(tr)
    p = {"lambda_beta2": 1.06, "n_beta": 0.987, "tau": 3.0, "flap_inertia": 1.0,
         "nu_zeta": 0.27, "zeta_lag": 0.15, "k_flap_lag": 1.0}
    from inflowsim.physics.bladeelement import trim_inflow
    lam_t = trim_inflow(k.mu, k.a0s, [tr["theta0"], 0, 0], [tr["beta0"], 0, 0],
                        tr["muz"])[0]
    t, blade = _blade_route(k, p, tr["theta0"], tr["beta0"], tr["muz"], lam_t, _inputs, 3.0)
    t, blade0 = _blade_route(k, p | {"k_flap_lag": 0.0}, tr["theta0"], tr["beta0"],
                             tr["muz"], lam_t, _inputs, 3.0, )
    m = ifs.build_model("basic+flap-inertia+lead-lag", p, k)
    model = _model_route(m, t)
    model0 = _model_route(m.with_parameters(k_flap_lag=0.0), t)
    err_base = np.abs(model0[:, :3] - blade0[:, :3]).max()
    lag_model = model[:, :3] - model0[:, :3]
    lag_blade = blade[:, :3] - blade0[:, :3]
    size = np.abs(lag_model).max()
    # measured: share 4.1e-4 of a 8.2e-3 response, its error 1.3e-5; base 5.5e-5
    assert size > 0.02 * np.abs(model[:, :3]).max()
    assert np.abs(lag_model - lag_blade).max() < 0.1 * size
    assert np.abs(model[:, :3] - blade[:, :3]).max() < 1.5 * err_base + 0.1 * size


def test_the_regressing_lag_frequency():
    """Decoupled (k_flap_lag = 0), in hover, the fixed-frame lag modes lie at ``1 +-
    sqrt(nu^2 - (C/2)^2)`` per rev with decay ``C/2``, ``C`` the damper's ``2 zeta_lag
    nu`` plus the blade-element lag damping ``2 n_beta (3 delta - 2 theta u) / 3``
    (profile and induced drag): the regressing lag mode at ``(1 - nu_zeta)`` per rev
    for a light damper (Johnson, Helicopter Theory ch. 12)."""
    k, tr = _hover()
    for nu, zl in ((0.25, 0.2), (0.7, 0.05)):
        p = {"lambda_beta2": 1.06, "n_beta": 0.987, "tau": 3.0, "nu_zeta": nu,
             "zeta_lag": zl, "k_flap_lag": 0.0}
        m = ifs.build_model("basic+lead-lag", p, k)
        lam_t = _trim_inflow(0.0, k.a0s, k.flow_speed, tr["theta0"], tr["beta0"],
                             tr["muz"])
        u = tr["muz"] - lam_t
        c = 2 * zl * nu + 2 * 0.987 * (3 * 0.01 / 5.73 - 2 * tr["theta0"] * u) / 3
        wd = np.sqrt(nu**2 - c**2 / 4)
        ev = m.eigenvalues() / k.omega
        for want in (-c / 2 + 1j * (1 - wd), -c / 2 + 1j * (1 + wd)):
            assert np.min(np.abs(ev - want)) < 1e-9
        reg = ev[np.argmin(np.abs(ev - (-c / 2 + 1j * (1 - wd))))]
        assert abs(reg.imag - (1 - nu)) < 0.02


def test_the_lag_needs_the_trim_and_registers_its_facts():
    s = ifs.Structure.parse("glauert+lead-lag")
    with pytest.raises(InputError, match="lead-lag needs the trim|needs the trim"):
        ifs.build_model(s, truth_parameters(s, ifs.PUMA), ifs.PUMA)
    from inflowsim.model.effects import CATALOGUE
    eff = CATALOGUE["lead-lag"]
    assert eff.offered and eff.about_trim      # offered since its detection study
    assert s.states[-6:] == ("zeta0", "zeta1c", "zeta1s", "zeta0_prime", "zeta1c_prime",
                             "zeta1s_prime")
    hl = ifs.PUMA.__class__(**{**ifs.PUMA.__dict__, "hub": "hingeless"})
    assert eff.theory(hl)["nu_zeta"] == 0.65 and eff.theory(ifs.PUMA)["nu_zeta"] == 0.25
    r = eff.plausible_ranges(hl)["nu_zeta"]
    assert r[0] <= 0.5 and r[1] >= 0.8


def test_the_linear_flight_test_flies_the_lag(tmp_path):
    """``flighttest --truth linear --add lead-lag`` (the truth linearised about the
    virtual Puma's trim, as every effect about the trim is): a record whose flap
    differs from the same flight without the lag."""
    from inflowsim.cli import main
    from inflowsim.data.record import read_record
    out = {}
    for add in ([], ["--add", "lead-lag"]):
        path = tmp_path / f"r{len(add)}.csv"
        assert main(["flighttest", "--truth", "linear", *add, "--duration", "6",
                     "--noise", "0", "--out", str(path)]) == 0
        out[len(add)] = read_record(path)
    assert "lead-lag" in out[2].meta["description"]
    d = np.abs(out[2].channels["beta1s"] - out[0].channels["beta1s"]).max()
    assert d > 1e-3 * np.abs(out[0].channels["beta1s"] - out[0].channels["beta1s"][0]).max()


def test_the_lag_sees_the_servos_pitch():
    """With servo-actuators the lag's own pitch forcing follows the servos' output,
    as the flap's does: at a command frequency far above the servos' bandwidth the
    whole response (flap and lag) falls with the servo's transfer function."""
    k = ifs.PUMA.with_trim({"theta0": 0.17, "theta1c": 0.01, "theta1s": -0.05, "beta0": 0.06,
                            "beta1c": 0.01, "beta1s": -0.002, "muz": 0.0})
    s0 = ifs.Structure.parse("glauert+lead-lag")
    s = s0.with_effect("servo-actuators")
    p = truth_parameters(s, k) | {"servo_tau": 0.03, "servo_zeta": 0.6}
    f = np.array([0.3, 1.0, 4.0])
    h = ifs.build_model(s, p, k).frequency_response(f)
    h0 = ifs.build_model(s0, {n: p[n] for n in s0.parameters}, k).frequency_response(f)
    sv = 2j * np.pi * f
    g = 1.0 / ((0.03 * sv) ** 2 + 2 * 0.6 * 0.03 * sv + 1.0)
    np.testing.assert_allclose(h[:, :3], h0[:, :3] * g, rtol=0,
                               atol=1e-12 * np.abs(h0).max())


def test_the_forward_flight_trims_coriolis_terms():
    """The inertial part of the trim's couplings (``model.md`` 9.1, "The forward-flight
    trim"), projected by hand: with ``n_beta = 0`` and no steady lag the generated
    coefficients are exactly ``2 beta zeta'`` in the flap rows and ``-2 beta beta'``
    in the lag rows about the cyclic flap ``(b0, b1c, b1s)``, and the lag's trim
    moment is the cyclic flap's Coriolis moment, its first harmonics and its 2/rev
    part."""
    from inflowsim.physics import lead_lag_terms as lt
    b0, b1c, b1s = 0.1, -0.05, 0.03
    args = (0.2, 0.0, 0.0, (0.1, 0.02, -0.03), (b0, b1c, b1s, 0.0, 0.0), -0.02, 0.001,
            0.002)
    flap, lag, _ = lt.terms(*args, (0.0,) * 5)
    # columns zeta0, zeta1c, zeta1s, zeta0', zeta1c', zeta1s'
    np.testing.assert_allclose(flap[:, 15:], [[0, -b1s, b1c, 2 * b0, b1c, b1s],
                                              [0, 0, 2 * b0, 2 * b1c, 2 * b0, 0],
                                              [0, -2 * b0, 0, 2 * b1s, 0, 2 * b0]],
                               atol=1e-15)
    # columns beta0, beta1c, beta1s, beta0', beta1c', beta1s'
    np.testing.assert_allclose(lag[:, :6], -np.array([[0, 0, 0, 2 * b0, b1c, b1s],
                                                      [2 * b1s, 0, 2 * b0, 2 * b1c, 2 * b0, 0],
                                                      [-2 * b1c, -2 * b0, 0, 2 * b1s, 0, 2 * b0]]),
                               atol=1e-15)
    # and its 2/rev part, -2 beta beta' on (2 cos 2psi, 2 sin 2psi), holds the trim's
    # 2/rev lag
    np.testing.assert_allclose(lt.lag_trim(*args), [0, -2 * b0 * b1s, 2 * b0 * b1c,
                                                    -2 * b1c * b1s, b1c**2 - b1s**2],
                               atol=1e-15)
    # no aerodynamics: nothing on the inflow and the inputs; no steady lag: nothing
    # on the base columns of the flap rows
    assert np.all(lag[:, 6:15] == 0) and np.all(flap[:, :15] == 0)


def test_the_second_harmonic_lags_coriolis_terms():
    """The second-harmonic lag's inertial couplings (``model.md`` 9.1): with ``n_beta
    = 0`` and no steady lag, the generated rows and columns are the Coriolis terms
    ``2 beta zeta'`` (flap) and ``-2 beta beta' (1 - zeta')`` (lag) about the cyclic
    flap with its 2/rev part, averaged here by quadrature over the azimuth (a 64-point
    rule, exact for these trigonometric polynomials) with ``zeta = zeta2c cos 2psi + zeta2s sin 2psi``
    at rest in the fixed frame; and the condensed lag moves the first harmonics'
    flap rows by ``flap_z2 zeta2`` per column."""
    from inflowsim.physics import lead_lag as ll
    from inflowsim.physics import lead_lag_terms as lt
    b0, b1c, b1s, b2c, b2s = 0.1, -0.05, 0.03, -0.006, 0.002
    args = (0.2, 0.0, 0.0, (0.1, 0.02, -0.03), (b0, b1c, b1s, b2c, b2s), -0.02, 0.001,
            0.002)
    lag2, lag2_z2, flap_z2, lag_z2, _ = lt.second_harmonic(*args, (0.0,) * 5)
    psi = 2 * np.pi * np.arange(64) / 64
    c, s_, c2, s2 = np.cos(psi), np.sin(psi), np.cos(2 * psi), np.sin(2 * psi)
    bt = b0 + b1c * c + b1s * s_ + b2c * c2 + b2s * s2
    dbt = -b1c * s_ + b1s * c - 2 * b2c * s2 + 2 * b2s * c2
    w1, w2 = (np.ones_like(psi), 2 * c, 2 * s_), (2 * c2, 2 * s2)
    dz = (-2 * s2, 2 * c2)                       # zeta' per (zeta2c, zeta2s)

    def avg(*f):
        return np.mean(np.prod(f, axis=0))
    np.testing.assert_allclose(flap_z2, [[avg(w, 2 * bt, d) for d in dz] for w in w1],
                               atol=1e-15)
    np.testing.assert_allclose(lag_z2, [[avg(w, 2 * bt * dbt, d) for d in dz] for w in w1],
                               atol=1e-15)
    np.testing.assert_allclose(lag2_z2, [[avg(w, 2 * bt * dbt, d) for d in dz] for w in w2],
                               atol=1e-15)
    # the flap columns of its rows: -2 (d beta beta_t' + beta_t d beta'), the blade's
    # flap (1, cos, sin) and its rate with the rotation of the coordinates
    one = np.ones_like(psi)
    dbeta = [(one, 0 * psi), (c, -s_), (s_, c), (0 * psi, one), (0 * psi, c), (0 * psi, s_)]
    np.testing.assert_allclose(lag2[:, :6], [[avg(w, -2 * (db * dbt + bt * ddb))
                                              for db, ddb in dbeta] for w in w2], atol=1e-15)
    assert np.all(lag2[:, 6:15] == 0)
    # its lag columns: 2 beta_t beta_t' d zeta', the first harmonics' rate (zeta0 ..
    # zeta1s' as the coordinates rotate)
    dzeta = [0 * psi, -s_, c, one, c, s_]
    np.testing.assert_allclose(lag2[:, 15:], [[avg(w, 2 * bt * dbt, d) for d in dzeta]
                                              for w in w2], atol=1e-15)
    # it couples: the cyclic flap drives it and it acts back on the flap
    assert np.abs(flap_z2).max() > 0.05 and np.abs(lag2[:, :6]).max() > 0.05
    t2 = ll.second_harmonic(0.65, 0.2, (lag2, lag2_z2))
    k = ll.second_harmonic_structure(0.65, 0.2) - lag2_z2
    np.testing.assert_allclose(k @ t2, lag2, atol=1e-15)


def test_the_trims_steady_lag_with_its_second_harmonic_by_harmonic_balance():
    """The steady lag of the trim, its 2/rev part included (``model.md`` 9.1, "The
    forward-flight trim"): with ``n_beta = 0`` each blade's lag is ``zeta'' + C zeta'
    + nu^2 zeta = -2 beta beta' (1 - zeta')`` about the trim's flap (with its 2/rev
    part, the Puma's), and its periodic
    solution in harmonics 0-2 (balanced here by a 64-point quadrature on ``(1, 2 cos
    psi, 2 sin psi, 2 cos 2psi, 2 sin 2psi)``) is the effect's :func:`steady_lag`
    from the generated tables.  The 2/rev part is mostly the cyclic flap's Coriolis
    moment ``-2 b1c b1s cos 2psi + (b1c^2 - b1s^2) sin 2psi`` and the coning's with
    the 2/rev flap, over ``nu^2 - 4``: about a tenth of the cyclic steady lag at the
    Puma's trim."""
    from inflowsim.physics import lead_lag as ll
    from inflowsim.physics import lead_lag_terms as lt
    nu, zl = 0.25, 0.2
    b0, b1c, b1s, b2c, b2s = 0.12, -0.05, -0.033, -0.006, 0.002
    args = (0.25, 0.0, 0.0, (0.17, 0.01, -0.05), (b0, b1c, b1s, b2c, b2s), -0.02, 0.001,
            0.002)
    zt = ll.steady_lag(ll.lag_structure(nu, zl), ll.second_harmonic_structure(nu, zl),
                       lt.lag_stiffness(*args), lt.lag_trim(*args))
    psi = 2 * np.pi * np.arange(64) / 64
    c, s_ = np.cos(psi), np.sin(psi)
    basis = np.array([np.ones_like(psi), c, s_, np.cos(2 * psi), np.sin(2 * psi)])
    rate = np.array([0 * psi, -s_, c, -2 * np.sin(2 * psi), 2 * np.cos(2 * psi)])
    accel = -np.array([0, 1, 1, 4, 4])[:, None] * basis
    weights = np.array([1, 2, 2, 2, 2])[:, None] * basis
    bb = b0 + b1c * c + b1s * s_ + b2c * np.cos(2 * psi) + b2s * np.sin(2 * psi)
    dbb = -b1c * s_ + b1s * c - 2 * b2c * np.sin(2 * psi) + 2 * b2s * np.cos(2 * psi)
    cz = 2 * zl * nu
    # the residual of each basis function, projected: L zeta = -2 beta beta'
    lhs = [(weights * (a + cz * r + nu**2 * f - 2 * bb * dbb * r)).mean(axis=1)
           for f, r, a in zip(basis, rate, accel)]
    want = np.linalg.solve(np.array(lhs).T, (weights * (-2 * bb * dbb)).mean(axis=1))
    np.testing.assert_allclose(zt, want, rtol=1e-12, atol=1e-17)
    assert 0.05 * np.abs(zt[1:3]).max() < np.abs(zt[3:]).max() < 0.5 * np.abs(zt[1:3]).max()


@pytest.mark.slow
def test_the_generated_coefficients_are_the_derivations_output():
    """``inflowsim/physics/lead_lag_terms.py`` is what ``bench/lead_lag_derivation.py``
    writes (the derivation also checks that the lag-free blades' columns are the
    base model's matrices); about a minute of sympy."""
    import subprocess
    import sys
    from pathlib import Path
    script = Path(__file__).resolve().parents[1] / "bench" / "lead_lag_derivation.py"
    assert subprocess.run([sys.executable, str(script), "--check"]).returncode == 0
