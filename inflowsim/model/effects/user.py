"""Effects written outside the package: loaded from a Python file or an installed
package, checked, and registered beside the catalogue's.

A user effect is an :class:`~inflowsim.model.effects.Effect` exactly like the
catalogue's (``docs/workflow.md``, "Writing your own effect"): a name, one
sentence of physics, where it comes from, its parameters with a
:class:`~inflowsim.model.params.ParameterSpec` each (unit, description, allowed and
plausible range), the theory and neutral values, and its contribution to the
structured equations and the measurement map as pure functions.  A file defines
``EFFECT`` (or ``EFFECTS``, a sequence); an installed package names one in the
entry-point group ``inflowsim.model.effects`` (the object, or a module defining
``EFFECT``/``EFFECTS``).  Once registered it is a candidate like any other
(offered to the diagnosis unless ``offered=False``).

:func:`check_effect` refuses, with one line naming the source and the problem, an
effect with a missing or malformed field, a name or parameter that clashes with
the catalogue, theory or neutral values outside the parameter's range, equations or
a measurement of the wrong shape or not finite, or neutral values that change the
model (the diagnosis starts every candidate there: it must be the structure
without the effect).
"""
from __future__ import annotations

import hashlib
import importlib.util
import re
import sys
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from ...errors import InputError
from ...fileio import read_input_bytes
from ..build import base_equations
from ..equations import Equations, Measurement
from ..params import PUMA, SPECS, ParameterSpec
from ..presets import theory_parameters
from ..structure import BASE_PARAMETERS, PRESETS
from . import CATALOGUE, LOADERS, register
from ._effect import Effect

__all__ = ["check_effect", "load_effect_file", "load_effect_files", "load_installed",
           "register_user", "unregister", "registered", "USER_EFFECTS", "ENTRY_POINT_GROUP"]

#: Entry-point group an installed package names its effects in.
ENTRY_POINT_GROUP = "inflowsim.model.effects"
#: ``{effect name: where it came from}`` of the registered user effects.
USER_EFFECTS: dict[str, str] = {}
_NAME = re.compile(r"^[a-z][a-z0-9]*(-[a-z0-9]+)*$")
_PARAM = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_installed_loaded = False


#: A level-flight trim (totals, record columns) at which an effect linearised about
#: trim can be tried: collective 0.17 rad, small cyclic and flap, no climb.
REFERENCE_TRIM = {"theta0": 0.17, "theta1c": 0.01, "theta1s": -0.05, "muz": 0.0,
                  "beta0": 0.06, "beta1c": 0.01, "beta1s": -0.002}


def _reference_constants():
    """Puma at 100 kt with :data:`REFERENCE_TRIM`: where an effect is tried."""
    return PUMA.with_trim(dict(REFERENCE_TRIM, mux=PUMA.mu, muy=0.0))


def _call(src, name, what, fn, *args):
    try:
        return fn(*args)
    except InputError as exc:
        raise InputError(f"{src}: effect {name}: {what}: {exc}") from None
    except Exception as exc:                       # the user's code: any failure
        raise InputError(f"{src}: effect {name}: {what} raised "
                         f"{type(exc).__name__}: {exc}") from None


def _values(src, name, what, fn, k, params, specs):
    vals = _call(src, name, what, fn, k)
    if not isinstance(vals, dict) or set(vals) != set(params):
        got = sorted(vals) if isinstance(vals, dict) else type(vals).__name__
        raise InputError(f"{src}: effect {name}: {what} must return a dict of its "
                         f"parameters {list(params)}, got {got}")
    out = {}
    for n, v in vals.items():
        try:
            out[n] = specs[n].check(v)
        except InputError as exc:
            raise InputError(f"{src}: effect {name}: {what} value {exc}") from None
    return out


def _same_blocks(src, name, what, base: Equations, eq):
    if not isinstance(eq, Equations):
        raise InputError(f"{src}: effect {name}: equations at the {what} values must "
                         f"return an Equations (eq.with_(...)), got {type(eq).__name__}")
    for f in base.__dataclass_fields__:
        a = np.asarray(getattr(eq, f))
        ref = np.asarray(getattr(base, f))
        if a.shape != ref.shape:
            raise InputError(f"{src}: effect {name}: equations at the {what} values: block "
                             f"{f} has shape {a.shape}, must be {ref.shape}")
        try:
            ok = np.all(np.isfinite(a.astype(float)))
        except (TypeError, ValueError):
            ok = False
        if not ok:
            raise InputError(f"{src}: effect {name}: equations at the {what} values: block "
                             f"{f} is not finite numbers")


def _same_measurement(src, name, what, m):
    if not isinstance(m, Measurement):
        raise InputError(f"{src}: effect {name}: measurement at the {what} values must "
                         f"return a Measurement (m.with_(...)), got {type(m).__name__}")
    if m.flap_map is not None:
        fm = np.asarray(m.flap_map)
        if fm.shape != (3, 6) or not np.all(np.isfinite(fm.astype(float))):
            raise InputError(f"{src}: effect {name}: measurement at the {what} values: "
                             f"flap_map must be a finite 3x6 array (recorded beta0, beta1c, "
                             f"beta1s by beta, lambda), got shape {fm.shape}")
    if len(tuple(m.delays)) != 3:
        raise InputError(f"{src}: effect {name}: measurement: delays must hold 3 values")


