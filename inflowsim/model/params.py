"""Named parameters and constants of the flap / inflow model.

Every quantity has one name used everywhere (code, C struct, FMI variable, CSV
column, JSON); the names are those of ``shared/spec/interface.md``.

Constants are aircraft data and the flight condition (never identified);
parameters are what identification estimates.  Both are validated here so that
every entry point refuses bad values with one line naming the quantity and the
allowed range.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Iterator, Mapping

from ..errors import InputError


class FrozenMap(Mapping):
    """An immutable, hashable ``{name: float}`` (trim values inside frozen constants)."""

    __slots__ = ("_d",)

    def __init__(self, items=()):
        object.__setattr__(self, "_d", {str(k): float(v) for k, v in dict(items).items()})

    def __getitem__(self, k):
        return self._d[k]

    def __iter__(self) -> Iterator[str]:
        return iter(self._d)

    def __len__(self):
        return len(self._d)

    def __hash__(self):
        return hash(tuple(sorted(self._d.items())))

    def __repr__(self):
        return f"FrozenMap({self._d!r})"

from ..physics.loads import MU_MIN  # noqa: E402  (a fact of the momentum theory)
#: No reverse-flow modelling: blade-element integrals assume ``U_T > 0`` over
#: most of the span.
MU_MAX = 0.5
#: Rotor speeds the model is built for [rad/s]: refused outside (a speed near zero
#: or 1e150 makes the azimuth-time scaling overflow), warned outside the plausible
#: range (full-scale main rotors 20-45 rad/s, tail and model rotors up to ~200).
OMEGA_RANGE = (0.5, 5000.0)
INFLOW_SPEEDS = ("mu", "mass-flow")
#: The trim thrust coefficient's range [-], open at 0 (:meth:`Constants.check`; the
#: FMU declares it and its mass-flow check is generated from it).
CT_RANGE = (0.0, 0.05)
#: The advance ratios of the mass-flow speed, hover included (likewise).
MASS_FLOW_MU = (0.0, MU_MAX)
OMEGA_PLAUSIBLE = (5.0, 200.0)


#: Kinds of rotor hub a record may name (``# hub:``, ``record-format.md``).
HUBS = ("articulated", "hingeless", "bearingless")


@dataclass(frozen=True)
class Constants:
    """Known aircraft data and flight condition.

    Parameters
    ----------
    mu : float
        Trim in-plane advance ratio [-].
    a0 : float
        Blade lift-curve slope [1/rad].
    solidity : float
        Rotor solidity ``s`` [-].
    omega : float
        Rotor speed [rad/s].
    radius : float, optional
        Blade radius [m]; informative only.
    trim : mapping, optional
        Trim totals by record column name (``theta0``, ``beta0``, ``mux`` ...)
        [rad, -]; only effects linearised about the trim state use them.
    hub : {"articulated", "hingeless", "bearingless"}, optional
        The rotor's hub (``# hub:`` in a record): the physically plausible range of
        the flap frequency follows it (:meth:`ParameterSpec.plausible_range`).
    ct : float, optional
        Trim thrust coefficient ``T / (rho pi R^2 (Omega R)^2)`` [-]; needed by the
        mass-flow speed.
    inflow_speed : {"mu", "mass-flow"}
        The speed through the disc in the momentum gains: ``"mu"`` (default) the
        paper's ``V ~ mu`` (forward flight, ``mu >= 0.1``, the presets bit for bit);
        ``"mass-flow"`` the momentum mass-flow parameter with the trim inflow
        (:func:`inflowsim.physics.loads.mass_flow_parameter`), finite from hover
        (``mu = 0``) to ``mu = 0.5``.
    """

    mu: float
    a0: float
    solidity: float
    omega: float
    radius: float | None = None
    trim: Mapping[str, float] | None = None
    ct: float | None = None
    inflow_speed: str = "mu"
    hub: str | None = None

    def __post_init__(self):
        if self.trim is not None and not isinstance(self.trim, FrozenMap):
            object.__setattr__(self, "trim", FrozenMap(self.trim))

    @property
    def a0s(self) -> float:
        """Lift slope times solidity ``a0 s`` [1/rad]."""
        return self.a0 * self.solidity

    def with_mu(self, mu: float) -> "Constants":
        return replace(self, mu=float(mu))

    @property
    def flow_speed(self) -> float:
        """Speed through the disc over ``Omega R`` in the momentum gains ``L`` and the
        apparent-mass time constants: ``mu``, or the mass-flow parameter."""
        if self.inflow_speed == "mass-flow":
            from ..physics.loads import mass_flow_parameter
            return mass_flow_parameter(self.mu, self.ct)
        return self.mu

    def as_dict(self) -> dict:
        d = {f.name: getattr(self, f.name) for f in fields(self)
             if getattr(self, f.name) is not None}
        if self.inflow_speed == "mu":
            d.pop("inflow_speed")           # the default: files stay as they were
        if self.trim is not None:
            d["trim"] = dict(self.trim)
        return d

    def with_trim(self, trim: Mapping[str, float]) -> "Constants":
        return replace(self, trim=FrozenMap(trim))

    def check(self) -> "Constants":
        """Raise :class:`InputError` naming the first bad constant."""
        if self.hub is not None and self.hub not in HUBS:
            raise InputError(f"hub = {self.hub!r}: choose {', '.join(HUBS)}")
        if self.inflow_speed not in INFLOW_SPEEDS:
            raise InputError(f"inflow_speed = {self.inflow_speed!r}: choose "
                             f"{' or '.join(INFLOW_SPEEDS)}")
        if self.ct is not None:
            _finite_in("ct", self.ct, *CT_RANGE, lower_open=True,
                       why="trim thrust coefficient")
        if self.inflow_speed == "mass-flow":
            if self.ct is None:
                raise InputError("inflow_speed 'mass-flow' needs the trim thrust "
                                 "coefficient ct")
            _finite_in("mu", self.mu, *MASS_FLOW_MU)
        else:
            _finite_in("mu", self.mu, MU_MIN, MU_MAX,
                       why="forward-flight local momentum (V ~ mu) needs fast forward "
                           "flight; the basic L matrix is singular at mu = 0 (the "
                           "mass-flow speed reaches hover)")
        _finite_in("a0", self.a0, 0.0, math.inf, lower_open=True)
        _finite_in("solidity", self.solidity, 0.0, 1.0, lower_open=True)
        _finite_in("omega", self.omega, OMEGA_RANGE[0], OMEGA_RANGE[1],
                   why="rotor speed in rad/s")
        if self.radius is not None:
            _finite_in("radius", self.radius, 0.0, math.inf, lower_open=True)
        for k, v in (self.trim or {}).items():
            _finite_in(f"trim {k}", v, -math.inf, math.inf)
        return self

    def warnings(self) -> list[str]:
        """Constants allowed but unusual for a rotor (a wrong unit, most often)."""
        out = []
        lo, hi = OMEGA_PLAUSIBLE
        if not lo <= self.omega <= hi:
            hint = (f"; if it is in rpm, omega = {self.omega * math.pi / 30:.4g} rad/s"
                    if self.omega > hi else "")
            out.append(f"omega = {self.omega:g} rad/s is outside the usual {lo:g}-{hi:g} "
                       f"rad/s of rotors{hint}")
        if not 2.0 <= self.a0 <= 7.0:
            out.append(f"a0 = {self.a0:g} /rad is outside the usual 2-7 /rad of lift "
                       "curve slopes")
        if not 0.01 <= self.solidity <= 0.3:
            out.append(f"solidity = {self.solidity:g} is outside the usual 0.01-0.3")
        if self.radius is not None and not 0.1 <= self.radius <= 30.0:
            out.append(f"radius = {self.radius:g} m is outside the usual 0.1-30 m")
        return out

    @classmethod
    def from_mapping(cls, m: Mapping) -> "Constants":
        """Build from a mapping holding ``mu, a0, omega`` and ``solidity`` or ``a0s``."""
        if not isinstance(m, Mapping):
            raise InputError(f"constants: must be an object of named numbers, not "
                             f"{type(m).__name__}")
        if m.get("trim") is not None and not isinstance(m["trim"], Mapping):
            raise InputError("constants: \"trim\" must be an object of named numbers")
        m = dict(m)
        if "solidity" not in m and "a0s" in m and "a0" in m:
            m["solidity"] = float(m["a0s"]) / float(m["a0"])
        missing = [k for k in ("mu", "a0", "solidity", "omega") if k not in m]
        if missing:
            raise InputError(f"constants: missing {', '.join(missing)} "
                             "(need mu, a0, solidity or a0s, omega)")
        try:
            c = cls(mu=float(m["mu"]), a0=float(m["a0"]), solidity=float(m["solidity"]),
                    omega=float(m["omega"]),
                    radius=None if m.get("radius") is None else float(m["radius"]),
                    trim=None if m.get("trim") is None else
                    {str(k): float(v) for k, v in dict(m["trim"]).items()},
                    ct=None if m.get("ct") is None else float(m["ct"]),
                    inflow_speed=str(m.get("inflow_speed", "mu")),
                    hub=None if m.get("hub") is None else str(m["hub"]).strip().lower())
        except (TypeError, ValueError) as exc:
            raise InputError(f"constants: not a number ({exc})") from None
        return c.check()


#: Puma at 100 kt, rotor speed 27.5 rad/s (model.md section 8); an articulated rotor.
PUMA = Constants(mu=0.249, a0=5.73, solidity=0.0917, omega=27.5, radius=7.5,
                 hub="articulated")


@dataclass(frozen=True)
class ParameterSpec:
    """A model parameter: canonical name, unit, meaning, allowed range, and the
    physically plausible range with its reason.

    ``lower``/``upper``/``lower_open`` bound what a model may be built with (one-line
    refusal outside); ``plausible = (low, high, why)`` is what physics expects
    (the diagnosis flags estimates outside it; ``plausible_seconds``: the range is
    in seconds for a time constant in azimuth units, to be divided by ``Omega``).
    The base parameters are declared here; each effect declares its own
    (``Effect.specs``), and the catalogue registers them.

    Attributes
    ----------
    name : str
        Canonical name.
    unit : str
        Unit (``rad``, ``-``, ``s``, ``azimuth rad`` for azimuth units).
    description : str
        Meaning.
    lower, upper : float
        Allowed range (in ``unit``).
    lower_open : bool
        ``lower`` itself excluded.
    plausible : tuple or None
        ``(low, high, why)``: the physically plausible range.
    plausible_seconds : bool
        The plausible range is in seconds (a time constant in azimuth units).
    plausible_by_hub : tuple
        Plausible ranges per hub type.
    physical : tuple or None
        ``(low, high, why)``: what the parameter can be at all for what it claims to
        be (a ``time-delay`` never leads); an estimate beyond it by more than three
        bounds makes the effect a stand-in (``inflowsim.diagnose.verdict``).
    """

    name: str
    unit: str
    description: str
    lower: float = -math.inf
    upper: float = math.inf
    lower_open: bool = False
    plausible: tuple | None = None
    plausible_seconds: bool = False
    #: ``((hub, (low, high, why)), ...)``: where the plausible range depends on the
    #: rotor's hub (:data:`HUBS`), the range for each; ``plausible`` covers them all
    #: and holds where the hub is not known
    plausible_by_hub: tuple = ()
    #: ``(low, high, why)``: what the parameter can be at all for what its effect
    #: claims to be (a measurement chain's delay cannot lead); ``None``: its
    #: allowed range.  An effect named with an estimate outside it is a stand-in
    #: (:mod:`inflowsim.diagnose.verdict`).
    physical: tuple | None = None

    def plausible_for(self, hub: str | None = None):
        """``(low, high, why)`` as declared (seconds for ``plausible_seconds``) for
        the rotor's ``hub``, or ``None``."""
        return dict(self.plausible_by_hub).get(hub, self.plausible)

    def plausible_range(self, omega: float | None = None, hub: str | None = None):
        """``(low, high, why)`` in the parameter's own unit, or ``None``: the range
        for ``hub`` where the parameter has one, else the one for every rotor."""
        rng = self.plausible_for(hub)
        if rng is None:
            return None
        lo, hi, why = rng
        if self.plausible_seconds:
            if not omega:
                return None
            lo, hi = lo * omega, hi * omega
        return lo, hi, why

    def check(self, value) -> float:
        return _finite_in(self.name, value, self.lower, self.upper, self.lower_open)

    def range_text(self) -> str:
        lo = "(" if self.lower_open else "["
        return f"{lo}{self.lower:g}, {self.upper:g}]"


