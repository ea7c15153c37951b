"""The one validation layer every command goes through (issue #37).

Two halves:

* argparse ``type=`` functions (:func:`finite_float`, :func:`positive_float`, ...):
  a number option that is not finite or out of its range is refused by the parser
  with one line naming the option, before any command code runs;
* :func:`check_paths`, called by :func:`inflowsim.cli.main` on every command's
  parsed arguments before ``run``: the options that name input files (by their
  ``dest``: :data:`INPUT_FILES`) must be regular files within the size limits of
  :data:`inflowsim.fileio.MAX_INPUT_BYTES` (a FIFO, device or folder is refused
  before anything opens it, so nothing blocks); the options that name outputs
  (:data:`OUTPUTS`) must be non-empty and never the same file as an input or as
  another output.

Nothing here imports NumPy: ``--help`` stays fast (issue #27).
"""
from __future__ import annotations

import argparse
import math
import os
from pathlib import Path

from ..errors import InputError

# -- numbers ------------------------------------------------------------------------


def _float(text) -> float:
    try:
        x = float(text)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(x):
        raise argparse.ArgumentTypeError(f"{text!r}: must be a finite number")
    return x


def finite_float(text) -> float:
    """A finite number."""
    return _float(text)


def positive_float(text) -> float:
    """A finite number > 0."""
    x = _float(text)
    if not x > 0:
        raise argparse.ArgumentTypeError(f"{text!r}: must be > 0")
    return x


def nonnegative_float(text) -> float:
    """A finite number >= 0."""
    x = _float(text)
    if not x >= 0:
        raise argparse.ArgumentTypeError(f"{text!r}: must be >= 0")
    return x


def fraction(text) -> float:
    """A finite number in [0, 1)."""
    x = _float(text)
    if not 0 <= x < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: must be in [0, 1)")
    return x


def probability(text) -> float:
    """A significance level: a number in (0, 0.5)."""
    x = _float(text)
    if not 0 < x < 0.5:
        raise argparse.ArgumentTypeError(f"{text!r}: choose a level in (0, 0.5)")
    return x


def _int(text) -> int:
    try:
        return int(str(text).strip(), 10)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None


def nonnegative_int(text) -> int:
    """An integer >= 0."""
    n = _int(text)
    if n < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: must be >= 0")
    return n


def positive_int(text) -> int:
    """An integer >= 1."""
    n = _int(text)
    if n < 1:
        raise argparse.ArgumentTypeError(f"{text!r}: must be >= 1")
    return n


def seed(text) -> int:
    """A noise seed NumPy takes: an integer in [0, 2**32)."""
    n = _int(text)
    if not 0 <= n < 2 ** 32:
        raise argparse.ArgumentTypeError(f"{text!r}: must be an integer in [0, 2**32)")
    return n


def bounded(kind, low=None, high=None, what=None):
    """A ``type=`` function: ``kind(text)`` within ``[low, high]``."""
    def check(text):
        x = kind(text)
        if (low is not None and x < low) or (high is not None and x > high):
            lo = "" if low is None else f"{low:g}"
            hi = "" if high is None else f"{high:g}"
            raise argparse.ArgumentTypeError(
                f"{text!r}: must be in [{lo}, {hi}]" + (f" {what}" if what else ""))
        return x
    check.__name__ = getattr(kind, "__name__", "value")
    return check


def check_band(band, option="--band", nyquist=None):
    """Refuse a frequency band [Hz] that is not ``0 < F1 < F2`` (and, given the
    Nyquist frequency of a sample step, ``F2 <= nyquist``)."""
    if band is None:
        return None
    f1, f2 = band
    if not (math.isfinite(f1) and math.isfinite(f2) and 0 < f1 < f2):
        raise InputError(f"{option} {f1:g} {f2:g}: need 0 < F1 < F2, finite [Hz]")
    if nyquist is not None and f2 > nyquist:
        raise InputError(f"{option} {f1:g} {f2:g}: F2 above the Nyquist frequency "
                         f"{nyquist:g} Hz of the sample step")
    return band