def check_effect(effect, source: str) -> Effect:
    """Refuse a malformed user effect with one line naming ``source``; return it.

    See the module's description for what is checked.  The effect is tried on the
    basic model at the Puma's 100 kt flight condition, trim :data:`REFERENCE_TRIM`.
    """
    src = source
    if not isinstance(effect, Effect):
        raise InputError(f"{src}: EFFECT must be an inflowsim.model.effects.Effect, got "
                         f"{type(effect).__name__}")
    name = effect.name
    if not isinstance(name, str) or not _NAME.match(name):
        raise InputError(f"{src}: effect name {name!r}: use lower-case words joined by "
                         "'-' (e.g. pitch-flap-coupling)")
    if name in PRESETS or (name in CATALOGUE and USER_EFFECTS.get(name) != src):
        where = USER_EFFECTS.get(name, "the catalogue")
        raise InputError(f"{src}: effect name {name!r} clashes with {where}")
    for f in ("physics", "paper"):
        v = getattr(effect, f)
        if not isinstance(v, str) or not v.strip():
            raise InputError(f"{src}: effect {name}: field {f!r} must be a non-empty "
                             "sentence")
    params = effect.parameters
    if not isinstance(params, tuple) or not params:
        raise InputError(f"{src}: effect {name}: parameters must be a non-empty tuple of "
                         "names")
    for p in params:
        if not isinstance(p, str) or not _PARAM.match(p):
            raise InputError(f"{src}: effect {name}: parameter name {p!r} is not an "
                             "identifier")
    if len(set(params)) != len(params):
        raise InputError(f"{src}: effect {name}: a parameter is named twice")
    specs = {}
    for s in effect.specs:
        if not isinstance(s, ParameterSpec):
            raise InputError(f"{src}: effect {name}: specs must be ParameterSpec objects")
        specs[s.name] = s
    for p in params:
        if p not in specs:
            raise InputError(f"{src}: effect {name}: parameter {p} has no ParameterSpec "
                             "(unit, description, range) in specs")
        s = specs[p]
        if not (isinstance(s.unit, str) and s.unit and isinstance(s.description, str)
                and s.description.strip()):
            raise InputError(f"{src}: effect {name}: parameter {p}: give its unit and a "
                             "description")
        if s.plausible is None or len(s.plausible) != 3 or not s.plausible[0] <= \
                s.plausible[1]:
            raise InputError(f"{src}: effect {name}: parameter {p}: give a plausible range "
                             "(low, high, why)")
        old = SPECS.get(p)
        if p in BASE_PARAMETERS or (old is not None and old != s):
            raise InputError(f"{src}: effect {name}: parameter {p} clashes with a "
                             "parameter of the model or the catalogue")
    if set(specs) - set(params):
        raise InputError(f"{src}: effect {name}: specs for parameters it does not have: "
                         f"{', '.join(sorted(set(specs) - set(params)))}")
    for f in ("theory", "equations", "measurement"):
        if not callable(getattr(effect, f)):
            raise InputError(f"{src}: effect {name}: {f} must be a function")
    if effect.neutral is not None and not callable(effect.neutral):
        raise InputError(f"{src}: effect {name}: neutral must be a function")
    for r in effect.removes:
        if r not in BASE_PARAMETERS:
            raise InputError(f"{src}: effect {name}: removes {r!r}, not a base parameter "
                             f"({', '.join(BASE_PARAMETERS)})")
    _try(effect, src, specs)
    return effect


def _try(effect, src, specs):
    """Apply the effect to the basic model at its theory and neutral values."""
    name = effect.name
    k = _reference_constants()
    theory = _values(src, name, "theory", effect.theory, k, effect.parameters, specs)
    neutral = _values(src, name, "neutral", effect.neutral_values, k, effect.parameters,
                      specs)
    base_p = {n: v for n, v in theory_parameters("basic", k).items()}
    base = base_equations(base_p, k)
    for what, vals in (("theory", theory), ("neutral", neutral)):
        p = {**base_p, **vals}
        eq = _call(src, name, f"equations at the {what} values", effect.equations,
                   base, p, k)
        _same_blocks(src, name, what, base, eq)
        m = _call(src, name, f"measurement at the {what} values", effect.measurement,
                  Measurement(), p, k)
        _same_measurement(src, name, what, m)
        if what == "neutral" and not effect.removes:
            changed = [f for f in base.__dataclass_fields__
                       if not np.allclose(np.asarray(getattr(eq, f), float),
                                          np.asarray(getattr(base, f), float),
                                          rtol=1e-12, atol=1e-14)]
            fm = m.flap_map
            if fm is not None and np.any(np.asarray(fm, float) != 0):
                changed.append("flap_map")
            if m.azimuth_bias != 0 or any(d != 0 for d in m.delays) or \
                    any(d for _, d in m.input_delays):
                changed.append("measurement")
            if changed:
                raise InputError(f"{src}: effect {name}: its neutral values change the "
                                 f"model ({', '.join(changed)}); at neutral the effect "
                                 "must change nothing")


