"""The model's equations in structured form, before assembly into ``E x' = A x + B u``.

Azimuth time, all ten candidate inputs (``INPUTS_AZ``); an effect edits these
blocks and :func:`assemble` turns them into the descriptor matrices of Eq. (8)-(9)
(first-order flapping) or the nine-state second-order form (``flap-inertia``).

Flap (Eq. 1):   ``m2 beta'' + c beta' + d beta = h_lambda lambda + h_u u``
Inflow (Eq. 2, 13, 19):
``d_tau lambda' + lambda = p_dbeta beta' + p_beta beta + p_lambda lambda + p_u u``
"""
from __future__ import annotations

from dataclasses import dataclass, field, fields, replace

import numpy as np

# the channel names, order and scaling: one table (inflowsim.channels), re-exported
from ..channels import (FLAP, FLAP_RATE, INFLOW, INPUT_UNITS, INPUTS, INPUTS_AZ,
                        N_BASE_INPUTS, OUTPUTS, input_scale)

__all__ = ["FLAP", "FLAP_RATE", "INFLOW", "INPUT_UNITS", "INPUTS", "INPUTS_AZ",
           "N_BASE_INPUTS", "OUTPUTS", "input_scale", "Equations", "Measurement",
           "rotation", "assemble"]


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
    sq = (eq.m2, eq.c, eq.d, eq.h_lambda, eq.d_tau, eq.p_dbeta, eq.p_beta, eq.p_lambda)
    if (all(type(x) is np.ndarray and x.dtype == np.float64 and x.shape == (3, 3)
            for x in sq)
            and all(type(x) is np.ndarray and x.dtype == np.float64 and x.ndim == 2
                    and x.shape[0] == 3 for x in (eq.h_u, eq.p_u))
            and eq.h_u.shape[1] == eq.p_u.shape[1]):
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
