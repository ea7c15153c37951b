"""Derivation of the lead-lag effect's multiblade coefficients about a forward-flight
trim (``model.md`` 9.1); writes :mod:`inflowsim.physics.lead_lag_terms`.

Single blade, rigid, central hinge with equivalent springs, flap ``beta`` up, lag
``zeta`` positive aft (against the rotation), azimuth time, moments over ``I_b
Omega^2`` (Johnson, *Helicopter Theory* ch. 9 and 12; *Rotorcraft Aeromechanics*
ch. 16-17).  Right-hand sides (the lag spring ``nu^2 zeta`` and damper ``C zeta'``
and the multiblade transformation's rotating-frame terms are the effect's own,
:func:`inflowsim.physics.lead_lag.lag_structure`)::

    flap:  4 n_beta int_0^1 r (theta U_T^2 + U_P U_T) dr          + 2 beta zeta' - beta zeta'^2
    lag:   4 n_beta int_0^1 r (-(theta U_T + U_P) U_P + delta U_T^2) dr - 2 beta beta' (1 - zeta')
    loads: (C_T, C_mc, C_ms) / (a0 s) = 1/2 int_0^1 (1, -r cos(psi - zeta), -r sin(psi - zeta)) (theta U_T^2 + U_P U_T) dr

(the Lagrangian inertia of a point-mass blade, ``sin beta cos beta -> beta``,
``cos^2 beta -> 1``), ``U_T = r (1 - zeta') + mu sin(psi - zeta)``, ``U_P = muz -
lambda0 - r ((lambda1c - qbar) cos(psi - zeta) + (lambda1s - pbar) sin(psi - zeta)) -
r beta' - mu beta cos(psi - zeta)``: the blade meets the free stream, the inflow and
the body rates where it is, at ``psi - zeta``; the swashplate sets its pitch
``theta = theta0 + theta1c cos psi + theta1s sin psi`` at the hub azimuth.

Linearised about a forward-flight trim in multiblade coordinates: pitch
``(th0, th1c, th1s)``, flap ``(b0, b1c, b1s, b2c, b2s)`` (the blade at ``b0 + b1c cos
psi + b1s sin psi + b2c cos 2psi + b2s sin 2psi``: the trim's 2/rev flap, which the
Coriolis moment carries into the lag's trim and couplings), up-flow ``u = muz - lambda0``,
cyclic inflow ``(l1c, l1s)`` and the steady lag ``(z0, z1c, z1s, z2c, z2s)`` (its
second harmonic: the trim's 2/rev lag, which the cyclic flap's Coriolis moment
``-2 beta beta'`` and the ``mu`` terms force).  Every product of the trim is kept;
the collective steady lag exactly (it turns the blades' azimuth: ``cos z0``, ``sin
z0``), its harmonics to first order (``sin(psi - zeta)`` to second order in
``zeta``, so that their product with a lag perturbation is kept).  Each
right-hand side is projected on ``(1, 2 cos psi, 2 sin psi)`` (loads: 1) and
averaged over the azimuth (the constant-coefficient approximation of the base
model, section 2).  The lag also has its second harmonic ``zeta2c cos 2psi + zeta2s
sin 2psi`` (for four blades the reactionless lag's 2/rev part): in forward flight the
flap's Coriolis moment and the ``mu`` terms drive it from the first harmonics and it
acts back on them; its modes are at ``2 -+ nu`` per rev, so it enters quasi-statically
(its own rates left out), its rows projected on ``(2 cos 2psi, 2 sin 2psi)``.  Polynomial arithmetic in sympy's sparse rings (a few seconds).

    python bench/lead_lag_derivation.py            # writes the module
    python bench/lead_lag_derivation.py --check    # exit 1 if it differs
"""
import sys
from math import prod
from pathlib import Path

import sympy as sp
from sympy import QQ
from sympy.polys.rings import ring

OUT = Path(__file__).resolve().parents[1] / "inflowsim" / "physics" / "lead_lag_terms.py"
#: perturbations, the columns of the generated matrices
COLS = ["b0", "b1c", "b1s", "db0", "db1c", "db1s", "l0", "l1c", "l1s", "t0", "t1c", "t1s",
        "muz", "q", "p", "z0", "z1c", "z1s", "dz0", "dz1c", "dz1s"]
