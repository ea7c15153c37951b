"""Turn a model or an identified parameter file into the FMU's variable values.

An FMU runs the structures it was generated for (:func:`inflowsim.fmu.build_fmu`'s
``model``).  The default one knows the three presets (``basic``, ``empirical``,
``glauert``); every structure made of ``separate-time-constants``,
``hub-velocity-coupling``, ``glauert`` and ``azimuth-bias`` is one of them with the
missing effects at their neutral values (``tau0 = tau_cs = tau``, ``K = 0``,
``azimuth_bias = 0``), which is exact, not an approximation; ``time-delay`` (a lag)
is every FMU's ``delay``.  Any other structure needs an FMU built for it.
"""
from __future__ import annotations

from typing import Mapping

from ..errors import InputError
from ..model.structure import Structure
from .codegen import TRIM_PARAMETERS
from .variables import DEFAULT, INFLOW_SPEEDS, STRUCTURES, Description

#: Effects the presets' FMU runs (as one of its three structures); an FMU built for a
#: structure runs every effect but those :mod:`.codegen` refuses.
SUPPORTED = ("separate-time-constants", "hub-velocity-coupling", "glauert", "azimuth-bias",
             "time-delay")
_K = ("k01", "k02", "k11", "k12", "k21", "k22")


def structure_code(structure) -> int:
    """The presets' FMU's integer ``structure`` for a structure, or
    :class:`InputError`.

    Parameters
    ----------
    structure : str or Structure
        A structure made of the presets' effects.
    """
    s = Structure.parse(structure)
    extra = [e for e in s.effects if e not in SUPPORTED]
    if extra:
        raise InputError(f"the presets' FMU does not run effect {extra[0]} (it runs "
                         f"{', '.join(SUPPORTED)}): build an FMU for the structure "
                         "(inflowsim fmu build --model FILE or STRUCTURE)")
    eff = set(s.effects) - {"time-delay"}         # a measurement effect, any base
    if "glauert" in eff:
        return STRUCTURES["glauert"]
    if eff:
        return STRUCTURES["empirical"]
    return STRUCTURES["basic"]


def start_values(source, constants=None, description: Description = DEFAULT) -> dict:
    """FMU start values from a model or a parameter file, for one call.

    Parameters
    ----------
    source : Model or ParameterSet
        A :class:`inflowsim.model.Model`, or what
        :func:`inflowsim.model.paramfile.read_parameters` returns (an ``identify`` fit).
    constants : Constants, optional
        Overrides the source's constants (``mu``, ``a0``, ``solidity``, ``omega``).
    description : Description, optional
        The FMU's (:func:`inflowsim.fmu.build.description_for`); default the
        presets' FMU.

    Returns
    -------
    dict
        ``{variable name: value}`` with ``structure``, every parameter the structure
        uses and the constants; pass it to ``fmpy.simulate_fmu(start_values=...)``
        or :func:`apply_parameters`.
    """
    try:
        structure, params = source.structure, dict(source.parameters)
    except AttributeError:
        raise InputError("start_values needs a Model or a ParameterSet "
                         "(inflowsim.model.paramfile.read_parameters)") from None
    k = constants if constants is not None else getattr(source, "constants", None)
    s = Structure.parse(structure)
    vals = {name: float(v) for name, v in params.items()}
    # every FMU has time-delay's ``delay``: a structure with it runs as one without
    bare = s.without_effect("time-delay") if "time-delay" in s.effects else s
    codes = description.codes
    code = codes.get(s.name, codes.get(bare.name))
    if code is not None:
        return _finish(code, vals, k, description)
    if description.structures != DEFAULT.structures:
        raise InputError(f"this FMU runs {', '.join(description.structures)}, not "
                         f"{s.name}: build one for it (inflowsim fmu build --model FILE)")
    code = structure_code(s)
    eff = set(s.effects)
    if code != STRUCTURES["basic"]:
        if "separate-time-constants" not in eff:
            vals["tau0"] = vals["tau_cs"] = vals.pop("tau")
        if "azimuth-bias" not in eff:
            vals["azimuth_bias"] = 0.0
    if code == STRUCTURES["empirical"] and "hub-velocity-coupling" not in eff:
        vals.update(dict.fromkeys(_K, 0.0))
    return _finish(code, vals, k, description)


def refuse_leads(params: Mapping[str, float]) -> None:
    """:class:`InputError` for a time shift that is a lead (``delay`` or
    ``delay_<channel>`` < 0): the FMU steps causally and applies lags only."""
    for name, x in params.items():
        if name.startswith("delay") and x < 0:
            raise InputError(f"{name} = {x:g} s is a lead: the FMU steps causally "
                             "and applies lags only (inflowsim.simulate.replay.replay applies "
                             "leads)")


def _finish(code, vals, k, description) -> dict:
    refuse_leads(vals)
    # a scheduled FMU computes these from mu (its trim too): they are not set
    vals = {n: v for n, v in vals.items() if n not in description.scheduled}
    unknown = sorted(set(vals) - set(description.vr))
    if unknown:
        raise InputError(f"parameter {unknown[0]} is not a variable of the FMU")
    out = {"structure": code}
    out.update(vals)
    if k is not None:
        k.check()
        out.update(mu=float(k.mu), a0=float(k.a0), solidity=float(k.solidity),
                   omega=float(k.omega), inflow_speed=INFLOW_SPEEDS[k.inflow_speed])
        if k.ct is not None:
            out["ct"] = float(k.ct)
        if k.trim is not None:        # the trim an effect is linearised about
            out.update({n: float(k.trim[c]) for n, c in TRIM_PARAMETERS.items()
                        if n in description.vr and c in k.trim
                        and n not in description.scheduled})
    return out


def apply_parameters(fmu, source, constants=None,
                     description: Description = DEFAULT) -> dict:
    """Set :func:`start_values` on an instantiated fmpy ``FMU2Slave`` or ``FMU3Slave``
    (before ``exitInitializationMode`` for ``structure``; tunable values also between
    steps).

    Returns the values set.

    Parameters
    ----------
    fmu : fmpy FMU2Slave or FMU3Slave
        An instantiated FMU.
    source : Model, ParameterSet, FitResult or mapping
        Where the values come from (:func:`start_values`): parameters (SI; time
        constants in azimuth units) and constants.
    constants : Constants, optional
        The flight condition and rotor (default the source's).
    description : Description
        The FMU's variables (default the presets' FMU).
    """
    vals = (source if isinstance(source, Mapping)
            else start_values(source, constants, description))
    integers = {v.name for v in description.integers}
    VR = description.vr
    reals = {n: v for n, v in vals.items() if n not in integers}
    ints = {n: v for n, v in vals.items() if n in integers}
    fmi3 = hasattr(fmu, "setFloat64")
    set_real = fmu.setFloat64 if fmi3 else fmu.setReal
    set_int = fmu.setInt32 if fmi3 else fmu.setInteger
    if ints:
        set_int([VR[n] for n in ints], [int(v) for v in ints.values()])
    if reals:
        set_real([VR[n] for n in reals], [float(v) for v in reals.values()])
    return dict(vals)


__all__ = ["SUPPORTED", "structure_code", "start_values", "refuse_leads",
           "apply_parameters"]
