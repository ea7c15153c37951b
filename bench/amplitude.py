"""In what input amplitude is the default nonlinear truth linear?  ``bench/amplitude.md``.

The virtual campaign's truth (``inflowsim flighttest --campaign``: the individual-blade
rotor, Eq. (14) speed through the disc, body motion, 20 s at 64 Hz) at each speed of
``--mus``, one record per control (``--controls``) and input shape (``--shapes``,
default a 3-2-1-1 as ``tests/test_schedule_campaign.py`` flies) at every amplitude of
``--amplitudes`` [deg].  Each speed's records are fitted jointly, as the campaign's
condition task fits them (its base fit: ``identify`` of the records together, the
default band), with the truth's physics from the catalogue (``STRUCTURE``), and each
estimate is set against the truth's own small-perturbation value
(:func:`inflowsim.flighttest.linearise.truth_parameters`; ``k_V``, ``k_mu`` and
``k_beta2`` at their theory value 1).

The records are deterministic apart from the flap noise, so each record is flown once
without noise and the noise added here exactly as the flight test adds it (white,
``default_rng(seed)``, one draw per flap channel in order): seed 0 is the campaign's
own seed (the record ``virtual_campaign`` writes), seed ``k`` its seed plus
``k * 1000003``.  Noise modes:

* ``none``: no noise, one fit: the model error alone (the fit then weights each
  channel by its own model error, so this is not what a noisy record gives);
* ``fixed``: 1e-4 rad whatever the amplitude (a user with a fixed sensor);
* ``scaled``: 1e-4 rad * A / 1 deg (the same signal-to-noise at every amplitude: for
  a linear truth the bias in bounds would not move with A; what moves is the
  truth's nonlinearity).

``--speed mu`` flies the truth with the trim mu as its speed through the disc, whose
linearisation the catalogue holds exactly (fitted without ``momentum-speed``): the
control, what the estimator leaves at this signal-to-noise without model error.

One JSON document a line per fit (estimates, bounds, truth); ``--summary FILE``
prints the tables from a results file.

    python bench/amplitude.py --out /tmp/amplitude.jsonl.gz
    python bench/amplitude.py --summary bench/results/current/amplitude-3211.jsonl.gz
"""
from __future__ import annotations

import argparse
import gzip
import json
import sys
import time
from pathlib import Path

import numpy as np

#: The truth's physics from the catalogue (the speed-mu truth's structure of
#: ``tests/test_schedule_campaign.py`` plus Eq. (14) linearised).
STRUCTURE = ("basic+separate-time-constants+flap-inertia+second-harmonic-flap"
             "+advance-ratio-perturbation+momentum-speed")
#: The structure per speed through the disc of the truth (``--speed mu``: the trim mu,
#: whose linearisation is inside the catalogue without ``momentum-speed``, the
#: control of what the estimator does at this signal-to-noise without model error).
STRUCTURES = {"eq14": STRUCTURE, "mu": STRUCTURE.removesuffix("+momentum-speed")}
REPORTED = ("tau0", "tau_cs", "lambda_beta2", "n_beta", "k_V")
NOISE = 1e-4
MODES = ("none", "fixed", "scaled")
SEED_STEP = 1000003


def truth(mu: float, speed: str = "eq14") -> dict:
    """The truth's small-perturbation parameters at ``mu`` (theory 1 for the scales)."""
    from inflowsim.flighttest.bladesim import RotorSpec
    from inflowsim.flighttest.linearise import truth_parameters
    from inflowsim.model.params import PUMA
    return {**truth_parameters(RotorSpec(constants=PUMA.with_mu(mu), speed=speed)),
            "k_V": 1.0, "k_mu": 1.0, "k_beta2": 1.0}


def clean_records(mu, amplitude_deg, controls, shapes, speed="eq14"):
    """The campaign's items at ``mu`` and their records flown without noise."""
    from inflowsim.flighttest.campaign import campaign_items, campaign_record
    items = campaign_items((mu,), controls, shapes)
    return items, [campaign_record(it, noise=0.0, amplitude_deg=amplitude_deg,
                                   speed=speed) for it in items]


def with_noise(rec, sigma: float, seed: int):
    """``rec`` with white flap noise as :func:`nonlinear_flighttest` adds it."""
    from inflowsim.data.record import FLAP_COLUMNS
    rng = np.random.default_rng(seed)
    return rec.with_channels(**{c: rec[c] + sigma * rng.standard_normal(len(rec))
                                for c in FLAP_COLUMNS})


