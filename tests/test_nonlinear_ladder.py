"""The ladder on a record from the nonlinear individual-blade truth (issue 5 part 7).

The truth keeps every blade's flap inertia and feels in-plane velocity directly
on the blades; the paper's candidates alone would credit that to the inflow.
Measured (bench/README.md): the ladder adds flap-inertia, then
advance-ratio-perturbation with k_mu near its theory value 1, and the error falls.
"""

from inflowsim.diagnose import ladder
from inflowsim.flighttest import FlightTest, nonlinear_flighttest


def test_ladder_on_nonlinear_truth_lowers_the_error():
    rec = nonlinear_flighttest(FlightTest(seed=1)).record
    lad = ladder(rec, "basic", max_steps=2)
    added = [r.added for r in lad.rungs[1:]]
    assert added[0] == "flap-inertia"
    assert "advance-ratio-perturbation" in added
    costs = [r.fit.cost for r in lad.rungs]
    assert costs == sorted(costs, reverse=True)
    first, last = lad.rungs[0].fit, lad.rungs[-1].fit
    assert last.fit["beta1s"]["fit_percent"] > first.fit["beta1s"]["fit_percent"] + 10
    k_mu, s = last.parameters["k_mu"], last.sigma["k_mu"]
    assert abs(k_mu - 1.0) < 3 * s + 0.1           # theory value, up to nonlinearity
