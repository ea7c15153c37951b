from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..equations import Equations, Measurement
from ..params import Constants, ParameterSpec

__all__ = ["Effect", "ParameterSpec", "RuntimeSolve", "RuntimeLinear", "RuntimePolynomials"]


def _unchanged(x, p, k):
    return x


@dataclass(frozen=True)
class RuntimeSolve:
    """A computation an effect needs at run time where its terms are no closed
    expression (``k.numeric`` while traced, :attr:`Effect.runtime`), declared as
    expressions and data so that code can be generated from it (the FMU's C,
    :mod:`inflowsim.fmu.codegen`): no effect is written in C by hand.

    The unknowns ``x`` start at the solution of ``M x = rhs``; Newton's method then
    drives the residual to zero, its Jacobian by the chain rule through the
    quadrature ``f_i = scale(arg) sum_k weights[i, k] q(w, point_k)`` of the
    variables ``w = w_of(arg, x)``; the results are computed at the solution.
    Every callable runs on numbers or on sympy expressions (arrays of dtype
    object); ``arg`` holds the arguments in the order the effect passes them to
    ``k.numeric``.

    Attributes
    ----------
    n_args : int
        Number of arguments.
    shapes : tuple of (int, int)
        Shape of each result.
    n_unknowns : int
        Number of unknowns ``x``.
    n_w : int
        Number of the integrand's variables ``w``.
    integrand : callable
        ``(w, *point, sqrt) -> q``: the quadrature's integrand at one point (``sqrt``
        numpy's or sympy's).
    points : tuple of ndarray
        The quadrature points, one array per coordinate.
    weights : ndarray
        ``(len(f), len(points[0]))``: each result of the quadrature's weights.
    scale : callable
        ``arg -> float``: the factor of the quadrature.
    w_of : callable
        ``(arg, x) -> w``: the variables (affine in ``x``).
    start : callable
        ``arg -> (M, rhs)``: the linear system of the start.
    residual : callable
        ``(arg, x, f) -> r``: Newton's residual (``n_unknowns`` entries).
    outputs : callable
        ``(arg, x, f, df) -> results`` (``df = df/dw``, ``len(f) x n_w``): arrays of
        ``shapes``.
    steps : int
        Most Newton steps.
    tol : float
        Newton stops after a step whose largest entry is below this.
    """

    n_args: int
    shapes: tuple
    n_unknowns: int
    n_w: int
    integrand: Callable
    points: tuple
    weights: object
    scale: Callable
    w_of: Callable
    start: Callable
    residual: Callable
    outputs: Callable
    steps: int
    tol: float


@dataclass(frozen=True)
class RuntimeLinear:
    """A linear solve an effect needs at run time (``k.numeric`` while traced,
    :attr:`Effect.runtime`): the result is ``Y = M(arg)^-1 R(arg)``, with ``M`` and
    ``R`` closed expressions of the arguments, declared so that code can be generated
    from it (the FMU's C, :mod:`inflowsim.fmu.codegen`: ``M`` and ``R`` printed from
    sympy, an LU solve with partial pivoting).  For a matrix whose symbolic inverse is
    large (the Peters-He gain ``L(X)``, 15 x 15 and polynomial in ``X``): the C then
    holds the matrix, not its inverse.

    Attributes
    ----------
    n_args : int
        Number of arguments (in the order the effect passes them to ``k.numeric``).
    matrix : callable
        ``arg -> M`` (n x n; numbers or sympy expressions, an array of dtype object).
    rhs : callable
        ``arg -> R`` (n x m).
    """

    n_args: int
    matrix: Callable
    rhs: Callable

    def shape(self, arg) -> tuple:
        """``(n, m)`` of the result (``R``'s shape) at arguments ``arg``."""
        return tuple(np.shape(self.rhs(arg)))

    def solve(self, arg) -> np.ndarray:
        """``M^-1 R`` on numbers (what the generated C computes)."""
        m = np.asarray(self.matrix(arg), dtype=float)
        return np.linalg.solve(m, np.asarray(self.rhs(arg), dtype=float))


@dataclass(frozen=True)
class RuntimePolynomials:
    """Polynomials an effect evaluates at run time (``k.numeric`` while traced,
    :attr:`Effect.runtime`): its arguments are the values of the table's variables,
    its one result the outputs (``n_out x 1``).  The table is data
    (:class:`inflowsim.physics.polynomial.Polynomials`), so the FMU's C holds it as
    arrays and evaluates it with the loop Python's own evaluation follows (the same
    doubles), where the expanded expressions (the lead-lag coefficients, polynomial
    of degree 8 in the trim) made most of the generated code and its compile time.

    Attributes
    ----------
    table : Polynomials
        The polynomials.
    """

    table: object

    @property
    def n_args(self) -> int:
        return len(self.table.variables)

    def shape(self, arg=None) -> tuple:
        """``(n_out, 1)``: the result's shape."""
        return (self.table.n_out, 1)

    def solve(self, arg) -> np.ndarray:
        """The outputs at ``arg`` on numbers (what the generated C computes)."""
        return self.table([float(x) for x in arg]).reshape(-1, 1)


