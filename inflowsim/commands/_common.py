"""Helpers shared by the command modules: loading models and records, JSON out.

Building the parsers (``add_*_arguments``) imports nothing that computes: every
``--help`` answers without NumPy (issue #27); the helpers that run a command import
what they use.
"""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

from ..defaults import ALPHA, DEFAULT_BAND, HOLDS
from ..errors import InputError

if TYPE_CHECKING:
    from ..model.structure import Structure


def add_model_arguments(p, params=True):
    p.add_argument("--model", "-m", required=True,
                   help="structure: basic, empirical, glauert, then +effect terms")
    add_effect_arguments(p)
    if params:
        p.add_argument("--params", "-p", metavar="FILE",
                       help="parameter file (JSON; identify --out writes one); "
                            "default: the paper's table values for the preset")


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
    from ..model.structure import Structure
    k = constants or PUMA
    if getattr(args, "params", None):
        ps = read_parameter_file(args.params)
        s = Structure.parse(args.model)
        if set(ps.structure.effects) != set(s.effects):
            raise InputError(f"{args.params}: parameters are for structure "
                             f"{ps.structure.name}, not {s.name}")
        return build_model(s, ps.parameters, k)
    return build_model(args.model, preset_parameters(args.model, k, "paper"), k)


def read_parameter_file(path):
    """:func:`~inflowsim.model.paramfile.read_parameters`, its warnings (``omega``
    in rpm ...) on stderr as a record's are."""
    from ..model.paramfile import read_parameters
    ps = read_parameters(path)
    for w in ps.warnings():
        progress(f"warning: {w}")
    return ps


def add_record_arguments(p):
    """``--hold`` and ``--trim-window``: how to read the records' samples."""
    p.add_argument("--hold", choices=HOLDS,
                   help="intersample behaviour of the records' inputs: continuous "
                        "(samples of continuous signals, measured data), zoh (held over "
                        "each sample), foh (linear between samples); default each "
                        "record's '# hold:' line, else continuous")
    p.add_argument("--trim-window", nargs=2, type=float, metavar=("T0", "T1"),
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
            progress(f"warning: {w}")
        trim = find_trim(rec)
        if trim.warning:
            progress(f"warning: {trim.warning}")
        recs.append(rec)
    return recs


def print_json(doc):
    from ..fileio import json_text
    sys.stdout.write(json_text(doc))


def check_seed(seed):
    """Refuse a noise seed numpy cannot take."""
    if not 0 <= seed < 2 ** 32:
        raise InputError(f"--seed {seed}: must be an integer in [0, 2**32)")


def progress(msg):
    sys.stderr.write(msg + "\n")
    sys.stderr.flush()


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
    p.add_argument("--band", nargs=2, type=float, metavar=("F1", "F2"),
                   default=DEFAULT_BAND, help=f"band [Hz] (default {DEFAULT_BAND[0]:g} "
                                              f"{DEFAULT_BAND[1]:g})")
    p.add_argument("--candidates", nargs="+", metavar="EFFECT",
                   help="effects to try (default: every applicable one)")
    p.add_argument("--alpha", type=float, default=ALPHA,
                   help=f"significance level per candidate (default {ALPHA:g})")
    p.add_argument("--report", metavar="DIR", help="write DIR/index.html with plots")
    p.add_argument("--json", action="store_true", help="one JSON document on stdout")


def check_search_arguments(args):
    """Refuse bad search options and an unusable ``--report`` folder before the work."""
    if not 0 < args.alpha < 0.5:
        raise InputError(f"--alpha {args.alpha:g}: choose a level in (0, 0.5)")
    if args.report:
        from ..report.document import check_report_folder
        check_report_folder(args.report, protect=args.record)


def parse_fix(items) -> dict:
    out = {}
    for it in items:
        name, _, val = it.partition("=")
        name = name.strip()
        if not name:
            raise InputError(f"--fix {it!r}: give NAME or NAME=VALUE")
        if val:
            try:
                out[name] = float(val)
            except ValueError:
                raise InputError(f"--fix {it!r}: {val!r} is not a number") from None
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
