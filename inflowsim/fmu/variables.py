"""The FMU's variables: the one description both ``modelDescription.xml`` and the
C variable table (``fmu/inflow_vars.[ch]``) are generated from.

Names are the project's one name per quantity (``interface.md``): inputs as the
record columns, outputs as the model outputs, parameters and constants by their
canonical names.  Inputs and outputs are PERTURBATIONS about trim in SI units,
the convention of :class:`inflowsim.simulator.Simulator`; only ``mu`` (the trim
advance ratio, the flight condition) is a total.

Value references are the position in :data:`VARIABLES` (reals first, contiguous
from 0, so the C side indexes its table directly), then the integer
``structure``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..channels import BY_NAME, INPUT_CHANNELS, LIMIT, LOAD_CHANNELS, OUTPUTS
from ..model.params import MU_MAX, MU_MIN, OMEGA_RANGE, PUMA, SPECS
from ..model.presets import paper_table

MODEL_IDENTIFIER = "inflowsim"
MODEL_NAME = "inflowsim rotor flap and Glauert-augmented dynamic inflow"

#: Values of the integer parameter ``structure``: the presets the C model knows.
STRUCTURES = {"basic": 0, "empirical": 1, "glauert": 2}

#: Default internal step [s] (the virtual records' sample period).
DT = 0.01
#: Default trim thrust coefficient: the Puma at about 5.8 t (used with inflow_speed 1).
CT_START = 0.0064
#: Values of the integer parameter ``inflow_speed``.
INFLOW_SPEEDS = {"mu": 0, "mass-flow": 1}


@dataclass(frozen=True)
class Variable:
    """One FMI scalar variable.

    ``lower``/``upper`` (and ``lower_open``) are the allowed range the C code
    enforces when the variable is set; ``math.inf`` means unbounded.
    """

    name: str
    type: str              # "Real" or "Integer"
    causality: str         # "input", "output", "parameter"
    variability: str       # "continuous", "tunable", "fixed"
    start: float | None
    unit: str
    description: str
    lower: float = -math.inf
    upper: float = math.inf
    lower_open: bool = False
    #: an output that depends on the inputs at the same instant (the loads)
    feedthrough: bool = False

    @property
    def initial(self) -> str | None:
        if self.causality == "output":
            return "calculated"
        if self.causality == "parameter":
            return "exact"
        return None


_UNITS = {"rad/s^2": "rad/s2", "azimuth rad": "rad"}
_PARAMETERS = ("lambda_beta2", "n_beta", "tau", "tau0", "tau_cs",
               "k01", "k02", "k11", "k12", "k21", "k22",
               "c1", "c2", "c3", "c4", "k0p", "kc", "ks", "azimuth_bias")


def _start_parameters() -> dict:
    """Paper Table 3 (the default structure glauert), Table 1's ``tau``, neutral K."""
    _, est, _ = paper_table(3)
    start = dict(est)
    start["tau"] = paper_table(1)[1]["tau"]
    start.update(dict.fromkeys(("k01", "k02", "k11", "k12", "k21", "k22"), 0.0))
    return start


def _build() -> tuple:
    v = []
    for ch in INPUT_CHANNELS:
        # no rotor quantity comes near LIMIT: beyond it a value is a unit or wiring
        # error, refused like a NaN rather than let overflow the state
        v.append(Variable(ch.name, "Real", "input", "continuous", 0.0,
                          _UNITS.get(ch.unit, ch.unit),
                          f"{ch.description}: perturbation about trim [{ch.unit}]",
                          -LIMIT, LIMIT))
    v.append(Variable("mu", "Real", "input", "continuous", PUMA.mu, "-",
                      "trim advance ratio (a total, the flight condition): "
                      f"{MU_MIN:g}-{MU_MAX:g} with inflow_speed 0 (V ~ mu), "
                      f"0-{MU_MAX:g} with inflow_speed 1 (mass flow)",
                      0.0, MU_MAX))
    for name in OUTPUTS:
        v.append(Variable(name, "Real", "output", "continuous", None, "rad" if
                          name.startswith("beta") else "-",
                          f"{BY_NAME[name].description}: perturbation about trim"))
    start = _start_parameters()
    for name in _PARAMETERS:
        s = SPECS[name]
        v.append(Variable(name, "Real", "parameter", "tunable", start[name],
                          _UNITS.get(s.unit, s.unit),
                          f"{s.description} [{s.unit}]", s.lower, s.upper, s.lower_open))
    v.append(Variable("a0", "Real", "parameter", "tunable", PUMA.a0, "1/rad",
                      "blade lift-curve slope [1/rad]", 0.0, math.inf, True))
    v.append(Variable("solidity", "Real", "parameter", "tunable", PUMA.solidity, "-",
                      "rotor solidity s [-]", 0.0, 1.0, True))
    v.append(Variable("omega", "Real", "parameter", "tunable", PUMA.omega, "rad/s",
                      "rotor speed Omega [rad/s]", *OMEGA_RANGE))
    v.append(Variable("dt", "Real", "parameter", "fixed", DT, "s",
                      "internal fixed step (exact zero-order hold) [s]", 1e-6, 10.0))
    # loads last among the reals, so the value references above stay as they were
    for ch in LOAD_CHANNELS:
        v.append(Variable(ch.name, "Real", "output", "continuous", None, "-",
                          f"{ch.description}: perturbation about trim (inflowsim.model."
                          "loads; depends on the inputs held now)", feedthrough=True))
    v.append(Variable("ct", "Real", "parameter", "tunable", CT_START, "-",
                      "trim thrust coefficient T / (rho pi R^2 (Omega R)^2), for the "
                      "mass-flow speed (inflow_speed 1) [-]", 0.0, 0.05, True))
    v.append(Variable("delay", "Real", "parameter", "fixed", 0.0, "s",
                      "time-delay effect: the recorded flap lags the rotor's by this [s] "
                      "(exact, fractions of dt included; at most 256 dt, communication "
                      "steps whole multiples of dt)", 0.0, 1.0))
    v.append(Variable("structure", "Integer", "parameter", "fixed", STRUCTURES["glauert"],
                      "", "model structure: 0 basic (tau), 1 empirical (tau0, tau_cs, K, "
                      "azimuth_bias), 2 glauert (tau0, tau_cs, c1..c4, k0p, kc, ks, "
                      "azimuth_bias)", 0, 2))
    v.append(Variable("inflow_speed", "Integer", "parameter", "fixed", 0, "",
                      "speed through the disc in the momentum gains: 0 the paper's V ~ mu "
                      "(mu >= 0.1), 1 the momentum mass-flow parameter with the trim "
                      "inflow from ct (hover to mu = 0.5; inflowsim.physics.loads."
                      "mass_flow_parameter)", 0, 1))
    return tuple(v)


#: Every variable, in value-reference order.
VARIABLES: tuple = _build()
#: Value reference by name.
VR: dict = {v.name: i for i, v in enumerate(VARIABLES)}
REALS = tuple(v for v in VARIABLES if v.type == "Real")
INTEGERS = tuple(v for v in VARIABLES if v.type == "Integer")
PARAMETER_NAMES = _PARAMETERS

assert VARIABLES[: len(REALS)] == REALS, "reals must come first (the C table is indexed by vr)"
