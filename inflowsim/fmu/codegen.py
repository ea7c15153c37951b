"""The FMU's model equations in C, generated from the Python model: one source.

The descriptor matrices ``E, A, B`` of Eq. (8) are what
:func:`inflowsim.model.build.apply_effects` (the base model and each effect's
``equations``) and :func:`inflowsim.model.equations.assemble` compute.  Here those same functions run
on symbols (sympy) instead of numbers: the parameters by their canonical names,
``mu``, ``a0``, ``solidity``, and ``V`` the speed through the disc (the paper's
``mu`` or the mass-flow parameter, which the C computes).  The expressions are
printed as C after common-subexpression elimination.  No effect is written in C by
hand, so every structure the library builds runs in the FMU, and a change to an
effect's Python changes the FMU at the next generation (a test regenerates the
committed sources and fails on any difference).

The measurement part comes from the effects' ``measurement`` the same way: the
azimuth bias that rotates the recorded flap and each flap channel's time shift.
What the FMU cannot do is refused with one line: leads and input time shifts (a
causal step cannot apply them; the Simulator refuses them too).  Effects
linearised about a trim state (``advance-ratio-perturbation``, ``momentum-speed``)
take the trim totals as parameters ``trim_theta0`` ... ``trim_muz``; their trim
inflow is solved in the generated C (the 3 x 3 solve of
:func:`inflowsim.physics.bladeelement.trim_inflow`, done symbolically).

An effect whose terms are no closed expression (``momentum-speed``: a disc
quadrature at the trim inflow of Eq. 14, found by Newton's method) asks, while
traced, for a run-time call (``k.numeric``): its arguments are traced expressions,
its results symbols that the descriptor's expressions use.  The called C function
is generated too, from what the effect declares
(:attr:`~inflowsim.model.effects.Effect.runtime`, a
:class:`~inflowsim.model.effects.RuntimeSolve`: its integrand differentiated by
sympy, its quadrature points, its Newton residual and settings, its results; or a
:class:`~inflowsim.model.effects.RuntimeLinear`: a matrix and right-hand side whose
solution the C finds by LU, as the Peters-He effects' ``L(X)^-1``, whose symbolic
inverse took minutes to generate from ten states up; or a
:class:`~inflowsim.model.effects.RuntimePolynomials`: a table of polynomials printed
as arrays with the loop of its Python evaluation, as ``lead-lag``'s trim
coefficients, whose expansion into the descriptor made 290-340 kB of C and 40-100 s
of CPU to generate and compile).  An effect may ask for several calls, named
``<effect>/<part>``.
"""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from ..channels import FLAP
from ..physics.bladeelement import TRIM_KEYS
from ..errors import InputError
from ..model.build import apply_effects
from ..model.equations import assemble
from ..model.structure import Structure

#: ``{FMU parameter: record column}`` of the trim totals.
TRIM_PARAMETERS = {f"trim_{c}": c for c in TRIM_KEYS}




def _sympy():
    try:
        import sympy
    except ImportError:                      # declared in pyproject; a broken install
        raise InputError("FMU code generation needs sympy (pip install sympy)") from None
    return sympy


class _NumericCalls:
    """The run-time calls a traced structure's effects ask for (``k.numeric``):
    ``(effect, arguments, shapes)`` each; the results are symbols named after the
    C arrays ``numeric_<call>_<result>[i]`` (row-major) that the generated
    descriptor fills before its expressions."""

    def __init__(self, sp):
        self.sp, self.calls, self.results = sp, [], []

    def __call__(self, effect: str, args, shapes):
        if _runtime_of(effect) is None:
            raise InputError(f"the FMU does not run effect {effect}: it asks for a "
                             "numerical computation it does not declare (Effect.runtime)")
        args = tuple(self.sp.sympify(a) for a in args)
        for (name, known, _), out in zip(self.calls, self.results):
            if name == effect and known == args:
                return out
        i = len(self.calls)
        out = tuple(np.array([[self.sp.Symbol(f"numeric_{i}_{o}[{r * m + c}]")
                               for c in range(m)] for r in range(n)], dtype=object)
                    for o, (n, m) in enumerate(shapes))
        self.calls.append((effect, args, tuple(shapes)))
        self.results.append(out)
        return out


