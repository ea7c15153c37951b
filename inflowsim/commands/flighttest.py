"""``inflowsim flighttest``: a virtual flight test that writes a record (CSV).

Default truth: the nonlinear individual-blade rotor (:mod:`inflowsim.flighttest`,
:mod:`inflowsim.flighttest.bladesim`); its physics is built in, so ``--add`` takes only the
measurement effects ``azimuth-bias`` and ``time-delay`` there.  ``--truth linear``
generates from any structure plus effects (paper values for the preset's
parameters, theory values for added effects or, where theory means "no effect",
the paper's estimates: :func:`inflowsim.model.presets.truth_parameters`; ``--set
NAME=VALUE`` to change any).  Records are continuous-time by default (smooth pilot
inputs, the truth integrated with them); ``--hold zoh`` holds the inputs over each
sample instead.
"""
from __future__ import annotations

import math
from pathlib import Path

from ._checks import finite_float, positive_float, positive_int
from ..channels import CONTROLS
from ..errors import InputError
from ._common import (add_add_option, add_channels_option, add_flight_options,
                      add_json_option, add_model_option, add_out_options, check_finite,
                      check_seed, print_json, progress)

HELP = "virtual flight test: write a record from a nonlinear blade truth or a linear model"

NONLINEAR_EFFECTS = ("azimuth-bias", "time-delay", "servo-actuators", "lead-lag")
NONLINEAR_SET = ("lambda_beta2", "n_beta", "tau0", "tau_cs", "K_R")
#: ``--set`` names of the nonlinear truth's servo actuators (with ``--add servo-actuators``)
SERVO_SET = ("servo_tau", "servo_zeta")
#: ``--set`` names of the nonlinear truth's blade lead-lag (with ``--add lead-lag``)
LAG_SET = ("nu_zeta", "zeta_lag")


