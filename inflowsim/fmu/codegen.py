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
linearised about a trim state (``advance-ratio-perturbation``) take the trim totals
as parameters ``trim_theta0`` ... ``trim_muz``; their trim inflow is solved in the
generated C (the 3 x 3 solve of :func:`inflowsim.physics.bladeelement.trim_inflow`,
done symbolically).
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

#: Effects whose equations are linearised about a trim state: the FMU gets the trim
#: totals as parameters ``trim_<column>`` (:data:`TRIM_PARAMETERS`).
TRIM_EFFECTS = ("advance-ratio-perturbation",)
#: Effects whose terms are computed numerically at build time (no expression in the
#: parameters to generate), with why the FMU does not run them.
NUMERIC_EFFECTS = {"momentum-speed": "its coupling is a disc quadrature at the trim "
                   "inflow of Eq. (14), solved numerically in Python (use the Python "
                   "Simulator, or glauert, in an FMU)"}
#: ``{FMU parameter: record column}`` of the trim totals.
TRIM_PARAMETERS = {f"trim_{c}": c for c in TRIM_KEYS}


def needs_trim(structures) -> bool:
    """Some structure has an effect linearised about the trim state."""
    return any(e in TRIM_EFFECTS for st in structures for e in Structure.parse(st).effects)


def _sympy():
    try:
        import sympy
    except ImportError:                      # declared in pyproject; a broken install
        raise InputError("FMU code generation needs sympy (pip install sympy)") from None
    return sympy


def _symbols(structure: Structure):
    sp = _sympy()

    p = {n: sp.Symbol(n) for n in structure.parameters}
    trim = {c: sp.Symbol(n) for n, c in TRIM_PARAMETERS.items()}
    k = SimpleNamespace(mu=sp.Symbol("mu"), a0s=sp.Symbol("a0") * sp.Symbol("solidity"),
                        omega=sp.Symbol("omega"), flow_speed=sp.Symbol("V"), trim=trim)
    return p, k


def supported(structure) -> Structure:
    """``structure`` parsed, or :class:`InputError` naming what the FMU cannot run."""
    s = Structure.parse(structure)
    for name in s.effects:
        if name in NUMERIC_EFFECTS:
            raise InputError(f"the FMU does not run effect {name}: {NUMERIC_EFFECTS[name]}")
        if name.startswith("delay-") and name[len("delay-"):] not in FLAP:
            raise InputError(f"the FMU does not run effect {name}: a time shift of an "
                             "input cannot be applied by a causal step (inflowsim.simulate.replay "
                             "applies it to a whole record)")
    from ..model.effects import USER_EFFECTS
    if any(name in USER_EFFECTS for name in s.effects):
        # a user effect may add an output map (Measurement.flap_map): not in the C
        if apply_effects(s, *_symbols(s))[1].flap_map is not None:
            raise InputError(f"the FMU does not run {s.name}: an effect of it adds terms "
                             "to the recorded flap (Measurement.flap_map), which the "
                             "FMU's output map does not hold")
    return s


def traced(structure):
    """``(structure, E, A, B, measurement)`` with sympy entries: the Python model run
    on symbols (azimuth time, all ten inputs, as :func:`assemble` returns)."""
    s = supported(structure)
    p, k = _symbols(s)
    eq, meas = apply_effects(s, p, k)
    e, a, b = assemble(eq, s.second_order)
    return s, e, a, b, meas


def _c_name(sym) -> str:
    name = str(sym)
    if name == "V" or name.startswith(("a[", "b[")):
        return name          # the generated function's own arguments
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


def _descriptor_c(s: Structure, e, a, b, index: int, sp) -> list:
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
    uses_v = any(str(x) == "V" for x in free)
    if not uses_v:
        lines.append("    (void)V;")
    for t, x in subs:
        lines.append(f"    const double {t} = {sp.ccode(x.xreplace(rename))};")
    lines += ["    memset(e, 0, sizeof(double) * IFS_NX * IFS_NX);",
              "    memset(a, 0, sizeof(double) * IFS_NX * IFS_NX);",
              "    memset(b, 0, sizeof(double) * IFS_NX * IFS_NU);"]
    for (target, _), x in zip(targets, reduced):
        lines.append(f"    {target} = {sp.ccode(x.xreplace(rename))};")
    return lines + ["}", ""]


def _assignments(sp, targets, indent="    ") -> list:
    """C lines computing ``targets`` (``[(lvalue, sympy expression)]``) after common-
    subexpression elimination."""
    subs, reduced = sp.cse([x for _, x in targets], symbols=sp.numbered_symbols("t"),
                           optimizations="basic")
    free = set().union(*(x.free_symbols for _, x in targets)) if targets else set()
    rename = {sym: sp.Symbol(_c_name(sym)) for sym in free}
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
    return ([f"static void loads_{index}(const IfsVariables *v, const double *a, "
             "const double *b, double *lc, double *ld)", "{",
             "    memset(lc, 0, sizeof(double) * IFS_NL * IFS_NX);",
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


def equations_c(structures) -> str:
    """The text of ``inflow_equations.c`` for the FMU's ``structures`` (in the order
    of its integer ``structure``): descriptor, azimuth bias and flap time shifts of
    each, and the dispatch on ``v->structure``."""
    sp = _sympy()
    body = []
    states = set()
    for i, st in enumerate(structures):
        s, e, a, b, meas = traced(st)
        states.add(e.shape[0])
        body += (_descriptor_c(s, e, a, b, i, sp) + _measurement_c(meas, i, sp)
                 + _loads_c(s, meas, i, sp))
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
            "#include <math.h>", "#include <string.h>", "", '#include "inflow_model.h"',
            ""]
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


__all__ = ["equations_c", "traced", "supported", "n_states", "needs_trim", "TRIM_EFFECTS",
           "TRIM_PARAMETERS"]
