"""``inflowsim design``: a multisine that maximises the information on chosen
parameters (D_s-optimal), with the Cramer-Rao bounds expected before (a 1 deg
doublet) and after; ``--out FILE`` writes the design for ``flighttest --design``.
"""
from __future__ import annotations

from ..channels import CONTROLS
from ..fileio import check_output, json_text, safe_write_text
from ._common import (DEFAULT_BAND, add_add_option, add_band_option, add_channels_option,
                      add_flight_options, add_json_option, add_model_option,
                      add_out_options, add_params_option, check_finite, print_json,
                      progress, read_structure_parameters)

HELP = "design a multisine input: most information on chosen parameters, bounds before/after"


def add_arguments(p):
    add_model_option(p, help="structure identified: preset, then +effect terms")
    add_params_option(p, help="current estimates (parameter file, identify --out); "
                              "default the paper's values")
    add_add_option(p, help="a candidate effect the diagnosis hesitates over (repeatable): "
                           "added to the structure, its parameters the interest")
    p.add_argument("--interest", nargs="+", metavar="NAME",
                   help="parameters to learn (default: the added effects', else all)")
    add_channels_option(p, default=list(CONTROLS))
    p.add_argument("--limit-deg", type=float, default=1.0, metavar="A",
                   help="amplitude limit per control [deg] (default 1: the peak)")
    p.add_argument("--rms", action="store_true",
                   help="the limit is the rms of each control's signal, not its peak")
    add_flight_options(p, duration=26.6, dt=0.01,
                       noise_help="flap sensor noise [rad] the bounds are expected for "
                                  "(default 1e-4)")
    add_band_option(p, DEFAULT_BAND, what="identification band [Hz]")
    add_out_options(p, "FILE", "write the design (JSON) for flighttest --design",
                    force_help="replace an existing --out")
    add_json_option(p)


def run(args) -> int:
    from ..flighttest.design import design_input, format_design
    check_finite(args, "limit_deg", "duration", "start", "dt", "noise")
    if args.out:
        check_output(args.out, args.force, protect=[args.params] if args.params else ())
    params = None
    if args.params:
        params = dict(read_structure_parameters(args.params, args.model)[1].parameters)
    d = design_input(args.model, params, interest=args.interest, effects=args.add,
                     channels=args.channels, limit_deg=args.limit_deg,
                     limit="rms" if args.rms else "peak", duration=args.duration,
                     t_start=args.start, dt=args.dt, band_hz=tuple(args.band),
                     noise_flap=args.noise, progress=progress)
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
