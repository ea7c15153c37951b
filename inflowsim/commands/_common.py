"""Helpers shared by the command modules: loading models and records, JSON out.

Building the parsers (``add_*_arguments``) imports nothing that computes: every
``--help`` answers without NumPy (issue #27); the helpers that run a command import
what they use.
"""
from __future__ import annotations

import math
import sys
from typing import TYPE_CHECKING

from ..defaults import ALPHA, DEFAULT_BAND, HOLDS
from ..errors import InputError
from ._checks import finite_float
from ..progress import SHOW as progress
from ..progress import warn

if TYPE_CHECKING:
    from ..model.structure import Structure


def add_model_arguments(p, params=True):
    add_model_option(p)
    add_effect_arguments(p)
    if params:
        add_params_option(p)


MODEL_HELP = "structure: basic, empirical, glauert, then +effect terms"
PARAMS_HELP = ("parameter file (JSON; identify --out writes one); default: the paper's "
               "table values for the preset")


def add_model_option(p, help=MODEL_HELP, required=True):
    """``--model/-m M``: a structure (preset, then ``+effect`` terms)."""
    p.add_argument("--model", "-m", required=required, metavar="M" if not required else None,
                   help=help)


def add_params_option(p, help=PARAMS_HELP):
    """``--params/-p FILE``: a parameter file for ``--model``."""
    p.add_argument("--params", "-p", metavar="FILE", help=help)


def add_add_option(p, help):
    """``--add EFFECT`` (repeatable)."""
    p.add_argument("--add", action="append", default=[], metavar="EFFECT", help=help)


def add_band_option(p, default=None, what="frequency band [Hz]", default_text=None):
    """``--band F1 F2`` [Hz]; the help names ``default`` (or ``default_text``)."""
    if default_text is None:
        default_text = f"{default[0]:g} {default[1]:g}"
    p.add_argument("--band", nargs=2, type=finite_float, metavar=("F1", "F2"), default=default,
                   help=f"{what} (default {default_text})")


def add_report_option(p, what="plots"):
    """``--report DIR``: a report folder."""
    p.add_argument("--report", metavar="DIR",
                   help=f"write {what} and DIR/index.html (the folder is created)")


def add_progress_options(p, default=None):
    """``--quiet`` and ``--progress``: whether progress is shown on standard error
    (default: when it is a terminal; :mod:`inflowsim.progress`).  A command's
    action parser passes ``default=argparse.SUPPRESS`` (the command's own stands)."""
    g = p.add_mutually_exclusive_group()
    g.add_argument("--quiet", "-q", dest="show_progress", action="store_false",
                   default=default, help="show no progress (warnings and errors still)")
    g.add_argument("--progress", dest="show_progress", action="store_true",
                   help="show progress on standard error even when it is not a "
                        "terminal (default: only on a terminal)")


def add_json_option(p, help="one JSON document on stdout"):
    p.add_argument("--json", action="store_true", help=help)


def add_out_options(p, metavar, help, force_help="replace existing output files"):
    """``--out/-o`` and ``--force`` (replace a regular file only)."""
    p.add_argument("--out", "-o", metavar=metavar, help=help)
    p.add_argument("--force", action="store_true", help=force_help)


def add_channels_option(p, default=None, help="controls moved at once (default all three)"):
    """``--channels CH...``: pilot controls."""
    from ..channels import CONTROLS
    p.add_argument("--channels", nargs="+", choices=CONTROLS, metavar="CH",
                   default=default, help=help)


def add_flight_options(p, duration=None, dt=None, duration_help=None, dt_help=None,
                       noise_help="flap sensor noise, standard deviation [rad] "
                                  "(default 1e-4)"):
    """``--start``, ``--duration``, ``--dt``, ``--noise``: the record a (virtual)
    flight test makes."""
    p.add_argument("--start", type=finite_float, default=2.0, metavar="S",
                   help="time of the first control movement [s] (default 2: a quiet "
                        "lead-in for trim)")
    p.add_argument("--duration", type=finite_float, default=duration, metavar="S",
                   help=duration_help or f"record length [s] (default {duration:g})")
    p.add_argument("--dt", type=finite_float, default=dt, metavar="S",
                   help=dt_help or f"sample step [s] (default {dt:g})")
    p.add_argument("--noise", type=finite_float, default=1e-4, metavar="R", help=noise_help)


