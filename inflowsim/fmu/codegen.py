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
is generated too (:data:`NUMERIC_C`): the effect's physics module's integrand
differentiated by sympy, its quadrature points and its Newton settings.
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
        if effect not in NUMERIC_C:
            raise InputError(f"the FMU does not run effect {effect}: it asks for a "
                             "numerical computation the code generator does not hold")
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
    declared, then filled by the effect's generated function from its arguments."""
    lines = []
    for i, (effect, args, shapes) in enumerate(calls):
        outs = [f"numeric_{i}_{o}" for o in range(len(shapes))]
        lines += [f"    double {o}[{n * m}];" for o, (n, m) in zip(outs, shapes)]
        rename = {x: sp.Symbol(_c_name(x)) for x in set().union(*(a.free_symbols
                                                                 for a in args))}
        vals = ", ".join(sp.ccode(a.xreplace(rename)) for a in args)
        lines += ["    {", f"        const double arg[{len(args)}] = {{{vals}}};",
                  f"        {NUMERIC_C[effect][0]}(arg, {', '.join(outs)});", "    }"]
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
    # an effect linearised about the trim inflow (lead-lag) has the speed through
    # the disc in its load terms: computed here as the descriptor's caller does
    speed = (["    const double V = ifs_flow_speed(v);"]
             if any(str(x) == "V" for x in free) else [])
    return ([f"static void loads_{index}(const IfsVariables *v, const double *a, "
             "const double *b, double *lc, double *ld)", "{"] + speed +
            ["    memset(lc, 0, sizeof(double) * IFS_NL * IFS_NX);",
             "    memset(ld, 0, sizeof(double) * IFS_NL * IFS_NU);"]
            + _assignments(sp, targets) + ["}", ""])


def _flow_speed_c(sp) -> list:
    """``ifs_flow_speed``: the speed through the disc, ``mu`` or (``inflow_speed`` 1) the
    mass-flow parameter by Newton's method: the functions of
    :mod:`inflowsim.physics.loads` run on symbols, in its loop."""
    from ..physics import loads as ld
    mu, ct, lam = sp.Symbol("mu"), sp.Symbol("ct"), sp.Symbol("lam")
    code = lambda x: sp.ccode(sp.sympify(x))                        # noqa: E731
    return ["double ifs_flow_speed(const IfsVariables *v)", "{",
            "    const double mu = v->mu, ct = v->ct;",
            "    double lam;",
            "    int k;",
            "    if (v->inflow_speed == 0) return mu;    /* the paper's V ~ mu */",
            f"    lam = {code(ld.inflow_start(ct))};",
            f"    for (k = 0; k < {ld.NEWTON_STEPS}; k++) {{",
            f"        const double step = {code(ld.inflow_newton_step(lam, mu, ct))};",
            "        lam -= step;",
            f"        if (fabs(step) <= {ld.NEWTON_TOL!r} * lam) break;",
            "    }",
            f"    return {code(ld.speed_through_disc(mu, lam))};", "}", ""]