def add_arguments(p):
    p.add_argument("--truth", choices=("nonlinear", "linear"), default="nonlinear",
                   help="nonlinear individual-blade rotor (default) or a linear model")
    add_model_option(p, required=False,
                     help="linear truth: structure (preset, then +effect terms); "
                          "default glauert")
    add_add_option(p, help="add an effect (repeatable); nonlinear truth: azimuth-bias, "
                           "time-delay, servo-actuators (--set servo_tau, servo_zeta), "
                           "lead-lag (each blade's lag; --set nu_zeta, zeta_lag)")
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                   help="a truth parameter value (repeatable), e.g. tau_cs=21.4")
    p.add_argument("--input", choices=("doublet", "3211", "sweep", "multisine"),
                   default="doublet",
                   help="pilot input shape (default doublet); sweep: a log frequency "
                        "sweep; multisine: several controls at once on interleaved "
                        "harmonics with Schroeder phases")
    p.add_argument("--channel", choices=CONTROLS,
                   default="theta1s", help="control the pilot moves (default theta1s)")
    p.add_argument("--design", metavar="FILE",
                   help="fly an input design (inflowsim design --out): its multisines, "
                        "record length and step replace --input, --duration, --dt")
    add_channels_option(p, help="multisine: the controls moved at once (default all "
                                "three)")
    p.add_argument("--sweep-range", "--freq-range", nargs=2, type=finite_float,
                   metavar=("F1", "F2"), default=None,
                   help="sweep or multisine: frequency range [Hz] (default 0.15 3)")
    p.add_argument("--sweep-duration", "--input-duration", type=finite_float, metavar="T",
                   help="sweep or multisine: its length [s] (default: to 1 s before "
                        "the record's end); the multisine's base frequency is 1/T")
    p.add_argument("--fade", type=finite_float, default=1.0, metavar="S",
                   help="sweep or multisine: fade in and out [s] (default 1)")
    p.add_argument("--amplitude-deg", type=finite_float, default=None, metavar="A",
                   help="input amplitude [deg], the peak of a sweep or of each "
                        "multisine channel (default 1; --campaign 0.25: the truth's "
                        "linear range at the default --noise)")
    p.add_argument("--width", type=finite_float, default=0.4, metavar="S",
                   help="doublet half-width or 3211 unit [s] (default 0.4)")
    add_flight_options(p, duration_help="record length [s] (default 26.6: 0.0376 Hz "
                                        "resolution; --campaign 20)",
                       dt_help="sample step [s] (default 0.01; --campaign 0.015625)")
    p.add_argument("--noise-color-hz", type=finite_float, metavar="F",
                   help="colour the flap noise by a first-order low-pass with corner F "
                        "[Hz] (default white)")
    p.add_argument("--hold", choices=("continuous", "zoh"), default="continuous",
                   help="continuous: smooth inputs, the truth integrated with them, as "
                        "measured data (default); zoh: inputs held over each sample")
    p.add_argument("--rise", type=finite_float, default=0.1, metavar="S",
                   help="10-90%% rise time of each switch of the pilot input [s] "
                        "(default 0.1; 0 for sharp steps)")
    p.add_argument("--seed", type=int, default=0, metavar="N", help="noise seed")
    p.add_argument("--azimuth-bias", type=finite_float, metavar="RAD",
                   help="offset of the recorded azimuth [rad] (adds azimuth-bias)")
    p.add_argument("--delay", type=finite_float, metavar="S",
                   help="time delay of the recorded flap [s] (adds time-delay)")
    p.add_argument("--blades", type=int, default=4, metavar="N",
                   help="nonlinear truth: number of blades (default 4)")
    p.add_argument("--mu", type=float, metavar="MU",
                   help="advance ratio of the flight (default 0.249, the Puma at "
                        "100 kt; --campaign: --speeds)")
    p.add_argument("--speed", choices=("eq14", "mu"), default="eq14",
                   help="nonlinear truth: speed through the disc, Eq. (14) (default) "
                        "or the trim mu (then the inflow is the basic model)")
    p.add_argument("--no-body", action="store_true",
                   help="hold the hub fixed (no body motion)")
    p.add_argument("--campaign", metavar="DIR",
                   help="write a virtual campaign instead: records from the nonlinear "
                        "truth at every --speeds, a doublet, a 3-2-1-1 and a sweep on "
                        "each control, --repeats times, and DIR/plan.csv for 'inflowsim "
                        "campaign' (default 20 s at 64 Hz each, inputs of 0.25 deg; "
                        "existing records of the same truth, flown alike, are kept, "
                        "others refused; --speed, --blades and --no-body choose the "
                        "truth)")
    p.add_argument("--speeds", nargs="+", type=positive_float, metavar="MU",
                   help="--campaign: advance ratios (default 0.10 0.15 ... 0.35)")
    p.add_argument("--repeats", type=positive_int, default=1, metavar="N",
                   help="--campaign: records per speed, control and shape (default 1)")
    p.add_argument("--workers", type=int, metavar="N",
                   help="--campaign: generating processes (default: the cores)")
    p.add_argument("--truth-json", metavar="FILE",
                   help="also write the truth (parameters, trim, settings) as JSON")
    add_out_options(p, "CSV", "output record (required unless --campaign)")
    add_json_option(p, help="print the truth JSON on stdout")


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
    from ..fileio import check_output
    paths = [Path(args.out)] + ([Path(args.truth_json)] if args.truth_json else [])
    if len(paths) == 2 and paths[0].resolve() == paths[1].resolve():
        raise InputError(f"--truth-json {args.truth_json}: same file as --out")
    for p in paths:
        check_output(p, args.force)


#: Limits checked before generating (a mistyped option must not run for hours):
#: 100 kHz at most, :data:`inflowsim.data.record.MAX_SAMPLES` samples at most, 20 deg
#: inputs.
MIN_DT = 1e-5
MAX_AMPLITUDE_DEG = 20.0
#: Blades of the nonlinear truth: multiblade coordinates need three; eight is the most
#: any helicopter flies (a judgement: ``interface.md``).
MIN_BLADES, MAX_BLADES = 3, 8


