"""Stored decisions decided again: which records a change of the rule's settings moves.

Every record of ``bench/detection.py`` keeps its decision as data (``"decision"``:
every structure scored, with the settings it was decided by; a ladder's, each
rung's), so lines 3-5 of the rule (:func:`inflowsim.diagnose.rule.decide`) can be
applied to the same rows under other settings without fitting anything::

    python bench/redecide.py results/current/input-view-*.jsonl.gz --set input_view=false

prints, for each record whose decision differs between the settings it was made
with and those with ``--set`` applied, both decisions and the chosen structure's
line-4 measures; a ladder is compared at its first rung that differs (the rungs
after it would have been other fits).  Rows stored before a measure existed (e.g.
``input_correlated``) carry none, so a setting that reads it changes nothing on
them: decide those records again from a run of the present code.
"""
from __future__ import annotations

import argparse
import gzip
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from inflowsim.diagnose.rule import Rule, Scored, decide  # noqa: E402


def _value(text):
    low = text.lower()
    if low in ("true", "false"):
        return low == "true"
    try:
        return int(text)
    except ValueError:
        try:
            return float(text)
        except ValueError:
            return text


def _records(path):
    p = Path(path)
    opener = gzip.open if p.suffix == ".gz" else open
    with opener(p, "rt") as fh:
        return [json.loads(line) for line in fh if line.strip()]


def _name(r):
    return (f'{r["kind"]} {r["effect"]} {r.get("rotor", "puma")} {r["hold"]} {r["rate"]} '
            f'{r["noise"]} seed {r["seed"]}')


def _measures(row, rule):
    out = (f"level {row.excess_before:.2f} -> {row.excess_after:.2f} "
           f"(noise {row.excess_noise:.2f})" if row.excess_before is not None else "")
    if row.input_before is not None:
        out += (f", input-correlated {row.input_before:.1f} -> {row.input_after:.1f} "
                f"(noise {row.input_noise:.1f}), {row.tried} atoms tried")
    return out + f", G {row.schwarz_gain:.1f}, failed {list(row.failed(rule))}"


def compare(paths, changes):
    """``(decisions, records changed)`` over ``paths``; prints each change."""
    n = moved = 0
    for path in paths:
        for r in _records(path):
            docs = ([("", r["decision"])] if "decision" in r else
                    [(f' rung {i} ({g["structure"]})', g["decision"])
                     for i, g in enumerate(r.get("rungs", ())) if g.get("decision")])
            for where, doc in docs:
                n += 1
                rows = [Scored.from_json(x) for x in doc["structures"]]
                was = decide(rows, Rule(**doc["rule"]))
                now = decide(rows, Rule(**{**doc["rule"], **changes}))
                if (was.accepted, was.added) == (now.accepted, now.added):
                    continue
                moved += 1
                c = was.chosen
                print(f"{_name(r)}{where}: {list(was.added) or 'nothing'} -> "
                      f"{list(now.added) or 'nothing'} ({' + '.join(c.atoms)}: "
                      f"{_measures(c, was.rule)})")
                break
    return n, moved


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("files", nargs="+")
    ap.add_argument("--set", action="append", default=[], metavar="FIELD=VALUE",
                    help="a Rule setting to decide again with (repeatable)")
    a = ap.parse_args(argv)
    changes = dict((k, _value(v)) for k, _, v in (s.partition("=") for s in a.set))
    n, moved = compare(a.files, changes)
    print(f"{n} decisions, {moved} records whose decision differs")


if __name__ == "__main__":
    main()
