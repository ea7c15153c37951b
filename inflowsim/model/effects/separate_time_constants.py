"""``separate-time-constants``: ``D_tau* = diag(tau0, tau_cs, tau_cs)``, Eq. (13)."""
import numpy as np

from ._effect import Effect
from ...physics.theory import pitt_peters_time_constants


def _equations(eq, p, k):
    return eq.with_(d_tau=np.diag([p["tau0"], p["tau_cs"], p["tau_cs"]]))


def _theory(k):
    tau0, tau_cs = pitt_peters_time_constants(k.mu)
    return {"tau0": tau0, "tau_cs": tau_cs}


EFFECT = Effect(
    name="separate-time-constants",
    physics="The mean inflow lambda0 and the cyclic inflow lambda1c, lambda1s settle "
            "with their own time constants tau0 and tau_cs instead of one shared tau.",
    paper="Eq. (13)",
    parameters=("tau0", "tau_cs"),
    theory=_theory,
    equations=_equations,
    plausible=lambda k: {n: (0.0, 2.0 * k.omega, "inflow time constants are below "
                             "about 2 s (azimuth units: 2 s x omega)")
                         for n in ("tau0", "tau_cs")},
    removes=("tau",),
)
