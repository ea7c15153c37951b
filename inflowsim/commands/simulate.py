"""``inflowsim simulate``: replay a record's inputs through the fixed-step simulator.

The record's input columns, as perturbations about its trim
(:func:`inflowsim.data.record.find_trim`), drive :class:`inflowsim.simulate.simulator.Simulator`
from a zero state.  With ``--dt`` other than the record's step the inputs are
held (zero-order hold of the record samples): the simulator's step ``k`` at
``t0 + k dt`` uses the last record sample at or before that time, and the run
ends at the record's last sample time (at most
:data:`inflowsim.data.record.MAX_SAMPLES` steps).  The output is a record
(``record-format.md``): the record's flight condition (``omega``, ``mu``, ``a0``,
``solidity``, ``radius``, ``hub``, ``trim_window``; not its aircraft, description or seed,
which say where the input came from), a new description and ``# hold: zoh`` (what the
simulator did with the inputs, whatever the record's own hold), ``t``, the model's inputs as
totals (trim added back; what the simulator was fed), predicted
``beta0 beta1c beta1s`` as totals and ``lambda0 lambda1c lambda1s`` as
perturbations (the inflow has no measured trim).
"""
from __future__ import annotations

import math
from pathlib import Path

from ._checks import finite_float
from ..errors import InputError
from ._common import add_model_arguments, load_model, print_json, warn

HELP = "replay a record's inputs through the fixed-step simulator; write a record CSV"


def add_arguments(p):
    p.add_argument("record", metavar="RECORD", help="flight-test record (CSV)")
    add_model_arguments(p)
    p.add_argument("--dt", type=finite_float, metavar="S",
                   help="simulator step [s] (default the record's; inputs are held)")
    p.add_argument("--method", choices=("zoh", "rk4"), default="zoh",
                   help="discretisation: exact zero-order hold (default) or RK4")
    p.add_argument("--out", "-o", required=True, metavar="CSV", help="output record")
    p.add_argument("--force", action="store_true",
                   help="replace an existing output file (never the input record)")
    p.add_argument("--json", action="store_true", help="one JSON summary on stdout")


def run(args) -> int:
    from ..data.record import read_record, write_record
    from ..data.simulated import simulate_record
    from ..fileio import check_output
    if args.dt is not None and not (math.isfinite(args.dt) and args.dt > 0):
        raise InputError(f"--dt {args.dt}: the step must be a finite number > 0 s")
    rec = read_record(args.record)
    for w in rec.warnings():
        warn(w)
    model = load_model(args, rec.constants)
    inputs = [q for q in (args.record, args.params) if q]
    out = check_output(args.out, args.force, inputs)
    step = rec.dt if args.dt is None else args.dt
    src = f" parameters {args.params}" if args.params else " (paper table values)"
    desc = (f"simulated by inflowsim: model {model.structure.name}{src}, {args.method} "
            f"step {step:g} s, inputs of {Path(args.record).name}")
    sim = simulate_record(rec, model, args.dt, args.method, desc.replace("\n", " "))
    path = write_record(sim, out, overwrite=args.force, protect=inputs)
    if args.json:
        print_json({"out": str(path), "structure": model.structure.name,
                    "method": args.method, "dt": step, "samples": len(sim),
                    "columns": ["t", *sim.order]})
    else:
        print(f"wrote {path} ({len(sim)} samples, {model.structure.name}, "
              f"{args.method}, dt {step:g} s)")
    return 0
