"""How close the ``mu`` table is to the exact zero-order hold, for the table the
Simulator and the FMU evaluate (``inflowsim.simulate.mutable``: each of the
``SEGMENTS`` segments cut into ``SPLIT`` parts of degree ``FINE_DEGREE``) and for
the degree-``DEGREE`` segments it is made from (what was evaluated before the
parts, issue #38).

    python bench/fmu_mu_accuracy.py [--points N] [--structures S ...]

For each structure (Puma, the trim below where an effect needs one, theory
parameters, dt = 0.01 s): the Simulator's table of ``[phi gam; c phi, c gam]``, its
check (``MuTable.err``: the worst error at the segment midpoints relative to each
block's largest entry), and the worst such error over N random ``mu`` in
``[0.1, 0.5]`` and every segment and part end, against scipy's ``expm``.
Results: bench/fmu.md.
"""
from __future__ import annotations

import argparse

import numpy as np

DEFAULT = ("glauert", "glauert+flap-inertia", "basic+peters-he-10", "basic+peters-he-15",
           "glauert+servo-actuators", "glauert+lead-lag")
TRIM = {"theta0": 0.17, "theta1c": 0.012, "theta1s": -0.05, "beta0": 0.06,
        "beta1c": 0.011, "beta1s": -0.004, "muz": -0.02}


def worst(structure, points):
    from inflowsim.model import build_model
    from inflowsim.model.effects import needs_trim
    from inflowsim.model.params import PUMA
    from inflowsim.model.presets import truth_parameters
    from inflowsim.simulate import mutable
    from scipy.linalg import expm
    from inflowsim.simulate.simulator import Simulator
    k = PUMA.with_trim(TRIM) if needs_trim([structure]) else PUMA
    m = build_model(structure, truth_parameters(structure, k), k)
    sim = Simulator(m, 0.01)
    t = sim._build_mu_table()
    n = sim.n
    e = np.array(t.edges)
    parts = (e[:-1, None] + np.diff(e)[:, None] * np.arange(mutable.SPLIT) / mutable.SPLIT)
    rng = np.random.default_rng(0)
    mus = np.concatenate([rng.uniform(mutable.MU_LO, mutable.MU_HI, points), e,
                          parts.ravel()])
    err = {"parts": 0.0, "segments": 0.0}
    for mu in mus:
        mm = m.with_mu(mu)
        aug = np.zeros((n + mm.b.shape[1],) * 2)
        aug[:n, :n], aug[:n, n:] = mm.a, mm.b
        pg = expm(aug * 0.01)[:n]         # an exponential not the table's own
        want = np.vstack([pg, mm.c @ pg])
        got = np.empty(want.size)
        t.into(mu, got)
        s = min(np.searchsorted(e, mu, side="right") - 1, len(e) - 2)
        x = (2.0 * mu - e[s] - e[s + 1]) / (e[s + 1] - e[s])
        coarse = (x ** np.arange(mutable.DEGREE + 1)) @ t._p[s]
        for name, g in (("parts", got), ("segments", coarse)):
            g = g.reshape(want.shape)
            for b in (slice(0, n), slice(n, None)):
                r = np.max(np.abs(g[b] - want[b])) / np.max(np.abs(want[b]))
                err[name] = max(err[name], r)
    return n, t.err, err


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--points", type=int, default=200)
    ap.add_argument("--structures", nargs="+", default=DEFAULT)
    a = ap.parse_args()
    from inflowsim.simulate import mutable
    print(f"| structure | NX | check (parts) | worst, parts ({mutable.SEGMENTS} x "
          f"{mutable.SPLIT} of degree {mutable.FINE_DEGREE}) | worst, segments "
          f"({mutable.SEGMENTS} of degree {mutable.DEGREE}) |")
    print("| --- | --- | --- | --- | --- |")
    for s in a.structures:
        n, check, err = worst(s, a.points)
        print(f"| `{s}` | {n} | {check:.2e} | {err['parts']:.2e} | {err['segments']:.2e} |")


if __name__ == "__main__":
    main()
