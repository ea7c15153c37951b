"""Translate the stepping algorithms of :mod:`inflowsim.simulate.algorithms` into C:
``fmu/inflow_algorithms.c``, one source with the Simulator.

A walk over each function's Python syntax tree (:mod:`ast`) that knows the subset
the algorithms are written in and refuses anything else with the line it cannot
translate: arguments annotated ``int``, ``float``, ``Vec`` (``double *``) or
``CVec`` (``const double *``); locals declared by an annotated assignment
(``s: int = 0``) or as ``P.new(size)`` (a zeroed local array; ``P.empty``: not
zeroed, every entry read written first; its size a C constant
expression after the size arguments are replaced); ``for ... in range(a[, b[,
+-1]])``, ``while``, ``if``/``elif``/``else``, ``return``, ``break``,
``continue``; ``+ - * / // %``, comparisons (one operator each), ``and``, ``or``,
``not``, ``x if c else y``; calls of :mod:`math`'s functions, ``int()``,
``float()``, the primitives ``P.<name>`` (C ``ifs_<name>``) and the other
algorithms; a vector's tail ``a[k:]`` (``a + k``) as an argument.  ``/`` of two
integers is Python's true division, written with a cast; ``//`` and ``%`` are
meant for non-negative integers (C truncates, Python floors).  A size argument
(:func:`~inflowsim.simulate.algorithms.algorithm`'s ``sizes``) becomes its C
constant with its annotated type (``IFS_MU_LO`` a double); a
:class:`~inflowsim.simulate.algorithms.Variant` writes the function again under
another name, guard and target, with other primitives (the ``mu`` table's
evaluation with the CPU's fused multiply-adds).
"""
from __future__ import annotations

import ast
import inspect
import re
import math
import textwrap

from ..errors import InputError
from ..simulate import algorithms as alg

#: :mod:`math` functions and constants, and Python built-ins, in C
_MATH = {"cos": "cos", "sin": "sin", "fabs": "fabs", "pow": "pow", "ldexp": "ldexp",
         "isfinite": "isfinite", "floor": "floor", "sqrt": "sqrt", "fma": "fma",
         "exp": "exp", "log": "log"}
_MATH_INT = {"isfinite"}                  # functions whose C result is an int
_MATH_CONST = {"pi": "M_PI", "inf": "INFINITY"}
_BINOP = {ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/", ast.FloorDiv: "/",
          ast.Mod: "%"}
_CMP = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==",
        ast.NotEq: "!="}
_TYPES = {"int": "int", "float": "double", "Vec": "double *", "CVec": "const double *",
          "Entries": "IfsMuEntries", "Ctx": "void *"}
#: the primitives' C result types (``void`` where none)
_PRIMITIVES = {"copy": "void", "scale": "void", "axpy": "void", "matmul": "void",
               "norm1": "double", "lu_solve": "int", "gemm": "void",
               "horner": "void", "fhorner": "void", "gemv_cols": "void", "absmax": "double",
               "absdiffmax": "double", "taylor_first": "void", "taylor_term": "void"}