#: the trim: pitch, flap (with its 2/rev part), up-flow, cyclic inflow
TRIM = ["th0", "th1c", "th1s", "b0t", "b1ct", "b1st", "b2ct", "b2st", "u", "l1c_t", "l1s_t"]
LAG_TRIM = ["cz0", "sz0", "z1ct", "z1st", "z2ct", "z2st"]
#: the second-harmonic lag ``zeta2c cos 2psi + zeta2s sin 2psi`` (quasi-static: its
#: modes at ``2 -+ nu`` per rev lie far above the flap's band)
Z2 = ["z2c", "z2s"]
GENS = (["h", "eps", "C", "S", "r", "mu", "nb", "dl"] + TRIM + LAG_TRIM
        + ["d_" + c for c in COLS + Z2])


def derive():
    """``{name: (3 x 21 matrix, or 3 vector) of sympy expressions}``."""
    R, *G = ring(GENS, QQ)
    g = dict(zip(GENS, G))
    h, eps, C, S, r, mu, nb, dl = (g[k] for k in GENS[:8])

    def tr(p):          # first order in the perturbation (h) and in the steady lag (eps)
        return R({m: c for m, c in p.items() if m[0] <= 1 and m[1] <= 1})

    def mul(*a):
        out = a[0]
        for x in a[1:]:
            out = tr(out * x)
        return out

    v = {c: h * g["d_" + c] for c in COLS + Z2}
    t = g
    c2, s2 = C * C - S * S, 2 * S * C               # cos 2 psi, sin 2 psi
    # the steady lag: its collective part exactly (a turn of the blade's azimuth,
    # cz0 = cos zeta0_t, sz0 = sin zeta0_t), its first and second harmonics to first
    # order (the trim's 2/rev lag: the cyclic flap's Coriolis moment and the mu
    # terms hold it); the second-harmonic lag perturbation quasi-static (its
    # coordinates' own rates left out)
    zeta = (eps * (t["z1ct"] * C + t["z1st"] * S + t["z2ct"] * c2 + t["z2st"] * s2)
            + v["z0"] + v["z1c"] * C + v["z1s"] * S + v["z2c"] * c2 + v["z2s"] * s2)
    dzeta = (eps * (-t["z1ct"] * S + t["z1st"] * C + 2 * t["z2st"] * c2 - 2 * t["z2ct"] * s2)
             + v["dz0"] + (v["dz1c"] + v["z1s"]) * C + (v["dz1s"] - v["z1c"]) * S
             + 2 * v["z2s"] * c2 - 2 * v["z2c"] * s2)
    # the trim's flap with its 2/rev part (the rigid blades' periodic coefficients
    # force it: second-harmonic-flap's quasi-static balance at the trim), at rest in
    # the fixed frame
    beta = (t["b0t"] + t["b1ct"] * C + t["b1st"] * S + t["b2ct"] * c2 + t["b2st"] * s2
            + v["b0"] + v["b1c"] * C + v["b1s"] * S)
    dbeta = (-t["b1ct"] * S + t["b1st"] * C + 2 * t["b2st"] * c2 - 2 * t["b2ct"] * s2
             + v["db0"] + (v["db1c"] + v["b1s"]) * C + (v["db1s"] - v["b1c"]) * S)
    z2 = mul(zeta, zeta)
    s0 = S * t["cz0"] - C * t["sz0"]                # sin(psi - zeta0_t)
    c0 = C * t["cz0"] + S * t["sz0"]                # cos(psi - zeta0_t)
    sa = s0 - mul(s0, z2) / 2 - mul(c0, zeta)       # sin(psi - zeta)
    ca = c0 - mul(c0, z2) / 2 + mul(s0, zeta)       # cos(psi - zeta)
    ut = r * (1 - dzeta) + mu * sa
    up = tr(t["u"] + v["muz"] - v["l0"] - mul(r, t["l1c_t"] + v["l1c"] - v["q"], ca)
            - mul(r, t["l1s_t"] + v["l1s"] - v["p"], sa) - r * dbeta - mul(mu, beta, ca))
    th = t["th0"] + v["t0"] + (t["th1c"] + v["t1c"]) * C + (t["th1s"] + v["t1s"]) * S
    lift = tr(mul(th, ut, ut) + mul(up, ut))
    drag = tr(-mul(mul(th, ut) + up, up) + dl * mul(ut, ut))
    flap = tr(4 * nb * r * lift + 2 * mul(beta, dzeta) - mul(beta, dzeta, dzeta))
    lag = tr(4 * nb * r * drag - 2 * mul(beta, dbeta, 1 - dzeta))
    loads = [lift / 2, -mul(r, ca, lift) / 2, -mul(r, sa, lift) / 2]

    def dfact(n):
        return prod(range(n, 0, -2)) if n > 0 else 1

    def average(p):     # (1/2 pi) int d psi int_0^1 dr of a polynomial in C, S, r
        out = {}
        for m, c in p.items():
            a, b, k = m[2], m[3], m[4]
            if a % 2 or b % 2:
                continue
            key = m[:2] + (0, 0, 0) + m[5:]
            out[key] = out.get(key, 0) + c * QQ(dfact(a - 1) * dfact(b - 1), dfact(a + b)) \
                / (k + 1)
        return R({m: c for m, c in out.items() if c})

    syms = {n: sp.Symbol(n) for n in GENS}

    def split(p):
        """``(zero-order value, {column: coefficient})`` of an averaged polynomial,
        as sympy expressions in the trim (eps set to 1: first order kept)."""
        e = p.as_expr(*[syms[n] for n in GENS]).subs({syms["eps"]: 1})
        # cos^2 + sin^2 = 1 of the collective steady lag
        e = sp.expand(sp.expand(e).subs(syms["cz0"] ** 2, 1 - syms["sz0"] ** 2))
        hh = syms["h"]
        lin = sp.expand(e.coeff(hh, 1))
        return e.coeff(hh, 0), {c: lin.coeff(syms["d_" + c]) for c in COLS + Z2}

    out, lag_free, z2_rows = {}, {}, {}
    no_lag = {syms["cz0"]: 1, syms["sz0"]: 0, syms["z1ct"]: 0, syms["z1st"]: 0,
              syms["z2ct"]: 0, syms["z2st"]: 0}
    # the second-harmonic lag's own rows (the lag projected on 2 cos 2psi, 2 sin 2psi)
    lag2 = [split(average(tr(lag * w))) for w in (2 * c2, 2 * s2)]
    for name, f, weights in (("flap", flap, (1, 2 * C, 2 * S)), ("lag", lag, (1, 2 * C, 2 * S)),
                             ("loads", None, None)):
        rows, zero, free = [], [], []
        for i in range(3):
            p = average(tr(f * weights[i]) if f is not None else loads[i])
            z, lin = split(p)
            if name != "lag":
                # the flap and load columns of the base states and inputs: the
                # lag-free blades' are the base model's own (checked below); the
                # effect adds the steady lag's share
                free.append([lin[c].subs(no_lag) for c in COLS[:15]])
                lin = {**lin, **{c: sp.expand(lin[c] - (free[-1][j] if j < 15 else 0))
                                 for j, c in enumerate(COLS)}}
            rows.append([lin[c] for c in COLS])
            zero.append(z)
            z2_rows.setdefault(name, []).append([lin[c] for c in Z2])
        out[name] = rows
        lag_free[name] = free
        if name == "lag":
            # the lag's trim moment and the displacement columns without steady lag
            # (its stiffness), rows and columns (zeta0, zeta1c, zeta1s, zeta2c, zeta2s):
            # the first harmonics' rows, then the second harmonic's
            z2r = z2_rows["lag"]
            out["lag_trim"] = [sp.expand(z.subs(no_lag)) for z in zero + [z for z, _ in lag2]]
            out["lag_stiffness"] = [
                [sp.expand(e.subs(no_lag)) for e in r[15:18] + z2r[i]]
                for i, r in enumerate(rows)] + [
                [sp.expand(lin[c].subs(no_lag)) for c in COLS[15:18] + Z2] for _, lin in lag2]
        if name == "loads":
            # the steady lag's share of the trim's loads (it moves the trim inflow)
            out["load_trim"] = [sp.expand(z - z.subs(no_lag)) for z in zero]
    # the second-harmonic lag's rows and its columns in the flap, lag and load rows
    lag2 = [lin for _, lin in lag2]
    out["second"] = {"lag2": [[r[c] for c in COLS] for r in lag2],
                     "lag2_z2": [[r[c] for c in Z2] for r in lag2],
                     **{name + "_z2": z2_rows[name] for name in ("flap", "lag", "loads")}}
    _check_base(lag_free, syms)
    return out


