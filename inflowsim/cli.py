"""The ``inflowsim`` command: a thin dispatcher over ``inflowsim.commands.*``.

Each command module defines ``HELP`` (one line), ``add_arguments(parser)`` and
``run(args) -> int``.  User errors (:class:`InputError`, bad options, missing
files) print one line on stderr and exit 2; ``--json`` output goes alone to stdout.
"""
from __future__ import annotations

import argparse
import importlib
import os
import sys

from .errors import InputError

COMMANDS = ("demo", "model", "simulate", "validate", "identify", "bandstudy", "diagnose",
            "ladder", "campaign", "flighttest", "fmu", "frf", "design")


class _Parser(argparse.ArgumentParser):
    def error(self, message):          # one line, exit 2 (argparse prints usage too)
        sys.stderr.write(f"inflowsim: error: {message}\n")
        raise SystemExit(2)


def build_parser():
    parser = _Parser(prog="inflowsim", description="Rotor flap and dynamic inflow: "
                     "simulate, validate, identify, diagnose, FMU.")
    from . import __version__
    parser.add_argument("--version", action="version", version=f"inflowsim {__version__}")
    from .commands._common import add_progress_options
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name in COMMANDS:
        try:
            mod = importlib.import_module(f".commands.{name}", __package__)
        except ModuleNotFoundError as exc:
            if exc.name and exc.name.endswith(f"commands.{name}"):
                continue                       # not built yet
            raise
        p = sub.add_parser(name, help=mod.HELP, description=mod.HELP)
        mod.add_arguments(p)
        add_progress_options(p)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "_run", None):
        parser.print_help(sys.stderr)
        return 2
    from . import progress
    progress.configure(getattr(args, "show_progress", None))
    stdout = sys.stdout
    sys.stdout = _NamedStream(stdout, _stream_name(stdout, "standard output"))
    try:
        if hasattr(args, "effect_file"):
            from .commands._common import load_effects
            load_effects(args)
        code = int(args._run(args) or 0)
        sys.stdout.flush()          # a full disk under stdout is reported here, named
        return code
    except InputError as exc:
        sys.stderr.write(f"inflowsim {args.command}: error: {_one_line(exc)}\n")
        return 2
    except OSError as exc:
        # what the output checks cannot foresee about the user's files and disk (full,
        # read-only, permissions changed meanwhile) is the user's to fix: one line;
        # any other OS error is the program's, and keeps its traceback
        if not _users_os_error(exc):
            raise
        where = f"{exc.filename}: " if exc.filename else ""
        sys.stderr.write(f"inflowsim {args.command}: error: {where}"
                         f"{exc.strerror or exc}\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("inflowsim: interrupted\n")
        return 130
    finally:
        sys.stdout = stdout


def _stream_name(stream, what: str) -> str:
    """``what`` and, where the system says, the file it goes to: "standard output
    (/dev/full)"."""
    try:
        target = os.readlink(f"/proc/self/fd/{stream.fileno()}")
    except (OSError, AttributeError, ValueError):
        return what
    return f"{what} ({target})" if target.startswith("/") else what


class _NamedStream:
    """A text stream whose OS errors name it: a write to a full disk through
    ``> file`` says which file (the OS error of a write carries no file name)."""

    def __init__(self, stream, name):
        self._stream, self._name = stream, name

    def _named(self, call, *a):
        try:
            return call(*a)
        except OSError as exc:
            if exc.filename is None and exc.errno is not None and _users_os_error(exc):
                raise type(exc)(exc.errno, exc.strerror or os.strerror(exc.errno),
                                self._name) from exc
            raise

    def write(self, text):
        return self._named(self._stream.write, text)

    def flush(self):
        return self._named(self._stream.flush)

    def __getattr__(self, name):
        return getattr(self._stream, name)


def _users_os_error(exc: OSError) -> bool:
    import errno
    return (isinstance(exc, (PermissionError, IsADirectoryError, NotADirectoryError,
                             FileExistsError))
            or exc.errno in (errno.ENOSPC, errno.EROFS, errno.EDQUOT, errno.EFBIG,
                             errno.ENAMETOOLONG))


def _one_line(exc) -> str:
    return " ".join(str(exc).split())


if __name__ == "__main__":
    raise SystemExit(main())