class _Function:
    """The C text of one registered function."""

    def __init__(self, f, c_name: str, static: bool, sizes: dict, others: dict,
                 variant=None):
        self.f, self.c_name, self.static, self.sizes = f, c_name, static, sizes
        self.others = others                     # {python name: (C name, C type)}
        self.variant = variant                   # an alg.Variant, or None
        self.size_types = {}                     # {size argument: its C type}
        src = textwrap.dedent(inspect.getsource(f))
        self.tree = ast.parse(src).body[0]
        self.line0 = inspect.getsourcelines(f)[1] - 1
        self.types = {}                           # {local: C type}
        self.out = []

    def fail(self, node, what: str):
        raise InputError(f"{self.f.__module__}:{self.line0 + getattr(node, 'lineno', 1)}: "
                         f"{what} is outside the subset inflowsim.fmu.pyc translates")

    # -- expressions ---------------------------------------------------------
    def expr(self, e) -> tuple:
        """``(C text, C type)`` of expression ``e``."""
        text, typ, _ = self.prec(e)
        return text, typ

    def sub(self, e, least: int) -> tuple:
        """``e``'s text, in parentheses if its operator binds less than ``least``
        (C's precedence: the grouping of Python's tree is kept, so the same
        operations in the same order)."""
        text, typ, p = self.prec(e)
        return (text if p >= least else f"({text})"), typ

    def prec(self, e) -> tuple:
        """``(C text, C type, C precedence)`` of expression ``e``."""
        if isinstance(e, ast.Constant):
            if isinstance(e.value, bool) or not isinstance(e.value, (int, float)):
                self.fail(e, f"the constant {e.value!r}")
            return (repr(e.value), "int", 16) if isinstance(e.value, int) else \
                (_c_float(e.value), "double", 16)
        if isinstance(e, ast.Name):
            if e.id in self.sizes:
                c = self.sizes[e.id]
                return ((c if c.isidentifier() or c.isdigit() else f"({c})"),
                        self.size_types.get(e.id, "int"), 16)
            if e.id in self.types:
                return e.id, self.types[e.id], 16
            return (*self.constant(e), 16)
        if isinstance(e, ast.Attribute):
            if isinstance(e.value, ast.Name) and e.value.id == "math" and e.attr in _MATH_CONST:
                return _MATH_CONST[e.attr], "double", 16
            self.fail(e, f"the attribute {ast.unparse(e)}")
        if isinstance(e, ast.UnaryOp):
            text, typ = self.sub(e.operand, 14)
            if isinstance(e.op, ast.USub):
                return f"-{text}", typ, 14
            if isinstance(e.op, ast.Not):
                return f"!{text}", "int", 14
            self.fail(e, "this unary operator")
        if isinstance(e, ast.BinOp):
            op = _BINOP.get(type(e.op))
            if op is None:
                self.fail(e, f"the operator in {ast.unparse(e)}")
            p = 12 if op in "+-" else 13
            (lt, ltyp), (rt, rtyp) = self.sub(e.left, p), self.sub(e.right, p + 1)
            both_int = ltyp == rtyp == "int"
            if isinstance(e.op, ast.Div) and both_int:
                return f"(double){self.sub(e.left, 16)[0]} / {rt}", "double", 13
            if isinstance(e.op, (ast.FloorDiv, ast.Mod)) and not both_int:
                self.fail(e, f"{ast.unparse(e)} of floats")
            return f"{lt} {op} {rt}", "int" if both_int else "double", p
        if isinstance(e, ast.Compare):
            if len(e.ops) != 1:
                self.fail(e, "a chained comparison")
            op = _CMP[type(e.ops[0])]
            p = 9 if op in ("==", "!=") else 10
            (lt, _), (rt, _) = self.sub(e.left, p), self.sub(e.comparators[0], p + 1)
            return f"{lt} {op} {rt}", "int", p
        if isinstance(e, ast.BoolOp):
            op, p = (" && ", 5) if isinstance(e.op, ast.And) else (" || ", 4)
            return op.join(self.sub(v, p + 1)[0] for v in e.values), "int", p
        if isinstance(e, ast.IfExp):
            (c, _), (a, at), (b, bt) = (self.sub(e.test, 4), self.sub(e.body, 4),
                                        self.sub(e.orelse, 3))
            return f"{c} ? {a} : {b}", "int" if at == bt == "int" else "double", 3
        if isinstance(e, ast.Subscript):
            if isinstance(e.slice, ast.Slice):
                self.fail(e, "a slice outside a call's arguments")
            base, btyp = self.sub(e.value, 16)
            index, ityp = self.expr(e.slice)
            if ityp != "int" or not btyp.endswith("*"):
                self.fail(e, f"the subscript {ast.unparse(e)}")
            return f"{base}[{index}]", "double", 16
        if isinstance(e, ast.Call):
            return (*self.call(e), 16)
        self.fail(e, f"the expression {ast.unparse(e)}")

    def constant(self, e):
        if e.id in alg.C_MACROS and self.f.__module__ == alg.__name__:
            return alg.C_MACROS[e.id], _py_type(getattr(alg, e.id))
        value = self.f.__globals__.get(e.id)         # the function's own module's
        if isinstance(value, tuple):
            return e.id, "static const double *"
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            return (repr(value), "int") if isinstance(value, int) else \
                (_c_float(value), "double")
        self.fail(e, f"the name {e.id}")

    def arg(self, e) -> str:
        if isinstance(e, ast.Subscript) and isinstance(e.slice, ast.Slice):
            s = e.slice
            if s.upper is not None or s.step is not None or s.lower is None:
                self.fail(e, "a slice other than a[k:]")
            return f"{self.sub(e.value, 12)[0]} + {self.sub(s.lower, 13)[0]}"
        return self.expr(e)[0]

    def call(self, e):
        f, args = e.func, e.args
        if e.keywords:
            self.fail(e, "keyword arguments")
        if isinstance(f, ast.Attribute) and isinstance(f.value, ast.Name):
            if f.value.id == "math" and f.attr in _MATH:
                typ = "int" if f.attr in _MATH_INT else "double"
                return f"{_MATH[f.attr]}({', '.join(self.arg(a) for a in args)})", typ
            if f.value.id == "P" and f.attr in _PRIMITIVES:
                name = self.variant.primitives.get(f.attr, f.attr) if self.variant else f.attr
                return (f"ifs_{name}({', '.join(self.arg(a) for a in args)})",
                        _PRIMITIVES[f.attr])
        if isinstance(f, ast.Name):
            if f.id in ("int", "float") and len(args) == 1:
                c = "int" if f.id == "int" else "double"
                return f"(({c})({self.expr(args[0])[0]}))", c
            if self.types.get(f.id) == "IfsMuEntries":
                return f"{f.id}({', '.join(self.arg(a) for a in args)})", "int"
            if f.id in self.others:
                c_name, typ, sizes, _ = self.others[f.id]
                params = [a.arg for a in self.others_tree(f.id).args.args]
                kept = [self.arg(a) for p, a in zip(params, args) if p not in sizes]
                return f"{c_name}({', '.join(kept)})", typ
        self.fail(e, f"the call {ast.unparse(e)}")

    def others_tree(self, name):
        return ast.parse(textwrap.dedent(inspect.getsource(self.others[name][3]))).body[0]

    # -- statements ----------------------------------------------------------
    def emit(self, depth: int, text: str):
        self.out.extend(_wrap_line("    " * depth + text))

    def block(self, body, depth: int):
        for s in body:
            self.stmt(s, depth)

    def stmt(self, s, d: int):
        if isinstance(s, ast.Expr):
            if isinstance(s.value, ast.Constant) and isinstance(s.value.value, str):
                return                                          # a docstring
            if not isinstance(s.value, ast.Call):
                self.fail(s, "an expression statement other than a call")
            self.emit(d, self.expr(s.value)[0] + ";")
        elif isinstance(s, ast.AnnAssign):
            if not isinstance(s.target, ast.Name) or s.value is None:
                self.fail(s, "this annotated assignment")
            typ = _TYPES.get(ast.unparse(s.annotation))
            if typ not in ("int", "double"):
                self.fail(s, f"the local type {ast.unparse(s.annotation)}")
            self.types[s.target.id] = typ
            self.emit(d, f"{typ} {s.target.id} = {self.expr(s.value)[0]};")
        elif isinstance(s, ast.Assign):
            if len(s.targets) != 1:
                self.fail(s, "a multiple assignment")
            t, v = s.targets[0], s.value
            if (isinstance(t, ast.Name) and isinstance(v, ast.Call)
                    and ast.unparse(v.func) in ("P.new", "P.empty") and t.id not in self.types):
                if any(isinstance(n, ast.Name) and n.id in self.types
                       for n in ast.walk(v.args[0])):
                    self.fail(s, "a local array's size that is not a C constant")
                self.types[t.id] = "double *"
                zero = " = {0.0}" if ast.unparse(v.func) == "P.new" else ""
                self.emit(d, f"double {t.id}[{self.expr(v.args[0])[0]}]{zero};")
                return
            if isinstance(t, ast.Name) and t.id not in self.types:
                self.fail(s, f"{t.id} assigned before its declaration (name: type = value)")
            self.emit(d, f"{self.expr(t)[0]} = {self.expr(v)[0]};")
        elif isinstance(s, ast.AugAssign):
            op = _BINOP.get(type(s.op))
            if op is None or isinstance(s.op, (ast.Div, ast.FloorDiv, ast.Mod)) and \
                    self.expr(s.target)[1] == "int":
                self.fail(s, "this augmented assignment")
            self.emit(d, f"{self.expr(s.target)[0]} {op}= {self.expr(s.value)[0]};")
        elif isinstance(s, ast.For):
            self.for_(s, d)
        elif isinstance(s, ast.While):
            if s.orelse:
                self.fail(s, "while ... else")
            self.emit(d, f"while {_wrap(self.expr(s.test)[0])} {{")
            self.block(s.body, d + 1)
            self.emit(d, "}")
        elif isinstance(s, ast.If):
            self.emit(d, f"if {_wrap(self.expr(s.test)[0])} {{")
            self.block(s.body, d + 1)
            orelse = s.orelse
            while len(orelse) == 1 and isinstance(orelse[0], ast.If):
                self.emit(d, f"}} else if {_wrap(self.expr(orelse[0].test)[0])} {{")
                self.block(orelse[0].body, d + 1)
                orelse = orelse[0].orelse
            if orelse:
                self.emit(d, "} else {")
                self.block(orelse, d + 1)
            self.emit(d, "}")
        elif isinstance(s, ast.Return):
            self.emit(d, "return;" if s.value is None else f"return {self.expr(s.value)[0]};")
        elif isinstance(s, ast.Break):
            self.emit(d, "break;")
        elif isinstance(s, ast.Continue):
            self.emit(d, "continue;")
        elif isinstance(s, ast.Pass):
            pass
        else:
            self.fail(s, f"the statement {ast.unparse(s).splitlines()[0]}")

    def for_(self, s, d: int):
        it = s.iter
        if (not isinstance(s.target, ast.Name) or s.orelse or not isinstance(it, ast.Call)
                or ast.unparse(it.func) != "range" or not 1 <= len(it.args) <= 3):
            self.fail(s, "a loop other than for i in range(...)")
        a = [self.expr(x)[0] for x in it.args]
        lo, hi = ("0", a[0]) if len(a) == 1 else (a[0], a[1])
        step = it.args[2] if len(a) == 3 else None
        down = False
        if step is not None:
            value = ast.literal_eval(step)     # +-1 only: a constant step
            if value not in (1, -1):
                self.fail(s, "a range step other than 1 or -1")
            down = value == -1
        v = s.target.id
        shadow = self.types.get(v)
        self.types[v] = "int"
        cmp, inc = (">", "--") if down else ("<", "++")
        self.emit(d, f"for (int {v} = {lo}; {v} {cmp} {hi}; {v}{inc}) {{")
        self.block(s.body, d + 1)
        self.emit(d, "}")
        if shadow is None:
            del self.types[v]

    # -- the function --------------------------------------------------------
    def signature(self) -> str:
        params = []
        for a in self.tree.args.args:
            if a.annotation is None:
                self.fail(a, f"the argument {a.arg} without a type")
            typ = _TYPES.get(ast.unparse(a.annotation))
            if typ is None:
                self.fail(a, f"the argument type {ast.unparse(a.annotation)}")
            if a.arg in self.sizes:
                self.size_types[a.arg] = typ
                continue
            self.types[a.arg] = typ
            params.append(f"{typ}{'' if typ.endswith('*') else ' '}{a.arg}")
        ret = self.tree.returns
        rtype = "void" if ret is None or ast.unparse(ret) == "None" else \
            _TYPES[ast.unparse(ret)]
        self.params, self.rtype = params, rtype
        head = ("static " if self.static or self.clones else "") + "".join(
            f"{m} " for m in alg.ATTRIBUTES.get(self.c_name, ()))
        name = self.c_name
        if self.variant:
            name += self.variant.suffix
        if self.clones:
            name += "_clones"
        return f"{head}{rtype} {name}({', '.join(params) or 'void'})"

    @property
    def clones(self) -> bool:
        """Compiled for several CPUs (``IFS_HOT``) and called from another file: GCC
        exports the clones' dispatcher of an external function whatever its
        visibility, so the clones are a static function and the public name a plain
        one that calls it."""
        return (not self.static and not self.variant
                and "IFS_HOT" in alg.ATTRIBUTES.get(self.c_name, ()))

    def text(self) -> list:
        sig = self.signature()
        doc = ast.get_docstring(self.tree) or ""
        first = " ".join(re.sub(r"(:\w+:)?`+~?\.?", "", doc.split("\n\n")[0]).split())
        lines = _comment(f"{self.f.__name__}: {first}" if not self.variant else
                         f"{self.f.__name__}{self.variant.suffix}: {self.variant.what}")
        self.block(self.tree.body, 1)
        body = lines + [*_wrap_line(sig), "{", *self.out, "}"]
        if self.clones:
            args = ", ".join(a.arg for a in self.tree.args.args if a.arg not in self.sizes)
            call = f"{self.c_name}_clones({args});"
            body += ["", *_wrap_line(f"{self.rtype} {self.c_name}("
                                     f"{', '.join(self.params) or 'void'})"),
                     "{", f"    {'' if self.rtype == 'void' else 'return '}{call}", "}"]
        if self.variant:
            body = [f"#ifdef {self.variant.guard}", *lines, self.variant.attribute,
                    *_wrap_line(sig), "{", *self.out, "}", "#endif"]
        return body