def _finite_in(name, value, lower, upper, lower_open=False, why=None) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"{name}: {value!r} is not a number") from None
    lo = "(" if lower_open else "["
    rng = f"{lo}{lower:g}, {upper:g}]"
    if not math.isfinite(v):
        raise InputError(f"{name} = {v}: must be finite, in {rng}")
    if v < lower or v > upper or (lower_open and v == lower):
        msg = f"{name} = {v:g} is outside the allowed range {rng}"
        if why:
            msg += f": {why}"
        raise InputError(msg)
    return v


#: The base model's parameters (Eqs. 1-2); every other parameter is declared by the
#: effect that introduces it and registered here by the catalogue
#: (:mod:`inflowsim.model.effects`).
SPECS: dict[str, ParameterSpec] = {s.name: s for s in (
    ParameterSpec("lambda_beta2", "-", "normalised flap frequency squared", 0.0, 10.0,
                  True, (0.95, 1.4, "flap frequency squared lies near 1.0-1.1 for "
                                    "articulated rotors and 1.1-1.35 for hingeless and "
                                    "bearingless ones (the record's '# hub:' narrows it)"),
                  plausible_by_hub=(
                      ("articulated", (0.95, 1.12, "flap frequency squared of an "
                                                   "articulated rotor (hinge offset up to "
                                                   "6 %) lies near 1.0-1.1 (Puma theory "
                                                   "1.06)")),
                      ("hingeless", (1.05, 1.4, "flap frequency squared of a hingeless "
                                                "rotor lies near 1.1-1.35")),
                      ("bearingless", (1.05, 1.4, "flap frequency squared of a "
                                                  "bearingless rotor lies near 1.1-1.35")))),
    ParameterSpec("n_beta", "-", "inertia number gamma/8", 0.0, 10.0, True,
                  (0.5, 1.5, "inertia number gamma/8 for Lock numbers 4-12 (Puma theory "
                             "0.987)")),
    ParameterSpec("tau", "azimuth rad", "single inflow time constant", 0.0, 1e4, True,
                  (0.0, 1.0, "an inflow time constant above 1 s is not physical for this "
                             "rotor"), plausible_seconds=True),
)}


