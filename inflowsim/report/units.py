"""Units as people read them in reports: angles in degrees (inflowsim computes in
radians), every column and row naming its unit, ``[-]`` for a dimensionless one.

The plots show flap, pitch and phase in degrees; the tables beside them use the same
unit, converted here and nowhere else."""
from __future__ import annotations

import math

#: Degrees per radian.
DEG = 180.0 / math.pi

#: Units shown for a parameter whose declared unit is in the first column.
_SHOWN = {"rad": "deg", "-": "-", "s": "s", "azimuth rad": "azimuth rad"}


def parameter_unit(name: str) -> str | None:
    """The unit a report shows ``name`` in (``deg`` for an angle declared in rad), or
    ``None`` for a name with no declared unit."""
    from ..model.params import SPECS
    spec = SPECS.get(name)
    if spec is None:
        return None
    return _SHOWN.get(spec.unit, spec.unit)


def parameter_label(name: str) -> str:
    """``"azimuth_bias [deg]"``: the name with the unit its values are shown in."""
    unit = parameter_unit(name)
    return name if unit is None else f"{name} [{unit}]"


def parameter_value(name: str, value):
    """``value`` (SI, as estimated) in the unit of :func:`parameter_label`; ``None``
    stays ``None``."""
    if value is None:
        return None
    from ..model.params import SPECS
    spec = SPECS.get(name)
    return value * DEG if spec is not None and spec.unit == "rad" else value


__all__ = ["DEG", "parameter_unit", "parameter_label", "parameter_value"]