def register_user(effect, source: str) -> Effect:
    """Check and register a user effect (idempotent for the same source)."""
    effect = check_effect(effect, source)
    if USER_EFFECTS.get(effect.name) == source:
        return effect
    register(effect)
    USER_EFFECTS[effect.name] = source
    return effect


def unregister(name: str) -> None:
    """Remove a user effect and its parameters (the catalogue's stay).

    Parameters
    ----------
    name : str
        The user effect's name.
    """
    if name not in USER_EFFECTS:
        raise InputError(f"{name} is not a user effect")
    eff = CATALOGUE.pop(name)
    for p in eff.parameters:
        SPECS.pop(p, None)
    del USER_EFFECTS[name]


@contextmanager
def registered(*effects, source="<memory>"):
    """Register effects for the duration of a ``with`` block (tests, scripts).

    Parameters
    ----------
    *effects : Effect
        The effects.
    source : str
        Where they come from (named in refusals).
    """
    names = []
    try:
        for e in effects:
            register_user(e, source)
            names.append(e.name)
        yield effects
    finally:
        for n in names:
            if n in USER_EFFECTS:
                unregister(n)


def _effects_of(obj, src):
    """The effects an imported module or entry-point object provides."""
    if isinstance(obj, Effect):
        return [obj]
    if isinstance(obj, (list, tuple)):
        return list(obj)
    found = []
    if hasattr(obj, "EFFECT"):
        found.append(obj.EFFECT)
    if hasattr(obj, "EFFECTS"):
        found.extend(obj.EFFECTS)
    if not found:
        raise InputError(f"{src}: defines no EFFECT (an inflowsim.model.effects.Effect) "
                         "or EFFECTS")
    return found


def load_effect_file(path) -> tuple:
    """Import a Python file and register the effect(s) it defines.

    Refuses (one line naming the file) a missing file, a syntax error, an import
    that fails, no ``EFFECT``, and anything :func:`check_effect` refuses.

    Parameters
    ----------
    path : path-like
        A Python file defining ``EFFECT`` (or ``EFFECTS``).
    """
    p = Path(path)
    src = str(path)
    if p.suffix != ".py":
        raise InputError(f"{src}: an effect file is Python source ending in .py")
    text = read_input_bytes(p, "effect file", "effect")
    tag = hashlib.sha1(str(p.resolve()).encode()).hexdigest()[:10]
    modname = f"inflowsim_user_effect_{re.sub(r'[^0-9a-zA-Z_]', '_', p.stem)}_{tag}"
    if modname in sys.modules:
        module = sys.modules[modname]
    else:
        try:
            code = compile(text, src, "exec")
        except SyntaxError as exc:
            raise InputError(f"{src}: syntax error at line {exc.lineno}: {exc.msg}") \
                from None
        spec = importlib.util.spec_from_file_location(modname, p)
        module = importlib.util.module_from_spec(spec)
        sys.modules[modname] = module
        try:
            exec(code, module.__dict__)
        except SystemExit as exc:        # sys.exit() at import: not an effect's doing
            del sys.modules[modname]
            raise InputError(f"{src}: importing it called sys.exit({exc.code!r}); an "
                             "effect file defines EFFECT and must not exit") from None
        except Exception as exc:
            del sys.modules[modname]
            raise InputError(f"{src}: importing it raised {type(exc).__name__}: "
                             f"{' '.join(str(exc).split())}") from None
    try:
        found = _effects_of(module, src)
        return tuple(register_user(e, src) for e in found)
    except InputError:
        sys.modules.pop(modname, None)
        raise


def load_installed() -> tuple:
    """Register the effects installed packages name in the ``inflowsim.model.effects``
    entry-point group (once per process)."""
    global _installed_loaded
    if _installed_loaded:
        return ()
    _installed_loaded = True
    from importlib.metadata import entry_points
    out = []
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        src = f"entry point {ep.name} ({ep.value})"
        try:
            obj = ep.load()
        except Exception as exc:
            raise InputError(f"{src}: loading it raised {type(exc).__name__}: {exc}") \
                from None
        out += [register_user(e, src) for e in _effects_of(obj, src)]
    return tuple(out)


def load_effect_files(paths=()) -> tuple:
    """Installed effects, then each of ``paths`` (``--effect-file``, repeatable).

    Parameters
    ----------
    paths : iterable of path-like
        Python files defining effects (``--effect-file``).
    """
    out = list(load_installed())
    for path in paths or ():
        out += load_effect_file(path)
    return tuple(out)


# an installed package's effects load when a structure first names one
LOADERS.append(load_installed)
