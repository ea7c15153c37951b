"""``separate-time-constants``: ``D_tau* = diag(tau0, tau_cs, tau_cs)``, Eq. (13)."""
import numpy as np

from ._effect import Effect, ParameterSpec
from ...physics.theory import pitt_peters_time_constants


def _equations(eq, p, k):
    return eq.with_(d_tau=np.diag([p["tau0"], p["tau_cs"], p["tau_cs"]]))


def _theory(k):
    tau0, tau_cs = pitt_peters_time_constants(k.flow_speed)
    return {"tau0": tau0, "tau_cs": tau_cs}


EFFECT = Effect(
    name="separate-time-constants",
    physics="The mean inflow lambda0 and the cyclic inflow lambda1c, lambda1s settle "
            "with their own time constants tau0 and tau_cs instead of one shared tau.",
    paper="Eq. (13)",
    parameters=("tau0", "tau_cs"),
    theory=_theory,
    equations=_equations,
    specs=(ParameterSpec("tau0", "azimuth rad", "time constant of lambda0", 0.0, 1e4, True,
                         (0.0, 0.3, "the mean inflow settles within a few rotor "
                                    "revolutions"), plausible_seconds=True),
           ParameterSpec("tau_cs", "azimuth rad", "time constant of lambda1c, lambda1s",
                         0.0, 1e4, True, (0.0, 1.0, "the cyclic inflow time constant should "
                                                    "be below about 1 s"),
                         plausible_seconds=True)),
    removes=("tau",),
)


__all__ = ["EFFECT"]
