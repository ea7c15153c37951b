"""Polynomials held as data (:mod:`inflowsim.physics.polynomial`): the lead-lag
coefficients' form that Python evaluates and the FMU's generator prints into C."""
from __future__ import annotations

import math

import numpy as np
import pytest
import sympy

from inflowsim.model.effects import CATALOGUE, RuntimePolynomials
from inflowsim.physics import lead_lag_terms as lt
from inflowsim.physics.polynomial import Polynomials


def test_a_table_is_its_sum_of_terms():
    """Each output is the sum of coefficient times monomial: numbers, and symbols
    (the same table expanded by sympy), and an output without terms is zero."""
    p = Polynomials(name="t", variables=("x", "y"), n_out=3,
                    monomials=((), (0,), (0, 0, 1)), terms=((0, 0, 2.0), (0, 2, -0.5),
                                                           (2, 1, 3.0)))
    x, y = 0.3, -1.7
    np.testing.assert_array_equal(p((x, y)), [2.0 - 0.5 * x * x * y, 0.0, 3.0 * x])
    sx, sy = sympy.symbols("x y")
    got = p((sx, sy))
    assert sympy.expand(got[0] - (2 - sympy.Rational(1, 2) * sx**2 * sy)) == 0
    assert got[1] == 0 and sympy.expand(got[2] - 3 * sx) == 0
    assert p.empty == (1,) and p.depth == 3


def test_the_prefix_tree_multiplies_as_the_table():
    """The generated C's monomials (one multiply per node of the prefix tree) are
    the doubles of the table's own evaluation (left to right), on the lag's terms."""
    t = lt.TABLES["terms"]
    parent, var, node = t.prefix_tree()
    v = np.random.default_rng(3).normal(0.0, 0.4, len(t.variables))
    m = [1.0]
    for a, b in zip(parent[1:], var[1:]):
        assert a < len(m)
        m.append(m[a] * v[b])
    want = np.multiply.reduce(np.append(v, 1.0)[t.index_rows()], axis=0)
    np.testing.assert_array_equal(np.array(m)[list(node)], want)


def test_the_lag_tables_are_the_effects_run_time_calls():
    """The lead-lag effect declares each table of ``lead_lag_terms`` as a run-time
    call ``lead-lag/<table>`` (the FMU's C evaluates the table), and the table's
    numbers are its symbolic expansion's at a trim (the lag's trim moment)."""
    rt = CATALOGUE["lead-lag"].runtime()
    for name, table in lt.TABLES.items():
        assert isinstance(rt[f"lead-lag/{name}"], RuntimePolynomials)
        assert rt[f"lead-lag/{name}"].table is table
    args = (0.3, 0.9, 0.0015, (0.17, 0.01, -0.05), (0.06, 0.011, -0.004, -0.003, 0.001),
            -0.03, 0.004, -0.002)
    values = [args[0], args[1], args[2], *args[3], *args[4], *args[5:]]
    t = lt.TABLES["lag_trim"]
    syms = sympy.symbols(" ".join(t.variables))
    expr = t(syms)
    want = [float(e.xreplace(dict(zip(syms, values)))) for e in expr]
    np.testing.assert_allclose(lt.lag_trim(*args), want, rtol=1e-13, atol=1e-16)
    np.testing.assert_array_equal(rt["lead-lag/lag_trim"].solve(values)[:, 0],
                                  lt.lag_trim(*args))
    zt = (0.01, 0.002, -0.001, 0.0005, -0.0003)
    flap, lag, loads = lt.terms(*args, zt)
    y = lt.TABLES["terms"]([*values, math.cos(zt[0]), math.sin(zt[0]), *zt[1:]])
    np.testing.assert_array_equal(np.concatenate([flap.ravel(), lag.ravel(),
                                                  loads.ravel()]), y)


@pytest.mark.slow
def test_the_traced_lag_with_its_calls_evaluated_is_the_python_descriptor():
    """Traced for the FMU, the lag's terms are run-time calls (its 3 x 3 solves and
    its trim tables); each call evaluated in Python through what the effect declares
    (``RuntimeLinear.solve``, ``RuntimePolynomials.solve``), in order (a call's
    arguments hold earlier calls' results), the traced E, A, B are build_model's:
    the tracing checked apart from the compiler (a second of sympy)."""
    from inflowsim.fmu.codegen import _runtime_of, _trace
    from inflowsim.model import descriptor
    from inflowsim.model.params import PUMA
    from inflowsim.model.presets import truth_parameters
    structure = "glauert+azimuth-bias+lead-lag"
    trim = {"theta0": 0.17, "theta1c": 0.012, "theta1s": -0.05, "beta0": 0.06,
            "beta1c": 0.011, "beta1s": -0.004, "muz": -0.02}
    k = PUMA.with_trim(trim).with_mu(0.27)
    p = truth_parameters(structure, k) | {"azimuth_bias": 0.2, "k_flap_lag": 1.3}
    e, a, b = descriptor(structure, p, k)
    _, es, as_, bs, _, calls = _trace(structure)
    assert {c[0] for c in calls} == {"lead-lag", *(f"lead-lag/{n}" for n in lt.TABLES)}
    values = {**p, "mu": k.mu, "a0": k.a0, "solidity": k.solidity, "V": k.flow_speed,
              **{f"trim_{c}": x for c, x in trim.items()}}
    subs = {sympy.Symbol(n): v for n, v in values.items()}
    for i, (name, args, shapes) in enumerate(calls):
        y = _runtime_of(name).solve([float(sympy.sympify(x).xreplace(subs)) for x in args])
        assert y.shape == shapes[0]
        subs.update({sympy.Symbol(f"numeric_{i}_0[{j}]"): v for j, v in enumerate(y.ravel())})
    for sym, num in ((es, e), (as_, a), (bs, b[:, : bs.shape[1]])):
        got = np.array([[float(sympy.sympify(x).xreplace(subs)) for x in row] for row in sym])
        np.testing.assert_allclose(got, num, rtol=1e-12, atol=1e-13 * np.abs(num).max())


@pytest.mark.slow
def test_the_generated_c_gives_the_tables_doubles(tmp_path):
    """The C the FMU's generator prints for each lag table, compiled with the FMU's
    flags, gives Python's evaluation bit for bit at random points."""
    import ctypes
    import subprocess
    from inflowsim.fmu import codegen
    from inflowsim.fmu.build import CFLAGS, compiler
    rt = CATALOGUE["lead-lag"].runtime()
    src = ["#include <string.h>"]
    for name in lt.TABLES:
        src += [line.replace("static void numeric", "void numeric")
                for line in codegen._polynomials_c(f"lead-lag/{name}", rt[f"lead-lag/{name}"])]
    (tmp_path / "t.c").write_text("\n".join(src))
    flags = [f for f in CFLAGS if f != "-fvisibility=hidden"]
    subprocess.run([compiler(), *flags, str(tmp_path / "t.c"), "-o", str(tmp_path / "t.so")],
                   check=True)
    lib = ctypes.CDLL(str(tmp_path / "t.so"))
    rng = np.random.default_rng(7)
    ptr = ctypes.POINTER(ctypes.c_double)
    for name, t in lt.TABLES.items():
        f = getattr(lib, "numeric_lead_lag_" + name)
        for _ in range(200):
            v = rng.normal(0.0, 0.4, len(t.variables))
            out = np.zeros(t.n_out)
            f(v.ctypes.data_as(ptr), out.ctypes.data_as(ptr))
            np.testing.assert_array_equal(out, t(list(v)))