def _symbols(structure: Structure):
    sp = _sympy()

    p = {n: sp.Symbol(n) for n in structure.parameters}
    trim = {c: sp.Symbol(n) for n, c in TRIM_PARAMETERS.items()}
    k = SimpleNamespace(mu=sp.Symbol("mu"), a0=sp.Symbol("a0"),
                        a0s=sp.Symbol("a0") * sp.Symbol("solidity"),
                        omega=sp.Symbol("omega"), flow_speed=sp.Symbol("V"), trim=trim,
                        numeric=_NumericCalls(sp))
    return p, k


def supported(structure) -> Structure:
    """``structure`` parsed, or :class:`InputError` naming what the FMU cannot run."""
    s = Structure.parse(structure)
    for name in s.effects:
        if name.startswith("delay-") and name[len("delay-"):] not in FLAP:
            raise InputError(f"the FMU does not run effect {name}: a time shift of an "
                             "input cannot be applied by a causal step (inflowsim.simulate.replay "
                             "applies it to a whole record)")
    from ..model.effects.user import USER_EFFECTS
    if any(name in USER_EFFECTS for name in s.effects):
        # a user effect may add an output map (Measurement.flap_map): not in the C
        if apply_effects(s, *_symbols(s))[1].flap_map is not None:
            raise InputError(f"the FMU does not run {s.name}: an effect of it adds terms "
                             "to the recorded flap (Measurement.flap_map), which the "
                             "FMU's output map does not hold")
    return s


def _trace(structure):
    s = supported(structure)
    p, k = _symbols(s)
    eq, meas = apply_effects(s, p, k)
    e, a, b = assemble(eq, s.second_order)
    return s, e, a, b, meas, k.numeric.calls


def bias_parameters(structures) -> frozenset:
    """Names of the parameters the outputs' rotation (the measurement's azimuth
    bias, ``ifs_bias_of``) depends on in any of ``structures``: the effects'
    measurement run on symbols, as for the C."""
    sp = _sympy()
    out = set()
    for st in structures:
        s = Structure.parse(st)
        bias = apply_effects(s, *_symbols(s))[1].azimuth_bias
        out |= {str(x) for x in sp.sympify(bias).free_symbols}
    return frozenset(out)


def traced(structure):
    """``(structure, E, A, B, measurement)`` with sympy entries: the Python model run
    on symbols (azimuth time, all ten inputs, as :func:`assemble` returns)."""
    return _trace(structure)[:5]


def _c_name(sym) -> str:
    name = str(sym)
    if name == "V" or name.startswith(("a[", "b[", "numeric_")):
        return name          # the generated function's own arguments and arrays
    return f"v->{name}"


def _is_zero(x) -> bool:
    return isinstance(x, (int, float)) and x == 0


def _measurement_c(meas, index: int, sp) -> list:
    # no shift from the structure: the FMU's own lag ``delay`` (time-delay's
    # parameter, neutral 0), so every build can model a measurement chain's lag
    bias_c = "0.0" if _is_zero(meas.azimuth_bias) else _c_name(meas.azimuth_bias)
    delays = ["v->delay" if _is_zero(d) else _c_name(d) for d in meas.delays]
    return [f"static double bias_{index}(const IfsVariables *v)",
            "{"] + (["    (void)v;"] if bias_c == "0.0" else []) + [
            f"    return {bias_c};",
            "}",
            "",
            f"static void flap_delays_{index}(const IfsVariables *v, double d[3])",
            "{"] + [f"    d[{i}] = {c};" for i, c in enumerate(delays)] + ["}", ""]


def _numeric_calls_c(calls, sp) -> list:
    """The descriptor's run-time calls (:class:`_NumericCalls`): each result array
    declared, then filled by the effect's generated function from its arguments
    (the same text for the loads, which trace the same calls: made once)."""
    key = tuple((effect, tuple(args), tuple(shapes)) for effect, args, shapes in calls)
    if key not in _CALLS_TEXT:
        _CALLS_TEXT.clear()                    # one structure's at a time
        _CALLS_TEXT[key] = tuple(_numeric_calls_lines(calls, sp))
    return list(_CALLS_TEXT[key])


