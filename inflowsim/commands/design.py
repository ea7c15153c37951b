"""``inflowsim design``: a multisine that maximises the information on chosen
parameters (D_s-optimal), with the Cramer-Rao bounds expected before (a 1 deg
doublet) and after; ``--out FILE`` writes the design for ``flighttest --design``.
"""
from __future__ import annotations

from ..channels import CONTROLS
from ..errors import InputError
from ..fileio import check_output, json_text, safe_write_text
from ._checks import check_band, finite_float
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
    p.add_argument("--limit-deg", type=finite_float, default=1.0, metavar="A",
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


#: Limits of a design, checked before any work (judgements, ``interface.md``): the
#: step of :mod:`inflowsim.commands.flighttest` (100 kHz at most), a record of at most
#: 200,000 samples and 100 harmonics in the band (each about 0.3 s of optimisation:
#: the default 26.6 s design holds 32), and a quiet lead-in for the trim.
MIN_DT, MAX_DT = 1e-5, 1.0
MAX_SAMPLES = 200_000
MAX_HARMONICS = 100
MIN_START = 0.5


def _check_design(args):
    """Refuse a design whose numbers cannot make one, or would run without a
    practical end (one line naming the option)."""
    import math
    check_finite(args, "limit_deg", "duration", "start", "dt", "noise", "band")
    if not MIN_DT <= args.dt <= MAX_DT:
        raise InputError(f"--dt {args.dt:g}: the sample step must be in "
                         f"[{MIN_DT:g}, {MAX_DT:g}] s")
    if not args.noise > 0:
        raise InputError(f"--noise {args.noise:g}: a standard deviation > 0")
    if not MIN_START <= args.start:
        raise InputError(f"--start {args.start:g}: the multisine starts after a quiet "
                         f"lead-in of at least {MIN_START:g} s (the trim is its mean)")
    if not args.duration > args.start + 1.0:
        raise InputError(f"--duration {args.duration:g}: must end more than 1 s after "
                         f"--start {args.start:g}")
    n = args.duration / args.dt
    if n > MAX_SAMPLES:
        raise InputError(f"--duration {args.duration:g} at --dt {args.dt:g}: "
                         f"{n:,.0f} samples; a design holds at most {MAX_SAMPLES:,}")
    check_band(args.band, nyquist=0.5 / args.dt)
    length = args.duration - args.start - 1.0
    k = math.floor(args.band[1] * length + 1e-9) - max(1, math.ceil(args.band[0] * length
                                                                    - 1e-9)) + 1
    if k > MAX_HARMONICS:
        raise InputError(f"--band {args.band[0]:g} {args.band[1]:g} over {length:g} s: "
                         f"{k} harmonics of {1 / length:.3g} Hz; a design optimises at "
                         f"most {MAX_HARMONICS} (shorten --duration or narrow --band)")


def run(args) -> int:
    from ..flighttest.design import design_input, format_design
    _check_design(args)
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