def _momentum_speed_c(sp) -> list:
    """``numeric_momentum_speed(arg, a, b, lam)``: the coupling of effect
    ``momentum-speed`` and the trim inflow it is linearised about, at run time
    (:func:`inflowsim.model.effects.momentum_speed.coupling`, arguments ``mu, a0 s,
    V, theta (3), beta (3), muz`` as it passes them).  The same steps as
    :mod:`inflowsim.physics.momentum_speed`: the base model's trim inflow, Newton's
    method on Eq. (14)'s momentum balance (its step count and tolerance), then the
    momentum loads' derivatives over the disc (its quadrature points; its integrand
    differentiated by sympy where Python takes complex steps) and ``-J``.  A
    singular solve leaves NaN, which the FMU's build refuses (non-finite matrices)."""
    from ..physics import loads as ld
    from ..physics import momentum_speed as ms
    nw = 19
    w = [sp.Symbol(f"w[{i}]") for i in range(nw)]
    c, s, r = sp.symbols("c s r")
    q = ms.speed_integrand(w[:9], w[9:], c, s, r, sqrt=sp.sqrt)
    grad = [(f"g[{j}]", sp.diff(q, x)) for j, x in enumerate(w)]
    point = (["static void ms_point(const double *w, double c, double s, double r, "
              "double *q, double *g)", "{"]
             + _assignments(sp, [("*q", q)] + [t for t in grad if t[1] != 0], c_name=str)
             + [f"    g[{j}] = 0.0;" for j, (_, x) in enumerate(grad) if x == 0]
             + ["}", ""])
    pc, ps, pr, w0, w1 = ms.disc_points()
    arr = lambda name, x: [f"static const double {name}[MS_N] = {{",     # noqa: E731
                           *(f"    {', '.join(repr(float(v)) for v in x[i:i + 4])},"
                             for i in range(0, len(x), 4)), "};"]
    loads = ([f"#define MS_N {len(pc)}  /* disc points: {ms.N_PSI} azimuths x "
              f"{ms.N_R} radii (Gauss-Legendre) */"] + arr("MS_C", pc) + arr("MS_S", ps)
             + arr("MS_R", pr) + arr("MS_W0", w0) + arr("MS_W1", w1) + [
        "",
        "/* c_mom = 4/(a0 s) (sum w0 q, -sum c w1 q, -sum s w1 q) and its derivatives "
        "(3 x 19) */",
        "static void ms_loads(const double *w, double a0s, double *f, double *df)", "{",
        f"    double q, g[{nw}];", "    int k, j;",
        "    memset(f, 0, sizeof(double) * 3);",
        f"    memset(df, 0, sizeof(double) * {3 * nw});",
        "    for (k = 0; k < MS_N; k++) {",
        "        const double a = MS_W0[k], bc = MS_C[k] * MS_W1[k], "
        "bs = MS_S[k] * MS_W1[k];",
        "        ms_point(w, MS_C[k], MS_S[k], MS_R[k], &q, g);",
        "        f[0] += a * q; f[1] -= bc * q; f[2] -= bs * q;",
        f"        for (j = 0; j < {nw}; j++) {{",
        f"            df[j] += a * g[j]; df[{nw} + j] -= bc * g[j]; "
        f"df[{2 * nw} + j] -= bs * g[j];", "        }", "    }",
        "    for (j = 0; j < 3; j++) f[j] *= 4.0 / a0s;",
        f"    for (j = 0; j < {3 * nw}; j++) df[j] *= 4.0 / a0s;", "}", ""])
    arg = [sp.Symbol(f"arg[{i}]") for i in range(10)]
    mu, a0s, v = arg[:3]
    theta, beta = np.array(arg[3:6], dtype=object), np.array(arg[6:9], dtype=object)
    blade = ld.g_theta(mu) @ theta + ld.g_beta(mu) @ beta + ld.g_nu(mu)[:, 0] * arg[9]
    gl, lm = ld.g_lambda(mu), ld.momentum_l(mu, a0s, v)
    gains = ([(f"blade[{i}]", sp.sympify(blade[i])) for i in range(3)]
             + [(f"gl[{3 * i + j}]", sp.sympify(gl[i, j])) for i in range(3)
                for j in range(3)]
             + [(f"lm[{3 * i + j}]", sp.sympify(lm[i, j])) for i in range(3)
                for j in range(3)])
    call = ["/* momentum-speed's coupling (inflowsim.physics.momentum_speed) */",
            "static void numeric_momentum_speed(const double *arg, double *ca, "
            "double *cb, double *cl)", "{",
            f"    double blade[3], gl[9], lm[9], m[9], lam[3], f[3], df[{3 * nw}], "
            "big;", f"    double w[{nw}] = {{0}};", "    int i, j, k;"]
    call += _assignments(sp, gains, c_name=str)
    call += [
        "    /* the start: the base model's trim inflow, (I - L G_lambda) lam = L blade */",
        "    for (i = 0; i < 3; i++) {",
        "        lam[i] = 0.0;",
        "        for (j = 0; j < 3; j++) {",
        "            lam[i] += lm[3 * i + j] * blade[j];",
        "            m[3 * i + j] = (i == j);",
        "            for (k = 0; k < 3; k++) m[3 * i + j] -= lm[3 * i + k] * gl[3 * k + j];",
        "        }", "    }",
        "    if (ifs_lu_solve(3, m, 1, lam, 1e-14) != 0) goto fail;",
        "    /* z = (beta, 0, lam), u = (theta, muz, 0, 0, 0, 0, mu, 0) */",
        "    for (i = 0; i < 3; i++) {",
        "        w[i] = arg[6 + i]; w[6 + i] = lam[i]; w[9 + i] = arg[3 + i];", "    }",
        "    w[12] = arg[9]; w[17] = arg[0];",
        f"    for (k = 0; k < {ms.NEWTON_STEPS}; k++) {{",
        "        double step[3];",
        "        ms_loads(w, arg[1], f, df);",
        "        for (i = 0; i < 3; i++) {",
        "            step[i] = blade[i] - f[i];",
        "            for (j = 0; j < 3; j++) {",
        "                step[i] += gl[3 * i + j] * lam[j];",
        f"                m[3 * i + j] = gl[3 * i + j] - df[{nw} * i + 6 + j];",
        "            }", "        }",
        "        if (ifs_lu_solve(3, m, 1, step, 1e-14) != 0) goto fail;",
        "        big = 0.0;",
        "        for (i = 0; i < 3; i++) {",
        "            lam[i] -= step[i]; w[6 + i] = lam[i];",
        "            if (fabs(step[i]) > big) big = fabs(step[i]);", "        }",
        f"        if (big < {ms.NEWTON_TOL!r}) break;", "    }",
        "    for (i = 0; i < 3; i++) cl[i] = lam[i];",
        "    /* J = L dc/d(z, u) - [0 0 I 0]; the coupling is -J */",
        "    ms_loads(w, arg[1], f, df);",
        "    for (i = 0; i < 3; i++)",
        f"        for (j = 0; j < {nw}; j++) {{",
        "            double x = 0.0;",
        f"            for (k = 0; k < 3; k++) x += lm[3 * i + k] * df[{nw} * k + j];",
        "            if (j == 6 + i) x -= 1.0;",
        "            if (j < 9) ca[9 * i + j] = -x; else cb[10 * i + j - 9] = -x;",
        "        }",
        "    return;",
        "fail:",
        "    for (i = 0; i < 27; i++) ca[i] = NAN;",
        "    for (i = 0; i < 30; i++) cb[i] = NAN;",
        "    for (i = 0; i < 3; i++) cl[i] = NAN;", "}", ""]
    return ["/* --- momentum-speed: Eq. (14)'s speed linearised over the disc, at run "
            "time --- */"] + point + loads + call


