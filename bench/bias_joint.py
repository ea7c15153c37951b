"""Monte Carlo of the estimator's noise bias on single-axis records fitted jointly.

For each seed: three records from the independent linear route
(:func:`inflowsim.flighttest.virtual.virtual_record`; truth = ``--truth`` (default:
``--structure``) at its theory values at ``mu``, the body responding), a 3-2-1-1
(0.3 s unit, 1 deg, from 2 s) on one control each, 20 s at 64 Hz, white flap noise;
fitted jointly by ``identify`` with ``--structure``.  ``--layout one`` puts the three
3-2-1-1s in one 60 s record instead (same inputs, same noise per second).  Prints
bias / spread and spread / mean bound per parameter (the truth of a parameter is the
truth structure's theory value).

A truth with an effect the fitted structure lacks (``--truth
basic+separate-time-constants+flap-inertia+advance-ratio-perturbation``: the in-plane
hub velocity the cyclic records' body motion makes, which the rotor's exact
linearisation carries) shows what model error does: a bias of several bounds with
noise, and a noise-free fit that looks exact (``--noise 0``; see ``bench/identify.md``).

Usage: ``python bench/bias_joint.py [--structure S] [--truth S] [--layout joint|one]
[--seeds 30] [--noise 1e-4] [--mu 0.1] [--json FILE]``
"""
from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np

from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record
from inflowsim.identify import identify
from inflowsim.model.params import PUMA
from inflowsim.model.presets import theory_parameters
from inflowsim.model.structure import Structure

CONTROLS = ("theta0", "theta1c", "theta1s")
STRUCTURE = "basic+separate-time-constants+flap-inertia"


def records(structure, truth, constants, layout, seed, noise, duration=20.0, dt=1 / 64):
    def one(mans, dur, sd):
        return virtual_record(VirtualTest(structure=structure, parameters=truth,
                                          constants=constants, manoeuvres=mans,
                                          duration=dur, dt=dt, noise_flap=noise, seed=sd))
    man = [Manoeuvre(c, "3211", np.radians(1.0), 2.0, 0.3) for c in CONTROLS]
    if layout == "joint":
        return [one((m,), duration, 1000 * seed + i) for i, m in enumerate(man)]
    if layout == "one":
        shifted = tuple(Manoeuvre(m.channel, m.shape, m.amplitude, 2.0 + duration * i, 0.3)
                        for i, m in enumerate(man))
        return [one(shifted, duration * len(man), 1000 * seed)]
    raise ValueError(layout)


def run(structure=STRUCTURE, layout="joint", seeds=30, noise=1e-4, mu=0.1, first_seed=1,
        truth_structure=None, **kw):
    truth_structure = truth_structure or structure
    constants = PUMA.with_mu(mu)
    truth = theory_parameters(Structure.parse(truth_structure), constants)
    est, sig = [], []
    t0 = time.perf_counter()
    for k in range(seeds):
        recs = records(truth_structure, truth, constants, layout, first_seed + k, noise)
        r = identify(recs, structure, **kw)
        names = list(r.free)
        est.append([r.parameters[n] for n in names])
        sig.append([r.sigma[n] or np.nan for n in names])
    est, sig = np.array(est), np.array(sig)
    tv = np.array([truth[n] for n in names])
    spread = est.std(axis=0, ddof=1) if seeds > 1 else np.full(len(names), np.nan)
    bias = est.mean(axis=0) - tv
    rows = {n: {"truth": float(tv[i]), "mean": float(est[:, i].mean()),
                "spread": float(spread[i]), "mean_sigma": float(np.nanmean(sig[:, i])),
                "bias_over_spread": float(bias[i] / spread[i]),
                "bias_over_sigma": float(bias[i] / np.nanmean(sig[:, i])),
                "ratio": float(spread[i] / np.nanmean(sig[:, i]))}
            for i, n in enumerate(names)}
    return {"structure": structure, "truth": truth_structure, "layout": layout,
            "seeds": seeds, "noise": noise, "mu": mu, "seconds": time.perf_counter() - t0,
            "parameters": rows, "estimates": est.tolist()}


def table(doc):
    lines = [f"fit {doc['structure']}, truth {doc['truth']}, layout {doc['layout']}, "
             f"mu {doc['mu']:g}, {doc['seeds']} seeds, noise {doc['noise']:g} rad, "
             f"{doc['seconds']:.0f} s",
             "| parameter | truth | mean | spread | mean sigma | bias/spread | bias/sigma "
             "| spread/sigma |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for n, r in doc["parameters"].items():
        lines.append(f"| `{n}` | {r['truth']:.5g} | {r['mean']:.5g} | {r['spread']:.3g} | "
                     f"{r['mean_sigma']:.3g} | {r['bias_over_spread']:+.2f} | "
                     f"{r['bias_over_sigma']:+.2f} | "
                     f"{r['ratio']:.2f} |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--structure", default=STRUCTURE)
    ap.add_argument("--truth", default=None, help="truth structure (default: --structure)")
    ap.add_argument("--layout", choices=("joint", "one"), default="joint")
    ap.add_argument("--seeds", type=int, default=30)
    ap.add_argument("--noise", type=float, default=1e-4)
    ap.add_argument("--mu", type=float, default=0.1)
    ap.add_argument("--json", metavar="FILE")
    a = ap.parse_args(argv)
    doc = run(a.structure, a.layout, a.seeds, a.noise, a.mu, truth_structure=a.truth)
    print(table(doc))
    if a.json:
        with open(a.json, "w", encoding="utf-8") as f:
            json.dump(doc, f, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
