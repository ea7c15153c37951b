"""Building a model: descriptor matrices (azimuth time) and state space (seconds).

:func:`equations` and :func:`descriptor` are pure functions of a structure, named
parameters and constants; :func:`build_model` packs the result with the SI state
space into a frozen :class:`Model`.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Mapping

import numpy as np

from ..physics import flapping as fl
from ..physics import loads as ld
from .effects import CATALOGUE
from .equations import (FLAP, OUTPUTS, Equations, Measurement, assemble, input_scale,
                        rotation)
from .params import Constants, check_parameters
from .structure import Structure


def base_equations(p: Mapping[str, float], k: Constants) -> Equations:
    """The basic momentum model, Eqs. (1)-(4), with all ten input columns."""
    mu, nb = k.mu, p["n_beta"]
    lm = ld.momentum_l(mu, k.a0s, k.flow_speed)
    h_u = np.zeros((3, 10))
    h_u[:, 0:3] = fl.flap_h_theta(mu, nb)
    h_u[:, 3:6] = fl.flap_h_nu(mu, nb)
    h_u[:, 6:8] = fl.flap_h_eta()
    p_u = np.zeros((3, 10))
    p_u[:, 0:3] = lm @ ld.g_theta(mu)
    p_u[:, 3:6] = lm @ ld.g_nu(mu)
    tau = p.get("tau", 1.0)   # superseded by separate-time-constants
    return Equations(
        m2=np.zeros((3, 3)), c=fl.flap_c(mu, nb), d=fl.flap_d(mu, nb, p["lambda_beta2"]),
        h_lambda=fl.flap_h_lambda(mu, nb), h_u=h_u, d_tau=tau * np.eye(3),
        p_dbeta=lm @ ld.g_dbeta(mu), p_beta=lm @ ld.g_beta(mu),
        p_lambda=lm @ ld.g_lambda(mu), p_u=p_u)


def equations(structure, params: Mapping[str, float], constants: Constants):
    """Structured equations and measurement of ``structure`` (validated inputs)."""
    s = Structure.parse(structure)
    constants.check()
    p = check_parameters(params, s.parameters)
    eq = base_equations(p, constants)
    meas = Measurement()
    for name in s.effects:
        eff = CATALOGUE[name]
        eq = eff.equations(eq, p, constants)
        meas = eff.measurement(meas, p, constants)
    return s, p, eq, meas


def descriptor(structure, params, constants):
    """``E, A, B`` of Eq. (8) in azimuth time; inputs ``structure.inputs_az``."""
    s, p, eq, _ = equations(structure, params, constants)
    e, a, b = assemble(eq, s.second_order)
    return e, a, b[:, : s.n_inputs]


def _frozen(a):
    a = np.array(a, dtype=float)
    a.flags.writeable = False
    return a


@dataclass(frozen=True, eq=False)
class Model:
    """A linear model of flap and inflow: descriptor and SI state space.

    ``x_dot = a x + b u``, ``y = c x`` with ``u`` the SI perturbation inputs
    (``inputs``, record column names) about trim, ``y`` the six ``outputs``
    (measured flap as recorded, i.e. including azimuth bias; true inflow), each
    delayed by ``delays`` [s] (negative: a lead); the recorded input ``j`` lags the
    true one by ``input_delays[j]`` [s].  ``E, A, B`` are the azimuth-time descriptor of
    Eq. (8) with inputs in azimuth units.
    """

    structure: Structure
    parameters: Mapping[str, float]
    constants: Constants
    E: np.ndarray
    A: np.ndarray
    B: np.ndarray
    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    d: np.ndarray
    delays: np.ndarray
    measurement: Measurement = field(repr=False)
    input_delays: np.ndarray = field(default=None, repr=False)
    end_basis: np.ndarray = field(default=None, repr=False)
    end_input: np.ndarray = field(default=None, repr=False)

    def end_state(self, v, u):
        """A record's end state from its slow coordinates ``v`` and the input ``u``
        there: ``end_basis v + end_input u`` (the identity for first-order
        flapping; with ``flap-inertia`` the flap rates are quasi-steady, see
        :func:`slow_manifold`)."""
        return self.end_basis @ v + self.end_input @ u

    @property
    def has_shifts(self) -> bool:
        """Any time shift on an output or input."""
        return bool(np.any(self.delays != 0) or np.any(self.input_delays != 0))

    @property
    def states(self):
        return self.structure.states

    @property
    def inputs(self):
        return self.structure.inputs

    @property
    def inputs_az(self):
        return self.structure.inputs_az

    @property
    def outputs(self):
        return OUTPUTS

    def with_mu(self, mu: float) -> "Model":
        """The same structure and parameters at another advance ratio."""
        return build_model(self.structure, self.parameters, self.constants.with_mu(mu))

    def with_parameters(self, **changes) -> "Model":
        p = dict(self.parameters)
        p.update(changes)
        return build_model(self.structure, p, self.constants)

    def eigenvalues(self) -> np.ndarray:
        """Poles of the SI state space [1/s], sorted by real part."""
        ev = np.linalg.eigvals(self.a)
        return ev[np.argsort(ev.real)]

    def is_stable(self) -> bool:
        return bool(np.all(self.eigenvalues().real < 0))

    def frequency_response(self, f_hz) -> np.ndarray:
        """``H(j w)``, shape ``(n_outputs, n_inputs, n_freq)``, time shifts included
        (outputs recorded ``delays`` late, inputs ``input_delays`` late)."""
        w = 2 * np.pi * np.atleast_1d(np.asarray(f_hz, dtype=float))
        n = self.a.shape[0]
        out = np.empty((self.c.shape[0], self.b.shape[1], w.size), dtype=complex)
        for i, wi in enumerate(w):
            out[:, :, i] = self.c @ np.linalg.solve(1j * wi * np.eye(n) - self.a, self.b)
        out *= np.exp(-1j * np.outer(self.delays, w))[:, None, :]
        out *= np.exp(1j * np.outer(self.input_delays, w))[None, :, :]
        return out

    def to_control(self):
        """``control.StateSpace`` in seconds (delays are not part of it)."""
        import control
        return control.ss(self.a, self.b, self.c, self.d, inputs=list(self.inputs),
                          outputs=list(self.outputs), states=list(self.states))


def slow_manifold(eq: Equations, n_inputs: int, scale: np.ndarray):
    """``(P, q)``: states ``x = P v + q u`` with the flap rates quasi-steady.

    For second-order flapping (``flap-inertia``), ``beta' = C^-1 (-D beta +
    H_lambda lambda + h_u u)``: the first-order model's flap rate, where the fast
    flap modes (``-C / flap_inertia``) have died out.  Records start and end in
    steady flight, so their end states lie there; with them the first-order limit
    of the structure is exact for the end effects too.  ``v = (beta, lambda)``;
    ``u`` SI inputs, ``scale`` their azimuth scaling.
    """
    ci = np.linalg.inv(eq.c)
    p = np.vstack([np.eye(6), ci @ np.hstack([-eq.d, eq.h_lambda])])
    q = np.vstack([np.zeros((6, n_inputs)), ci @ eq.h_u[:, :n_inputs] * scale])
    return p, q


def build_model(structure, params: Mapping[str, float], constants: Constants) -> Model:
    """Build and validate a :class:`Model`.

    Parameters
    ----------
    structure : str or Structure
        Preset or ``base+effect...`` text.
    params : mapping
        Every parameter of the structure, by canonical name (``interface.md``).
    constants : Constants
        ``mu`` [-], ``a0`` [1/rad], ``solidity`` [-], ``omega`` [rad/s].
    """
    s, p, eq, meas = equations(structure, params, constants)
    e, a_az, b_az = assemble(eq, s.second_order)
    b_az = b_az[:, : s.n_inputs]
    om = constants.omega
    a_s = om * np.linalg.solve(e, a_az)
    b_s = om * np.linalg.solve(e, b_az) * input_scale(om)[: s.n_inputs]
    n = e.shape[0]
    c = np.zeros((6, n))
    c[:, :6] = np.eye(6)
    c[1:3, 1:3] = rotation(meas.azimuth_bias)
    delays = np.concatenate([np.asarray(meas.delays, float), np.zeros(3)])
    scale = input_scale(om)[: s.n_inputs]
    if s.second_order:
        end_basis, end_input = slow_manifold(eq, s.n_inputs, scale)
    else:
        end_basis, end_input = np.eye(n), np.zeros((n, s.n_inputs))
    in_delay = dict(meas.input_delays)
    input_delays = np.array([in_delay.get(n, 0.0) for n in s.inputs], dtype=float)
    return Model(structure=s, parameters=MappingProxyType(dict(p)), constants=constants,
                 E=_frozen(e), A=_frozen(a_az), B=_frozen(b_az), a=_frozen(a_s),
                 b=_frozen(b_s), c=_frozen(c), d=_frozen(np.zeros((6, s.n_inputs))),
                 delays=_frozen(delays), measurement=meas,
                 input_delays=_frozen(input_delays), end_basis=_frozen(end_basis),
                 end_input=_frozen(end_input))


__all__ = ["Model", "build_model", "descriptor", "equations", "base_equations", "FLAP"]
