"""A-priori (theory) values: the Puma's and the Pitt-Peters apparent mass."""
from __future__ import annotations

import math

#: Puma theory values (model.md section 8; the paper's Tables 1-3, last column).
PUMA_LAMBDA_BETA2 = 1.06
PUMA_N_BETA = 0.987


def pitt_peters_time_constants(mu: float) -> tuple[float, float]:
    """Inflow time constants from the Pitt-Peters apparent mass at speed ``mu``
    through the disc (``V ~ mu``, or a mass-flow parameter passed in its place).

    ``tau0 = (8/(3 pi)) / (2 V)`` and ``tau_cs = (16/(45 pi)) (2/V)`` [azimuth rad]:
    the apparent-mass matrix ``diag(8/(3 pi), 16/(45 pi), 16/(45 pi))`` times the
    local-momentum gains ``diag(1/(2V), 2/V, 2/V)`` of ``L/(a0 s)``.  The paper
    gives no theory value; these are starting values, not the paper's estimates.
    """
    return 4.0 / (3.0 * math.pi * mu), 32.0 / (45.0 * math.pi * mu)


__all__ = ["PUMA_LAMBDA_BETA2", "PUMA_N_BETA", "pitt_peters_time_constants"]