#: :func:`_numeric_calls_c`'s text of the last calls
_CALLS_TEXT = {}


def _numeric_calls_lines(calls, sp) -> list:
    lines = []
    for i, (effect, args, shapes) in enumerate(calls):
        outs = [f"numeric_{i}_{o}" for o in range(len(shapes))]
        lines += [f"    double {o}[{n * m}];" for o, (n, m) in zip(outs, shapes)]
        # the arguments after common-subexpression elimination (the trim inflow in
        # the wake skew's two places once)
        lines += ["    {", f"        double arg[{len(args)}];"]
        lines += _assignments(sp, [(f"arg[{j}]", a) for j, a in enumerate(args)],
                              indent="        ")
        lines += [f"        {_c_function(effect)}(arg, {', '.join(outs)});", "    }"]
    return lines


def _descriptor_c(s: Structure, e, a, b, index: int, sp, calls=()) -> list:
    n = e.shape[0]
    targets = []
    for arr, name, ncol in ((e, "e", n), (a, "a", n), (b, "b", b.shape[1])):
        for i in range(arr.shape[0]):
            for j in range(arr.shape[1]):
                x = sp.sympify(arr[i, j])
                x = sp.expand(x) if x.has(sp.Symbol) else x
                if x.is_zero is not True:
                    targets.append((f"{name}[{i * ncol + j}]", x))
    subs, reduced = sp.cse([x for _, x in targets], symbols=sp.numbered_symbols("t"),
                           optimizations="basic")
    free = set().union(*(x.free_symbols for _, x in targets)) if targets else set()
    rename = {sym: sp.Symbol(_c_name(sym)) for sym in free}
    lines = [f"/* {s.name}: {', '.join(s.effects) or 'the basic momentum model'} */",
             f"static void descriptor_{index}(const IfsVariables *v, double V, "
             "double *e, double *a, double *b)", "{"]
    uses_v = any(str(x) == "V" for x in free.union(*(a.free_symbols for c in calls
                                                    for a in c[1])))
    if not uses_v:
        lines.append("    (void)V;")
    lines += _numeric_calls_c(calls, sp)
    for t, x in subs:
        lines.append(f"    const double {t} = {sp.ccode(x.xreplace(rename))};")
    lines += ["    memset(e, 0, sizeof(double) * IFS_NX * IFS_NX);",
              "    memset(a, 0, sizeof(double) * IFS_NX * IFS_NX);",
              "    memset(b, 0, sizeof(double) * IFS_NX * IFS_NU);"]
    for (target, _), x in zip(targets, reduced):
        lines.append(f"    {target} = {sp.ccode(x.xreplace(rename))};")
    return lines + ["}", ""]


def _assignments(sp, targets, indent="    ", c_name=_c_name) -> list:
    """C lines computing ``targets`` (``[(lvalue, sympy expression)]``) after common-
    subexpression elimination; ``c_name`` names a free symbol in C."""
    subs, reduced = sp.cse([x for _, x in targets], symbols=sp.numbered_symbols("t"),
                           optimizations="basic")
    free = set().union(*(x.free_symbols for _, x in targets)) if targets else set()
    rename = {sym: sp.Symbol(c_name(sym)) for sym in free}
    lines = [f"{indent}const double {t} = {sp.ccode(x.xreplace(rename))};" for t, x in subs]
    return lines + [f"{indent}{t} = {sp.ccode(x.xreplace(rename))};"
                    for (t, _), x in zip(targets, reduced)]


