"""``flap-inertia``: keep the multiblade flap second derivatives (second-order flapping).

The single-blade ``beta_i''`` projects onto ``beta0''``, ``beta1c'' + 2 beta1s' -
beta1c`` and ``beta1s'' - 2 beta1c' - beta1s`` (``model.md`` section 2).  The paper's
first-order Eq. (1) keeps the rotating-frame terms (in ``C`` and ``D``) and drops
the ``''`` terms; this effect restores them:

``beta'' + C beta' + D beta = H_lambda lambda + H_theta theta + H_nu nu + H_eta eta``

with the same right-hand side.  The state grows by ``beta' = (beta0_prime,
beta1c_prime, beta1s_prime)`` (nine states, appended so the outputs stay the first
six) and every ``beta'`` term of the inflow equation (the loads' ``L G_beta'`` and
the Glauert ``-beta1s'``, ``-beta1c'`` of ``p*``, ``q*``) moves from ``E21`` into
``A`` (:func:`inflowsim.equations.assemble`).

No parameter.  The coefficient of ``beta''`` is exactly 1: the flap equation is
normalised by the blade's own flap inertia ``I_beta Omega^2``, the same
normalisation that defines ``lambda_beta2`` and ``n_beta``, so a scale on the
``''`` terms would have no physical uncertainty to estimate.  Nor would it nest:
at scale 0 the descriptor matrix ``E`` is singular (the first-order model is a
singular limit, not a parameter value), so a chi-square test on it would be
meaningless.  Compare the two structures by cost and fit instead (same number of
parameters).
"""
import numpy as np

from ._effect import Effect


def _equations(eq, p, k):
    # The core also sets m2 = I for any second-order structure; set here so the
    # effect says what it does on its own.
    return eq.with_(m2=np.eye(3))


EFFECT = Effect(
    name="flap-inertia",
    physics="The blades' own flap inertia: the multiblade flap second derivatives "
            "that first-order flapping drops matter near the flap regressing mode "
            "(second-order flapping, nine states).",
    paper="Section 2 (terms neglected in Eq. 1)",
    parameters=(),
    theory=lambda k: {},
    equations=_equations,
    second_order=True,
)