# -- paths --------------------------------------------------------------------------

#: Options (by ``dest``) naming input files, with the size class of
#: :data:`inflowsim.fileio.MAX_INPUT_BYTES` and what the message calls them.
INPUT_FILES = {"effect_file": ("effect", "effect file"), "record": ("record", "record"),
               "records": ("record", "record"),
               "params": ("json", "parameter file"), "start": ("json", "parameter file"),
               "schedule": ("json", "schedule file"), "design": ("json", "design file")}

#: Options (by ``dest``) naming outputs: a file or a folder the command writes.
OUTPUTS = ("out", "report", "truth_json", "campaign")


def _values(v):
    """The file names in an option's value (``--start`` is a number in some
    commands, a file in others: only text is a name)."""
    if v is None:
        return []
    return [x for x in (v if isinstance(v, (list, tuple)) else [v]) if isinstance(x, str)]


def _option(dest: str) -> str:
    return dest if dest in ("record", "records", "plan") else "--" + dest.replace("_", "-")


def _same(a, b) -> bool:
    """``a`` and ``b`` are one file: the same path after resolving links, or one
    inode (a hard link)."""
    try:
        if os.path.realpath(a) == os.path.realpath(b):
            return True
        return os.path.exists(a) and os.path.exists(b) and os.path.samefile(a, b)
    except (OSError, ValueError):
        return False


def _looks_like_file(text: str) -> bool:
    return text.endswith(".json") or os.path.sep in text or os.path.lexists(text)


def check_paths(args) -> None:
    """Refuse (``InputError``, one line) before the command runs: an input file that
    is empty, missing, not a regular file or too large; an output that is empty or
    the same file as an input or another output."""
    from ..fileio import check_input_file
    inputs = []
    for dest, (kind, what) in INPUT_FILES.items():
        for v in _values(getattr(args, dest, None)):
            try:
                check_input_file(v, what, kind)
            except InputError as exc:
                raise InputError(f"{_option(dest)} {exc}") from None
            if dest == "effect_file" and Path(v).suffix != ".py":
                raise InputError(f"--effect-file {v}: an effect file is Python source "
                                 "ending in .py")
            inputs.append((_option(dest), v))
    model = getattr(args, "model", None)
    if getattr(args, "command", None) == "fmu" and model and _looks_like_file(model):
        try:
            check_input_file(model, "parameter file", "json")
        except InputError as exc:
            raise InputError(f"--model {exc}") from None
        inputs.append(("--model", model))
    plan = getattr(args, "plan", None)
    if plan is not None:
        _check_plan(plan)
        inputs.append(("plan", plan))
    outputs = []
    for dest in OUTPUTS:
        v = getattr(args, dest, None)
        if v is None or isinstance(v, bool):
            continue
        if not str(v).strip():
            raise InputError(f"{_option(dest)} {str(v)!r}: an empty name; give a file "
                             "or folder name")
        for opt, q in inputs:
            if _same(v, q):
                raise InputError(f"{_option(dest)} {v}: refusing to write over the "
                                 f"input file {q} ({opt})")
        for opt, q in outputs:
            if _same(v, q):
                raise InputError(f"{_option(dest)} {v}: the same as {opt}; give each "
                                 "output its own name")
        outputs.append((_option(dest), v))


def _check_plan(plan) -> None:
    """A campaign's plan: a folder, or a manifest that is a regular file."""
    import stat
    from ..fileio import check_input_file
    if not str(plan).strip():
        raise InputError("plan '': an empty name; give a folder of records or a manifest")
    try:
        st = os.stat(plan)
    except OSError:
        return                               # read_plan names what is missing
    if stat.S_ISDIR(st.st_mode):
        return
    check_input_file(plan, "manifest", "manifest")