#: What the base flap rows hold besides the blade-element moments: the
#: multiblade transformation's rotating-frame terms with the flap inertia
#: (``beta1c'' = ... + beta1c - 2 beta1s'``, the first-order model's ``C``, ``D``
#: with ``lambda_beta2 = 0``) and the hub's gyroscopic moments (``2 pbar``, ``-2 qbar``).
INERTIAL = {("flap", 1, "b1c"): -1, ("flap", 2, "b1s"): -1, ("flap", 1, "db1s"): 2,
            ("flap", 2, "db1c"): -2, ("flap", 1, "p"): -2, ("flap", 2, "q"): 2}


def _check_base(free, syms):
    """The lag-free blades' flap and load columns (states and the first six inputs)
    are the base model's matrices (``model.md`` sections 2-3), exactly: whatever the
    trim (they do not depend on it)."""
    import numpy as np
    from inflowsim.physics import flapping as fl
    from inflowsim.physics import loads as ld
    mu, nb = syms["mu"], syms["nb"]
    flap = np.hstack([-fl.flap_d(mu, nb, 0), -fl.flap_c(mu, nb), fl.flap_h_lambda(mu, nb),
                      fl.flap_h_theta(mu, nb), fl.flap_h_nu(mu, nb)])
    loads = np.hstack([ld.g_beta(mu), ld.g_dbeta(mu), ld.g_lambda(mu), ld.g_theta(mu),
                       ld.g_nu(mu)])
    for name, base in (("flap", flap), ("loads", loads)):
        for i in range(3):
            for j in range(15):
                d = sp.nsimplify(sp.expand(sp.sympify(free[name][i][j]) - sp.sympify(base[i, j])
                                           - INERTIAL.get((name, i, COLS[j]), 0)))
                assert d == 0, (name, i, COLS[j], d)