#: the generated lines' length, where a break at a comma or an operator can keep them
WIDTH = 92


def _wrap_line(line: str) -> list:
    """``line`` broken after a comma or before a ``&&`` or ``||`` of the shallowest
    parentheses that have one (a comma first), the longest head that fits,
    continued under the parenthesis' first character; as it is if none fits."""
    if len(line) <= WIDTH:
        return [line]
    depth, stack, spots = 0, [], []            # spots: (depth, kind, cut, column)
    for i, ch in enumerate(line):
        if ch in "([":
            depth += 1
            stack.append(i)
        elif ch in ")]":
            depth -= 1
            stack.pop()
        elif stack and line[stack[-1]] == "(":
            if ch == "," and line[i + 1:i + 2] == " ":
                spots.append((depth, 0, i + 2, stack[-1] + 1))
            elif line.startswith(("&& ", "|| "), i) and line[i - 1] == " ":
                spots.append((depth, 1, i, stack[-1] + 1))
    fits = [sp for sp in spots if sp[2] <= WIDTH]
    if not fits:
        return [line]
    least = min(sp[:2] for sp in fits)
    _, _, cut, column = max(sp for sp in fits if sp[:2] == least)
    # the rest is inside the parenthesis at column - 1: wrapped with it in place
    rest = _wrap_line(" " * (column - 1) + "(" + line[cut:])
    return [line[:cut].rstrip(), " " * column + rest[0][column:]] + rest[1:]


