"""The one table of channels: every quantity a record, the model, the simulator, the
FMU and the plots exchange, with its name, unit, position and scaling.

Names are the project's one name per quantity (``interface.md``): record column,
model input or output, FMU variable, JSON key.  Inputs are in the model's order
(``model.md`` section 3: ``theta``, then ``nu = (muz, qbar, pbar)``, then ``eta =
(qbar', pbar')``, then the in-plane ``mux, muy`` where a structure uses them);
records may hold their columns in any order.  Inside the descriptor matrices
``E, A, B`` (azimuth time, as in the paper) rates are over ``Omega`` and
accelerations over ``Omega^2``: ``omega_power`` says which.  Change a fact here
and every layer follows.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Channel:
    """One quantity.

    ``name`` the record column / model / FMU name; ``unit`` its SI unit as written
    in ``record-format.md`` (``-`` for a ratio); ``azimuth`` its name in azimuth
    units inside ``E, A, B`` (``qbar`` for ``q``); ``omega_power`` ``k`` with
    ``azimuth value = SI value / Omega^k``; ``description`` one phrase;
    ``plausible`` the largest magnitude a rotor in flight gives (a record beyond it
    draws a warning: a wrong unit, or a wrong column).
    """

    name: str
    unit: str
    description: str
    azimuth: str = ""
    omega_power: int = 0
    plausible: float = 1.0

    @property
    def azimuth_name(self) -> str:
        return self.azimuth or self.name


#: Model inputs, in the model's order.
INPUT_CHANNELS = (
    Channel("theta0", "rad", "collective pitch", plausible=0.6),
    Channel("theta1c", "rad", "lateral cyclic pitch theta1cw", plausible=0.6),
    Channel("theta1s", "rad", "longitudinal cyclic pitch theta1sw", plausible=0.6),
    Channel("muz", "-", "hub velocity normal to the disc over Omega R, down positive"),
    Channel("q", "rad/s", "pitch rate", "qbar", 1, plausible=5.0),
    Channel("p", "rad/s", "roll rate", "pbar", 1, plausible=5.0),
    Channel("qdot", "rad/s^2", "pitch acceleration", "qbar_prime", 2, plausible=50.0),
    Channel("pdot", "rad/s^2", "roll acceleration", "pbar_prime", 2, plausible=50.0),
    Channel("mux", "-", "in-plane hub velocity x over Omega R (a total in records)"),
    Channel("muy", "-", "in-plane hub velocity y over Omega R"),
)
#: Inputs every structure has; ``mux, muy`` only where an effect uses them.
N_BASE_INPUTS = 8
#: Multiblade flap, as measured (azimuth bias included).
FLAP_CHANNELS = (
    Channel("beta0", "rad", "coning", plausible=0.6),
    Channel("beta1c", "rad", "longitudinal flap (as recorded: azimuth bias included)",
            plausible=0.6),
    Channel("beta1s", "rad", "lateral flap (as recorded: azimuth bias included)",
            plausible=0.6),
)
#: Induced inflow over Omega R (never measured; a virtual record may carry it).
INFLOW_CHANNELS = (
    Channel("lambda0", "-", "uniform induced inflow over Omega R"),
    Channel("lambda1c", "-", "cosine induced inflow over Omega R"),
    Channel("lambda1s", "-", "sine induced inflow over Omega R"),
)
#: The flap rates, the extra states of second-order flapping (azimuth time).
FLAP_RATE_CHANNELS = tuple(Channel(f"{c.name}_prime", "rad/azimuth rad",
                                   f"azimuth rate of {c.name}") for c in FLAP_CHANNELS)

#: Rotor loads, perturbations about trim (``inflowsim.model.loads``): the aerodynamic
#: thrust and hub moments of Eq. (4) and the hub moments the flap springs pass on.
LOAD_CHANNELS = (
    Channel("CT", "-", "thrust coefficient T / (rho pi R^2 (Omega R)^2), Eq. (4)"),
    Channel("C_mc", "-", "aerodynamic pitch moment coefficient, nose up, Eq. (4)"),
    Channel("C_ms", "-", "aerodynamic roll moment coefficient, starboard down, Eq. (4)"),
    Channel("C_mc_hub", "-", "hub pitch moment coefficient from the flap springs"),
    Channel("C_ms_hub", "-", "hub roll moment coefficient from the flap springs"),
)

INPUTS = tuple(c.name for c in INPUT_CHANNELS)
INPUTS_AZ = tuple(c.azimuth_name for c in INPUT_CHANNELS)
INPUT_UNITS = tuple(c.unit for c in INPUT_CHANNELS)
FLAP = tuple(c.name for c in FLAP_CHANNELS)
INFLOW = tuple(c.name for c in INFLOW_CHANNELS)
FLAP_RATE = tuple(c.name for c in FLAP_RATE_CHANNELS)
OUTPUTS = FLAP + INFLOW
LOADS = tuple(c.name for c in LOAD_CHANNELS)
CONTROLS = INPUTS[:3]
#: Every channel by name.
BY_NAME = {c.name: c for c in INPUT_CHANNELS + FLAP_CHANNELS + INFLOW_CHANNELS
           + LOAD_CHANNELS}


#: No channel of any record comes near this magnitude in SI units; beyond it a value is
#: refused (squares of it would overflow the fits) rather than warned about.
LIMIT = 1e6


def input_scale(omega: float, names=INPUTS) -> np.ndarray:
    """Factors turning SI inputs ``names`` into azimuth-unit inputs (``pbar = p /
    Omega``, ``pbar' = pdot / Omega^2``)."""
    import numpy as np          # here: the command line's help imports this module
    try:
        o = float(omega)
    except TypeError:       # a sympy symbol: the FMU's loads are generated from this code
        return np.array([omega ** -BY_NAME[n].omega_power for n in names], dtype=object)
    return np.array([o ** -BY_NAME[n].omega_power for n in names], dtype=float)


def unit_of(name: str) -> str:
    return BY_NAME[name].unit


__all__ = ["Channel", "INPUT_CHANNELS", "N_BASE_INPUTS", "FLAP_CHANNELS",
           "INFLOW_CHANNELS", "FLAP_RATE_CHANNELS", "LOAD_CHANNELS", "INPUTS", "INPUTS_AZ",
           "INPUT_UNITS", "FLAP", "INFLOW", "FLAP_RATE", "OUTPUTS", "LOADS", "CONTROLS",
           "BY_NAME", "LIMIT", "input_scale", "unit_of"]
