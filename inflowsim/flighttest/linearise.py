"""The nonlinear truth linearised about its periodic trim: its parameters by a route
independent of identification.

The individual-blade truth (:mod:`inflowsim.flighttest.bladesim`) has periodic
coefficients.  Its multiblade form (:func:`~inflowsim.flighttest.bladesim.multiblade_derivatives`),
differentiated by central differences at the periodic trim and averaged over one
blade passage (``2 pi/Nb`` of azimuth), is the constant-coefficient system the
linear model (1) approximates:

``z' = A z + B u``, ``z = (beta0, beta1c, beta1s, beta0', beta1c', beta1s', lambda0,
lambda1c, lambda1s)``, ``u`` the inputs in azimuth units (``channels.INPUTS_AZ``:
``theta0 theta1c theta1s muz qbar pbar qbar' pbar' mux muy``), azimuth time.

With the trim ``mu`` as the speed through the disc (``RotorSpec.speed = "mu"``) this
is the structure ``basic+separate-time-constants+flap-inertia`` at the truth's own
values (Pitt-Peters time constants at ``mu``, ``lambda_beta2``, ``n_beta``,
``flap_inertia = 1``): ``tests/test_linearise.py`` checks it entry by entry, so a
campaign of that truth has known parameters at every speed.  With Eq. (14) the
inflow rows gain the coupling of the speed's perturbations: in the cyclic rows the
paper's ``q*``, ``p*`` combinations of Eq. (19), and terms outside the Glauert
form (the mass flow's self-terms, the mean row's normal velocity): the truth is
then not inside any catalogue structure, and what a fit estimates are equivalent
parameters (:func:`eq14_coupling` separates the two parts).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..channels import FLAP, FLAP_RATE, INFLOW, INPUTS_AZ
from .bladesim import BladeRotor, RotorSpec, multiblade_derivatives
from .nonlinear import trim_inputs

#: Azimuths per blade passage the Jacobian is averaged over.
N_PSI = 16
#: Central-difference step [rad or -]: the truth's right-hand side is smooth (its
#: only non-polynomial part is the square root of Eq. 14, far from zero in forward
#: flight), so the truncation error ~ step^2 is far below the rounding's ~1e-10.
STEP = 1e-6
#: State names of :attr:`TruthLinearisation.A`.
STATES = FLAP + FLAP_RATE + INFLOW


@dataclass(frozen=True, eq=False)
class TruthLinearisation:
    """The truth's azimuth-averaged linearisation (module docstring).

    ``A`` (9, 9) and ``B`` (9, 10) in azimuth time and azimuth-unit inputs;
    ``trim_beta``, ``trim_lambda`` the trim's mean multiblade flap [rad] and inflow
    [-]; ``spec`` the rotor.
    """

    spec: RotorSpec
    A: np.ndarray
    B: np.ndarray
    trim_beta: np.ndarray
    trim_lambda: np.ndarray
    states: tuple = STATES
    inputs: tuple = INPUTS_AZ

    def __post_init__(self):
        for name in ("A", "B", "trim_beta", "trim_lambda"):
            a = np.array(getattr(self, name), dtype=float)
            a.flags.writeable = False
            object.__setattr__(self, name, a)


def _averaged_jacobian(rotor: BladeRotor, z0, u0, n_psi: int, step: float) -> np.ndarray:
    """``d(beta'', lambda')/d(z, u)`` (6, 19) averaged over one blade passage."""
    w0 = np.concatenate([z0, u0])
    n = w0.size
    jac = np.zeros((6, n))
    for psi in np.linspace(0.0, 2.0 * np.pi / rotor.nb, n_psi, endpoint=False):
        for j in range(n):
            d = np.zeros(n)
            d[j] = step
            hi, lo = w0 + d, w0 - d
            jac[:, j] += (multiblade_derivatives(rotor, psi, hi[:9], hi[9:])
                          - multiblade_derivatives(rotor, psi, lo[:9], lo[9:])) / (2 * step)
    return jac / n_psi


def linearise(spec: RotorSpec, trim_controls=None, trim_muz: float = 0.0,
              n_psi: int = N_PSI, step: float = STEP) -> TruthLinearisation:
    """Linearise the truth ``spec`` about the periodic trim at ``trim_controls``
    (true pitch ``theta0, theta1c, theta1s`` [rad]; default the virtual Puma's)
    and ``trim_muz`` [-], ``mux = mu``, ``muy = 0``, no hub rates.

    Returns
    -------
    TruthLinearisation
        Central differences of :func:`multiblade_derivatives` about the trim's mean
        multiblade state, averaged over ``n_psi`` azimuths of one blade passage.
    """
    u0 = trim_inputs(spec.constants.mu, trim_controls, trim_muz)
    rotor = BladeRotor(spec)
    trim = rotor.periodic_trim(u0)
    z0 = np.concatenate([trim.beta, np.zeros(3), trim.lam])
    jac = _averaged_jacobian(rotor, z0, u0, n_psi, step)
    a = np.zeros((9, 9))
    b = np.zeros((9, 10))
    a[0:3, 3:6] = np.eye(3)
    a[3:9] = jac[:, :9]
    b[3:9] = jac[:, 9:]
    return TruthLinearisation(spec, a, b, trim.beta, trim.lam)


def truth_parameters(spec: RotorSpec) -> dict:
    """The truth's own values of the structure
    ``basic+separate-time-constants+flap-inertia`` (exact for ``speed = "mu"``)."""
    return {"lambda_beta2": float(spec.lambda_beta2), "n_beta": float(spec.n_beta),
            "tau0": float(spec.tau0), "tau_cs": float(spec.tau_cs), "flap_inertia": 1.0}


def model_linearisation(model) -> tuple:
    """A linear model's ``(A, B)`` in the states and inputs of
    :class:`TruthLinearisation` (azimuth time; inputs the model lacks are zero
    columns).  The model must keep the flap rates as states (``flap-inertia``)."""
    e_inv = np.linalg.inv(model.E)
    a_m, b_m = e_inv @ model.A, e_inv @ model.B
    names = list(model.states)
    missing = [s for s in STATES if s not in names]
    if missing:
        raise ValueError(f"the model has no state {missing[0]}: linearisations compare "
                         "second-order flapping (add flap-inertia)")
    idx = [names.index(s) for s in STATES]
    b = np.zeros((9, len(INPUTS_AZ)))
    for j, name in enumerate(model.inputs_az):
        b[:, INPUTS_AZ.index(name)] = b_m[idx, j]
    return a_m[np.ix_(idx, idx)], b


def eq14_coupling(spec: RotorSpec, trim_controls=None, trim_muz: float = 0.0) -> dict:
    """What Eq. (14) adds to the truth's inflow rows: the Eq. 14 truth's
    linearisation less the same rotor's with ``speed = "mu"`` at the same trim
    state, times ``D_tau`` (the units of the inflow equation's right-hand side).
    Returns ``{"A": (3, 9), "B": (3, 10)}`` (rows ``lambda0, lambda1c, lambda1s``;
    columns :data:`STATES` and ``INPUTS_AZ``)."""
    from dataclasses import replace
    e14 = linearise(replace(spec, speed="eq14"), trim_controls, trim_muz)
    z0 = np.concatenate([e14.trim_beta, np.zeros(3), e14.trim_lambda])
    jac = _averaged_jacobian(BladeRotor(replace(spec, speed="mu")), z0,
                             trim_inputs(spec.constants.mu, trim_controls, trim_muz),
                             N_PSI, STEP)
    tau = np.diag([spec.tau0, spec.tau_cs, spec.tau_cs])
    return {"A": tau @ (e14.A[6:] - jac[3:, :9]), "B": tau @ (e14.B[6:] - jac[3:, 9:])}


__all__ = ["N_PSI", "STEP", "STATES", "TruthLinearisation", "linearise",
           "truth_parameters", "model_linearisation", "eq14_coupling"]