def _loads_c(s: Structure, meas, index: int, sp) -> list:
    """``loads_<index>``: the load rows ``lc`` (5 x NX) and ``ld`` (5 x NU, SI) from the
    SI state space ``a, b``: :func:`inflowsim.model.loads.load_rows` run on symbols
    (``a[i]``, ``b[i]`` the C arrays' entries, row-major)."""
    from ..channels import INPUTS
    from ..model.loads import load_rows
    p, k = _symbols(s)
    n, nu = len(s.states), len(INPUTS)
    a = np.array([[sp.Symbol(f"a[{i * n + j}]") for j in range(n)] for i in range(n)])
    b = np.array([[sp.Symbol(f"b[{i * nu + j}]") for j in range(nu)] for i in range(n)])
    c, d = load_rows(a, b, s.effects, p, k, meas.azimuth_bias, s.states, INPUTS)
    targets = []
    for arr, name, ncol in ((c, "lc", n), (d, "ld", nu)):
        for i in range(arr.shape[0]):
            for j in range(arr.shape[1]):
                x = sp.sympify(arr[i, j])
                if x.is_zero is not True:
                    targets.append((f"{name}[{i * ncol + j}]", x))
    free = set().union(*(x.free_symbols for _, x in targets)) if targets else set()
    # the run-time calls the load terms ask for (lead-lag's steady lag), made here
    # as in the descriptor
    calls = k.numeric.calls
    free = free.union(*(sp.sympify(x).free_symbols for c in calls for x in c[1]))
    # an effect linearised about the trim inflow (lead-lag) has the speed through
    # the disc in its load terms: computed here as the descriptor's caller does
    speed = (["    const double V = ifs_flow_speed(v->inflow_speed, v->mu, v->ct);"]
             if any(str(x) == "V" for x in free) else [])
    return ([f"static void loads_{index}(const IfsVariables *v, const double *a, "
             "const double *b, double *lc, double *ld)", "{"] + speed
            + _numeric_calls_c(calls, sp) +
            ["    memset(lc, 0, sizeof(double) * IFS_NL * IFS_NX);",
             "    memset(ld, 0, sizeof(double) * IFS_NL * IFS_NU);"]
            + _assignments(sp, targets) + ["}", ""])


def _runtime_of(call: str):
    """What the run-time call ``call`` (an effect's name, or ``<effect>/<part>``)
    computes, as its effect declares it (:attr:`~inflowsim.model.effects.Effect.
    runtime`: a :class:`~inflowsim.model.effects.RuntimeSolve`, ``RuntimeLinear`` or
    ``RuntimePolynomials``), or None."""
    from ..model.effects import CATALOGUE
    e = CATALOGUE.get(call.split("/")[0])
    if e is None or e.runtime is None:
        return None
    rt = e.runtime()
    if isinstance(rt, dict):
        return rt.get(call)
    return rt if call == e.name else None


def _c_function(effect: str) -> str:
    return "numeric_" + "".join(ch if ch.isalnum() else "_" for ch in effect)


def _c_array(name, rows) -> list:
    """A static const double array of the rows (numbers) of ``rows``."""
    rows = np.atleast_2d(np.asarray(rows, dtype=float))
    out = [f"static const double {name}[{rows.shape[0]}][{rows.shape[1]}] = {{"]
    for row in rows:
        out.append("    {")
        out += [f"        {', '.join(repr(float(v)) for v in row[i:i + 4])},"
                for i in range(0, len(row), 4)]
        out.append("    },")
    return out + ["};"]


def _c_body(signature: str, params, body) -> list:
    """A C function of ``signature`` whose ``body`` lines may leave some of
    ``params`` unused (then cast to void)."""
    import re
    used = set(re.findall(r"[A-Za-z_]\w*", " ".join(body)))
    return ([signature, "{"] + [f"    (void){p};" for p in params if p not in used]
            + body + ["}", ""])


