"""Generate ``modelDescription.xml`` and the C variable table from :mod:`.variables`.

Pure text generators (deterministic: the GUID is a hash of the description), so a
test can regenerate the committed files in ``fmu/`` and fail on any difference.
"""
from __future__ import annotations

import hashlib
import math
import re
import uuid
from pathlib import Path
from xml.sax.saxutils import quoteattr

from . import codegen, pyc
from ..errors import InputError
from ..simulate import mutable
from ..channels import BY_NAME, LIMIT
from .variables import (DEFAULT, DT, MODEL_IDENTIFIER, MODEL_NAME, Description, Variable,
                        checks_c)

#: Bump when the C model's equations change in a way importers must notice.
MODEL_VERSION = "2"
GENERATED = ("modelDescription.xml", "modelDescription-fmi3.xml", "inflow_vars.h",
             "inflow_vars.c", "inflow_equations.c", "inflow_algorithms.c", "inflow_names.h")
#: FMI 3.0 only: the independent variable, after every variable of :data:`VARIABLES`
#: (FMI 3.0 value references are unique across types, and these already are).
TIME_VR = len(DEFAULT.variables)


def time_vr(d: Description = DEFAULT) -> int:
    return len(d.variables)


def _num(x) -> str:
    return repr(float(x))


#: The C sources compiled for each FMI version (the generated variable table included):
#: ``inflowsim fmu build`` compiles them, FMI 2.0's ``<SourceFiles>`` and the build
#: description list them, so an importer can build the binary itself.
SOURCES = {2: ("inflow_numerics.c", "inflow_model.c", "inflow_slave.c", "inflow_fmi2.c",
               "inflow_vars.c",
               "inflow_equations.c", "inflow_algorithms.c"),
           3: ("inflow_numerics.c", "inflow_model.c", "inflow_slave.c", "inflow_fmi3.c",
               "inflow_vars.c",
               "inflow_equations.c", "inflow_algorithms.c")}


def source_dir() -> Path:
    """The folder holding the C sources: ``inflowsim/fmu/csrc``, a link to the
    repository's ``fmu/`` that setuptools follows, so an installed package ships
    the sources as package data."""
    here = Path(__file__).resolve().parent
    for cand in (here / "csrc", here.parents[1] / "fmu"):
        if (cand / "inflow_model.c").is_file():
            return cand
    raise InputError(f"FMU build: the C sources are missing from {here / 'csrc'}")


def guid(d: Description = DEFAULT) -> str:
    """A GUID that changes whenever a variable, a structure or the model version
    changes."""
    text = (MODEL_VERSION + "\n" + "\n".join(d.structures) + "\n"
            + "\n".join(repr(v) for v in d.variables))
    if d.schedule is not None:            # another schedule is another model
        text += "\n" + "\n".join(schedule_c(d))
    h = hashlib.sha256(text.encode()).digest()
    return "{" + str(uuid.UUID(bytes=h[:16], version=5)) + "}"


#: SI base-unit exponents of every unit the variables use (FMI ``BaseUnit``), and the
#: display unit an importer may show instead: degrees for angles.  ``"1"``: a
#: dimensionless quantity (every exponent 0: advance ratios, inflow ratios, load
#: coefficients, and the time constants in azimuth units, ``psi = Omega t``).
BASE_UNITS = {"rad": {"rad": 1}, "rad/s": {"s": -1, "rad": 1},
              "rad/s2": {"s": -2, "rad": 1}, "s": {"s": 1}, "1/rad": {"rad": -1},
              "1": {}}
_DEG = 180.0 / math.pi
DISPLAY_UNITS = {"rad": ("deg", _DEG), "rad/s": ("deg/s", _DEG),
                 "rad/s2": ("deg/s2", _DEG), "1/rad": ("1/deg", 1.0 / _DEG)}


def xml_unit(unit: str) -> str:
    """The unit a variable declares in modelDescription.xml: its own, ``"1"`` for a
    dimensionless one (``"-"`` in :mod:`.variables`), ``""`` for none (integers).

    Parameters
    ----------
    unit : str
        A :class:`~.variables.Variable`'s unit.
    """
    return "1" if unit == "-" else unit


