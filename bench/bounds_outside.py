"""Truths outside the catalogue (issue #36, done-when, first clause): is every
estimate ``identify`` reports within 3 of its widest stated bound, or marked
conditional / not determined?

Over the records of ``tests/outside_truths.py`` (the cases of ``bench/outside.py``:
five kinds, seeds 1-5, both cyclics and one), ``basic`` is fitted (``identify``) and
marked by the identify command's test (:mod:`inflowsim.diagnose.conditional`).  Per
estimate: the widest bound of ``sigma``, ``sigma_colored``, ``sigma_robust``; within
3 of it; marked conditional; not determined.  Only ``identify``'s base fit (the
ladder's final structures are ``bench/outside.py``'s business and cost a lattice
each).

Run: ``OPENBLAS_NUM_THREADS=1 python bench/bounds_outside.py [KIND ...]`` (all kinds:
the rows are written to ``bench/results/bounds_outside.json``, which
``bench/outside.py`` summarises in ``bench/outside.md``)
"""
from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
sys.path.insert(0, str(HERE))

from outside import cases  # noqa: E402
from outside_truths import KINDS, outside_record  # noqa: E402

from inflowsim.diagnose.conditional import marked  # noqa: E402
from inflowsim.diagnose.search import analyses_of  # noqa: E402
from inflowsim.identify import identify  # noqa: E402


def row(kind, seed, axes, rate, colour, folder):
    rec, info = outside_record(Path(folder) / "r.csv", kind, seed, rate, axes, colour)
    truth = info["parameters"]
    fit = identify(rec, "basic")
    fit = marked(fit, analyses_of([rec], fit, fit.band_hz, check_colour=False))
    out = []
    for n in fit.free:
        bounds = [b.get(n) for b in (fit.sigma, fit.sigma_colored, fit.sigma_robust)]
        bounds = [b for b in bounds if b is not None]
        widest = max(bounds) if bounds else None
        err = fit.parameters[n] - truth[n]
        out.append({"kind": kind, "seed": seed, "axes": axes, "parameter": n,
                    "z_cr": err / fit.sigma[n] if fit.sigma.get(n) else None,
                    "z_widest": err / widest if widest else None,
                    "within": widest is not None and abs(err) < 3 * widest,
                    "marked": fit.conditional is not None,
                    "undetermined": widest is None})
    return out


def main(argv):
    kinds = tuple(argv) or KINDS
    rows, t0 = [], time.time()
    with tempfile.TemporaryDirectory() as d:
        for case in cases(kinds):
            rows += row(*case, d)
    print(f"{len(rows)} estimates, {time.time() - t0:.0f} s")
    if not argv:
        import json
        (HERE / "results").mkdir(exist_ok=True)
        (HERE / "results" / "bounds_outside.json").write_text(json.dumps(rows, indent=1))
    for r in rows:
        if not (r["within"] or r["marked"] or r["undetermined"]):
            print(f"  not covered, not marked: {r['kind']} seed {r['seed']} {r['axes']} "
                  f"{r['parameter']}: z widest {r['z_widest']:.1f}, z CR {r['z_cr']:.1f}")
    print("| truth | estimates | within 3 widest | marked | within, marked or undetermined "
          "| max abs z (widest) |")
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    for kind in kinds + ("all",):
        rs = [r for r in rows if kind in ("all", r["kind"])]
        ok = [r["within"] or r["marked"] or r["undetermined"] for r in rs]
        zs = [abs(r["z_widest"]) for r in rs if r["z_widest"] is not None]
        print(f"| {kind} | {len(rs)} | {100 * sum(r['within'] for r in rs) / len(rs):.0f} % "
              f"| {100 * sum(r['marked'] for r in rs) / len(rs):.0f} % "
              f"| {100 * sum(ok) / len(rs):.0f} % | {max(zs):.1f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
