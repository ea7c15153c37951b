"""``inflowsim demo``: the workflow on a virtual Puma doublet record.

For now: a virtual record (``glauert`` truth with the paper's Table 3 values,
longitudinal cyclic doublet, seed 0) is written into the output folder as
``record.csv`` and read back, then compared with the ``basic`` preset (Table 1)
and the ``glauert`` preset (Table 3); the report goes to ``DIR/index.html`` and
a summary to stdout.  :func:`run_demo` is the whole body, so later steps
(diagnose, add, refit) extend it.
"""
from __future__ import annotations

from pathlib import Path

from ..model import build_model
from ..presets import preset_parameters
from ..record import format_record, parse_record
from ..validation import validate
from ..virtual import VirtualTest, virtual_record
from ..errors import InputError
from ._common import print_json
from .validate import validation_report

HELP = "the workflow on a virtual Puma doublet record: compare models, report with plots"
DEFAULT_DIR = "inflowsim-demo"
#: Structures compared, in order: the paper's Table 1 and Table 3 presets.
DEMO_STRUCTURES = ("basic", "glauert")


def add_arguments(p):
    p.add_argument("--out", "-o", default=DEFAULT_DIR, metavar="DIR",
                   help=f"report folder (default {DEFAULT_DIR}; created)")
    p.add_argument("--json", action="store_true", help="one JSON summary on stdout")


def demo_record():
    """The embedded default: a virtual Puma doublet record, glauert truth, seed 0."""
    return virtual_record(VirtualTest(structure="glauert", seed=0))


def run_demo(out_dir, structures=DEMO_STRUCTURES):
    """Write the demo into ``out_dir``; return ``(index.html path, results)``."""
    out = Path(out_dir)
    if out.exists() and not out.is_dir():    # refuse before any work
        raise InputError(f"{out}: exists and is not a directory; choose a report folder")
    text = format_record(demo_record())
    rec = parse_record(text, str(out / "record.csv"))     # as a user would read it
    results = []
    for s in structures:
        model = build_model(s, preset_parameters(s, rec.constants, "paper"), rec.constants)
        results.append(validate(rec, model))
    rep = validation_report(
        results, title="inflowsim demo: which model explains the Puma doublet?",
        subtitle="virtual Puma record at 100 kt (glauert truth, paper Table 3 values, "
                 "flap noise 1e-4 rad); models with the paper's Table 1 and 3 values")
    rep.attach("record.csv", text, "the virtual record (record-format CSV)")
    return rep.write(out), results


def run(args) -> int:
    path, results = run_demo(args.out)
    if args.json:
        print_json({"report": str(path),
                    "models": {r.structure: r.to_json()["channels"] for r in results}})
        return 0
    print(f"{'model':<10}{'channel':<8}{'rms [rad]':>12}{'TIC':>8}{'fit [%]':>9}")
    for r in results:
        for c, f in r.channels.items():
            print(f"{r.structure:<10}{c:<8}{f.rms:>12.4g}{f.tic:>8.4f}{f.fit_percent:>9.2f}")
    print(f"report: {path}")
    return 0