def _fill(text: str) -> list:
    return textwrap.wrap(text, 84) or [""]


def _comment(text: str) -> list:
    """``text`` as a C block comment, filled."""
    lines = ["/* " + ln for ln in _fill(text)]
    lines[1:] = [" * " + ln[3:] for ln in lines[1:]]
    lines[-1] += " */"
    return lines


def _wrap(text: str) -> str:
    return text if text.startswith("(") and _balanced_outer(text) else f"({text})"


def _balanced_outer(text: str) -> bool:
    depth = 0
    for i, ch in enumerate(text):
        depth += ch == "("
        depth -= ch == ")"
        if depth == 0 and i < len(text) - 1:
            return False
    return True


def _c_float(x: float) -> str:
    if not math.isfinite(x):
        raise InputError(f"the constant {x} has no C literal")
    return repr(float(x))


def _py_type(value) -> str:
    return "int" if isinstance(value, int) else "double"


def _c_type(annotation) -> str:
    return "void" if annotation in (None, "None") else _TYPES[annotation]


def algorithms_c() -> str:
    """The text of ``inflow_algorithms.c``."""
    others = {}
    for f, c_name, _, sizes in alg.ALGORITHMS:
        ret = inspect.signature(f).return_annotation
        others[f.__name__] = (c_name, _c_type(ret if isinstance(ret, str) else
                                              getattr(ret, "__name__", None)), sizes, f)
    tables = sorted({n.id for f, *_ in alg.ALGORITHMS
                     for n in ast.walk(ast.parse(textwrap.dedent(inspect.getsource(f))))
                     if isinstance(n, ast.Name) and isinstance(getattr(alg, n.id, None), tuple)})
    out = ["/* Generated by inflowsim.fmu.pyc from inflowsim/simulate/algorithms.py: "
           "do not edit. */",
           "/*",
           " * The stepping algorithms the Simulator runs in Python, translated: the same",
           " * operations in the same order.  The primitives (ifs_matmul, ifs_lu_solve, ...)",
           " * are in inflow_numerics.h and .c, the step's own (ifs_taylor_first ...) in",
           " * inflow_model.h.",
           " */",
           "#include <math.h>", "", '#include "inflow_model.h"', "",
           "#ifndef M_PI", "#define M_PI 3.14159265358979323846", "#endif", ""]
    for name in tables:
        values = ", ".join(_c_float(v) for v in getattr(alg, name))
        out += [f"static const double {name}[{len(getattr(alg, name))}] = {{",
                *["    " + ln for ln in textwrap.wrap(values, 84)], "};", ""]
    statics = [fn for fn in alg.ALGORITHMS if fn[2]]
    publics = [fn for fn in alg.ALGORITHMS if not fn[2]]
    for f, c_name, static, sizes in statics + publics:
        out += _Function(f, c_name, static, sizes, others).text() + [""]
        for v in alg.VARIANTS.get(c_name, ()):
            out += _Function(f, c_name, static, sizes, others, v).text() + [""]
    return "\n".join(out)


__all__ = ["algorithms_c"]