HEADER = '''"""Generated by ``bench/lead_lag_derivation.py`` (do not edit): the lead-lag
effect's multiblade coefficients about a forward-flight trim (``model.md`` 9.1).

:func:`terms` returns the averaged linear coefficients ``(flap, lag, loads)``, each
3 x 21, rows ``(0, 1c, 1s)`` (flap and lag: the right-hand sides projected on ``(1,
2 cos psi, 2 sin psi)``; loads: ``(C_T, C_mc, C_ms) / (a0 s)``), columns :data:`COLS`
(flap, flap rate, inflow, pitch, ``muz``, ``qbar``, ``pbar``, lag, lag rate);
:func:`lag_trim` the lag's trim moment (the zero-order right-hand side of the lag
rows, 5: the first harmonics' rows, then the second harmonic's),
:func:`lag_stiffness` their displacement columns without steady lag (5 x 5),
:func:`load_trim` the steady lag's share of the trim's loads (3) and
:func:`second_harmonic` the second-harmonic lag's rows and columns (quasi-static,
condensed into the first harmonics by :func:`inflowsim.physics.lead_lag.
coefficients`).  The trim: pitch ``th``, flap ``b``, up-flow ``u = muz - lambda0``,
cyclic inflow ``l1c_t, l1s_t`` (the flap ``b`` with its 2/rev part: 5) and (``terms``, ``load_trim``) the steady lag ``zt =
(zeta0, zeta1c, zeta1s, zeta2c, zeta2s)``: its collective part exactly (a turn of
the blades' azimuth: ``cz0, sz0``, its cosine and sine), its first and second
harmonics to first order.

Each is a polynomial in the trim, held as data (:class:`~inflowsim.physics.
polynomial.Polynomials`: the derivation's exact coefficients rounded once to
doubles, expanded): evaluated on numbers in a few array operations, or (``numeric``,
the FMU's code generator tracing the model) a run-time call whose C the generator
prints from the same table.
"""
from __future__ import annotations

import math

from .polynomial import Polynomials

#: Columns of the matrices of :func:`terms`.
COLS = {cols!r}
#: The variables of :func:`lag_trim` and :func:`lag_stiffness` (the trim without lag).
TRIM_VARIABLES = {trim!r}
#: The variables of :func:`terms` and :func:`load_trim` (with the steady lag).
VARIABLES = {variables!r}


def _cos_sin(x):
    try:
        return math.cos(x), math.sin(x)
    except TypeError:                # a symbol
        import sympy
        return sympy.cos(x), sympy.sin(x)


def _evaluate(table, values, numeric):
    """``table`` at ``values``: on numbers, or (``numeric``: the traced model's
    run-time call, ``(name, arguments, shapes) -> results``) a call named after the
    table, its identically zero outputs left exact."""
    if numeric is None:
        return table(values)
    y = numeric(table.name, tuple(values), ((table.n_out, 1),))[0][:, 0].copy()
    y[list(table.empty)] = 0
    return y

'''
#: The variables of the trim polynomials (:data:`TRIM` with the steady lag's
#: collective part as its cosine and sine).
TRIM_VARIABLES = ["mu", "nb", "dl"] + TRIM
VARIABLES = TRIM_VARIABLES + LAG_TRIM


