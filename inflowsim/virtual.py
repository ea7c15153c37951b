"""Virtual Puma records from a linear structure: data on a fresh machine.

The truth here is the linear model itself (a chosen structure plus effects and
parameters), driven by a pilot doublet or 3-2-1-1, hub motion from
:class:`~inflowsim.body.BodyModel`, replayed with the exact zero-order-hold
simulator at the record's sample step, and seeded Gaussian sensor noise.  The
record holds totals: trim plus perturbations.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .body import BodyModel
from .inputs import SHAPES
from .model import build_model
from .params import PUMA, Constants
from .presets import preset_parameters
from .record import FLAP_COLUMNS, INPUT_COLUMNS, Record
from .simulator import Simulator

#: Trim totals of the virtual Puma at 100 kt [rad, -].
PUMA_TRIM = {"theta0": 0.17, "theta1c": 0.01, "theta1s": -0.05, "muz": 0.0, "p": 0.0,
             "q": 0.0, "pdot": 0.0, "qdot": 0.0, "muy": 0.0,
             "beta0": 0.06, "beta1c": 0.01, "beta1s": -0.002}
CONTROL_INDEX = {"theta0": 0, "theta1c": 1, "theta1s": 2}


@dataclass(frozen=True)
class Manoeuvre:
    """Pilot input: ``shape`` on ``channel`` [rad] starting at ``t_start`` [s]."""

    channel: str = "theta1s"
    shape: str = "doublet"
    amplitude: float = np.radians(1.0)
    t_start: float = 2.0
    width: float = 0.4          # doublet half-width or 3211 unit [s]


@dataclass(frozen=True)
class VirtualTest:
    """Everything that defines a virtual record; see :func:`virtual_record`."""

    structure: str = "glauert"
    parameters: dict | None = None
    constants: Constants = PUMA
    manoeuvres: tuple = (Manoeuvre(),)
    duration: float = 26.6
    dt: float = 0.01
    noise_flap: float = 1e-4
    noise_inputs: float = 0.0
    seed: int = 0
    body: BodyModel = field(default_factory=BodyModel)
    description: str = "longitudinal cyclic doublet, 100 kt"


def pilot_controls(t, manoeuvres) -> np.ndarray:
    u = np.zeros((len(t), 3))
    for m in manoeuvres:
        u[:, CONTROL_INDEX[m.channel]] += SHAPES[m.shape](t, m.t_start, m.width, m.amplitude)
    return u


def virtual_record(test: VirtualTest = VirtualTest(), include_truth: bool = True) -> Record:
    """A record (totals, ``record-format.md``) from a linear truth.

    Columns: the ten inputs, the measured flap (with noise), and where
    ``include_truth`` the true inflow ``lambda0, lambda1c, lambda1s`` (fitting never
    reads them).
    """
    k = test.constants
    trim = dict(PUMA_TRIM, mux=k.mu)
    if k.trim is None:                 # effects linearised about trim see the record's trim
        k = k.with_trim(trim)
    params = test.parameters or preset_parameters(test.structure, k, "paper")
    model = build_model(test.structure, params, k)
    n = int(round(test.duration / test.dt))
    t = np.arange(n) * test.dt
    controls = pilot_controls(t, test.manoeuvres)
    omega_r = k.omega * (k.radius or 7.5)
    hub = test.body.response(controls, test.dt, omega_r, k.mu)
    pert = {"theta0": controls[:, 0], "theta1c": controls[:, 1], "theta1s": controls[:, 2],
            **hub}
    u = np.column_stack([pert[c] for c in model.inputs])
    y = Simulator(model, test.dt).replay(u)
    rng = np.random.default_rng(test.seed)
    cols = {}
    for c in INPUT_COLUMNS:
        v = trim[c] + pert[c]
        if test.noise_inputs:
            v = v + test.noise_inputs * rng.standard_normal(n)
        cols[c] = v
    for i, c in enumerate(FLAP_COLUMNS):
        cols[c] = trim[c] + y[:, i] + test.noise_flap * rng.standard_normal(n)
    if include_truth:
        for i, c in enumerate(("lambda0", "lambda1c", "lambda1s")):
            cols[c] = y[:, 3 + i]
    meta = {"omega": k.omega, "mu": k.mu, "a0": k.a0, "solidity": k.solidity,
            "radius": k.radius or 7.5, "aircraft": "Puma (virtual)",
            "description": test.description, "synthetic": "true", "seed": test.seed}
    return Record.from_arrays(t, cols, meta, source="<virtual>")
