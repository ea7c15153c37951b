"""``flap-inertia``: keep the multiblade flap second derivatives (second-order flapping).

The single-blade ``beta_i''`` projects onto ``beta0''``, ``beta1c'' + 2 beta1s' -
beta1c`` and ``beta1s'' - 2 beta1c' - beta1s`` (``model.md`` section 2).  The paper's
first-order Eq. (1) keeps the rotating-frame terms (in ``C`` and ``D``) and drops
the ``''`` terms; this effect restores them, scaled by ``flap_inertia``:

``flap_inertia beta'' + C beta' + D beta = H_lambda lambda + H_theta theta + H_nu nu
+ H_eta eta``

with the same right-hand side.  The state grows by ``beta' = (beta0_prime,
beta1c_prime, beta1s_prime)`` (nine states, appended so the outputs stay the first
six) and every ``beta'`` term of the inflow equation (the loads' ``L G_beta'`` and
the Glauert ``-beta1s'``, ``-beta1c'`` of ``p*``, ``q*``) moves from ``E21`` into
``A`` (:func:`inflowsim.model.equations.assemble`).

Parameter ``flap_inertia`` [-]: the coefficient of ``beta''``.  Its theory value is
exactly 1: the flap equation is normalised by the blade's own flap inertia
``I_beta Omega^2``, the normalisation that defines ``lambda_beta2`` and ``n_beta``.
It exists to make the test of the effect *nested*: as ``flap_inertia -> 0`` the
three fast flap modes (``-C / flap_inertia``) leave every band and the model
tends to the paper's first-order one, so the structure without the effect is
the boundary ``flap_inertia = 0`` of the one with it.  The end states of the
fit are taken on the slow manifold (``beta'`` quasi-steady, :mod:`inflowsim.model`)
so that the limit holds for the record's end effects too.  The likelihood-ratio
statistic of a parameter on the boundary of its range is distributed as the
50:50 mixture of chi-square with 0 and 1 degree of freedom (Chernoff, 1954;
Self and Liang, 1987): :mod:`inflowsim.diagnose.rule` uses that.  The search keeps
``flap_inertia >= FLOOR`` (1e-6: the first-order model to a part in a million).
"""
import numpy as np

from ._effect import Effect
from ..params import ParameterSpec

#: The smallest flap_inertia a model is built with: the first-order limit.
FLOOR = 1e-6


def _equations(eq, p, k):
    return eq.with_(m2=p["flap_inertia"] * np.eye(3))


EFFECT = Effect.of_one(
    name="flap-inertia",
    physics="The blades' own flap inertia: the multiblade flap second derivatives "
            "that first-order flapping drops matter near the flap regressing mode "
            "(second-order flapping, nine states).",
    paper="Section 2 (terms neglected in Eq. 1)",
    theory=1.0,
    neutral=FLOOR,
    equations=_equations,
    spec=ParameterSpec("flap_inertia", "-", "coefficient of the multiblade flap second "
                       "derivatives (1: the blades' own inertia; 0: first-order "
                       "flapping)", FLOOR, 10.0, plausible=(0.5, 1.5, "the flap equation "
                       "is normalised by the blade's own inertia: theory 1")),
    second_order=True,
    boundary=("flap_inertia",),
)


__all__ = ["FLOOR", "EFFECT"]
