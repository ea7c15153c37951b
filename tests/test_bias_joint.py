"""Noise bias of the estimator in the campaign's setting: three single-axis 3-2-1-1
records (20 s at 64 Hz, mu 0.1) fitted jointly (``bench/bias_joint.py``, the
independent linear route).

With the truth inside the fitted structure the estimates centre on it (the mean within
0.6 of the spread) and the spread matches the Cramer-Rao bound; with a truth holding
an effect the structure lacks (the in-plane hub velocity of the cyclic records' body
motion, ``advance-ratio-perturbation``) the same fits sit bounds away: the bias the
rotor-twin study saw is that model error, not the estimator (``bench/identify.md``,
"Joint single-axis records").
"""
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))

from bias_joint import STRUCTURE, run  # noqa: E402


@pytest.mark.slow
def test_joint_single_axis_fits_centre_on_the_truth():
    """20 seeds (about 100 s): measured |bias/spread| <= 0.36, spread/sigma 0.85-1.13
    (30 seeds: <= 0.24 and 0.99-1.23, bench/identify.md)."""
    doc = run(seeds=20)
    for name, row in doc["parameters"].items():
        assert abs(row["bias_over_spread"]) < 0.6, (name, row)
        assert 0.7 < row["ratio"] < 1.45, (name, row)


@pytest.mark.slow
def test_an_unmodelled_input_response_biases_the_same_fits():
    """The contrast (5 seeds, about 25 s): the truth with the in-plane forcing
    fitted without it puts n_beta and lambda_beta2 about 3 bounds high (measured
    +3.1 and +3.4 sigma; 30 seeds: +3.1 and +2.7), so the first test can tell a
    biased fit."""
    doc = run(seeds=5, truth_structure=STRUCTURE + "+advance-ratio-perturbation")
    rows = doc["parameters"]
    assert rows["n_beta"]["bias_over_sigma"] > 1.5, rows["n_beta"]
    assert rows["lambda_beta2"]["bias_over_sigma"] > 1.5, rows["lambda_beta2"]