def _to_double(c) -> float:
    """A rational coefficient correctly rounded."""
    from fractions import Fraction
    c = sp.Rational(c)
    return float(Fraction(int(c.p), int(c.q)))


def table(exprs, variables):
    """``(monomials, terms)`` of :class:`inflowsim.physics.polynomial.Polynomials`
    for the polynomials ``exprs`` in ``variables``: the monomials by degree, then
    by their exponents (the first variable's highest first); each output's terms in
    the monomials' order."""
    syms = [sp.Symbol(v) for v in variables]
    polys = [sp.Poly(sp.expand(sp.sympify(e)), *syms) for e in exprs]
    monos = sorted({m for p in polys for m in p.monoms()},
                   key=lambda m: (sum(m), tuple(-k for k in m)))
    index = {m: j for j, m in enumerate(monos)}
    terms = []
    for o, p in enumerate(polys):
        if p.is_zero:
            continue
        terms += sorted((o, index[m], _to_double(c)) for m, c in p.terms())
    monomials = [tuple(i for i, k in enumerate(m) for _ in range(k)) for m in monos]
    return monomials, terms


def _table_code(var, name, exprs, variables, variables_name):
    monomials, terms = table(exprs, variables)
    lines = [f"{var} = Polynomials(",
             f"    name={name!r}, variables={variables_name}, n_out={len(exprs)},",
             "    monomials=("]
    for i in range(0, len(monomials), 8):
        lines.append("        " + " ".join(f"{m!r}," for m in monomials[i:i + 8]))
    lines += ["    ),", "    terms=("]
    for i in range(0, len(terms), 3):
        lines.append("        " + " ".join(f"({o}, {j}, {c!r})," for o, j, c in terms[i:i + 3]))
    return lines + ["    ))", ""]


def _flat(rows):
    return [e for row in rows for e in (row if isinstance(row, list) else [row])]


#: The second harmonic's outputs, in the order of its table (sizes 42, 4, 6, 6, 6).
SECOND = ("lag2", "lag2_z2", "flap_z2", "lag_z2", "loads_z2")