def _unit_xml(u: str) -> list:
    base = " ".join(f'{k}="{e}"' for k, e in BASE_UNITS[u].items())
    lines = [f'    <Unit name="{u}">', f"      <BaseUnit {base}/>" if base
             else "      <BaseUnit/>"]
    if u in DISPLAY_UNITS:
        name, factor = DISPLAY_UNITS[u]
        lines.append(f'      <DisplayUnit name="{name}" factor="{_num(factor)}"/>')
    return lines + ["    </Unit>"]


def _units_categories_experiment(units) -> list:
    """The lines both FMI versions share between the interface type and the variables."""
    return (["  <UnitDefinitions>"] + [ln for u in units for ln in _unit_xml(u)] +
            ["  </UnitDefinitions>",
             "  <LogCategories>",
             '    <Category name="logStatusError" description="errors: refused values, '
             'invalid parameters, wrong calls"/>',
             '    <Category name="logStatusWarning" description="warnings"/>',
             '    <Category name="logAll" description="informational messages"/>',
             "  </LogCategories>",
             f'  <DefaultExperiment startTime="0.0" stopTime="26.6" '
             f'stepSize="{_num(DT)}"/>'])


def _common_attributes(vr: int, v: Variable) -> list:
    """name ... initial: the same attributes in FMI 2.0 and 3.0."""
    attrs = [f"name={quoteattr(v.name)}", f'valueReference="{vr}"',
             f"description={quoteattr(v.description)}", f'causality="{v.causality}"',
             f'variability="{v.variability}"']
    if v.initial:
        attrs.append(f'initial="{v.initial}"')
    return attrs


def _value_attributes(v: Variable) -> list:
    """start, unit, min, max: on the type element in FMI 2.0, the variable in 3.0."""
    out = []
    integer = v.type == "Integer"
    if v.start is not None and v.initial != "calculated":   # a calculated value has none
        out.append(f'start="{int(v.start)}"' if integer else f'start="{_num(v.start)}"')
    if not integer and v.unit:
        out.append(f'unit="{xml_unit(v.unit)}"')
        if v.unit in DISPLAY_UNITS:
            out.append(f'displayUnit="{DISPLAY_UNITS[v.unit][0]}"')
    fmt = (lambda x: str(int(x))) if integer else _num
    if math.isfinite(v.lower):
        # an open bound (0, x] is declared as the least double above it: exactly the
        # values the C code accepts
        low = math.nextafter(v.lower, math.inf) if v.lower_open else v.lower
        out.append(f'min="{fmt(low)}"')
    if math.isfinite(v.upper):
        out.append(f'max="{fmt(v.upper)}"')
    return out


def _xml_variable(vr: int, v: Variable) -> str:
    return (f"    <ScalarVariable {' '.join(_common_attributes(vr, v))}>\n"
            f"      <{v.type} {' '.join(_value_attributes(v))}/>\n    </ScalarVariable>")


def _input_positions(d: Description):
    return [i for i, v in enumerate(d.variables) if v.causality == "input"]


def _unknown2(d: Description, i: int, v) -> str:
    """FMI 2.0 ``<Unknown>``: flap and inflow read the state only (no inputs); the
    loads depend on the inputs held now (Eq. (4)'s pitch and hub-motion terms)."""
    deps = " ".join(str(k + 1) for k in _input_positions(d)) if v.feedthrough else ""
    return f'      <Unknown index="{i + 1}" dependencies="{deps}"/>'


def _deps3(d: Description, v) -> str:
    deps = " ".join(str(k) for k in _input_positions(d)) if v.feedthrough else ""
    return f' dependencies="{deps}"'