#: Run-time computations an effect may ask for while traced: ``{effect: (C function,
#: generator of its C lines)}``; the function is ``f(const double *arg, double *out0,
#: ...)`` with the effect's arguments and results in the order it passes them.
NUMERIC_C = {"momentum-speed": ("numeric_momentum_speed", _momentum_speed_c)}


def equations_c(structures) -> str:
    """The text of ``inflow_equations.c`` for the FMU's ``structures`` (in the order
    of its integer ``structure``): descriptor, azimuth bias and flap time shifts of
    each, and the dispatch on ``v->structure``."""
    sp = _sympy()
    body = []
    states = set()
    numeric = []
    for i, st in enumerate(structures):
        s, e, a, b, meas, calls = _trace(st)
        states.add(e.shape[0])
        numeric += [c[0] for c in calls if c[0] not in numeric]
        body += (_descriptor_c(s, e, a, b, i, sp, calls) + _measurement_c(meas, i, sp)
                 + _loads_c(s, meas, i, sp))
    for effect in numeric:                     # before the descriptors that call them
        body = NUMERIC_C[effect][1](sp) + body
    if len(states) != 1:
        raise InputError("the structures of one FMU must have the same number of states "
                         f"(these have {sorted(states)})")
    n = len(structures)
    cases = lambda call: [f"    case {i}: {call.format(i=i)}" for i in range(n)]
    head = ["/* Generated by inflowsim.fmu.codegen from the Python model "
            "(inflowsim.model): do not edit. */",
            "/* The descriptor E x' = A x + B u of each structure (azimuth time, "
            "model.md Eq. 8),", " * its azimuth bias, its flap channels' time "
            "shifts and its loads (model.md section 3);", " * the speed through the "
            "disc of the momentum gains. */",
            "#include <math.h>", "#include <string.h>", "", '#include "inflow_model.h"']
    if numeric:
        head.append('#include "inflow_numerics.h"')
    head.append("")
    tail = ["void ifs_descriptor_of(const IfsVariables *v, double V, double *e, "
            "double *a, double *b)", "{", "    switch (v->structure) {"]
    tail += cases("descriptor_{i}(v, V, e, a, b); break;")
    tail += ["    default: descriptor_0(v, V, e, a, b); break;", "    }", "}", "",
             "double ifs_bias_of(const IfsVariables *v)", "{", "    switch (v->structure) {"]
    tail += cases("return bias_{i}(v);")
    tail += ["    default: return bias_0(v);", "    }", "}", "",
             "void ifs_flap_delays_of(const IfsVariables *v, double d[3])", "{",
             "    switch (v->structure) {"]
    tail += cases("flap_delays_{i}(v, d); break;")
    tail += ["    default: flap_delays_0(v, d); break;", "    }", "}", "",
             "void ifs_loads_of(const IfsVariables *v, const double *a, const double *b, "
             "double *lc, double *ld)", "{", "    switch (v->structure) {"]
    tail += cases("loads_{i}(v, a, b, lc, ld); break;")
    tail += ["    default: loads_0(v, a, b, lc, ld); break;", "    }", "}", ""]
    tail += _flow_speed_c(sp)
    return "\n".join(head + body + tail)


def n_states(structures) -> int:
    """States of the FMU's structures (all the same)."""
    return len(Structure.parse(structures[0]).states)


__all__ = ["equations_c", "traced", "supported", "n_states", "TRIM_PARAMETERS"]
