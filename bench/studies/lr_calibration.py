"""Are the diagnosis's likelihood-ratio p-values calibrated?  (issue #35, page
``bench/studies/lr-calibration.md``)

Reads null-record results of ``bench/detection.py`` (each candidate's raw statistic
``2 (J_base - J)`` and degrees of freedom) and, per atom, computes how often the
p-value passes each level under three readings: chi-square (the rule before), the
statistic over ``kappa`` as chi-square, and the library's reading, over ``kappa k`` as
``F(k, d)`` (:func:`inflowsim.identify.estimator.lr_calibration`).  ``kappa`` and
``d`` depend on the record's bins and the fit's dimensions only, not on the noise
draw: they are taken from one record of each configuration, fitted with the base
and the atom (the same for every seed).  A boundary atom (its parameter's neutral
value the range's edge) takes the 50:50 mixture in each reading.

    python bench/studies/lr_calibration.py results/current/null-calibration-*.jsonl.gz
"""
from __future__ import annotations

import gzip
import json
import os
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

LEVELS = (0.1, 0.03, 0.01, 3e-3, 1e-3)


def _rows(paths):
    seen, out = set(), []
    for p in paths:
        with (gzip.open(p, "rt") if str(p).endswith(".gz") else open(p)) as fh:
            for line in fh:
                r = json.loads(line)
                if r.get("kind") != "null":
                    continue
                key = (r["effect"], r["hold"], r["rate"], r["noise"], r["seed"],
                       r.get("rotor", "puma"))
                if key in seen:
                    continue
                seen.add(key)
                for c in r.get("candidates", []):
                    if c.get("statistic") is None or c.get("error"):
                        continue
                    out.append((key, c))
    return out


#: ``(kappa, d)`` by configuration and structure, fitted once a run
_FITTED: dict = {}


def _calibration(key, structure):
    """``(kappa, d)`` of ``structure`` fitted to the configuration's record."""
    effect, hold, rate, noise, seed, rotor = key
    k = (effect, hold, rate, noise, rotor, structure)
    cache = _FITTED
    if k not in cache:
        os.environ["INFLOWSIM_STUDY_ROTOR"] = rotor
        from detection import record_for
        from inflowsim.identify import identify
        rec, _ = record_for("null", effect, hold, rate, noise, seed)
        cache[k] = identify([rec], structure).lr
    return cache[k]


def main(argv=None):
    from inflowsim.diagnose.rule import lr_test
    from inflowsim.diagnose.tails import chi2_sf
    paths = argv if argv is not None else sys.argv[1:]
    rows = _rows(paths)
    table = defaultdict(lambda: defaultdict(list))
    for key, c in rows:
        held = c.get("held_at_neutral") or []
        kappa, d = _calibration(key, c["structure"])
        stat, k = float(c["statistic"]), int(c["dof"])
        # the boundary mixture as the rule takes it: the stored p against chi-square's
        raw = 10.0 ** c["log10_p_value"] if c["log10_p_value"] is not None else 1.0
        b = int(stat > 0 and abs(raw - 0.5 * chi2_sf(stat, k)) < 1e-6 * max(raw, 1e-300))
        ps = {"chi-square": lr_test(stat / 2, 0.0, k, b)[2],
              "over kappa": lr_test(stat / 2, 0.0, k, b, (kappa, float("inf")))[2],
              "F (library)": lr_test(stat / 2, 0.0, k, b, (kappa, d))[2]}
        for name, lp in ps.items():
            for atom in (c["atom"], "all atoms"):
                table[atom][name].append(lp)
        table[c["atom"]]["_kappa"].append(kappa)
        table[c["atom"]]["_d"].append(d)
    n_records = len({k for k, _ in rows})
    print(f"{n_records} null records, {len(rows)} atom tests\n")
    print("| atom | tests | kappa | d | reading | "
          + " | ".join(f"P(p < {a:g}) / {a:g}" for a in LEVELS) + " |")
    print("| --- | ---: | ---: | ---: | --- | " + " | ".join("---:" for _ in LEVELS) + " |")
    order = sorted((a for a in table if a != "all atoms")) + ["all atoms"]
    for atom in order:
        t = table[atom]
        kap = t.get("_kappa") or table[order[0]]["_kappa"]
        dd = t.get("_d") or table[order[0]]["_d"]
        for name in ("chi-square", "over kappa", "F (library)"):
            lp = np.array(t[name])
            cells = " | ".join(f"{np.mean(lp < np.log10(a)) / a:.2f}" for a in LEVELS)
            print(f"| {atom} | {lp.size} | {np.mean(kap):.3f} | {np.mean(dd):.1f} | {name} | {cells} |")


if __name__ == "__main__":
    main()