def model_description(d: Description = DEFAULT) -> str:
    """The text of ``modelDescription.xml`` (FMI 2.0 co-simulation)."""
    units = sorted({xml_unit(v.unit) for v in d.reals if v.unit})
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           '<!-- Generated by inflowsim.fmu.generate from inflowsim/fmu/variables.py: '
           'do not edit. -->',
           f'<fmiModelDescription fmiVersion="2.0" modelName={quoteattr(MODEL_NAME)} '
           f'guid="{guid(d)}"',
           '  description="Rotor flap and Glauert-augmented dynamic inflow after ERF 1989 '
           '(inflowsim). Inputs and outputs are perturbations about trim in SI units, '
           'as the inflowsim Simulator; mu is the total trim advance ratio."',
           '  generationTool="inflowsim" variableNamingConvention="flat" '
           'numberOfEventIndicators="0">',
           f'  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" '
           'canHandleVariableCommunicationStepSize="true" canGetAndSetFMUstate="true" '
           'canSerializeFMUstate="true" canInterpolateInputs="false" '
           'maxOutputDerivativeOrder="0" canRunAsynchronuously="false" '
           'providesDirectionalDerivative="true">',
           "    <SourceFiles>",
           *[f'      <File name="{f}"/>' for f in SOURCES[2]],
           "    </SourceFiles>",
           "  </CoSimulation>",
           *_units_categories_experiment(units),
           "  <ModelVariables>"]
    for vr, v in enumerate(d.variables):
        out.append(f"    <!-- index {vr + 1} -->")
        out.append(_xml_variable(vr, v))
    out += ["  </ModelVariables>", "  <ModelStructure>", "    <Outputs>"]
    # outputs read the state only: no direct feedthrough of any input
    out += [_unknown2(d, i, v) for i, v in enumerate(d.variables) if v.causality == "output"]
    out += ["    </Outputs>", "    <InitialUnknowns>"]
    out += [_unknown2(d, i, v) for i, v in enumerate(d.variables) if v.causality == "output"]
    out += ["    </InitialUnknowns>", "  </ModelStructure>", "</fmiModelDescription>", ""]
    return "\n".join(out)


def _xml_variable_fmi3(vr: int, v: Variable) -> str:
    kind = "Float64" if v.type == "Real" else "Int32"
    return f"    <{kind} {' '.join(_common_attributes(vr, v) + _value_attributes(v))}/>"


def model_description_fmi3(d: Description = DEFAULT) -> str:
    """The text of the FMI 3.0 ``modelDescription.xml`` (co-simulation): the same
    variables and value references as FMI 2.0, plus the independent ``time``."""
    units = sorted({xml_unit(v.unit) for v in d.reals if v.unit} | {"s"})
    out = ['<?xml version="1.0" encoding="UTF-8"?>',
           '<!-- Generated by inflowsim.fmu.generate from inflowsim/fmu/variables.py: '
           'do not edit. -->',
           f'<fmiModelDescription fmiVersion="3.0" modelName={quoteattr(MODEL_NAME)} '
           f'instantiationToken="{guid(d)}"',
           '  description="Rotor flap and Glauert-augmented dynamic inflow after ERF 1989 '
           '(inflowsim). Inputs and outputs are perturbations about trim in SI units, '
           'as the inflowsim Simulator; mu is the total trim advance ratio."',
           '  generationTool="inflowsim" variableNamingConvention="flat">',
           f'  <CoSimulation modelIdentifier="{MODEL_IDENTIFIER}" '
           'canHandleVariableCommunicationStepSize="true" canGetAndSetFMUState="true" '
           'canSerializeFMUState="true" hasEventMode="false" '
           'providesIntermediateUpdate="false" canReturnEarlyAfterIntermediateUpdate="false" '
           'maxOutputDerivativeOrder="0" providesDirectionalDerivatives="true"/>',
           *_units_categories_experiment(units),
           "  <ModelVariables>",
            f'    <Float64 name="time" valueReference="{time_vr(d)}" causality="independent" '
            'variability="continuous" unit="s" description="simulation time"/>']
    out += [_xml_variable_fmi3(vr, v) for vr, v in enumerate(d.variables)]
    out += ["  </ModelVariables>", "  <ModelStructure>"]
    outs = [(vr, v) for vr, v in enumerate(d.variables) if v.causality == "output"]
    out += [f'    <Output valueReference="{vr}"{_deps3(d, v)}/>' for vr, v in outs]
    out += [f'    <InitialUnknown valueReference="{vr}"{_deps3(d, v)}/>' for vr, v in outs]
    out += ["  </ModelStructure>", "</fmiModelDescription>", ""]
    return "\n".join(out)


