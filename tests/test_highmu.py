"""Why the Eq. (14) truth's joint fits sit 2-3 bounds off at mu 0.35 whatever the
amplitude (``bench/amplitude.md``, "High mu"; ``bench/highmu.py``): the campaign's
nine records at 0.25 deg, the noise scaled with the amplitude, flown from twins of
the truth with the same inputs and noise draws and fitted with the structure that
holds its physics."""
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))

from amplitude import NOISE, SEED_STEP, fit_row, with_noise  # noqa: E402
from highmu import SHAPES, records  # noqa: E402

MU, AMPLITUDE, SEEDS = 0.35, 0.25, 5
HELD = ("tau0", "tau_cs", "lambda_beta2", "n_beta")


def _z(which):
    items, clean = records(which, MU, AMPLITUDE, lambda m: None)
    z = {n: [] for n in HELD}
    for k in range(SEEDS):
        recs = [with_noise(r, NOISE * AMPLITUDE, (it.seed + k * SEED_STEP) % 2**32)
                for it, r in zip(items, clean)]
        row = fit_row(recs, MU, AMPLITUDE, "scaled", NOISE * AMPLITUDE, k, SHAPES)
        for n in HELD:
            z[n].append((row["estimate"][n] - row["truth"][n]) / row["sigma"][n])
    return {n: np.array(v) for n, v in z.items()}


@pytest.mark.slow
def test_the_high_mu_bias_is_the_dynamic_flap_harmonics_and_the_body():
    """About 100 s.  The truth's averaged system with each blade's flap kept to
    harmonic 2, condensed quasi-steadily as second-harmonic-flap does, fits within
    1.2 bounds on average (measured, 5 seeds: within 0.82); kept to harmonic 3 as
    states it puts tau0 lower and lambda_beta2 higher by more than 0.8 bounds on
    the same noise (measured -1.3, +1.4): the higher harmonics' own dynamics.  The
    truth puts n_beta more than 2 bounds high (+3.2); with the hub fixed less than
    1.5 (+1.0): the rest is the body's quadratic response."""
    qs, k3 = _z("K2qs"), _z("K3")
    for n in HELD:
        assert abs(qs[n].mean()) < 1.2, (n, qs[n])
    assert (k3["tau0"] - qs["tau0"]).mean() < -0.8, (k3["tau0"], qs["tau0"])
    assert (k3["lambda_beta2"] - qs["lambda_beta2"]).mean() > 0.8
    truth, fixed = _z("truth"), _z("hubfixed")
    assert truth["n_beta"].mean() > 2.0, truth["n_beta"]
    assert fixed["n_beta"].mean() < 1.5, fixed["n_beta"]