def _manoeuvre(args):
    from ..data.record import MAX_SAMPLES
    from ..flighttest.virtual import Manoeuvre
    designed = _designed(args) if args.design else None
    check_finite(args, "amplitude_deg", "start", "width", "duration", "dt", "noise", "rise",
                 "fade", "sweep_range", "sweep_duration", "speeds", "noise_color_hz")
    check_seed(args.seed)
    if not MIN_DT <= args.dt <= 1.0:
        raise InputError(f"--dt {args.dt:g}: the sample step must be in [{MIN_DT:g}, 1] s")
    if not 4 * args.dt <= args.duration or args.duration / args.dt > MAX_SAMPLES:
        raise InputError(f"--duration {args.duration:g}: must hold 4 to {MAX_SAMPLES:,} "
                         f"samples of --dt {args.dt:g} s")
    if args.noise < 0:
        raise InputError(f"--noise {args.noise:g}: a standard deviation is >= 0")
    if not 0 < args.amplitude_deg <= MAX_AMPLITUDE_DEG:
        raise InputError(f"--amplitude-deg {args.amplitude_deg:g}: must be in (0, "
                         f"{MAX_AMPLITUDE_DEG:g}] deg (the shape sets the signs; beyond "
                         f"{MAX_AMPLITUDE_DEG:g} deg leaves any linear model's range)")
    if args.delay is not None and not (math.isfinite(args.delay)
                                       and 0 <= args.delay < args.duration):
        raise InputError(f"--delay {args.delay:g}: a recording delay is in [0, "
                         f"--duration {args.duration:g}) s")
    if args.azimuth_bias is not None and not (math.isfinite(args.azimuth_bias)
                                              and abs(args.azimuth_bias) <= math.pi):
        raise InputError(f"--azimuth-bias {args.azimuth_bias:g}: an azimuth offset is in "
                         "[-pi, pi] rad")

    if args.width <= 0:
        raise InputError(f"--width {args.width}: must be > 0 s")
    if args.rise < 0 or args.rise > args.width:
        raise InputError(f"--rise {args.rise}: must be in [0, --width {args.width:g}] s")
    c = args.noise_color_hz
    if c is not None and not (math.isfinite(c) and 0 < c < 0.5 / args.dt):
        raise InputError(f"--noise-color-hz {c}: must be above 0 and below the Nyquist "
                         f"frequency {0.5 / args.dt:g} Hz")
    if designed is not None:
        return designed
    if args.input in ("sweep", "multisine"):
        return _frequency_input(args)
    if args.channels or args.sweep_range or args.sweep_duration is not None:
        raise InputError(f"--channels, --sweep-range and --sweep-duration apply to "
                         f"--input sweep or multisine, not {args.input}")
    return (Manoeuvre(channel=args.channel, shape=args.input,
                      amplitude=math.radians(args.amplitude_deg), t_start=args.start,
                      width=args.width, rise=args.rise),)


def _check_flight(args):
    """The checks that follow the truth's own (its messages first): the input starts
    within the record; the nonlinear rotor's blades within the limits."""
    if not args.design and not 0 <= args.start < args.duration:
        raise InputError(f"--start {args.start:g}: the input must start within the "
                         f"record, in [0, --duration {args.duration:g}) s")
    if not MIN_BLADES <= args.blades <= MAX_BLADES:
        raise InputError(f"--blades {args.blades}: n_blades must be {MIN_BLADES} to "
                         f"{MAX_BLADES} (multiblade coordinates need 3; no rotor flies "
                         f"more than {MAX_BLADES})")


def _designed(args):
    from ..fileio import read_json
    from ..flighttest.design import manoeuvres_from_json
    try:
        doc = read_json(args.design, "design file")
    except InputError as exc:
        raise InputError(f"--design {exc}") from None
    try:
        man, args.duration, args.dt = manoeuvres_from_json(doc)
    except InputError as exc:
        raise InputError(f"--design {args.design}: {exc}") from None
    args.input = "multisine"
    return man


#: Default frequency range [Hz] of a sweep or multisine.
SWEEP_RANGE = (0.15, 3.0)