FUNCTIONS = '''

def terms(mu, nb, dl, th, b, u, l1c_t, l1s_t, zt, numeric=None):
    """``(flap, lag, loads)``, each 3 x 21 (:data:`COLS`) [-]."""
    cz0, sz0 = _cos_sin(zt[0])
    y = _evaluate(_TERMS, (mu, nb, dl, *th, *b, u, l1c_t, l1s_t, cz0, sz0, *zt[1:5]),
                  numeric)
    return y[:63].reshape(3, 21), y[63:126].reshape(3, 21), y[126:].reshape(3, 21)


def lag_trim(mu, nb, dl, th, b, u, l1c_t, l1s_t, numeric=None):
    """The lag rows' right-hand side at the trim without lag, rows ``(0, 1c, 1s, 2c,
    2s)`` (5) [-]."""
    return _evaluate(_LAG_TRIM, (mu, nb, dl, *th, *b, u, l1c_t, l1s_t), numeric)


def lag_stiffness(mu, nb, dl, th, b, u, l1c_t, l1s_t, numeric=None):
    """The lag rows' displacement columns without steady lag, rows and columns
    ``(zeta0, zeta1c, zeta1s, zeta2c, zeta2s)`` (5 x 5) [-]."""
    return _evaluate(_LAG_STIFFNESS, (mu, nb, dl, *th, *b, u, l1c_t, l1s_t),
                     numeric).reshape(5, 5)


def load_trim(mu, nb, dl, th, b, u, l1c_t, l1s_t, zt, numeric=None):
    """The steady lag's share of the trim's ``(C_T, C_mc, C_ms) / (a0 s)`` (3) [-]."""
    cz0, sz0 = _cos_sin(zt[0])
    return _evaluate(_LOAD_TRIM, (mu, nb, dl, *th, *b, u, l1c_t, l1s_t, cz0, sz0,
                                  *zt[1:5]), numeric)


def second_harmonic(mu, nb, dl, th, b, u, l1c_t, l1s_t, zt, numeric=None):
    """The second-harmonic lag ``(zeta2c, zeta2s)`` (quasi-static): ``(lag2, lag2_z2,
    flap_z2, lag_z2, loads_z2)``, its own rows' right-hand side per :data:`COLS` (2 x
    21) and per itself (2 x 2), and its columns in the flap, lag and load rows of
    :func:`terms` (3 x 2 each) [-]."""
    cz0, sz0 = _cos_sin(zt[0])
    y = _evaluate(_SECOND, (mu, nb, dl, *th, *b, u, l1c_t, l1s_t, cz0, sz0, *zt[1:5]),
                  numeric)
    return (y[:42].reshape(2, 21), y[42:46].reshape(2, 2), y[46:52].reshape(3, 2),
            y[52:58].reshape(3, 2), y[58:64].reshape(3, 2))


#: The tables, by name (each a run-time call of the FMU).
TABLES = {t.name: t for t in (_TERMS, _LAG_TRIM, _LAG_STIFFNESS, _LOAD_TRIM, _SECOND)}

__all__ = ["COLS", "TRIM_VARIABLES", "VARIABLES", "TABLES", "terms", "lag_trim",
           "lag_stiffness", "load_trim", "second_harmonic"]
'''


def render(out) -> str:
    lines = [HEADER.format(cols=tuple(COLS), trim=tuple(TRIM_VARIABLES),
                           variables=tuple(VARIABLES))]
    for var, name, exprs, variables in (
            ("_TERMS", "terms", _flat(out["flap"] + out["lag"] + out["loads"]), VARIABLES),
            ("_LAG_TRIM", "lag_trim", _flat(out["lag_trim"]), TRIM_VARIABLES),
            ("_LAG_STIFFNESS", "lag_stiffness", _flat(out["lag_stiffness"]), TRIM_VARIABLES),
            ("_LOAD_TRIM", "load_trim", _flat(out["load_trim"]), VARIABLES),
            ("_SECOND", "second_harmonic",
             _flat([e for k in SECOND for e in _flat(out["second"][k])]), VARIABLES)):
        lines += _table_code(var, name, exprs, variables,
                             "VARIABLES" if variables is VARIABLES else "TRIM_VARIABLES")
    return "\n".join(lines) + FUNCTIONS


if __name__ == "__main__":
    text = render(derive())
    if "--check" in sys.argv:
        sys.exit(0 if OUT.read_text() == text else 1)
    OUT.write_text(text)
    print(f"wrote {OUT} ({len(text)} characters)")