def check_finite(args, *names):
    """Refuse a non-finite value of the options ``names`` (``args`` attributes; a
    pair such as ``--band`` is checked element by element)."""
    import math
    for name in names:
        v = getattr(args, name)
        if v is None:
            continue
        vals = v if isinstance(v, (list, tuple)) else [v]
        if not all(math.isfinite(x) for x in vals):
            shown = " ".join(f"{x:g}" for x in vals)
            raise InputError(f"--{name.replace('_', '-')} {shown}: must be finite")


def add_effect_arguments(p):
    """``--effect-file FILE`` (repeatable): effects written outside the package."""
    p.add_argument("--effect-file", action="append", default=[], metavar="FILE",
                   help="a Python file defining EFFECT, an effect in the catalogue's form "
                        "(docs/workflow.md, 'Writing your own effect'); then usable in "
                        "--model and as a candidate (repeatable)")


def load_effects(args):
    """Register the installed packages' effects and the ``--effect-file`` ones
    (refused with one line naming the file)."""
    from ..model.effects.user import load_effect_files
    load_effect_files(getattr(args, "effect_file", None) or ())


def load_model(args, constants=None):
    """The model named by ``--model`` / ``--params`` at ``constants`` (record's, or Puma)."""
    from ..model.build import build_model
    from ..model.params import PUMA
    from ..model.presets import preset_parameters
    k = constants or PUMA
    if getattr(args, "params", None):
        s, ps = read_structure_parameters(args.params, args.model)
        return build_model(s, ps.parameters, k)
    return build_model(args.model, preset_parameters(args.model, k, "paper"), k)


def read_structure_parameters(path, model):
    """``(structure, parameter file)``: ``model`` parsed and the file ``path`` read
    for it (refused, naming both, when the file's structure is another)."""
    from ..model.structure import Structure
    ps = read_parameter_file(path)
    s = Structure.parse(model)
    if set(ps.structure.effects) != set(s.effects):
        raise InputError(f"{path}: parameters are for structure "
                         f"{ps.structure.name}, not {s.name}")
    return s, ps


def read_parameter_file(path):
    """:func:`~inflowsim.model.paramfile.read_parameters`, its warnings (``omega``
    in rpm ...) on stderr as a record's are."""
    from ..model.paramfile import read_parameters
    ps = read_parameters(path)
    for w in ps.warnings():
        warn(w)
    return ps


def add_record_arguments(p):
    """``--hold`` and ``--trim-window``: how to read the records' samples."""
    p.add_argument("--hold", choices=HOLDS,
                   help="intersample behaviour of the records' inputs: continuous "
                        "(samples of continuous signals, measured data), zoh (held over "
                        "each sample), foh (linear between samples); default each "
                        "record's '# hold:' line, else continuous")
    add_trim_window_option(p)


def add_trim_window_option(p):
    p.add_argument("--trim-window", nargs=2, type=finite_float, metavar=("T0", "T1"),
                   help="trim is the mean over T0-T1 s (default: the quiet lead-in "
                        "before the first control movement)")


def read_records(paths, args):
    """Records from ``paths`` with ``--trim-window`` applied; trim problems are
    reported on stderr (a warning) or refused (no quiet lead-in)."""
    from ..data.record import find_trim, read_record
    recs = []
    for path in paths:
        rec = read_record(path)
        tw = getattr(args, "trim_window", None)
        if tw:
            rec = rec.with_meta(trim_window=f"{tw[0]!r} {tw[1]!r}")
        for w in rec.warnings():
            warn(w)
        trim = find_trim(rec)
        if trim.warning:
            warn(trim.warning)
        recs.append(rec)
    return recs


def print_json(doc):
    from ..fileio import json_text
    sys.stdout.write(json_text(doc))


def emit(command, args, result, report, text, protect=()):
    """A command's last steps, alike in every command with ``--report`` and
    ``--json``: write ``report(result)`` to ``args.report`` (say so on stderr),
    then print ``result.to_json()`` (with the report's page) or ``text(result)``."""
    if args.report:
        path = report(result).write(args.report, protect=protect)
        progress(f"{command}: report written to {path}")
    if args.json:
        doc = result.to_json()
        if args.report:
            from pathlib import Path
            doc["report"] = str(Path(args.report) / "index.html")
        print_json(doc)
    else:
        print(text(result))


