"""Parameter files (``interface.md``): ``{"structure", "constants", "parameters"}``.

A parameter is a number or ``{"estimate": x, "sigma": s}``; ``identify`` writes
the second form, and every reader takes both, so a fit feeds straight back into
``simulate``, ``validate`` and the FMU.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError
from .params import Constants
from .structure import Structure


@dataclass(frozen=True)
class ParameterSet:
    """A parameter file's content (:func:`read_parameters`).

    Attributes
    ----------
    structure : Structure
        The structure the parameters are for.
    constants : Constants or None
        The flight condition and rotor the file gives (``mu`` [-], ``omega``
        [rad/s] ...), or ``None``.
    parameters : dict of str to float
        The parameters (SI; angles [rad], time constants in azimuth units [-]).
    sigma : dict of str to float or None
        Their 1-sigma bounds (same units), ``None`` where not given.
    source : str
        Where they were read from.
    """

    structure: Structure
    constants: Constants | None
    parameters: dict
    sigma: dict
    source: str = "parameter file"

    def warnings(self) -> list[str]:
        """Constants allowed but unusual (``omega`` in rpm ...), as a record's
        :meth:`~inflowsim.data.record.Record.warnings` gives them."""
        if self.constants is None:
            return []
        return [f"{self.source}: {w}" for w in self.constants.warnings()]

    def model(self, constants: Constants | None = None):
        from .build import build_model
        k = constants or self.constants
        if k is None:
            raise InputError("parameter file has no constants and none were given")
        return build_model(self.structure, self.parameters, k)

    def to_json(self, extra: dict | None = None) -> dict:
        doc = {"structure": self.structure.name,
               "effects": list(self.structure.effects)}
        if self.constants is not None:
            doc["constants"] = self.constants.as_dict()
        doc["parameters"] = {
            n: ({"estimate": v, "sigma": self.sigma[n]} if n in self.sigma else v)
            for n, v in self.parameters.items()}
        if extra:
            doc.update(extra)
        return doc


def parse_parameter_doc(doc, where="parameter file") -> ParameterSet:
    if not isinstance(doc, dict) or "parameters" not in doc or "structure" not in doc:
        raise InputError(f"{where}: needs \"structure\" and \"parameters\"")
    if not isinstance(doc["structure"], str):
        raise InputError(f"{where}: \"structure\" must be a string such as "
                         "\"glauert+time-delay\"")
    s = Structure.parse(doc["structure"])
    if "effects" in doc:
        eff = doc["effects"]
        if not isinstance(eff, list) or not all(isinstance(e, str) for e in eff):
            raise InputError(f"{where}: \"effects\" must be a list of effect names")
        twice = next((e for i, e in enumerate(eff) if e in eff[:i]), None)
        if twice is not None:
            raise InputError(f"{where}: \"effects\" lists {twice} twice")
        if set(eff) != set(s.effects):
            # "structure" is the file's required field; "effects" repeats it (identify
            # writes both).  Files that disagree were edited in one place: which one
            # is meant is a guess, so neither wins.
            raise InputError(f"{where}: \"structure\" {doc['structure']!r} has the "
                             f"effects [{', '.join(s.effects)}] but \"effects\" lists "
                             f"[{', '.join(eff)}]; make them agree or drop \"effects\"")
    consts = None
    if doc.get("constants"):
        consts = Constants.from_mapping(_constants_numbers(doc["constants"], where))
    params, sigma = {}, {}
    if not isinstance(doc["parameters"], dict):
        raise InputError(f"{where}: \"parameters\" must be an object")
    for name, v in doc["parameters"].items():
        if isinstance(v, dict):
            if "estimate" not in v:
                raise InputError(f"{where}: parameter {name} has no \"estimate\"")
            params[name] = _strict(v["estimate"], f"{where}: parameter {name} estimate")
            if v.get("sigma") is not None:
                sigma[name] = _number(v["sigma"], f"{where}: parameter {name} sigma")
        else:
            params[name] = _strict(v, f"{where}: parameter {name}")
    from .params import check_parameters
    params = check_parameters(params, s.parameters)
    return ParameterSet(s, consts, params, sigma, where)


#: Constants that are text, not numbers (:class:`~inflowsim.model.params.Constants`).
_TEXT_CONSTANTS = ("inflow_speed", "hub")


def _strict(v, what):
    """A JSON number as it is (range checks follow); text and true/false refused:
    ``"27.5"`` is a string in JSON, and ``true`` is not 1 for a parameter."""
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        hint = " (write it without quotes)" if isinstance(v, str) else ""
        raise InputError(f"{what}: {json.dumps(v)} is not a number{hint}")
    return v


def _constants_numbers(m, where):
    """``m`` with every number a JSON number (the shape of ``m`` and of its ``trim``
    is :meth:`Constants.from_mapping`'s to check)."""
    if not isinstance(m, dict):
        return m
    for k, v in m.items():
        if k in _TEXT_CONSTANTS or v is None or (k == "trim" and not isinstance(v, dict)):
            continue
        if k == "trim":
            for c, x in v.items():
                _strict(x, f"{where}: constants trim {c}")
        else:
            _strict(v, f"{where}: constants {k}")
    return m


def _number(v, what) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise InputError(f"{what}: {v!r} is not a number")
    x = float(v)
    if not math.isfinite(x) or x < 0:
        raise InputError(f"{what}: {v!r} must be a finite number >= 0")
    return x


def read_parameters(path) -> ParameterSet:
    """Read and validate a parameter file; errors name the file and the problem.

    Parameters
    ----------
    path : path-like
        A parameter file (JSON; ``identify --out`` writes one).
    """
    from ..fileio import parse_json, read_input_text
    p = Path(path)
    text = read_input_text(p, "parameter file", "json")
    doc = parse_json(text, str(p), parse_constant=lambda c: math.nan)
    try:
        return parse_parameter_doc(doc, str(p))
    except InputError as exc:
        msg = str(exc)
        raise InputError(msg if msg.startswith(str(p)) else f"{p}: {msg}") from None


def write_json(doc: dict, path, overwrite: bool = False, protect=()) -> Path:
    """Write JSON atomically (temp file, then rename); refuse to replace an
    existing file unless ``overwrite``, and never a path in ``protect``."""
    from ..fileio import json_text, safe_write_text
    return safe_write_text(path, json_text(doc), overwrite, protect)


__all__ = ["ParameterSet", "parse_parameter_doc", "read_parameters", "write_json"]