def fit_row(recs, mu, amplitude_deg, mode, noise, seed, shapes, speed="eq14") -> dict:
    from inflowsim.identify import identify
    t0 = time.process_time()
    r = identify(recs, STRUCTURES[speed])
    tv = truth(mu, speed)
    return {"mu": mu, "amplitude_deg": amplitude_deg, "mode": mode, "noise": noise,
            "seed": seed, "shapes": list(shapes), "speed": speed,
            "structure": STRUCTURES[speed],
            "estimate": {n: float(r.parameters[n]) for n in r.free},
            "sigma": {n: float(r.sigma[n]) if r.sigma[n] is not None else None
                      for n in r.free},
            "truth": {n: float(tv[n]) for n in r.free if n in tv},
            "cpu_seconds": time.process_time() - t0}


def run(mus, amplitudes, seeds, controls, shapes, out, modes=MODES, speed="eq14",
        progress=None):
    """Every fit of the study, one line each to ``out`` (gzip when it ends ``.gz``)."""
    progress = progress or (lambda m: print(m, file=sys.stderr))
    opener = gzip.open if str(out).endswith(".gz") else open
    t_all = time.process_time()
    with opener(out, "wt", encoding="utf-8") as fh:
        for mu in mus:
            for a in amplitudes:
                t0 = time.process_time()
                items, clean = clean_records(mu, a, controls, shapes, speed)
                t_gen = time.process_time() - t0
                for mode in modes:
                    if mode == "none":
                        rows = [fit_row(clean, mu, a, mode, 0.0, None, shapes, speed)]
                    else:
                        sig = NOISE * (a if mode == "scaled" else 1.0)
                        rows = []
                        for k in range(seeds):
                            recs = [with_noise(r, sig, (it.seed + k * SEED_STEP) % 2**32)
                                    for it, r in zip(items, clean)]
                            rows.append(fit_row(recs, mu, a, mode, sig, k, shapes, speed))
                    for row in rows:
                        row["generation_cpu_seconds"] = t_gen
                        fh.write(json.dumps(row) + "\n")
                progress(f"mu {mu:g} A {a:g} deg: records {t_gen:.1f} s, total "
                         f"{time.process_time() - t_all:.0f} s CPU")


def read_rows(paths):
    rows = []
    for p in paths:
        p = Path(p)
        text = gzip.decompress(p.read_bytes()).decode() if p.suffix == ".gz" \
            else p.read_text()
        rows += [json.loads(line) for line in text.splitlines() if line.strip()]
    return rows


def _groups(rows):
    g = {}
    for r in rows:
        shapes = tuple(r["shapes"]) + (("speed mu",) if r.get("speed") == "mu" else ())
        g.setdefault((shapes, r["mode"], r["mu"], r["amplitude_deg"]),
                     []).append(r)
    return g


def summary(rows, names=REPORTED) -> str:
    """Tables: per shapes and noise mode, per speed and amplitude, the mean over
    seeds of ``(estimate - truth)/sigma`` (the largest |.| over seeds beside it) and
    the relative error; for ``none`` the relative error (the model error) and that
    error in the bounds of a 1e-4 rad record at the same amplitude (from the
    ``fixed`` fits' mean sigma)."""
    g = _groups(rows)
    out = []
    shapes_modes = sorted({(k[0], k[1]) for k in g},
                          key=lambda k: (k[0], MODES.index(k[1])))
    for shapes, mode in shapes_modes:
        keys = sorted(k for k in g if k[0] == shapes and k[1] == mode)
        n_seeds = max(len(g[k]) for k in keys)
        if mode == "none":
            out.append(f"\n### {'+'.join(shapes)}, no noise: relative error [%] "
                       f"(in bounds of a 1e-4 rad record)")
        else:
            out.append(f"\n### {'+'.join(shapes)}, noise {mode} "
                       f"({'1e-4 rad' if mode == 'fixed' else '1e-4 rad * A/1 deg'}), "
                       f"{n_seeds} seeds: mean (est - truth)/sigma [largest |.|]; "
                       f"mean relative error [%]")
        out.append("| mu | A [deg] | " + " | ".join(f"`{n}`" for n in names) + " |")
        out.append("| --- | --- | " + " | ".join("---" for _ in names) + " |")
        for k in keys:
            cells = []
            for n in names:
                rs = [r for r in g[k] if n in r["estimate"]]
                if not rs:                # k_V: not in the speed-mu truth's structure
                    cells.append("-")
                    continue
                est = np.array([r["estimate"][n] for r in rs])
                tv = rs[0]["truth"][n]
                rel = 100 * (est / tv - 1)
                if mode == "none":
                    ref = g.get((shapes, "fixed", k[2], k[3]), [])
                    s = np.mean([r["sigma"][n] for r in ref]) if ref else np.nan
                    cells.append(f"{rel[0]:+.2f} ({(est[0] - tv) / s:+.1f})")
                else:
                    z = (est - tv) / np.array([r["sigma"][n] for r in rs])
                    cells.append(f"{z.mean():+.1f} [{np.abs(z).max():.1f}]; "
                                 f"{rel.mean():+.2f}")
            out.append(f"| {k[2]:.2f} | {k[3]:g} | " + " | ".join(cells) + " |")
    return "\n".join(out)


