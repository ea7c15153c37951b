"""Monte Carlo check of the Cramer-Rao bounds (opt-in study, not a test).

For each seed: a virtual record (paper parameters as truth, three doublets so every
parameter is excited, flap noise ``1e-4`` rad), fitted by ``identify``.  Records are
continuous-time by default (smooth inputs, the truth integrated by an adaptive ODE
solver, then sampled: :func:`inflowsim.flighttest.virtual.virtual_record`), or held
(``--hold zoh``), at ``--rate`` Hz.  Compares the spread of the estimates over
seeds with the mean reported 1-sigma bound (plain, coloured-residual corrected
and robust).  Ratio spread / mean bound near 1 means honest bounds; above 1
optimistic.

Usage: ``python bench/montecarlo.py [--structure glauert] [--seeds 100] [--coloured]
[--hold continuous|zoh] [--rate HZ] [--json FILE]``
"""
from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np

from inflowsim.identify import identify
from inflowsim.model.presets import preset_parameters
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record

MANOEUVRES = (Manoeuvre("theta1s", "doublet", np.radians(1.0), 2.0, 0.4),
              Manoeuvre("theta1c", "doublet", np.radians(1.0), 8.0, 0.4),
              Manoeuvre("theta0", "doublet", np.radians(1.0), 14.0, 0.4))


def truth_of(structure):
    p = preset_parameters(structure)
    if "delay" in p:
        p["delay"] = 0.0437
    return p


#: Corner of the coloured (first-order low-pass) flap noise [Hz].
COLOUR_HZ = 0.5


def run(structure="glauert", seeds=100, noise=1e-4, first_seed=1000, colour=False,
        hold="continuous", rate=100.0):
    truth = truth_of(structure)
    est, sig, sigc, sigr, conv = [], [], [], [], 0
    t0 = time.perf_counter()
    for k in range(seeds):
        rec = virtual_record(VirtualTest(structure=structure, parameters=truth,
                                         manoeuvres=MANOEUVRES, noise_flap=noise,
                                         seed=first_seed + k, dt=1.0 / rate, hold=hold,
                                         noise_color_hz=COLOUR_HZ if colour else None))
        r = identify(rec, structure)
        names = list(r.parameters)
        est.append([r.parameters[n] for n in names])
        sig.append([r.sigma[n] if r.sigma[n] is not None else np.nan for n in names])
        sigc.append([r.sigma_colored[n] if r.sigma_colored[n] is not None else np.nan
                     for n in names])
        sigr.append([r.sigma_robust[n] if r.sigma_robust[n] is not None else np.nan
                     for n in names])
        conv += r.converged
    elapsed = time.perf_counter() - t0
    est, sig, sigc, sigr = np.array(est), np.array(sig), np.array(sigc), np.array(sigr)
    tv = np.array([truth[n] for n in names])
    spread = est.std(axis=0, ddof=1)
    bias = est.mean(axis=0) - tv
    mean_sig, mean_sigc = np.nanmean(sig, axis=0), np.nanmean(sigc, axis=0)
    mean_sigr = np.nanmean(sigr, axis=0)
    z = (est - tv) / sig
    rows = {n: {"truth": float(tv[i]), "mean": float(est[:, i].mean()),
                "bias_over_spread": float(bias[i] / spread[i]),
                "spread": float(spread[i]), "mean_sigma": float(mean_sig[i]),
                "ratio": float(spread[i] / mean_sig[i]),
                "mean_sigma_colored": float(mean_sigc[i]),
                "ratio_colored": float(spread[i] / mean_sigc[i]),
                "mean_sigma_robust": float(mean_sigr[i]),
                "ratio_robust": float(spread[i] / mean_sigr[i]),
                "within_3sigma": float(np.mean(np.abs(z[:, i]) <= 3))}
            for i, n in enumerate(names)}
    return {"structure": structure, "seeds": seeds, "noise_flap": noise,
            "noise": f"low-pass {COLOUR_HZ:g} Hz" if colour else "white",
            "hold": hold, "rate_hz": rate,
            "converged": conv, "seconds": elapsed, "parameters": rows}


def table(doc):
    lines = [f"structure {doc['structure']}, {doc['seeds']} seeds, {doc['hold']} records "
             f"at {doc['rate_hz']:g} Hz, noise {doc['noise_flap']:g} rad {doc['noise']}, "
             f"{doc['converged']} converged, {doc['seconds']:.1f} s",
             "| parameter | truth | mean | spread (std) | mean CR sigma | spread/sigma "
             "| mean MK sigma | spread/MK | mean robust sigma | spread/robust "
             "| within 3 sigma |",
             "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for n, r in doc["parameters"].items():
        lines.append(f"| `{n}` | {r['truth']:.4g} | {r['mean']:.5g} | {r['spread']:.3g} | "
                     f"{r['mean_sigma']:.3g} | {r['ratio']:.2f} | "
                     f"{r['mean_sigma_colored']:.3g} | {r['ratio_colored']:.2f} | "
                     f"{r['mean_sigma_robust']:.3g} | {r['ratio_robust']:.2f} | "
                     f"{100 * r['within_3sigma']:.0f} % |")
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--structure", default="glauert")
    ap.add_argument("--seeds", type=int, default=100)
    ap.add_argument("--noise", type=float, default=1e-4)
    ap.add_argument("--coloured", action="store_true",
                    help="low-pass (0.5 Hz) flap noise instead of white")
    ap.add_argument("--hold", choices=("continuous", "zoh"), default="continuous")
    ap.add_argument("--rate", type=float, default=100.0, help="sample rate [Hz]")
    ap.add_argument("--json", metavar="FILE")
    a = ap.parse_args(argv)
    doc = run(a.structure, a.seeds, a.noise, colour=a.coloured, hold=a.hold, rate=a.rate)
    print(table(doc))
    if a.json:
        with open(a.json, "w", encoding="utf-8") as f:
            json.dump(doc, f, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
