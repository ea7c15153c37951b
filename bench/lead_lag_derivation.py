"""Derivation of the lead-lag effect's multiblade coefficients (``model.md`` 9.1).

Single blade, rigid, central hinge with equivalent springs, lag ``zeta`` positive
aft; blade-element lift ``theta U_T^2 + U_P U_T`` and in-plane (aft) force
``-(theta U_T U_P + U_P^2) + delta U_T^2`` with ``U_T = r (1 - zeta') + mu sin(psi -
zeta)``, ``U_P = muz - lambda_i - r beta' - mu beta cos(psi - zeta) + r (p sin psi + q
cos psi)``, linearised about the axisymmetric trim (``theta_t``, ``beta_t``, up-flow
``u = muz_t - lambda0_t``), projected on ``(1, 2 cos psi, 2 sin psi)`` (flap, lag) and
``(1, -r cos(psi - zeta), -r sin(psi - zeta)) / 2`` (loads: the lagged blade's lift
acts where the blade is) and averaged over the azimuth.  Prints the
coefficients that :mod:`inflowsim.physics.lead_lag` holds (about a minute of sympy).

    python bench/lead_lag_derivation.py
"""
import sympy as sp

r, psi, mu, nb, dl = sp.symbols("r psi mu nb dl", real=True)
th, b, u = sp.symbols("th b u", real=True)
NAMES = ["b0", "b1c", "b1s", "db0", "db1c", "db1s", "l0", "l1c", "l1s", "t0", "t1c", "t1s",
         "muz", "q", "p", "z0", "z1c", "z1s", "dz0", "dz1c", "dz1s"]
V = dict(zip(NAMES, sp.symbols(NAMES, real=True)))
c, s = sp.cos(psi), sp.sin(psi)
zeta = V["z0"] + V["z1c"] * c + V["z1s"] * s
dzeta = V["dz0"] + (V["dz1c"] + V["z1s"]) * c + (V["dz1s"] - V["z1c"]) * s
beta = V["b0"] + V["b1c"] * c + V["b1s"] * s
dbeta = V["db0"] + (V["db1c"] + V["b1s"]) * c + (V["db1s"] - V["b1c"]) * s
UT = r * (1 - dzeta) + mu * sp.sin(psi - zeta)
UP = (u + V["muz"] - (V["l0"] + r * (V["l1c"] * c + V["l1s"] * s)) - r * dbeta
      - mu * (b + beta) * sp.cos(psi - zeta) + r * (V["p"] * s + V["q"] * c))
TH = th + V["t0"] + V["t1c"] * c + V["t1s"] * s
LIFT = TH * UT**2 + UP * UT
DRAG = -(TH * UT * UP + UP**2) + dl * UT**2


def linear(f):
    zero = {x: 0 for x in V.values()}
    return {n: sp.expand(sp.expand_trig(sp.diff(f, x).subs(zero))) for n, x in V.items()}


def project(f, w):
    e = sp.integrate(sp.expand(w * f), (r, 0, 1))
    return sp.factor(sp.expand(sp.integrate(sp.expand(e), (psi, 0, 2 * sp.pi)) / (2 * sp.pi)))


if __name__ == "__main__":
    lag = ["z0", "z1c", "z1s", "dz0", "dz1c", "dz1s"]
    for title, f, weights, cols in (
            ("flap rows (beta0, beta1c, beta1s) per lag", 4 * nb * r * LIFT, (1, 2 * c, 2 * s), lag),
            ("lag rows (zeta0, zeta1c, zeta1s)", 4 * nb * r * DRAG, (1, 2 * c, 2 * s), NAMES)):
        lin = linear(f)
        print("#", title, cols)
        for w in weights:
            print([project(lin[n], w) for n in cols])
    # the loads: a lagged blade's lift acts on the hub where the blade is, at
    # psi - zeta (the weights linearised with the lift)
    print("# loads (C_T, C_mc, C_ms)/(a0 s) per lag", lag)
    for w in (1, -r * sp.cos(psi - zeta), -r * sp.sin(psi - zeta)):
        lin = linear(LIFT / 2 * w)
        print([project(lin[n], 1) for n in lag])