def _frequency_input(args):
    """The sweep's manoeuvre, or one multisine manoeuvre per control on interleaved
    harmonics of ``1 / length``."""
    from ..data.inputs import interleaved_harmonics
    from ..flighttest.virtual import Manoeuvre
    f1, f2 = args.sweep_range or SWEEP_RANGE
    nyq = 0.5 / args.dt
    if not (math.isfinite(f1) and math.isfinite(f2) and 0 < f1 < f2 <= nyq):
        raise InputError(f"--sweep-range {f1:g} {f2:g}: need 0 < F1 < F2 <= the Nyquist "
                         f"frequency {nyq:g} Hz")
    length = args.sweep_duration
    if length is None:
        length = args.duration - args.start - 1.0
    if not (math.isfinite(length) and length > 0 and args.start + length <= args.duration):
        raise InputError(f"--sweep-duration {length:g}: must be > 0 s and end within the "
                         f"record (--start {args.start:g} + T <= --duration "
                         f"{args.duration:g})")
    if not (math.isfinite(args.fade) and 0 <= args.fade <= 0.5 * length):
        raise InputError(f"--fade {args.fade:g}: must be in [0, half the input's "
                         f"length {0.5 * length:g}] s")
    amp = math.radians(args.amplitude_deg)
    if args.input == "sweep":
        if args.channels:
            raise InputError("--channels applies to --input multisine (a sweep moves "
                             "--channel)")
        if f1 * length < 1:
            raise InputError(f"--sweep-range {f1:g}: a sweep of {length:g} s cannot "
                             f"hold one period at {f1:g} Hz")
        return (Manoeuvre(channel=args.channel, shape="sweep", amplitude=amp,
                          t_start=args.start, f_range=(f1, f2), length=length,
                          fade=args.fade),)
    channels = tuple(args.channels or CONTROLS)
    if len(set(channels)) < len(channels):
        raise InputError(f"--channels {' '.join(channels)}: a control given twice")
    k1, k2 = max(1, math.ceil(f1 * length - 1e-9)), math.floor(f2 * length + 1e-9)
    if k2 - k1 + 1 < 2 * len(channels):
        raise InputError(f"--sweep-range {f1:g} {f2:g} over {length:g} s holds "
                         f"{max(k2 - k1 + 1, 0)} harmonics of {1 / length:.4g} Hz; "
                         f"{len(channels)} channel(s) need at least two each")
    return tuple(Manoeuvre(channel=c, shape="multisine", amplitude=amp,
                           t_start=args.start, length=length, harmonics=h, fade=args.fade)
                 for c, h in zip(channels, interleaved_harmonics(len(channels), k1, k2)))


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
    servo = None
    if "servo-actuators" in args.add:
        from ..model.effects.servo_actuators import EFFECT as SERVO
        sv = SERVO.theory(None) | {n: values.pop(n) for n in SERVO_SET if n in values}
        servo = (sv["servo_tau"], sv["servo_zeta"])
    k = _constants(args)
    if "lead-lag" in args.add:
        # the blades' lag: the effect's theory values for the rotor, or --set
        from ..model.effects.lead_lag import EFFECT as LAG
        if "k_flap_lag" in values:
            raise InputError("--set k_flap_lag: the nonlinear truth's flap-lag coupling "
                             "is its physics (k_flap_lag = 1); set nu_zeta, zeta_lag")
        values = {n: v for n, v in LAG.theory(k).items() if n in LAG_SET} | values
    takes = NONLINEAR_SET + (LAG_SET if "lead-lag" in args.add else ())
    unknown = sorted(set(values) - set(takes))
    if unknown:
        extra = [f"{', '.join(names)} with --add {effect}" for effect, names in
                 (("servo-actuators", SERVO_SET), ("lead-lag", LAG_SET))
                 if effect not in args.add]
        raise InputError(f"--set {unknown[0]}: the nonlinear truth takes "
                         f"{', '.join(takes)}"
                         + (f" ({'; '.join(extra)})" if extra else ""))
    rotor = RotorSpec(constants=k, n_blades=args.blades, speed=args.speed, **values)
    return FlightTest(rotor=rotor, manoeuvres=man, duration=args.duration, dt=args.dt,
                      noise_flap=args.noise, seed=args.seed,
                      azimuth_bias=args.azimuth_bias or 0.0, delay=args.delay or 0.0,
                      body=None if args.no_body else FlightTest().body,
                      hold=args.hold, noise_color_hz=args.noise_color_hz, servo=servo,
                      description=f"{_what(args, man)}, nonlinear blade-element truth"
                      + (f", servo actuators {servo[0]:g} s, damping {servo[1]:g}"
                         if servo else "")
                      + (f", blade lead-lag nu_zeta {rotor.nu_zeta:g}, zeta_lag "
                         f"{rotor.zeta_lag:g}" if rotor.lag else ""))


def _linear(args, man, values):
    from ..flighttest.nonlinear import FlightTest
    from ..model.build import build_model
    from ..model.presets import truth_parameters
    from ..model.structure import Structure
    from ..flighttest.virtual import PUMA_TRIM, VirtualTest
    if args.blades != 4 or args.speed != "eq14":
        raise InputError("--blades and --speed apply to --truth nonlinear only")
    s = Structure.parse(args.model or "glauert")
    for e in args.add:
        s = s.with_effect(e)
    if args.azimuth_bias is not None and "azimuth-bias" not in s.effects:
        s = s.with_effect("azimuth-bias")
    if args.delay is not None and "time-delay" not in s.effects:
        s = s.with_effect("time-delay")
    k = _constants(args)
    # effects linearised about the trim see the virtual record's trim (as the
    # record's generator gives them, flighttest.virtual)
    k_trim = k if k.trim is not None else k.with_trim(dict(PUMA_TRIM, mux=k.mu))
    params = truth_parameters(s, k_trim)
    if args.azimuth_bias is not None:
        params["azimuth_bias"] = args.azimuth_bias
    if args.delay is not None:
        params["delay"] = args.delay
    params.update(values)
    build_model(s, params, k_trim)          # one-line refusal of unknown or bad values
    FlightTest(duration=args.duration, dt=args.dt, noise_flap=args.noise).check()
    return VirtualTest(structure=s.name, parameters=params, constants=k, manoeuvres=man,
                       duration=args.duration, dt=args.dt, noise_flap=args.noise,
                       seed=args.seed, body=FlightTest().body if not args.no_body
                       else _still_body(), hold=args.hold,
                       noise_color_hz=args.noise_color_hz,
                       description=f"{_what(args, man)}, linear truth {s.name}")