def _c_num(x: float) -> str:
    if math.isinf(x):
        return "DBL_MAX" if x > 0 else "-DBL_MAX"     # constant for every compiler
    return repr(float(x))


_KIND = {("input", "continuous"): "IFS_INPUT", ("output", "continuous"): "IFS_OUTPUT",
         ("parameter", "tunable"): "IFS_TUNABLE", ("parameter", "fixed"): "IFS_FIXED",
         ("local", "continuous"): "IFS_LOCAL"}
_HEAD = "/* Generated by inflowsim.fmu.generate from inflowsim/fmu/variables.py: do not edit. */"


def vars_header(d: Description = DEFAULT) -> str:
    """``inflow_vars.h``: the struct of all variable values and the table's type."""
    n_in = sum(1 for v in d.reals if v.causality == "input" and v.name != "mu")
    lines = [_HEAD, "#ifndef INFLOW_VARS_H", "#define INFLOW_VARS_H", "",
             "#include <stddef.h>", "",
             '#include "inflow_names.h"  /* prefixed internal names for static linking */',
             "",
             f'#define IFS_GUID "{guid(d)}"',
             f'#define IFS_MODEL_IDENTIFIER "{MODEL_IDENTIFIER}"',
             f"#define IFS_N_REALS {len(d.reals)}",
             f"#define IFS_N_INTEGERS {len(d.integers)}",
             f"#define IFS_NX {codegen.n_states(d.structures)}  /* states */",
             f"#define IFS_N_STRUCTURES {len(d.structures)}",
             '#define IFS_STRUCTURE_NAMES "'
             + ", ".join(f"{i} {n}" for i, n in enumerate(d.structures)) + '"',
             f"#define IFS_N_INPUTS {n_in}  /* the perturbation inputs, theta0 .. muy */",
             f"#define IFS_INPUT_LIMIT {_c_num(LIMIT)}  /* |input| beyond it is refused */",
             "#define IFS_INPUT_OMEGA_POWERS {"
             + ", ".join(str(BY_NAME[v.name].omega_power) for v in d.reals
                         if v.causality == "input" and v.name != "mu")
             + "}  /* the inputs in azimuth units: u / Omega^k (inflowsim.channels) */",
             "", *mutable.c_defines(), *checks_c(), *outputs_defines(),
             *schedule_defines(d), "",
             "/* value references */", "enum {"]
    lines += [f"    IFS_VR_{v.name} = {vr}," for vr, v in enumerate(d.variables)]
    lines += [f"    IFS_VR_time = {time_vr(d)},  /* FMI 3.0 only: the independent variable */",
              "    IFS_VR_END", "};", "",
              "/* Every variable's value, by name (inputs contiguous from theta0). */",
              "typedef struct {"]
    for v in d.variables:
        ctype = "double" if v.type == "Real" else "int"
        lines.append(f"    {ctype} {v.name};  /* {v.causality} [{v.unit or '-'}] */")
    lines += ["} IfsVariables;", "",
              "/* IFS_LOCAL: a scheduled parameter, computed from mu (read-only) */",
              "typedef enum { IFS_INPUT, IFS_OUTPUT, IFS_TUNABLE, IFS_FIXED, IFS_LOCAL } "
              "IfsKind;", "",
              "typedef struct {",
              "    const char *name;",
              "    IfsKind kind;",
              "    size_t offset;      /* offsetof(IfsVariables, name) */",
              "    double start, lower, upper;",
              "    int lower_open;     /* lower bound excluded */",
              "} IfsRealVar;", "",
              "typedef struct {",
              "    unsigned int vr;",
              "    const char *name;",
              "    IfsKind kind;",
              "    size_t offset;",
              "    int start, lower, upper;",
              "} IfsIntegerVar;", "",
              "/* Real variables indexed by value reference. */",
              "extern const IfsRealVar ifs_real_vars[IFS_N_REALS];",
              "extern const IfsIntegerVar ifs_integer_vars[IFS_N_INTEGERS];", "",
              "#endif", ""]
    return "\n".join(lines)


