"""``hub-velocity-coupling``: empirical forcing ``K mu_xy`` of the inflow, Eq. (13)."""
import numpy as np

from ._effect import Effect, ParameterSpec

NAMES = ("k01", "k02", "k11", "k12", "k21", "k22")


def _equations(eq, p, k):
    p_u = eq.p_u.copy()
    p_u[:, 8:10] += np.array([p[n] for n in NAMES]).reshape(3, 2)
    return eq.with_(p_u=p_u)


EFFECT = Effect(
    name="hub-velocity-coupling",
    physics="In-plane hub velocity perturbations (mux, muy) change the inflow through "
            "a free empirical gain matrix K.",
    paper="Eq. (13)",
    parameters=NAMES,
    theory=lambda k: dict.fromkeys(NAMES, 0.0),
    equations=_equations,
    specs=tuple(ParameterSpec(n, "-", f"empirical K element ({n[1]},{n[2]}) (Eq. 13)",
                              plausible=(-5.0, 5.0, "an empirical inflow gain this large "
                                                    "is not physical")) for n in NAMES),
    uses_inplane=True,
    alternatives=("glauert",),
)


__all__ = ["NAMES", "EFFECT"]