#: The advance ratios a single flight test flies (the nonlinear truth's trim and
#: the linear models' range).
MU_RANGE = (0.0, 0.5)


def _constants(args):
    """The Puma's constants at ``--mu`` (refused outside :data:`MU_RANGE`)."""
    from ..model.params import PUMA
    if args.mu is None:
        return PUMA
    if not (math.isfinite(args.mu) and MU_RANGE[0] < args.mu <= MU_RANGE[1]):
        raise InputError(f"--mu {args.mu:g}: the advance ratio must be in "
                         f"({MU_RANGE[0]:g}, {MU_RANGE[1]:g}]")
    return PUMA.with_mu(args.mu)


def _what(args, manoeuvres) -> str:
    chans = " ".join(m.channel for m in manoeuvres)
    m = manoeuvres[0]
    if m.shape == "sweep":
        return f"{chans} sweep {m.f_range[0]:g}-{m.f_range[1]:g} Hz"
    if m.shape == "multisine":
        ks = [k for x in manoeuvres for k in x.harmonics]
        what = "designed multisine" if args.design else "multisine"
        return f"{chans} {what} {min(ks) / m.length:.3g}-{max(ks) / m.length:.3g} Hz"
    return f"{chans} {args.input}"


def _still_body():
    from ..flighttest.body import BodyModel
    return BodyModel(m_theta=0.0, l_theta=0.0, z_theta=0.0)


def _campaign(args) -> int:
    from ..flighttest.campaign import AMPLITUDE_DEG, MUS, virtual_campaign
    if args.out or args.truth_json or args.json:
        raise InputError("--campaign writes its own records and plan: drop --out, "
                         "--truth-json and --json")
    if args.mu is not None:
        raise InputError("--mu flies one record; a campaign's speeds are --speeds")
    if args.truth != "nonlinear" or args.add or args.set or args.model:
        raise InputError("--campaign flies the nonlinear truth as it is: drop --truth, "
                         "--model, --add and --set")
    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers {args.workers}: need at least 1")
    args.duration = 20.0 if args.duration is None else args.duration
    args.dt = 1.0 / 64 if args.dt is None else args.dt
    if args.amplitude_deg is None:
        args.amplitude_deg = AMPLITUDE_DEG
    _manoeuvre(args)                       # the shared checks of duration, step, noise
    _check_flight(args)
    plan = virtual_campaign(args.campaign, mus=tuple(args.speeds or MUS),
                            repeats=args.repeats, duration=args.duration, dt=args.dt,
                            noise=args.noise, workers=args.workers, progress=progress,
                            speed=args.speed, n_blades=args.blades, body=not args.no_body,
                            amplitude_deg=args.amplitude_deg)
    progress(f"flighttest: wrote the campaign's plan {plan}")
    return 0


def run(args) -> int:
    import json

    from ..data.record import write_record
    from ..fileio import json_text, safe_write_text
    from ..flighttest.nonlinear import flighttest
    if args.campaign:
        return _campaign(args)
    if not args.out:
        raise InputError("--out CSV is required (or --campaign DIR)")
    args.duration = 26.6 if args.duration is None else args.duration
    args.dt = 0.01 if args.dt is None else args.dt
    args.amplitude_deg = 1.0 if args.amplitude_deg is None else args.amplitude_deg
    _check_outputs(args)
    man = _manoeuvre(args)
    values = _settings(args.set)
    test = (_nonlinear if args.truth == "nonlinear" else _linear)(args, man, values)
    if hasattr(test, "check"):
        test.check()                        # refuse before the progress line
    _check_flight(args)
    progress(f"flighttest: generating {args.duration:g} s at {args.dt:g} s "
             f"({args.truth} truth)")
    res = flighttest(test, progress)
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
    import numpy as np
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    return str(o)
