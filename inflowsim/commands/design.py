"""``inflowsim design``: a multisine that maximises the information on chosen
parameters (D_s-optimal), with the Cramer-Rao bounds expected before (a 1 deg
doublet) and after; ``--out FILE`` writes the design for ``flighttest --design``.
"""
from __future__ import annotations

import math

from ..channels import CONTROLS
from ..errors import InputError
from ..fileio import check_output, json_text, safe_write_text
from ._common import DEFAULT_BAND, print_json, progress

HELP = "design a multisine input: most information on chosen parameters, bounds before/after"


def add_arguments(p):
    p.add_argument("--model", "-m", required=True,
                   help="structure identified: preset, then +effect terms")
    p.add_argument("--params", "-p", metavar="FILE",
                   help="current estimates (parameter file, identify --out); default "
                        "the paper's values")
    p.add_argument("--add", action="append", default=[], metavar="EFFECT",
                   help="a candidate effect the diagnosis hesitates over (repeatable): "
                        "added to the structure, its parameters the interest")
    p.add_argument("--interest", nargs="+", metavar="NAME",
                   help="parameters to learn (default: the added effects', else all)")
    p.add_argument("--channels", nargs="+", choices=CONTROLS, default=list(CONTROLS),
                   metavar="CH", help="controls moved at once (default all three)")
    p.add_argument("--limit-deg", type=float, default=1.0, metavar="A",
                   help="amplitude limit per control [deg] (default 1: the peak)")
    p.add_argument("--rms", action="store_true",
                   help="the limit is the rms of each control's signal, not its peak")
    p.add_argument("--duration", type=float, default=26.6, metavar="S",
                   help="record length [s] (default 26.6)")
    p.add_argument("--start", type=float, default=2.0, metavar="S",
                   help="input start [s] (default 2: a quiet lead-in for trim)")
    p.add_argument("--dt", type=float, default=0.01, metavar="S",
                   help="sample step [s] (default 0.01)")
    p.add_argument("--noise", type=float, default=1e-4, metavar="R",
                   help="flap sensor noise [rad] the bounds are expected for (default 1e-4)")
    p.add_argument("--band", nargs=2, type=float, metavar=("F1", "F2"),
                   default=DEFAULT_BAND, help=f"identification band [Hz] (default "
                                              f"{DEFAULT_BAND[0]:g} {DEFAULT_BAND[1]:g})")
    p.add_argument("--out", "-o", metavar="FILE",
                   help="write the design (JSON) for flighttest --design")
    p.add_argument("--force", action="store_true", help="replace an existing --out")
    p.add_argument("--json", action="store_true", help="one JSON document on stdout")


def run(args) -> int:
    from ..flighttest.design import design_input, format_design
    from ..model.paramfile import read_parameters
    from ..model.structure import Structure
    for name in ("limit_deg", "duration", "start", "dt", "noise"):
        v = getattr(args, name)
        if not math.isfinite(v):
            raise InputError(f"--{name.replace('_', '-')} {v}: must be finite")
    if args.out:
        check_output(args.out, args.force, protect=[args.params] if args.params else ())
    params = None
    if args.params:
        ps = read_parameters(args.params)
        s = Structure.parse(args.model)
        if set(ps.structure.effects) != set(s.effects):
            raise InputError(f"{args.params}: parameters are for structure "
                             f"{ps.structure.name}, not {s.name}")
        params = dict(ps.parameters)
    progress("design: optimising and computing the expected bounds")
    d = design_input(args.model, params, interest=args.interest, effects=args.add,
                     channels=args.channels, limit_deg=args.limit_deg,
                     limit="rms" if args.rms else "peak", duration=args.duration,
                     t_start=args.start, dt=args.dt, band_hz=tuple(args.band),
                     noise_flap=args.noise)
    doc = d.to_json()
    if args.out:
        safe_write_text(args.out, json_text(doc), overwrite=args.force,
                        protect=[args.params] if args.params else ())
        progress(f"design: wrote {args.out} (fly it: inflowsim flighttest --design "
                 f"{args.out} ...)")
    if args.json:
        print_json(doc)
    else:
        print(format_design(d))
    return 0
