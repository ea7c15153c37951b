"""``azimuth-bias``: the recorded azimuth is offset by ``azimuth_bias`` (section 2.3).

Recorded cyclic flap and pitch are the true ones rotated (``model.md`` section 6):
the model takes recorded pitch, so the true pitch ``R(-dpsi) theta_m`` drives it,
and its flap output is rotated by ``R(dpsi)``.  One parameter, several matrix
elements: the paper's "relationships between elements".
"""
import math

from ._effect import Effect, ParameterSpec
from ..equations import rotation


def _equations(eq, p, k):
    r = rotation(-p["azimuth_bias"])
    h_u, p_u = eq.h_u.copy(), eq.p_u.copy()
    h_u[:, 1:3] = eq.h_u[:, 1:3] @ r
    p_u[:, 1:3] = eq.p_u[:, 1:3] @ r
    return eq.with_(h_u=h_u, p_u=p_u)


def _measurement(m, p, k):
    return m.with_(azimuth_bias=p["azimuth_bias"])


EFFECT = Effect.of_one(
    name="azimuth-bias",
    physics="The recorded blade azimuth is offset, so recorded cyclic flap and pitch "
            "are rotated copies of the true ones: a phase error shared by beta1c and "
            "beta1s.",
    paper="Section 2.3",
    theory=0.0,
    equations=_equations,
    spec=ParameterSpec("azimuth_bias", "rad", "offset of the recorded blade azimuth",
                       -math.pi, math.pi, plausible=(-0.5, 0.5, "an azimuth offset over "
                                                     "30 deg points at a wiring or sign "
                                                     "error, not a bias")),
    measurement=_measurement,
)


__all__ = ["EFFECT"]
