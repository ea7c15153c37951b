"""Preset parameter sets: the paper's Tables 1-3 and the Puma theory values.

``paper_table(n)`` gives the estimates and 1-sigma bounds of Table n (band
0.226-1.58 Hz, Puma at 100 kt); ``theory_parameters`` gives a-priori values for
any structure (Puma flap theory, Pitt-Peters time constants, neutral effects).
"""
from __future__ import annotations

from .effects import CATALOGUE
from ..errors import InputError
from .params import PUMA, Constants, check_constants
from .structure import Structure
from ..physics.theory import PUMA_LAMBDA_BETA2, PUMA_N_BETA, pitt_peters_time_constants

# (estimate, sigma); lambda_beta2 = 1 - (1 - lambda_beta2) as tabulated.
_TABLES = {
    1: ("basic", {
        "lambda_beta2": (1.3992, 0.084), "n_beta": (1.0027, 0.11), "tau": (19.426, 11.0)}),
    2: ("empirical", {
        "lambda_beta2": (1.0703, 0.025), "n_beta": (0.906, 0.035),
        "tau0": (16.28, 5.107), "tau_cs": (31.91, 2.23),
        "k01": (-0.279, 0.12), "k02": (0.0583, 0.008), "k11": (-1.105, 0.36),
        "k12": (-1.835, 0.12), "k21": (-0.168, 0.14), "k22": (-0.698, 0.058),
        "azimuth_bias": (0.283, 0.042)}),
    3: ("glauert", {
        "lambda_beta2": (1.0224, 0.021), "n_beta": (0.857, 0.030),
        "tau0": (1.079, 1.12), "tau_cs": (21.442, 0.89),
        "c1": (-0.0752, 0.034), "c2": (-0.0214, 0.020), "c3": (-1.329, 0.083),
        "c4": (-0.4579, 0.022), "k0p": (0.0692, 0.012), "kc": (0.1629, 0.038),
        "ks": (-0.1901, 0.055), "azimuth_bias": (0.392, 0.036)}),
}
TABLE_OF_PRESET = {v[0]: k for k, v in _TABLES.items()}


def paper_table(n: int) -> tuple[str, dict, dict]:
    """``(preset, estimates, sigmas)`` of the paper's Table ``n`` (1, 2 or 3).

    Parameters
    ----------
    n : {1, 2, 3}
        The table: 1 basic, 2 empirical, 3 glauert.
    """
    preset, rows = _TABLES[n]
    return preset, {k: v[0] for k, v in rows.items()}, {k: v[1] for k, v in rows.items()}


def theory_parameters(structure, constants: Constants = PUMA) -> dict:
    """A-priori values for every parameter of ``structure``.

    Flap: Puma theory ``lambda_beta2 = 1.06``, ``n_beta = 0.987``.  Inflow:
    Pitt-Peters apparent-mass time constants (``tau = tau0``).  Effects: their
    neutral values (``k0p = a0 s/(8 mu)``, all other augmentation zero).

    Parameters
    ----------
    structure : str or Structure
        The structure.
    constants : Constants
        Flight condition and rotor (``mu`` [-], ``a0`` [1/rad], ``solidity`` [-]);
        default the Puma at 100 kt.
    """
    s = Structure.parse(structure)
    tau0, _ = pitt_peters_time_constants(constants.flow_speed)
    vals = {"lambda_beta2": PUMA_LAMBDA_BETA2, "n_beta": PUMA_N_BETA, "tau": tau0}
    for e in s.effects:
        vals.update(CATALOGUE[e].theory(constants))
    return {n: vals[n] for n in s.parameters}


#: Where :func:`preset_parameters` takes its values from.
SOURCES = ("paper", "theory")


def preset_parameters(structure, constants: Constants = PUMA, source: str = "paper") -> dict:
    """Parameters for ``structure``: ``source="paper"`` takes the paper's table for
    the matching preset (theory values for parameters the table lacks),
    ``source="theory"`` takes :func:`theory_parameters`.

    Parameters
    ----------
    structure : str or Structure
        The structure.
    constants : Constants
        Flight condition and rotor (``mu`` [-], ``a0`` [1/rad], ``solidity`` [-],
        ``omega`` [rad/s]); default the Puma at 100 kt.
    source : {"paper", "theory"}
        Where the values come from.
    """
    if source not in SOURCES:
        raise InputError(f"source {source!r}: choose {' or '.join(map(repr, SOURCES))}")
    s = Structure.parse(structure)
    check_constants(constants)
    vals = theory_parameters(s, constants)
    if source == "paper":
        base = max((p for p in TABLE_OF_PRESET
                    if set(Structure.parse(p).effects) <= set(s.effects)),
                   key=lambda p: len(Structure.parse(p).effects))
        _, est, _ = paper_table(TABLE_OF_PRESET[base])
        vals.update({k: v for k, v in est.items() if k in vals})
    return vals


#: Values a virtual truth gives an effect whose theory value is neutral and that no
#: paper table estimates (a time shift of zero would not be a hidden effect).
DEMONSTRATION = {"delay": 0.03}


def truth_parameters(structure, constants: Constants = PUMA) -> dict:
    """Parameters for a virtual truth of ``structure`` in which every effect acts.

    :func:`preset_parameters` (``"paper"``), then for every parameter of an added
    effect still at its neutral value (the theory value of ``glauert``,
    ``hub-velocity-coupling``, ``azimuth-bias``, ``time-delay`` ... is "no
    effect"): the paper's estimate from the table that has it (Tables 3, 2), else
    :data:`DEMONSTRATION` (``delay`` 0.03 s; a per-channel ``delay_<c>`` 0.02 s).
    """
    s = Structure.parse(structure)
    vals = preset_parameters(s, constants, "paper")
    table = {}
    for n in (3, 2, 1):
        for k, v in paper_table(n)[1].items():
            table.setdefault(k, v)
    for e in s.effects:
        neutral = CATALOGUE[e].neutral_values(constants)
        for name in CATALOGUE[e].parameters:
            if name in neutral and abs(vals[name] - neutral[name]) <= 1e-12 * max(
                    1.0, abs(neutral[name])):
                if name in table:
                    vals[name] = table[name]
                elif name in DEMONSTRATION:
                    vals[name] = DEMONSTRATION[name]
                elif name.startswith("delay_"):
                    vals[name] = 0.02
    return vals


__all__ = ["TABLE_OF_PRESET", "paper_table", "theory_parameters", "SOURCES",
           "preset_parameters", "DEMONSTRATION", "truth_parameters"]
