"""The model's equations in structured form, before assembly into ``E x' = A x + B u``.

Azimuth time, all ten candidate inputs (``INPUTS_AZ``); an effect edits these
blocks and :func:`assemble` turns them into the descriptor matrices of Eq. (8)-(9)
(first-order flapping) or the nine-state second-order form (``flap-inertia``).

Flap (Eq. 1):   ``m2 beta'' + c beta' + d beta = h_lambda lambda + h_u u + f_x x``
Inflow (Eq. 2, 13, 19):
``d_tau lambda' + lambda = p_dbeta beta' + p_beta beta + p_lambda lambda + p_u u + l_x x``

``x`` are the states an effect appends (:class:`StateBlock`: lead-lag, servo
actuators, higher inflow states); ``f_x``, ``l_x`` are their blocks' couplings
into the flap and inflow rows (``model.md`` section 9).
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

import numpy as np

# the channel names, order and scaling: one table (inflowsim.channels), re-exported
from ..channels import (FLAP, FLAP_RATE, INFLOW, INPUT_UNITS, INPUTS, INPUTS_AZ,
                        N_BASE_INPUTS, OUTPUTS, input_scale)

__all__ = ["FLAP", "FLAP_RATE", "INFLOW", "INPUT_UNITS", "INPUTS", "INPUTS_AZ",
           "N_BASE_INPUTS", "OUTPUTS", "input_scale", "Equations", "Measurement",
           "StateBlock", "rotation", "assemble"]


@dataclass(frozen=True, eq=False)
class StateBlock:
    """States an effect appends after the base ones, and how they couple (azimuth time).

    The block's own equations, with ``z = (beta, lambda, beta')`` the base model's
    physical quantities (nine columns whatever the flap order) and ``u`` the ten
    azimuth-unit inputs (``INPUTS_AZ``)::

        e x' = a x + a_z z + b u

    and the base equations gain ``f_x x`` on the flap right-hand side and ``l_x x``
    on the inflow right-hand side.  ``through``: ``((input column, state index),
    ...)``: the base equations see that state where they saw that input (a servo
    actuator's output pitch in place of the recorded command); the input then
    drives the block only.  ``to_output``: ``None`` or a ``6 x m`` map: what the
    block's states add to the model's ``(beta, lambda)`` as the record sees them
    (before the azimuth bias rotates the recorded flap).  :func:`assemble` makes it a
    change of state variables, ``x6 <- x6 + to_output x_block``, so that the first
    six states are always the recorded quantities (the output map and the FMU's
    outputs stay the first six states); the block's equations are written in the
    variables before it (``model.md`` section 9).

    Every field is a pure function of the effect's parameters, so the FMU's C is
    generated from it as from the rest (:mod:`inflowsim.fmu.codegen`).  ``e`` must be
    invertible; a block's neutral limit is a parameter on the boundary of its range
    (as ``flap-inertia``'s), not a singular ``e``.
    """

    effect: str
    states: tuple
    e: np.ndarray
    a: np.ndarray
    a_z: np.ndarray
    b: np.ndarray
    f_x: np.ndarray
    l_x: np.ndarray
    through: tuple = ()
    to_output: object = None

    @property
    def n(self) -> int:
        return len(self.states)


@dataclass(frozen=True)
class Equations:
    m2: np.ndarray
    c: np.ndarray
    d: np.ndarray
    h_lambda: np.ndarray
    h_u: np.ndarray
    d_tau: np.ndarray
    p_dbeta: np.ndarray
    p_beta: np.ndarray
    p_lambda: np.ndarray
    p_u: np.ndarray
    #: appended state blocks (:class:`StateBlock`), in catalogue order
    blocks: tuple = ()

    def with_(self, **blocks) -> "Equations":
        # dataclasses.replace, without its generality (every effect calls this in
        # every model build of a fit); unknown names still go through replace
        if type(self) is not Equations or not blocks.keys() <= _EQ_FIELDS:
            return replace(self, **blocks)
        new = object.__new__(Equations)
        new.__dict__.update(self.__dict__)
        new.__dict__.update(blocks)
        return new


_EQ_FIELDS = frozenset(f.name for f in fields(Equations))
#: The ten 3-row arrays of :class:`Equations` (without the appended blocks).
ARRAY_FIELDS = tuple(f.name for f in fields(Equations) if f.name != "blocks")


@dataclass(frozen=True)
class Measurement:
    """How the records relate to the model: azimuth bias, time shifts, and an
    effect's own terms in the recorded flap (``flap_map``).

    ``delays``: per flap channel, the recorded flap lags the model's by this time
    [s] (negative: leads).  ``input_delays``: ``((input, d), ...)``, the recorded
    input lags the true one by ``d`` [s] (negative: leads).
    """

    azimuth_bias: float = 0.0                       # [rad]
    delays: tuple = (0.0, 0.0, 0.0)                 # per flap channel [s]
    input_delays: tuple = ()                        # ((record column, s), ...)
    #: flap channels sharing one delay *parameter* (structural: the sampled-data
    #: model gives each group its own end states, whatever the values)
    delay_groups: tuple = ((0, 1, 2),)
    extra: dict = field(default_factory=dict)
    #: ``None``, or a 3x6 array added to the flap rows of the output map: the
    #: recorded flap gains ``flap_map @ (beta, lambda)`` (a sensor's cross-talk or
    #: gain error; an effect's pure function of its parameters)
    flap_map: object = None

    def with_(self, **kw) -> "Measurement":
        return replace(self, **kw)


def rotation(angle: float) -> np.ndarray:
    """Maps true ``(c, s)`` cyclic components to those recorded with azimuth
    offset ``angle`` (``model.md`` section 6)."""
    try:
        ca, sa = np.cos(angle), np.sin(angle)
    except TypeError:       # a sympy symbol: the FMU's C is generated from this code
        import sympy
        ca, sa = sympy.cos(angle), sympy.sin(angle)
    return np.array([[ca, -sa], [sa, ca]])


def assemble(eq: Equations, second_order: bool):
    """Descriptor matrices ``E, A, B`` (azimuth time, all ten inputs).

    First order: ``x = (beta, lambda)``, Eq. (9)/(20).  Second order: ``x = (beta,
    lambda, beta')`` with ``beta'`` appended so outputs stay the first six states.
    """
    if eq.blocks:
        return _with_blocks(eq, second_order)
    if _float_blocks(eq):
        return _assemble_float(eq, second_order)
    z, i3 = np.zeros((3, 3)), np.eye(3)
    zu = np.zeros_like(eq.h_u)
    if not second_order:
        e = np.block([[eq.c, z], [-eq.p_dbeta, eq.d_tau]])
        a = np.block([[-eq.d, eq.h_lambda], [eq.p_beta, eq.p_lambda - i3]])
        b = np.vstack([eq.h_u, eq.p_u])
        return e, a, b
    e = np.block([[i3, z, z], [z, eq.d_tau, z], [z, z, eq.m2]])
    a = np.block([[z, z, i3],
                  [eq.p_beta, eq.p_lambda - i3, eq.p_dbeta],
                  [-eq.d, eq.h_lambda, -eq.c]])
    b = np.vstack([zu, eq.p_u, eq.h_u])
    return e, a, b


_F64 = np.dtype(np.float64)
_SQUARE = ("m2", "c", "d", "h_lambda", "d_tau", "p_dbeta", "p_beta", "p_lambda")
_FLOAT_FIELDS = _SQUARE + ("h_u", "p_u")


def _float_blocks(eq: Equations) -> bool:
    """Every block a float array of its shape (3 x 3; ``h_u``, ``p_u`` 3 rows and
    the same columns): :func:`_assemble_float` applies.  One pass over the blocks
    (the test runs in every model build of a fit)."""
    d = getattr(eq, "__dict__", {})
    if not all(n in d for n in _FLOAT_FIELDS):     # not a plain Equations: np.block
        return False
    for n in _SQUARE:
        x = d[n]
        if type(x) is not np.ndarray or not _is_f64(x) or x.shape != (3, 3):
            return False
    h, p = d["h_u"], d["p_u"]
    return (type(h) is np.ndarray and type(p) is np.ndarray and _is_f64(h)
            and _is_f64(p) and h.ndim == 2 and h.shape[0] == 3 and h.shape == p.shape)


def _is_f64(x) -> bool:
    # the canonical dtype object first (an unpickled array has an equal other one)
    return x.dtype is _F64 or x.dtype == _F64


def _with_blocks(eq: Equations, second_order: bool):
    """:func:`assemble` with appended state blocks: the base matrices (``n0`` = 6 or
    9 states), then each block's rows and columns (``model.md`` section 9).

    Built by stacking, not by assignment into float arrays, so that it runs on sympy
    symbols as on numbers (the FMU's C is generated from this function)."""
    e0, a0, b0 = assemble(eq.with_(blocks=()), second_order)
    n0 = e0.shape[0]
    blocks = eq.blocks
    ms = [bl.n for bl in blocks]
    m = sum(ms)
    # rows of the flap and the inflow equations in the base state
    fr, lr = (slice(0, 3), slice(3, 6)) if not second_order else (slice(6, 9), slice(3, 6))
    fx = np.hstack([bl.f_x for bl in blocks])
    lx = np.hstack([bl.l_x for bl in blocks])
    zero = np.zeros((3, m))
    if second_order:
        top = np.vstack([zero, lx, fx])          # rows: beta, lambda, beta'
    else:
        top = np.vstack([fx, lx])
    # the base equations' input columns routed through a block's state
    obj = any(np.asarray(x).dtype == object
              for x in (b0, top) + tuple(bl.b for bl in blocks) + tuple(bl.a for bl in blocks))
    b0, top = _object_safe(b0, obj), _object_safe(top, obj)
    off = 0
    for bl in blocks:
        for col, i in bl.through:
            top[:, off + i] = top[:, off + i] + b0[:, col]
            b0[:, col] = 0 * b0[:, col]
        off += bl.n
    a_top = np.hstack([a0, top])
    e_top = np.hstack([e0, np.zeros((n0, m))])
    rows_e, rows_a, rows_b = [], [], []
    off = 0
    for bl in blocks:
        az = np.asarray(bl.a_z)
        # z = (beta, lambda, beta'): beta' is a state (second order) or a derivative
        if second_order:
            a_base, e_base = az, np.zeros((bl.n, n0))
        else:
            # a beta' term moves to the left: the derivative of the beta states
            a_base = az[:, :6]
            e_base = np.hstack([-az[:, 6:9], np.zeros((bl.n, 3))])
        left_e = np.hstack([e_base, np.zeros((bl.n, off)), bl.e,
                            np.zeros((bl.n, m - off - bl.n))])
        left_a = np.hstack([a_base, np.zeros((bl.n, off)), bl.a,
                            np.zeros((bl.n, m - off - bl.n))])
        rows_e.append(left_e)
        rows_a.append(left_a)
        rows_b.append(np.asarray(bl.b))
        off += bl.n
    # another block's input columns routed through a block's state too (the pitch a
    # servo actuator gives drives the higher inflow states as it drives the base)
    off = 0
    for k, bl in enumerate(blocks):
        for col, i in bl.through:
            for q, other in enumerate(blocks):
                if q == k:
                    continue
                bq = _object_safe(rows_b[q], obj)
                aq = _object_safe(rows_a[q], obj)
                aq[:, n0 + off + i] = aq[:, n0 + off + i] + bq[:, col]
                bq[:, col] = 0 * bq[:, col]
                rows_a[q], rows_b[q] = aq, bq
        off += bl.n
    e = np.vstack([e_top] + rows_e)
    a = np.vstack([a_top] + rows_a)
    b = np.vstack([b0] + rows_b)
    # another block's rows see a routed input through that state too (the lag's
    # pitch forcing sees the servos' output pitch, not the command)
    routes = []
    off = 0
    for bl in blocks:
        routes += [(n0 + off, bl.n, col, n0 + off + i) for col, i in bl.through]
        off += bl.n
    if routes:
        obj = any(x.dtype == object for x in (a, b))
        a, b = _object_safe(a, obj), _object_safe(b, obj)
        for start, n, col, state in routes:
            rows = [r for r in range(n0, a.shape[0]) if not start <= r < start + n]
            a[rows, state] = a[rows, state] + b[rows, col]
            b[rows, col] = 0 * b[rows, col]
    if any(bl.to_output is not None for bl in blocks):
        # the recorded (beta, lambda) are the first six states: the change of
        # variables x6 <- x6 + to_output x_block, i.e. E, A times (I - N), N holding
        # to_output in the first six rows of the block's columns (N^2 = 0)
        n = n0 + m
        cols, off = [], 0
        for bl in blocks:
            cols.append(np.zeros((6, bl.n)) if bl.to_output is None
                        else np.asarray(bl.to_output))
            off += bl.n
        nmat = np.vstack([np.hstack([np.zeros((6, n0))] + cols),
                          np.zeros((n - 6, n))])
        t_inv = np.eye(n) - nmat
        e, a = e @ t_inv, a @ t_inv
    if all(x.dtype != object for x in (e, a, b)):
        e, a, b = (np.ascontiguousarray(x, dtype=float) for x in (e, a, b))
    return e, a, b


def _object_safe(x, obj):
    """A copy of ``x`` that takes assignments of symbols (``obj``) or of numbers."""
    return np.array(x, dtype=object if obj else float)


def _assemble_float(eq: Equations, second_order: bool):
    """:func:`assemble` of float blocks of the right shapes, filled in place: the same numbers as
    ``np.block`` (a copy of each block; ``A``'s ``P_lambda - I`` computed alike) at
    a fraction of its cost, which counts inside a fit's Jacobian.  ``np.block``
    stays the general path (the FMU's generator runs :func:`assemble` on symbols)."""
    nu = eq.h_u.shape[1]
    i3 = np.eye(3)
    if not second_order:
        e = np.zeros((6, 6))
        e[:3, :3] = eq.c
        e[3:, :3] = -eq.p_dbeta
        e[3:, 3:] = eq.d_tau
        a = np.empty((6, 6))
        a[:3, :3] = -eq.d
        a[:3, 3:] = eq.h_lambda
        a[3:, :3] = eq.p_beta
        a[3:, 3:] = eq.p_lambda - i3
        b = np.empty((6, nu))
        b[:3] = eq.h_u
        b[3:] = eq.p_u
        return e, a, b
    e = np.zeros((9, 9))
    e[:3, :3] = i3
    e[3:6, 3:6] = eq.d_tau
    e[6:, 6:] = eq.m2
    a = np.zeros((9, 9))
    a[:3, 6:] = i3
    a[3:6, :3] = eq.p_beta
    a[3:6, 3:6] = eq.p_lambda - i3
    a[3:6, 6:] = eq.p_dbeta
    a[6:, :3] = -eq.d
    a[6:, 3:6] = eq.h_lambda
    a[6:, 6:] = -eq.c
    b = np.zeros((9, nu))
    b[3:6] = eq.p_u
    b[6:] = eq.h_u
    return e, a, b