def vars_source(d: Description = DEFAULT) -> str:
    """``inflow_vars.c``: the variable table (names, offsets, starts, ranges)."""
    lines = [_HEAD, '#include <float.h>', '#include "inflow_vars.h"', "",
             "const IfsRealVar ifs_real_vars[IFS_N_REALS] = {"]
    for v in d.reals:
        lines.append(f'    {{"{v.name}", {_KIND[(v.causality, v.variability)]}, '
                     f"offsetof(IfsVariables, {v.name}), "
                     f"{_c_num(v.start) if v.start is not None else '0.0'}, "
                     f"{_c_num(v.lower)}, {_c_num(v.upper)}, {int(v.lower_open)}}},")
    lines += ["};", "", "const IfsIntegerVar ifs_integer_vars[IFS_N_INTEGERS] = {"]
    for v in d.integers:
        lines.append(f'    {{IFS_VR_{v.name}, "{v.name}", '
                     f"{_KIND[(v.causality, v.variability)]}, "
                     f"offsetof(IfsVariables, {v.name}), {int(v.start)}, {int(v.lower)}, "
                     f"{int(v.upper)}}},")
    lines += ["};", ""]
    return "\n".join(lines)


def schedule_defines(d: Description = DEFAULT) -> list:
    """``inflow_vars.h``'s lines for the parameter schedule: how many parameters
    follow ``mu``, the table's knots (:meth:`inflowsim.model.schedule.Schedule.
    knots`, :func:`inflowsim.simulate.mutable.edges`), whether the azimuth bias
    (the outputs' rotation) follows ``mu``."""
    sch = d.schedule
    n = len(d.scheduled)
    knots = (mutable.knot_edges(sch.knots(mutable.MU_LO, mutable.MU_HI))
             if sch is not None else ())
    lines = [f"#define IFS_N_SCHEDULED {n}  /* parameters that follow mu (a schedule) */",
             f"#define IFS_MU_N_KNOTS {len(knots)}  /* the schedule's range ends: extra "
             "segment ends of the mu table */",
             "#define IFS_MU_NSEG (IFS_MU_SEG + IFS_MU_N_KNOTS)  /* segments */"]
    if knots:
        lines.append("#define IFS_MU_KNOTS {" + ", ".join(_num(k) for k in knots) + "}")
    # the outputs' rotation follows mu where a scheduled parameter enters it
    follows = bool(d.scheduled) and bool(codegen.bias_parameters(d.structures)
                                         & set(d.scheduled))
    lines.append(f"#define IFS_SCHEDULED_BIAS {int(follows)}")
    return lines