def check_seed(seed):
    """Refuse a noise seed numpy cannot take."""
    if not 0 <= seed < 2 ** 32:
        raise InputError(f"--seed {seed}: must be an integer in [0, 2**32)")


def start_values(args):
    """``--params`` as start values for a fit of ``--model`` (names it shares)."""
    if not getattr(args, "params", None):
        return None
    from ..model.structure import Structure
    ps = read_parameter_file(args.params)
    s = Structure.parse(args.model)
    shared = {n: v for n, v in ps.parameters.items() if n in s.parameters}
    if not shared:
        raise InputError(f"{args.params}: no parameter of structure {s.name} in it")
    return shared


def add_search_arguments(p):
    """Options shared by ``diagnose`` and ``ladder``: band, candidates, level, outputs."""
    p.add_argument("--band", nargs=2, type=finite_float, metavar=("F1", "F2"),
                   default=DEFAULT_BAND, help=f"band [Hz] (default {DEFAULT_BAND[0]:g} "
                                              f"{DEFAULT_BAND[1]:g})")
    p.add_argument("--candidates", nargs="+", metavar="EFFECT",
                   help="effects to try (default: every applicable one)")
    add_also_option(p)
    p.add_argument("--alpha", type=finite_float, default=ALPHA,
                   help=f"significance level per candidate (default {ALPHA:g})")
    p.add_argument("--report", metavar="DIR", help="write DIR/index.html with plots")
    p.add_argument("--json", action="store_true", help="one JSON document on stdout")


def add_also_option(p):
    p.add_argument("--also", nargs="+", metavar="EFFECT", default=[],
                   help="effects not offered by default to try as well "
                        "(e.g. momentum-speed, delay-beta0)")


def pool_with(candidates, also):
    """The candidate pool: ``candidates`` (default the offered effects) and ``also``."""
    if not also:
        return candidates
    from ..model.effects import CATALOGUE
    for e in also:
        if e not in CATALOGUE:
            raise InputError(f"--also {e}: {unknown_effect(e, CATALOGUE)}")
    base = list(candidates) if candidates else [n for n, e in CATALOGUE.items()
                                                if e.offered]
    return base + [e for e in also if e not in base]


def unknown_effect(name, known=None) -> str:
    """:func:`inflowsim.model.structure.unknown_effect` without its first words."""
    from ..model.structure import unknown_effect as text
    return "not an effect" + text(name).split(")", 1)[0].split(f"{name!r}", 1)[1] + ")"


def check_search_arguments(args):
    """Refuse bad search options and an unusable ``--report`` folder before the work."""
    if not 0 < args.alpha < 0.5:
        raise InputError(f"--alpha {args.alpha:g}: choose a level in (0, 0.5)")
    check_finite(args, "band")
    from ._checks import check_band
    check_band(args.band)
    pool = pool_with(args.candidates, args.also) or ()      # refused before any fit
    from ..model.effects import CATALOGUE
    for e in pool:
        if e not in CATALOGUE:
            raise InputError(f"--candidates {e}: {unknown_effect(e)}")
    if args.report:
        from ..report.document import check_report_folder
        check_report_folder(args.report, protect=args.record)


def parse_fix(items) -> dict:
    out = {}
    for it in items:
        name, sep, val = it.partition("=")
        name = name.strip()
        if not name:
            raise InputError(f"--fix {it!r}: give NAME or NAME=VALUE")
        if sep and not val.strip():
            raise InputError(f"--fix {it!r}: no value after '='; give NAME=VALUE, or "
                             "NAME alone for its theory value")
        if val:
            try:
                out[name] = float(val)
            except ValueError:
                raise InputError(f"--fix {it!r}: {val!r} is not a number") from None
            if not math.isfinite(out[name]):
                raise InputError(f"--fix {it!r}: the value must be finite")
        else:
            out[name] = None
    return out


def parse_ties(items) -> list:
    ties = []
    for it in items:
        names = [n.strip() for n in it.split("=")]
        if len(names) < 2 or not all(names):
            raise InputError(f"--tie {it!r}: give two or more names as A=B")
        ties.append(tuple(names))
    return ties


def structure_of(args) -> Structure:
    """``--model`` plus the ``--add`` effects."""
    from ..model.structure import Structure
    s = Structure.parse(args.model)
    for e in args.add:
        s = s.with_effect(e)
    return s