def _runtime_c(effect: str, rs, sp) -> list:
    """The C function ``numeric_<effect>(arg, out0, out1, ...)`` that an effect's
    run-time computation asks for (:class:`~inflowsim.model.effects.RuntimeSolve`):
    every expression of it generated from the effect's declaration (sympy
    differentiates the integrand and the residual); only the loops are the
    generator's (the quadrature's sum, Newton's method with the LU solve of
    ``inflow_numerics.c``).  A singular solve leaves NaN, which the FMU's build
    refuses (non-finite matrices)."""
    f = _c_function(effect)
    up = f.upper()
    nx, nw, npt = rs.n_unknowns, rs.n_w, len(rs.points)
    weights = np.atleast_2d(np.asarray(rs.weights, dtype=float))
    nf, n = weights.shape
    arg = np.array([sp.Symbol(f"arg[{i}]") for i in range(rs.n_args)], dtype=object)
    x = np.array([sp.Symbol(f"x[{i}]") for i in range(nx)], dtype=object)
    w = np.array([sp.Symbol(f"w[{i}]") for i in range(nw)], dtype=object)
    fs = np.array([sp.Symbol(f"f[{i}]") for i in range(nf)], dtype=object)
    df = np.array([[sp.Symbol(f"df[{i * nw + j}]") for j in range(nw)] for i in range(nf)],
                  dtype=object)
    pt = [sp.Symbol(f"pt[{i}]") for i in range(npt)]
    sym = lambda v: sp.sympify(v)                              # noqa: E731
    # the integrand and its gradient at one point
    q = sym(rs.integrand(w, *pt, sqrt=sp.sqrt))
    grad = [(f"g[{j}]", sp.diff(q, w[j])) for j in range(nw)]
    lines = [f"/* --- {effect}: its run-time computation "
             "(inflowsim.model.effects.RuntimeSolve), generated --- */",
             f"static void {f}_point(const double *w, const double *pt, double *q, "
             "double *g)", "{"]
    lines += _assignments(sp, [("*q", q)] + [t for t in grad if t[1] != 0], c_name=str)
    lines += [f"    g[{j}] = 0.0;" for j, (_, d) in enumerate(grad) if d == 0] + ["}", ""]
    # the quadrature: f = scale sum_k weights[:, k] q_k, df = d f / d w
    lines += [f"#define {up}_N {n}  /* quadrature points */"]
    lines += _c_array(f"{up}_PT", np.array([np.asarray(c, dtype=float) for c in rs.points]))
    lines += _c_array(f"{up}_W", weights)
    lines += ["", f"static void {f}_quad(const double *w, double scale, double *f, "
              "double *df)", "{",
              f"    double q, g[{nw}], pt[{npt}];", "    int k, i, j;",
              f"    memset(f, 0, sizeof(double) * {nf});",
              f"    memset(df, 0, sizeof(double) * {nf * nw});",
              f"    for (k = 0; k < {up}_N; k++) {{",
              f"        for (i = 0; i < {npt}; i++) pt[i] = {up}_PT[i][k];",
              f"        {f}_point(w, pt, &q, g);",
              f"        for (i = 0; i < {nf}; i++) {{",
              f"            const double a = {up}_W[i][k];",
              "            f[i] += a * q;",
              f"            for (j = 0; j < {nw}; j++) df[{nw} * i + j] += a * g[j];",
              "        }", "    }",
              f"    for (i = 0; i < {nf}; i++) f[i] *= scale;",
              f"    for (i = 0; i < {nf * nw}; i++) df[i] *= scale;", "}", ""]
    # the variables, the start's system, the residual and its Jacobian (chain rule
    # through f), the results
    wx = [sym(v) for v in rs.w_of(arg, x)]
    lines += _c_body(f"static void {f}_w(const double *arg, const double *x, double *w)",
                     ("arg", "x"), _assignments(sp, [(f"w[{i}]", v) for i, v in enumerate(wx)],
                                                c_name=str))
    m0, r0 = rs.start(arg)
    lines += _c_body(f"static void {f}_start(const double *arg, double *m, double *x)",
                     ("arg",), _assignments(sp, [(f"m[{i * nx + j}]", sym(m0[i][j]))
                                                 for i in range(nx) for j in range(nx)]
                                            + [(f"x[{i}]", sym(r0[i])) for i in range(nx)],
                                            c_name=str))
    res = [sym(r) for r in rs.residual(arg, x, fs)]
    jac = []
    for i in range(nx):
        for j in range(nx):
            d = sp.diff(res[i], x[j])
            for k in range(nf):
                dk = sp.diff(res[i], fs[k])
                if dk != 0:
                    d += dk * sum(df[k, m] * sp.diff(wx[m], x[j]) for m in range(nw))
            jac.append((f"m[{i * nx + j}]", d))
    lines += _c_body(f"static void {f}_newton(const double *arg, const double *x, "
                     "const double *f, const double *df, double *r, double *m)",
                     ("arg", "x", "f", "df"),
                     _assignments(sp, [(f"r[{i}]", v) for i, v in enumerate(res)] + jac,
                                  c_name=str))
    outs = [np.asarray(o, dtype=object) for o in rs.outputs(arg, x, fs, df)]
    ocode = [(f"out{o}[{i}]", sym(v)) for o, a in enumerate(outs)
             for i, v in enumerate(a.ravel())]
    sig = ", ".join(f"double *out{o}" for o in range(len(outs)))
    lines += _c_body(f"static void {f}_outputs(const double *arg, const double *x, "
                     f"const double *f, const double *df, {sig})", ("arg", "x", "f", "df"),
                     _assignments(sp, ocode, c_name=str))
    size = [int(np.prod(shape)) for shape in rs.shapes]
    lines += [f"static void {f}(const double *arg, {sig})", "{",
              f"    double x[{nx}], w[{nw}], f[{nf}], df[{nf * nw}], r[{nx}], "
              f"m[{nx * nx}], big;", "    int k, i;",
              f"    {f}_start(arg, m, x);",
              f"    if (ifs_lu_solve({nx}, m, 1, x, 1e-14) != 0) goto fail;",
              f"    for (k = 0; k < {rs.steps}; k++) {{",
              f"        {f}_w(arg, x, w);",
              f"        {f}_quad(w, {sp.ccode(sym(rs.scale(arg)))}, f, df);",
              f"        {f}_newton(arg, x, f, df, r, m);",
              f"        if (ifs_lu_solve({nx}, m, 1, r, 1e-14) != 0) goto fail;",
              "        big = 0.0;",
              f"        for (i = 0; i < {nx}; i++) {{",
              "            x[i] -= r[i];",
              "            if (fabs(r[i]) > big) big = fabs(r[i]);", "        }",
              f"        if (big < {rs.tol!r}) break;", "    }",
              f"    {f}_w(arg, x, w);",
              f"    {f}_quad(w, {sp.ccode(sym(rs.scale(arg)))}, f, df);",
              f"    {f}_outputs(arg, x, f, df, "
              f"{', '.join(f'out{o}' for o in range(len(outs)))});",
              "    return;", "fail:"]
    lines += [f"    for (i = 0; i < {n_}; i++) out{o}[i] = NAN;" for o, n_ in enumerate(size)]
    return lines + ["}", ""]