def schedule_c(d: Description = DEFAULT) -> list:
    """``ifs_schedule_apply`` (appended to ``inflow_equations.c`` of a scheduled
    FMU; none without a schedule): every scheduled parameter at ``v->mu`` held to
    the schedule's range, by Horner's rule in ``x = (v - center)/scale`` (``v`` is
    ``mu`` or ``1.0 / mu``, the parameter's variable), the
    operations of :meth:`inflowsim.model.schedule.Schedule.__call__` in the same
    order (so, built without contraction, the same doubles); then the scheduled
    trim totals ``trim_<column>`` (those among :attr:`Description.scheduled`) in
    ``x = (mu - center)/scale``, the operations of
    :meth:`~inflowsim.model.schedule.Schedule.trim_values`."""
    sch = d.schedule
    if sch is None or not d.scheduled:
        return []
    # (C name, coefficients, variable, center, scale) of every value computed
    polys = [(p.name, p.coefficients, p.variable, p.center, p.scale)
             for p in sch.parameters]
    polys += [(f"trim_{t.column}", t.coefficients, "mu", t.center, t.scale)
              for t in sch.trim if f"trim_{t.column}" in d.scheduled]
    lo, hi = (_num(v) for v in sch.mu_range)
    out = ["", "/* The parameter schedule (inflowsim.model.schedule, from the schedule file "
           "of", " * inflowsim fmu build --schedule): each parameter a polynomial in "
           "x = (mu - center) / scale", " * or in x = (1/mu - center) / scale, mu held "
           f"to the schedule's range [{lo}, {hi}]. */",
           f"void {SCHEDULE_APPLY}(IfsVariables *v)", "{"]
    if any(len(c) > 1 for _, c, _, _, _ in polys):
        out += [f"    const double mu = v->mu < {lo} ? {lo} : v->mu > {hi} ? {hi} : v->mu;",
                "    double x;"]
    last = None
    for name, coefficients, variable, center, scale in polys:
        c = [_num(v) for v in coefficients]
        expr = c[-1]
        for ck in c[-2::-1]:
            expr = f"({expr}) * x + {ck}" if "x" in expr else f"{expr} * x + {ck}"
        if len(c) > 1 and (variable, center, scale) != last:   # same x: not again
            v = "mu" if variable == "mu" else "1.0 / mu"
            out.append(f"    x = ({v} - {_num(center)}) / {_num(scale)};")
            last = (variable, center, scale)
        out.append(f"    v->{name} = {expr};")
    if all(len(c) == 1 for _, c, _, _, _ in polys):
        out.append("    (void)v->mu;")
    return out + ["}"]


#: The parameter schedule's function (:func:`schedule_c`): a global name of a
#: scheduled FMU only.
SCHEDULE_APPLY = "ifs_schedule_apply"
#: An external definition in a C source: a line that starts with a type (not
#: ``static``, ``typedef`` or ``extern``) and names an ``ifs_`` function or array.
_DEFINITION = re.compile(r"^(?!static\b|typedef\b|extern\b)[A-Za-z_][^;(=\n]*?"
                         r"\b(ifs_\w+)\s*[\[(]", re.M)


def outputs_defines() -> list:
    """``inflow_vars.h``'s output map, generated from the Python model's
    (:func:`inflowsim.model.build.output_map` run on a symbolic azimuth bias):
    ``IFS_OUTPUT_MAP(y, X, c, s)`` writes the outputs ``y`` (``beta0`` ..
    ``lambda1s``), row ``i`` from the states ``X(i)`` (the delayed flap's own), ``c``,
    ``s`` the bias' cosine and sine; ``IFS_STORE_OUTPUTS(v, y)`` puts them in the
    variables; ``IFS_N_FLAP`` the flap rows (each with its own delay)."""
    import sympy as sp
    from ..channels import FLAP, OUTPUTS
    from ..model.build import output_map
    from ..model.equations import Measurement
    bias = sp.Symbol("bias")
    c = output_map(len(OUTPUTS), Measurement(azimuth_bias=bias))
    factor = {sp.cos(bias): "(c) * ", sp.sin(bias): "(s) * "}
    rows = []
    for i in range(len(OUTPUTS)):
        terms = ""
        for j in range(c.shape[1]):
            x = sp.sympify(c[i, j])
            if x.is_zero:
                continue
            sign = " - " if x.could_extract_minus_sign() else " + "
            x = -x if sign == " - " else x
            x = sp.Integer(1) if x.is_number and float(x) == 1.0 else x
            if x != 1 and x not in factor:
                raise ValueError(f"output_map[{i}, {j}] = {x}: not a term the C prints")
            term = f"{'' if x == 1 else factor[x]}X({i})[{j}]"
            terms += (("-" if sign == " - " else "") + term) if not terms else sign + term
        rows.append(f"    (y)[{i}] = {terms};")
    store = [f"    (v)->{name} = (y)[{i}];" for i, name in enumerate(OUTPUTS)]
    def macro(head, body):
        return [head + " \\", "    do { \\", *["    " + ln + " \\" for ln in body],
                "    } while (0)"]
    return (["/* the outputs (inflowsim.model.build.output_map): row i from the states X(i), "
             "c, s the", " * azimuth bias' cosine and sine; stored in the variables */",
             f"#define IFS_N_FLAP {len(FLAP)}"]
            + macro("#define IFS_OUTPUT_MAP(y, X, c, s)", rows)
            + macro("#define IFS_STORE_OUTPUTS(v, y)", store))


