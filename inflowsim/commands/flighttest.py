"""``inflowsim flighttest``: a virtual flight test that writes a record (CSV).

Default truth: the nonlinear individual-blade rotor (:mod:`inflowsim.flighttest`,
:mod:`inflowsim.bladesim`); its physics is built in, so ``--add`` takes only the
measurement effects ``azimuth-bias`` and ``time-delay`` there.  ``--truth linear``
generates from any structure plus effects (paper values for the preset's
parameters, theory values for added effects or, where theory means "no effect",
the paper's estimates: :func:`inflowsim.presets.truth_parameters`; ``--set
NAME=VALUE`` to change any).  Records are continuous-time by default (smooth pilot
inputs, the truth integrated with them); ``--hold zoh`` holds the inputs over each
sample instead.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..channels import CONTROLS
from ..fileio import check_output, json_text, safe_write_text
from ..model.params import PUMA
from ..data.record import write_record
from ._common import check_seed, print_json, progress

HELP = "virtual flight test: write a record from a nonlinear blade truth or a linear model"

NONLINEAR_EFFECTS = ("azimuth-bias", "time-delay")
NONLINEAR_SET = ("lambda_beta2", "n_beta", "tau0", "tau_cs")


def add_arguments(p):
    p.add_argument("--truth", choices=("nonlinear", "linear"), default="nonlinear",
                   help="nonlinear individual-blade rotor (default) or a linear model")
    p.add_argument("--model", "-m", metavar="M",
                   help="linear truth: structure (preset, then +effect terms); "
                        "default glauert")
    p.add_argument("--add", action="append", default=[], metavar="EFFECT",
                   help="add an effect (repeatable); nonlinear truth: azimuth-bias, "
                        "time-delay")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a truth parameter value (repeatable), e.g. tau_cs=21.4")
    p.add_argument("--input", choices=("doublet", "3211"), default="doublet",
                   help="pilot input shape (default doublet)")
    p.add_argument("--channel", choices=CONTROLS,
                   default="theta1s", help="control the pilot moves (default theta1s)")
    p.add_argument("--amplitude-deg", type=float, default=1.0, metavar="A",
                   help="input amplitude [deg] (default 1)")
    p.add_argument("--start", type=float, default=2.0, metavar="S",
                   help="time of the first control movement [s] (default 2)")
    p.add_argument("--width", type=float, default=0.4, metavar="S",
                   help="doublet half-width or 3211 unit [s] (default 0.4)")
    p.add_argument("--duration", type=float, default=None, metavar="S",
                   help="record length [s] (default 26.6: 0.0376 Hz resolution; "
                        "--campaign 20)")
    p.add_argument("--dt", type=float, default=None, metavar="S",
                   help="sample step [s] (default 0.01; --campaign 0.015625)")
    p.add_argument("--noise", type=float, default=1e-4, metavar="R",
                   help="flap sensor noise, standard deviation [rad] (default 1e-4)")
    p.add_argument("--noise-color-hz", type=float, metavar="F",
                   help="colour the flap noise by a first-order low-pass with corner F "
                        "[Hz] (default white)")
    p.add_argument("--hold", choices=("continuous", "zoh"), default="continuous",
                   help="continuous: smooth inputs, the truth integrated with them, as "
                        "measured data (default); zoh: inputs held over each sample")
    p.add_argument("--rise", type=float, default=0.1, metavar="S",
                   help="10-90%% rise time of each switch of the pilot input [s] "
                        "(default 0.1; 0 for sharp steps)")
    p.add_argument("--seed", type=int, default=0, metavar="N", help="noise seed")
    p.add_argument("--azimuth-bias", type=float, metavar="RAD",
                   help="offset of the recorded azimuth [rad] (adds azimuth-bias)")
    p.add_argument("--delay", type=float, metavar="S",
                   help="time delay of the recorded flap [s] (adds time-delay)")
    p.add_argument("--blades", type=int, default=4, metavar="N",
                   help="nonlinear truth: number of blades (default 4)")
    p.add_argument("--speed", choices=("eq14", "mu"), default="eq14",
                   help="nonlinear truth: speed through the disc, Eq. (14) (default) "
                        "or the trim mu (then the inflow is the basic model)")
    p.add_argument("--no-body", action="store_true",
                   help="hold the hub fixed (no body motion)")
    p.add_argument("--out", "-o", metavar="CSV", help="output record (required unless "
                                                      "--campaign)")
    p.add_argument("--campaign", metavar="DIR",
                   help="write a virtual campaign instead: records from the nonlinear "
                        "truth at every --speeds, a doublet and a 3-2-1-1 on each "
                        "control, --repeats times, and DIR/plan.csv for 'inflowsim "
                        "campaign' (default 20 s at 64 Hz each; existing records are kept)")
    p.add_argument("--speeds", nargs="+", type=float, metavar="MU",
                   help="--campaign: advance ratios (default 0.10 0.15 ... 0.35)")
    p.add_argument("--repeats", type=int, default=1, metavar="N",
                   help="--campaign: records per speed, control and shape (default 1)")
    p.add_argument("--workers", type=int, metavar="N",
                   help="--campaign: generating processes (default: the cores)")
    p.add_argument("--truth-json", metavar="FILE",
                   help="also write the truth (parameters, trim, settings) as JSON")
    p.add_argument("--force", action="store_true", help="replace existing output files")
    p.add_argument("--json", action="store_true", help="print the truth JSON on stdout")


def _settings(items) -> dict:
    out = {}
    for item in items:
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or not name:
            raise InputError(f"--set {item!r}: expected NAME=VALUE")
        try:
            out[name] = float(value)
        except ValueError:
            raise InputError(f"--set {name}: {value.strip()!r} is not a number") from None
    return out


def _check_outputs(args):
    paths = [Path(args.out)] + ([Path(args.truth_json)] if args.truth_json else [])
    if len(paths) == 2 and paths[0].resolve() == paths[1].resolve():
        raise InputError(f"--truth-json {args.truth_json}: same file as --out")
    for p in paths:
        check_output(p, args.force)


#: Limits checked before generating (a mistyped option must not run for hours):
#: 100 kHz at most, 2 million samples at most (5.5 h at 100 Hz), 20 deg inputs.
MIN_DT = 1e-5
MAX_SAMPLES = 2_000_000
MAX_AMPLITUDE_DEG = 20.0


def _manoeuvre(args):
    from ..flighttest.virtual import Manoeuvre
    for name in ("amplitude_deg", "start", "width", "duration", "dt", "noise", "rise"):
        v = getattr(args, name)
        if not math.isfinite(v):
            raise InputError(f"--{name.replace('_', '-')} {v}: must be finite")
    check_seed(args.seed)
    if not MIN_DT <= args.dt <= 1.0:
        raise InputError(f"--dt {args.dt:g}: the sample step must be in [{MIN_DT:g}, 1] s")
    if not 4 * args.dt <= args.duration or args.duration / args.dt > MAX_SAMPLES:
        raise InputError(f"--duration {args.duration:g}: must hold 4 to {MAX_SAMPLES:,} "
                         f"samples of --dt {args.dt:g} s")
    if args.noise < 0:
        raise InputError(f"--noise {args.noise:g}: a standard deviation is >= 0")
    if abs(args.amplitude_deg) > MAX_AMPLITUDE_DEG:
        raise InputError(f"--amplitude-deg {args.amplitude_deg:g}: a pilot input beyond "
                         f"{MAX_AMPLITUDE_DEG:g} deg leaves any linear model's range")
    if args.width <= 0:
        raise InputError(f"--width {args.width}: must be > 0 s")
    if args.rise < 0 or args.rise > args.width:
        raise InputError(f"--rise {args.rise}: must be in [0, --width {args.width:g}] s")
    c = args.noise_color_hz
    if c is not None and not (math.isfinite(c) and 0 < c < 0.5 / args.dt):
        raise InputError(f"--noise-color-hz {c}: must be above 0 and below the Nyquist "
                         f"frequency {0.5 / args.dt:g} Hz")
    return Manoeuvre(channel=args.channel, shape=args.input,
                     amplitude=math.radians(args.amplitude_deg), t_start=args.start,
                     width=args.width, rise=args.rise)


def _nonlinear(args, man, values):
    from ..flighttest.bladesim import RotorSpec
    from ..flighttest.nonlinear import FlightTest
    if args.model:
        raise InputError("--model selects a linear truth: add --truth linear")
    bad = [e for e in args.add if e not in NONLINEAR_EFFECTS]
    if bad:
        raise InputError(f"--add {bad[0]}: the nonlinear truth has its physics built in "
                         f"and takes only the measurement effects "
                         f"{', '.join(NONLINEAR_EFFECTS)} (use --truth linear for {bad[0]})")
    unknown = sorted(set(values) - set(NONLINEAR_SET))
    if unknown:
        raise InputError(f"--set {unknown[0]}: the nonlinear truth takes "
                         f"{', '.join(NONLINEAR_SET)}")
    rotor = RotorSpec(n_blades=args.blades, speed=args.speed, **values)
    return FlightTest(rotor=rotor, manoeuvres=(man,), duration=args.duration, dt=args.dt,
                      noise_flap=args.noise, seed=args.seed,
                      azimuth_bias=args.azimuth_bias or 0.0, delay=args.delay or 0.0,
                      body=None if args.no_body else FlightTest().body,
                      hold=args.hold, noise_color_hz=args.noise_color_hz,
                      description=f"{args.channel} {args.input}, nonlinear blade-element "
                                  "truth")


def _linear(args, man, values):
    from ..flighttest.nonlinear import FlightTest
    from ..model.build import build_model
    from ..model.presets import truth_parameters
    from ..model.structure import Structure
    from ..flighttest.virtual import VirtualTest
    if args.blades != 4 or args.speed != "eq14":
        raise InputError("--blades and --speed apply to --truth nonlinear only")
    s = Structure.parse(args.model or "glauert")
    for e in args.add:
        s = s.with_effect(e)
    if args.azimuth_bias is not None and "azimuth-bias" not in s.effects:
        s = s.with_effect("azimuth-bias")
    if args.delay is not None and "time-delay" not in s.effects:
        s = s.with_effect("time-delay")
    params = truth_parameters(s, PUMA)
    if args.azimuth_bias is not None:
        params["azimuth_bias"] = args.azimuth_bias
    if args.delay is not None:
        params["delay"] = args.delay
    params.update(values)
    build_model(s, params, PUMA)            # one-line refusal of unknown or bad values
    FlightTest(duration=args.duration, dt=args.dt, noise_flap=args.noise).check()
    return VirtualTest(structure=s.name, parameters=params, manoeuvres=(man,),
                       duration=args.duration, dt=args.dt, noise_flap=args.noise,
                       seed=args.seed, body=FlightTest().body if not args.no_body
                       else _still_body(), hold=args.hold,
                       noise_color_hz=args.noise_color_hz,
                       description=f"{args.channel} {args.input}, linear truth {s.name}")


def _still_body():
    from ..flighttest.body import BodyModel
    return BodyModel(m_theta=0.0, l_theta=0.0, z_theta=0.0)


def _campaign(args) -> int:
    from ..flighttest.campaign import MUS, virtual_campaign
    if args.out or args.truth_json or args.json:
        raise InputError("--campaign writes its own records and plan: drop --out, "
                         "--truth-json and --json")
    if args.truth != "nonlinear" or args.add or args.set or args.model:
        raise InputError("--campaign flies the nonlinear truth as it is: drop --truth, "
                         "--model, --add and --set")
    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers {args.workers}: need at least 1")
    args.duration = 20.0 if args.duration is None else args.duration
    args.dt = 1.0 / 64 if args.dt is None else args.dt
    _manoeuvre(args)                       # the shared checks of duration, step, noise
    plan = virtual_campaign(args.campaign, mus=tuple(args.speeds or MUS),
                            repeats=args.repeats, duration=args.duration, dt=args.dt,
                            noise=args.noise, workers=args.workers, progress=progress)
    progress(f"flighttest: wrote the campaign's plan {plan}")
    return 0


def run(args) -> int:
    from ..flighttest.nonlinear import flighttest
    if args.campaign:
        return _campaign(args)
    if not args.out:
        raise InputError("--out CSV is required (or --campaign DIR)")
    args.duration = 26.6 if args.duration is None else args.duration
    args.dt = 0.01 if args.dt is None else args.dt
    _check_outputs(args)
    man = _manoeuvre(args)
    values = _settings(args.set)
    test = (_nonlinear if args.truth == "nonlinear" else _linear)(args, man, values)
    if hasattr(test, "check"):
        test.check()                        # refuse before the progress line
    progress(f"flighttest: generating {args.duration:g} s at {args.dt:g} s "
             f"({args.truth} truth)")
    res = flighttest(test)
    write_record(res.record, args.out, overwrite=args.force)
    truth = json.loads(json.dumps(res.truth, default=_plain))
    if args.truth_json:
        safe_write_text(args.truth_json, json_text(truth),
                        overwrite=args.force, protect=(args.out,))
    progress(f"flighttest: wrote {args.out} ({len(res.record)} samples)")
    if args.json:
        print_json(truth)
    return 0


def _plain(o):
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    return str(o)