#: What the campaign's default is decided on: the truth's small-perturbation
#: parameters (``k_V`` is reported, not held: its bound is 10-40 % of it).
HELD = ("tau0", "tau_cs", "lambda_beta2", "n_beta")


def decision(rows, names=HELD) -> str:
    """Per shapes, noisy mode and amplitude, over the seeds (each seed a whole
    campaign: every speed): the share of campaigns whose joint fits hold every one of
    ``names`` within 2 and 3 bounds at every speed; the largest ``|mean z|`` over
    speeds and ``names`` (the bias, in bounds) and the largest single ``|z|``; the
    bound of tau0 relative to it (median over speeds and seeds)."""
    g = _groups(rows)
    out = [f"\n### Campaigns (each seed: every speed) holding {', '.join(names)}",
           "| shapes | noise | A [deg] | speeds | seeds | all within 2 | all within 3 "
           "| largest mean z | largest z | tau0 bound [%] |",
           "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    combos = sorted({(k[0], k[1], k[3]) for k in g if k[1] != "none"},
                    key=lambda k: (k[0], MODES.index(k[1]), k[2]))
    for shapes, mode, a in combos:
        keys = sorted(k for k in g if k[:2] == (shapes, mode) and k[3] == a)
        # a campaign is a seed flown at every speed
        seeds = sorted(set.intersection(*({r["seed"] for r in g[k]} for k in keys)))
        worst = {s: 0.0 for s in seeds}
        mean_z, rel = [], []
        for k in keys:
            for n in names:
                z = {r["seed"]: (r["estimate"][n] - r["truth"][n]) / r["sigma"][n]
                     for r in g[k] if r["seed"] in worst}
                mean_z.append(abs(np.mean(list(z.values()))))
                for s in seeds:
                    worst[s] = max(worst[s], abs(z[s]))
            rel += [r["sigma"]["tau0"] / r["truth"]["tau0"] for r in g[k]]
        w = np.array(list(worst.values()))
        out.append(f"| {'+'.join(shapes)} | {mode} | {a:g} | {len(keys)} | {len(seeds)} | "
                   f"{np.mean(w < 2):.0%} | {np.mean(w < 3):.0%} | {max(mean_z):.1f} | "
                   f"{w.max():.1f} | {100 * np.median(rel):.1f} |")
    return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mus", nargs="+", type=float,
                    default=[0.10, 0.15, 0.20, 0.25, 0.30, 0.35])
    ap.add_argument("--amplitudes", nargs="+", type=float,
                    default=[0.125, 0.25, 0.5, 1.0, 2.0], help="input amplitudes [deg]")
    ap.add_argument("--seeds", type=int, default=8, help="noise seeds per noisy mode")
    ap.add_argument("--controls", nargs="+", default=["theta0", "theta1c", "theta1s"])
    ap.add_argument("--shapes", nargs="+", default=["3211"],
                    help="input shapes per control (the campaign's: doublet 3211 sweep)")
    ap.add_argument("--modes", nargs="+", choices=MODES, default=list(MODES))
    ap.add_argument("--speed", choices=tuple(STRUCTURES), default="eq14",
                    help="the truth's speed through the disc (mu: the control)")
    ap.add_argument("--out", help="results, one JSON line per fit (.jsonl or .jsonl.gz)")
    ap.add_argument("--summary", nargs="+", metavar="FILE",
                    help="print the tables of results files instead")
    a = ap.parse_args(argv)
    if a.summary:
        rows = read_rows(a.summary)
        print(summary(rows))
        print(decision(rows))
        return 0
    if not a.out:
        ap.error("--out FILE is required (or --summary FILE)")
    t0 = time.process_time()
    run(a.mus, a.amplitudes, a.seeds, tuple(a.controls), tuple(a.shapes), a.out,
        tuple(a.modes), a.speed)
    print(f"{time.process_time() - t0:.0f} s CPU", file=sys.stderr)
    rows = read_rows([a.out])
    print(summary(rows))
    print(decision(rows))
    return 0


if __name__ == "__main__":
    sys.exit(main())