def names_header(texts) -> str:
    """``inflow_names.h``: the FMU's global names (every ``ifs_`` function or array
    defined without ``static`` in the C sources ``texts``, hand-written and generated,
    and :data:`SCHEDULE_APPLY`), prefixed like the FMI functions under a prefix."""
    names = sorted({m.group(1) for t in texts for m in _DEFINITION.finditer(t)}
                   | {SCHEDULE_APPLY})
    return "\n".join([
        "/* Generated by inflowsim.fmu.generate from the FMU's C sources: do not edit. */",
        "/*",
        " * The FMU's internal global names, prefixed like the FMI functions when the FMU is",
        " * compiled for static linking (FMI2_FUNCTION_PREFIX or FMI3_FUNCTION_PREFIX defined,",
        " * e.g. to the model identifier): two FMUs made by inflowsim (a main and a tail rotor)",
        " * can then be linked into one program.  Without a prefix the names stay as they are",
        " * (a shared library hides them: -fvisibility=hidden).  Every other function is",
        " * static; tests/test_fmu.py checks that a prefixed build defines no other global name.",
        " */",
        "#ifndef INFLOW_NAMES_H", "#define INFLOW_NAMES_H", "",
        "#if defined(FMI2_FUNCTION_PREFIX) || defined(FMI3_FUNCTION_PREFIX)",
        "#define IFS_PASTE_(a, b) a##b", "#define IFS_PASTE(a, b) IFS_PASTE_(a, b)",
        "#if defined(FMI2_FUNCTION_PREFIX)",
        "#define IFS_NAME(n) IFS_PASTE(FMI2_FUNCTION_PREFIX, n)", "#else",
        "#define IFS_NAME(n) IFS_PASTE(FMI3_FUNCTION_PREFIX, n)", "#endif",
        *[f"#define {n} IFS_NAME({n})" for n in names],
        "#endif", "", "#endif", ""])


def generated_files(d: Description = DEFAULT) -> dict:
    """``{file name: text}`` of every generated file of the FMU ``d`` describes."""
    files = {"modelDescription.xml": model_description(d),
             "modelDescription-fmi3.xml": model_description_fmi3(d),
             "inflow_vars.h": vars_header(d), "inflow_vars.c": vars_source(d),
             "inflow_equations.c": codegen.equations_c(d.structures)
             + "".join(line + "\n" for line in schedule_c(d)),
             "inflow_algorithms.c": pyc.algorithms_c()}
    src = source_dir()
    hand = sorted({f for v in SOURCES.values() for f in v if f not in files})
    files["inflow_names.h"] = names_header(
        [(src / f).read_text(encoding="utf-8") for f in hand]
        + [t for f, t in files.items() if f.endswith(".c")])
    return files


def write_generated(directory) -> list:
    """Regenerate the files in ``directory`` (the repository's ``fmu/``)."""
    d = Path(directory)
    paths = []
    for name, text in generated_files().items():
        p = d / name
        p.write_text(text, encoding="utf-8")
        paths.append(p)
    return paths


__all__ = ["MODEL_VERSION", "GENERATED", "TIME_VR", "time_vr", "SOURCES", "guid",
           "BASE_UNITS", "DISPLAY_UNITS", "xml_unit", "model_description",
           "model_description_fmi3", "vars_header", "vars_source", "schedule_defines",
           "schedule_c", "SCHEDULE_APPLY", "outputs_defines", "names_header", "source_dir",
           "generated_files", "write_generated"]