@dataclass(frozen=True)
class Effect:
    """One candidate physical or measurement effect (``workflow.md``).

    Attributes
    ----------
    name : str
        Public name, e.g. ``"glauert"``.
    physics : str
        One sentence of physics, shown when the effect is ranked.
    paper : str
        Where it comes from (equation or section of the paper).
    parameters : tuple of str
        Canonical names of the parameters it adds.
    theory : callable
        ``Constants -> {name: value}``: a-priori (physical) values; used as
        starting values and for ``source="theory"``.
    neutral : callable, optional
        ``Constants -> {name: value}``: values at which the effect changes nothing,
        so that a structure with it reproduces one without it (the nested start of
        a candidate refit).  Default: ``theory``, where the theory value is neutral.
    equations, measurement : callable
        ``(Equations|Measurement, params, Constants) -> same``.
    removes : tuple of str
        Base parameters it supersedes (``tau`` for separate time constants).
    uses_inplane : bool
        Needs the in-plane velocity inputs ``mux, muy``.
    second_order : bool
        Keeps the multiblade flap second derivatives (nine states).
    alternatives : tuple of str
        Effects it may never be combined with (singular information matrix).
    boundary : tuple of str
        Parameters whose neutral value is the boundary of their range (the
        likelihood-ratio statistic is then a 50:50 mixture of chi-square laws).
    specs : tuple of ParameterSpec
        Unit, allowed and plausible range and description of each parameter it
        adds (registered in :data:`inflowsim.model.params.SPECS` by the catalogue).
    offered : bool
        Tried by the diagnosis by default.  Per-channel time shifts are not: the
        user asks for them by name.
    parts : tuple of tuple of str
        Groups of its parameters that are separate physical terms (Glauert's ``F``
        on the rates and ``G`` on the in-plane velocities).  A record that leaves
        one part undetermined can still test the others: the diagnosis holds that
        part at neutral.  Default: one part, all or nothing.
    parts_in_order : bool
        A later part acts only through an earlier one, so that alone, the earlier
        at neutral, it is not identified (the lag's frequency and damper at
        ``k_flap_lag = 0``; the servos' damping at ``servo_tau -> 0``): the
        diagnosis tries the first part alone and each later one once the parts
        before it are in the structure.
    states : tuple of str
        Names of the states it appends (its :class:`~inflowsim.model.equations.StateBlock`
        has them, in this order, after the base states).
    replaces_inputs : tuple of (str, str)
        ``(input, state)``: the base equations and the loads see that state where
        they saw that recorded input (its block's ``through``).
    theory_start : bool
        Its neutral values are a saddle of the likelihood (parameters that act only
        through another, as the lag's frequency and damping through
        ``k_flap_lag = 0``, have no gradient there): a fit started with the effect
        at neutral also tries it at its theory values
        (:func:`inflowsim.identify.estimator.identify`'s starts).
    about_trim : bool
        Its equations are linearised about the record's trim state
        (``Constants.trim``, refused without it): a schedule must give the trim of
        each ``mu`` and the FMU takes it as parameters.
    loads : callable, optional
        ``(params, Constants) -> (3, len(states))``: its appended states' own part of
        the aerodynamic loads ``(C_T, C_mc, C_ms) / (a0 s)`` (higher inflow states'
        thrust and moments); runs on numbers or sympy symbols
        (:func:`inflowsim.model.loads.load_rows`).
    runtime : callable, optional
        ``() -> RuntimeSolve | RuntimeLinear | dict``: what it computes at run time
        when traced on symbols asks for a call (``k.numeric(name, args, shapes)``,
        ``name`` the effect's): the FMU's code generator makes the called C function
        from it (a Newton solve over a quadrature, a linear solve).  An effect with
        several calls gives ``{call name: RuntimeSolve | RuntimeLinear |
        RuntimePolynomials}``, each name the effect's or ``<effect>/<part>``.
    """

    name: str
    physics: str
    paper: str
    parameters: tuple
    theory: Callable[[Constants], dict]
    equations: Callable[[Equations, dict, Constants], Equations] = _unchanged
    measurement: Callable[[Measurement, dict, Constants], Measurement] = _unchanged
    removes: tuple = ()
    uses_inplane: bool = False
    second_order: bool = False
    alternatives: tuple = ()
    neutral: Callable[[Constants], dict] | None = None
    offered: bool = True
    boundary: tuple = ()
    specs: tuple = ()
    parts: tuple = ()
    parts_in_order: bool = False
    about_trim: bool = False
    theory_start: bool = False
    states: tuple = ()
    replaces_inputs: tuple = ()
    loads: Callable | None = None
    runtime: Callable | None = None

    @classmethod
    def of_one(cls, *, spec: ParameterSpec, theory, neutral=None, **fields) -> "Effect":
        """An effect of one parameter, ``spec``'s, named once: its ``parameters``,
        ``specs``, ``theory`` and ``neutral`` from it.

        Parameters
        ----------
        spec : ParameterSpec
            The parameter.
        theory : float or callable
            Its a-priori value [``spec.unit``], or ``Constants -> value``.
        neutral : float or callable, optional
            Its value at which the effect changes nothing, or ``Constants -> value``
            (default: the theory value, neutral).
        **fields
            The other fields (``name``, ``physics``, ``paper``, ``equations`` ...).
        """
        def values(v):
            if v is None:
                return None
            if callable(v):
                return lambda k: {spec.name: v(k)}
            v = float(v)
            return lambda k: {spec.name: v}
        return cls(parameters=(spec.name,), theory=values(theory), neutral=values(neutral),
                   specs=(spec,), **fields)

    def plausible_ranges(self, constants: Constants) -> dict:
        """``{name: (low, high, why)}`` of its parameters, in their own units."""
        out = {}
        for s in self.specs:
            r = s.plausible_range(constants.omega, constants.hub)
            if r is not None:
                out[s.name] = r
        return out

    def neutral_values(self, constants: Constants) -> dict:
        return (self.neutral or self.theory)(constants)
