"""An effect's run-time computation declared as expressions and data
(``Effect.runtime``, :class:`inflowsim.model.effects.RuntimeSolve`), from which the
FMU's C is generated: evaluated in Python step by step as the generated C does
(start, Newton's method through the quadrature, results), it gives what the
effect's own Python computes; an effect asking for a run-time call it does not
declare is refused by the generator."""
from __future__ import annotations

import numpy as np
import pytest

from inflowsim.errors import InputError
from inflowsim.model.effects import CATALOGUE, RuntimeSolve
from inflowsim.model.effects import momentum_speed


def evaluate(rs: RuntimeSolve, arg):
    """The declared computation on numbers (the generated C's steps; the Jacobian
    and ``df`` by complex steps where the C has sympy's derivatives)."""
    arg = np.asarray(arg, dtype=float)
    pts = [np.asarray(p, dtype=float) for p in rs.points]
    wts = np.atleast_2d(np.asarray(rs.weights, dtype=float))

    def quad(w):
        q = rs.integrand(list(w), *pts, sqrt=np.sqrt)
        return rs.scale(arg) * (wts @ q)

    def residual(x):
        return np.asarray(rs.residual(arg, x, quad(np.asarray(rs.w_of(arg, x)))))

    m, rhs = rs.start(arg)
    x = np.linalg.solve(np.asarray(m, dtype=float), np.asarray(rhs, dtype=float))
    h = 1e-30
    for _ in range(rs.steps):
        jac = np.array([residual(x + 1j * h * e).imag / h for e in np.eye(rs.n_unknowns)]).T
        step = np.linalg.solve(jac, residual(x).real)
        x = x - step
        if np.max(np.abs(step)) < rs.tol:
            break
    w = np.asarray(rs.w_of(arg, x), dtype=float)
    df = np.array([quad(w + 1j * h * e).imag / h for e in np.eye(rs.n_w)]).T
    return rs.outputs(arg, x, quad(w), df)


@pytest.mark.parametrize("mu, v", [(0.15, None), (0.3, None), (0.05, 0.07)])
def test_the_declared_computation_is_the_effects_python(mu, v):
    rs = CATALOGUE["momentum-speed"].runtime()
    assert rs.n_args == 10 and [tuple(s) for s in rs.shapes] == [(3, 9), (3, 10), (3, 1)]
    a0s = 5.73 * 0.0917
    theta, beta, muz = (0.17, 0.012, -0.05), (0.06, 0.011, -0.004), -0.02
    v = mu if v is None else v
    got = evaluate(rs, (mu, a0s, v, *theta, *beta, muz))
    want = momentum_speed._coupling(mu, a0s, v, theta, beta, muz)
    for g, w in zip(got, want):
        np.testing.assert_allclose(np.asarray(g, dtype=float), w, rtol=0,
                                   atol=1e-12 * np.max(np.abs(w)))


def test_a_run_time_call_without_a_declaration_is_refused():
    from inflowsim.fmu.codegen import _NumericCalls
    import sympy
    calls = _NumericCalls(sympy)
    with pytest.raises(InputError, match="does not declare"):
        calls("glauert", (sympy.Symbol("mu"),), ((1, 1),))
    out = calls("momentum-speed", tuple(sympy.symbols("a0:10")),
                ((3, 9), (3, 10), (3, 1)))
    assert [o.shape for o in out] == [(3, 9), (3, 10), (3, 1)]