def _linear_c(effect: str, rl, sp) -> list:
    """The C function ``numeric_<effect>(arg, out0)`` of a run-time linear solve
    (:class:`~inflowsim.model.effects.RuntimeLinear`): ``M`` and ``R`` printed from
    the effect's expressions of ``arg`` (zeros left by a memset), then the LU solve
    of ``inflow_numerics.c`` in place: ``out0 = M^-1 R`` (row-major).  A singular
    ``M`` leaves NaN, which the FMU's build refuses (non-finite matrices)."""
    f = _c_function(effect)
    arg = np.array([sp.Symbol(f"arg[{i}]") for i in range(rl.n_args)], dtype=object)
    m, r = np.asarray(rl.matrix(arg), dtype=object), np.asarray(rl.rhs(arg), dtype=object)
    n, nr = r.shape
    targets = [(f"m[{i * n + j}]", sp.sympify(m[i, j])) for i in range(n)
               for j in range(n)]
    targets += [(f"out0[{i * nr + j}]", sp.sympify(r[i, j])) for i in range(n)
                for j in range(nr)]
    targets = [(t, sp.expand(x)) for t, x in targets if x.is_zero is not True]
    body = ([f"    double m[{n * n}];", "    int i;",
             "    memset(m, 0, sizeof m);",
             f"    memset(out0, 0, sizeof(double) * {n * nr});"]
            + _assignments(sp, targets, c_name=str)
            + [f"    if (ifs_lu_solve({n}, m, {nr}, out0, 1e-14) == 0) return;",
               f"    for (i = 0; i < {n * nr}; i++) out0[i] = NAN;"])
    return ([f"/* --- {effect}: its run-time linear solve "
             "(inflowsim.model.effects.RuntimeLinear), generated --- */"]
            + _c_body(f"static void {f}(const double *arg, double *out0)", ("arg",), body))


