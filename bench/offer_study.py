"""Summary of a detection study run before offering effects (``bench/detection.py
--offer ...``): the figures of ``bench/rotor-physics.md``.

    python bench/offer_study.py bench/results/current/offer-*.jsonl.gz

For the null records: false alarms, and for every atom how often its likelihood-ratio
test gave p < 0.05, 0.01 and 1e-3 (beside the others of its rung: the calibration of
the test, whatever the other checks then decided).  For the hidden records: the effect
named, what else was named beside it, the residual over the floor, the estimates'
errors in their bounds.  For the ladders (``multi``, ``nonlinear``): what they added.
"""
from __future__ import annotations

import collections
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from detection import _read  # noqa: E402  (a results file's text, .jsonl or .jsonl.gz)


def _rows(paths):
    for p in paths:
        yield from (json.loads(line) for line in _read(p).splitlines() if line.strip())


def _span(values, fmt, sep=" to "):
    """The least and the largest of ``values`` in ``fmt``, or ``-`` when there are none."""
    return f"{min(values):{fmt}}{sep}{max(values):{fmt}}" if values else "-"


def null_table(rows):
    alarms = [r for r in rows if r["decision"].get("accepted")]
    print(f"null records: {len(rows)}; false alarms {len(alarms)}"
          + "".join(f"\n  {r['effect']} {r['hold']} {r['rate']} {r['noise']} seed "
                    f"{r['seed']} {r.get('rotor')}: {r['decision']['added']}"
                    for r in alarms))
    ps = collections.defaultdict(list)
    for r in rows:
        for s in r["decision"]["structures"]:
            lp = s["log10_p_beside_others"].get(s["atoms"][0])
            if len(s["atoms"]) == 1 and lp is not None:    # None: a part with nothing to test
                ps[s["atoms"][0]].append(10 ** lp)
    print("| atom | tests | p < 0.05 | p < 0.01 | p < 1e-3 | smallest p |")
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    for a, v in sorted(ps.items()):
        print(f"| `{a}` | {len(v)} | {sum(p < 0.05 for p in v)} | {sum(p < 0.01 for p in v)}"
              f" | {sum(p < 1e-3 for p in v)} | {min(v):.2g} |")


def hidden_table(rows):
    by = collections.defaultdict(list)
    for r in rows:
        by[r["effect"], r.get("rotor", "puma")].append(r)
    print("| hidden | rotor | records | named first | others named beside it | "
          "residual / floor | estimates' errors [bounds] |")
    print("| --- | --- | ---: | ---: | --- | --- | --- |")
    for (e, rotor), rs in sorted(by.items()):
        first = sum(r["missing_effect"] == e for r in rs)
        beside = collections.Counter(x for r in rs for x in r["missing_effects"] if x != e)
        fr = [x for r in rs for x in (r.get("with_floor_ratio") or [])]
        z = [v for r in rs for v in (r.get("z") or {}).values()]
        others = ", ".join(f"{k} {n}" for k, n in beside.items()) or "none"
        print(f"| `{e}` | {rotor} | {len(rs)} | {first} | {others} | "
              f"{_span(fr, '.2f', '-')} | {_span(z, '+.2f')} |")


def ladder_table(rows):
    added = collections.Counter()
    for r in rows:
        added[" + ".join(r.get("added") or []) or "(nothing)"] += 1
    fr = [x for r in rows for x in r.get("final_floor_ratio") or []]
    z = [abs(v[0] if isinstance(v, list) else v) for r in rows
         for v in (r.get("z") or {}).values() if v is not None]
    print(f"ladders: {len(rows)}; final residual / floor {min(fr):.2f}-{max(fr):.2f}; "
          f"largest |z| of the truth's parameters {max(z):.2f}" if fr and z else
          f"ladders: {len(rows)}")
    for k, n in added.most_common():
        print(f"  {n:3d}  {k}")


def main(paths):
    rows = list(_rows(paths))
    kinds = collections.defaultdict(list)
    for r in rows:
        kinds[r["kind"]].append(r)
    if kinds.get("null"):
        null_table(kinds["null"])
    if kinds.get("hidden"):
        hidden_table(kinds["hidden"])
    for k in ("multi", "nonlinear", "nonlinear-mu"):
        if kinds.get(k):
            print(k, end=" ")
            ladder_table(kinds[k])


if __name__ == "__main__":
    main(sys.argv[1:])
