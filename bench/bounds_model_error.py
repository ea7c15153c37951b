"""Bounds under model error (issue #36): Cramer-Rao, coloured and robust bounds on
records whose truth is the fitted structure and on records whose truth has a term
outside it (opt-in study, not a test).

Records: ``tests/extra_term_truths.py`` (the ``basic`` truth's matrices integrated by
scipy's DOP853, 30 s at 100 Hz, white flap noise 1e-4 rad; two-axis: a 3-2-1-1 on
theta1s and a doublet on theta1c; single-axis: the 3-2-1-1 alone), kinds ``none``
(right structure), ``coupling`` (cyclic flap cross-coupling 2 1/s) and ``pitch-lag``
(a 0.05 s servo on the cyclic pitch).  Each record is fitted by ``identify`` with
``basic``, and marked conditional by the diagnosis's test (the identify command's).

Per kind and record kind: the mean of ``sigma_robust / sigma`` (the robust bound is
floored at Cramer-Rao; ``raw`` the sandwich before flooring), the spread of
``(estimate - truth) / sigma`` over seeds, and the share of estimates within 3 sigma of
the truth for each bound, and the share marked conditional.

Usage: ``python bench/bounds_model_error.py [--seeds 30] [--kinds none coupling
pitch-lag] [--json FILE]``
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

import inflowsim.identify.estimator as E                              # noqa: E402
from extra_term_truths import write_record                           # noqa: E402
from inflowsim.diagnose.conditional import marked                    # noqa: E402
from inflowsim.diagnose.search import analyses_of                    # noqa: E402

_RAW = {}
_BOUNDS = E._bounds


def _capture(prob, st):
    out = _BOUNDS(prob, st)
    _RAW["cov"], _RAW["cov_r"] = out[0], out[2]
    return out


def study(kind, axes, seeds):
    E._bounds = _capture
    rows = []
    try:
        for seed in seeds:
            with tempfile.TemporaryDirectory() as d:
                rec, truth = write_record(Path(d) / "r.csv", None if kind == "none" else kind,
                                          seed, axes)
            fit = E.identify(rec, "basic")
            fit = marked(fit, analyses_of([rec], fit, fit.band_hz))
            raw = np.sqrt(np.diag(_RAW["cov_r"]) / np.diag(_RAW["cov"]))
            for i, n in enumerate(fit.free):
                err = fit.parameters[n] - truth[n]
                rows.append((err / fit.sigma[n], err / fit.sigma_colored[n],
                             err / fit.sigma_robust[n], fit.sigma_robust[n] / fit.sigma[n],
                             raw[i], fit.conditional is not None))
    finally:
        E._bounds = _BOUNDS
    a = np.array(rows, dtype=float)
    return {"kind": kind, "axes": axes, "seeds": len(seeds), "estimates": len(rows),
            "robust_over_cr": float(a[:, 3].mean()), "raw_robust_over_cr": float(a[:, 4].mean()),
            "z_sd_cr": float(a[:, 0].std()), "z_sd_robust": float(a[:, 2].std()),
            "max_abs_z_robust": float(np.abs(a[:, 2]).max()),
            "within3_cr": float(np.mean(np.abs(a[:, 0]) < 3)),
            "within3_colored": float(np.mean(np.abs(a[:, 1]) < 3)),
            "within3_robust": float(np.mean(np.abs(a[:, 2]) < 3)),
            "marked": float(a[:, 5].mean())}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=30)
    ap.add_argument("--kinds", nargs="+", default=["none", "coupling", "pitch-lag"])
    ap.add_argument("--json")
    a = ap.parse_args(argv)
    out = []
    print("| truth | record | seeds | robust/CR (raw) | sd z CR | sd z robust | within 3 "
          "sigma: CR / coloured / robust | marked conditional |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for kind in a.kinds:
        for axes in (2, 1):
            t0 = time.time()
            r = study(kind, axes, range(100, 100 + a.seeds))
            r["seconds"] = time.time() - t0
            out.append(r)
            print(f"| {kind} | {'two-axis' if axes == 2 else 'single-axis'} | {r['seeds']} "
                  f"| {r['robust_over_cr']:.3f} ({r['raw_robust_over_cr']:.3f}) "
                  f"| {r['z_sd_cr']:.2f} | {r['z_sd_robust']:.2f} "
                  f"| {100 * r['within3_cr']:.0f} / {100 * r['within3_colored']:.0f} / "
                  f"{100 * r['within3_robust']:.0f} % | {100 * r['marked']:.0f} % |",
                  flush=True)
    if a.json:
        Path(a.json).write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