def _int_array(name, ctype, values, per_line=16) -> list:
    """A static const integer array of ``values`` (1-D or 2-D)."""
    a = np.asarray(values)
    shape = "".join(f"[{n}]" for n in a.shape)
    rows = a if a.ndim == 2 else a[None, :]
    out = [f"static const {ctype} {name}{shape} = {{"]
    for row in rows:
        body = [f"{'    ' * a.ndim}{', '.join(str(int(v)) for v in row[i:i + per_line])},"
                for i in range(0, len(row), per_line)]
        out += (["    {"] + body + ["    },"]) if a.ndim == 2 else body
    return out + ["};"]


def _polynomials_c(call: str, rp) -> list:
    """The C function ``numeric_<call>(arg, out0)`` of run-time polynomials
    (:class:`~inflowsim.model.effects.RuntimePolynomials`): the table
    (:class:`inflowsim.physics.polynomial.Polynomials`) as arrays, its monomials by
    their prefix tree (one multiply each, :meth:`~inflowsim.physics.polynomial.
    Polynomials.prefix_tree`), then each output's terms (monomial and coefficient);
    the multiplies and adds of its Python evaluation in the same order (so, built
    without contraction, the same doubles): each monomial the product of its
    variables left to right, each output the sum of its terms from zero."""
    t = rp.table
    f = _c_function(call)
    up = f.upper()
    nv = len(t.variables)
    parent, var, node = t.prefix_tree()
    out, mono, coef = t.term_arrays()
    nn = len(parent)
    assert nv < 127 and max(nn, t.n_out) < 65536
    lines = [f"/* --- {call}: its run-time polynomials "
             "(inflowsim.model.effects.RuntimePolynomials), generated --- */",
             f"/* variables: {', '.join(t.variables)}; the monomials' prefix tree: "
             "node j = node PARENT[j] * variable VAR[j], node 0 = 1 */"]
    # each output's terms together, in the table's order (as numpy's bincount adds
    # them): the C sums them in a register, from zero
    assert np.all(np.diff(out) >= 0), "a table's terms grouped by output"
    first = np.searchsorted(out, np.arange(t.n_out + 1))
    lines += _int_array(f"{up}_PARENT", "unsigned short", parent[1:])
    lines += _int_array(f"{up}_VAR", "signed char", var[1:])
    lines += _int_array(f"{up}_FIRST", "unsigned short", first)
    lines += _int_array(f"{up}_NODE", "unsigned short", [node[j] for j in mono])
    lines += [f"static const double {up}_COEF[{len(coef)}] = {{"]
    lines += [f"    {', '.join(repr(float(c)) for c in coef[i:i + 4])},"
              for i in range(0, len(coef), 4)] + ["};", ""]
    body = [f"    double m[{nn}];", "    int i, o;", "    m[0] = 1.0;",
            f"    for (i = 1; i < {nn}; i++) "
            f"m[i] = m[{up}_PARENT[i - 1]] * arg[{up}_VAR[i - 1]];",
            f"    for (o = 0; o < {t.n_out}; o++) {{",
            "        double s = 0.0;",
            f"        for (i = {up}_FIRST[o]; i < {up}_FIRST[o + 1]; i++) "
            f"s += {up}_COEF[i] * m[{up}_NODE[i]];",
            "        out0[o] = s;", "    }"]
    return lines + _c_body(f"static void {f}(const double *arg, double *out0)", ("arg",),
                           body)


#: the generated functions of each structure, ``<kind>_<index>``
KINDS = ("descriptor", "bias", "flap_delays", "loads")