def register(spec: ParameterSpec) -> ParameterSpec:
    """Add a parameter introduced by a new effect (idempotent)."""
    old = SPECS.get(spec.name)
    if old is not None and old != spec:
        raise ValueError(f"parameter {spec.name} already registered differently")
    SPECS[spec.name] = spec
    return spec


def check_constants(constants) -> "Constants":
    """``constants`` checked (:meth:`Constants.check`); anything but a
    :class:`Constants` is refused naming what to give."""
    if not isinstance(constants, Constants):
        raise InputError(f"constants: a Constants is needed (inflowsim.PUMA, "
                         "Constants.from_mapping({...}) or a record's .constants), not "
                         f"{type(constants).__name__}")
    return constants.check()


def check_parameters(values: Mapping[str, float], names) -> dict[str, float]:
    """Return ``{name: float}`` for ``names``, refusing missing, unknown or bad values."""
    names = list(names)
    unknown = sorted(set(values) - set(names))
    if unknown:
        raise InputError(f"parameter {unknown[0]} is not a parameter of this structure "
                         f"(its parameters: {', '.join(names)})")
    missing = [n for n in names if n not in values]
    if missing:
        raise InputError(f"parameter {missing[0]} is missing")
    return {n: SPECS[n].check(values[n]) for n in names}


__all__ = ["FrozenMap", "MU_MAX", "CT_RANGE", "MASS_FLOW_MU", "OMEGA_RANGE", "INFLOW_SPEEDS",
           "OMEGA_PLAUSIBLE",
           "HUBS", "Constants", "PUMA", "ParameterSpec", "SPECS", "register",
           "check_constants", "check_parameters"]