def _without_name(kind: str, index: int, lines) -> str:
    """A generated function's text with its own name and its leading comment (the
    structure's name) left out: equal for two structures exactly when one function
    serves both."""
    return "\n".join(line.replace(f"{kind}_{index}(", f"{kind}_(") for line in lines
                     if not line.startswith("/*"))


def equations_c(structures) -> str:
    """The text of ``inflow_equations.c`` for the FMU's ``structures`` (in the order
    of its integer ``structure``): descriptor, azimuth bias, flap time shifts and
    loads of each (a function written once where structures share it, e.g. the same
    loads), and the dispatch on ``v->structure``."""
    sp = _sympy()
    body = []
    states = set()
    numeric = []
    first = {}                            # a function's text -> the structure writing it
    impl = {kind: [] for kind in KINDS}   # the function each structure calls
    for i, st in enumerate(structures):
        s, e, a, b, meas, calls = _trace(st)
        states.add(e.shape[0])
        for c in calls:                       # each effect's function once (lead-lag
            if c[0] not in numeric:           # calls its solve several times)
                numeric.append(c[0])
        measurement = _measurement_c(meas, i, sp)
        cut = measurement.index("") + 1
        parts = {"descriptor": _descriptor_c(s, e, a, b, i, sp, calls),
                 "bias": measurement[:cut], "flap_delays": measurement[cut:],
                 "loads": _loads_c(s, meas, i, sp)}
        for kind in KINDS:
            key = (kind, _without_name(kind, i, parts[kind]))
            if key not in first:
                first[key] = i
                body += parts[kind]
            impl[kind].append(first[key])
    from ..model.effects import RuntimeLinear, RuntimePolynomials
    for effect in numeric:                     # before the descriptors that call them
        rt = _runtime_of(effect)
        body = (_linear_c(effect, rt, sp) if isinstance(rt, RuntimeLinear)
                else _polynomials_c(effect, rt) if isinstance(rt, RuntimePolynomials)
                else _runtime_c(effect, rt, sp)) + body
    if len(states) != 1:
        raise InputError("the structures of one FMU must have the same number of states "
                         f"(these have {sorted(states)})")
    def cases(kind, call):
        return ([f"    case {i}: {call.format(i=j)}" for i, j in enumerate(impl[kind])]
                + [f"    default: {call.format(i=impl[kind][0])}"])
    head = ["/* Generated by inflowsim.fmu.codegen from the Python model "
            "(inflowsim.model): do not edit. */",
            "/* The descriptor E x' = A x + B u of each structure (azimuth time, "
            "model.md Eq. 8),", " * its azimuth bias, its flap channels' time "
            "shifts and its loads (model.md section 3). */",
            "#include <math.h>", "#include <string.h>", "", '#include "inflow_model.h"']
    if numeric:
        head.append('#include "inflow_numerics.h"')
    head.append("")
    tail = ["void ifs_descriptor_of(const IfsVariables *v, double V, double *e, "
            "double *a, double *b)", "{", "    switch (v->structure) {"]
    tail += cases("descriptor", "descriptor_{i}(v, V, e, a, b); break;")
    tail += ["    }", "}", "",
             "double ifs_bias_of(const IfsVariables *v)", "{", "    switch (v->structure) {"]
    tail += cases("bias", "return bias_{i}(v);")
    tail += ["    }", "}", "",
             "void ifs_flap_delays_of(const IfsVariables *v, double d[3])", "{",
             "    switch (v->structure) {"]
    tail += cases("flap_delays", "flap_delays_{i}(v, d); break;")
    tail += ["    }", "}", "",
             "void ifs_loads_of(const IfsVariables *v, const double *a, const double *b, "
             "double *lc, double *ld)", "{", "    switch (v->structure) {"]
    tail += cases("loads", "loads_{i}(v, a, b, lc, ld); break;")
    tail += ["    }", "}", ""]
    return "\n".join(head + body + tail)


def n_states(structures) -> int:
    """States of the FMU's structures (all the same)."""
    return len(Structure.parse(structures[0]).states)


__all__ = ["equations_c", "traced", "bias_parameters", "supported", "n_states", "TRIM_PARAMETERS"]
