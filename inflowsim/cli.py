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
        sys.stderr.write(f"{self.prog}: error: {_one_line(message)}\n")
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
    """Run one command; return its exit status: 0 done, 2 refused (one line on
    stderr), 130 interrupted.

    Standard output is handled here once for every command (issue #37): closed
    (``>&-``) is refused before any work; a reader that stops early (``| head``)
    ends the command quietly with status 0, as Unix tools do; a write that fails
    (``> /dev/full``) is one line naming it and status 2, ``--help`` and
    ``--version`` included."""
    _one_blas_thread()
    _tune_allocator()
    stdout, stderr = sys.stdout, sys.stderr
    if stderr is None:                    # 2>&- : nowhere to say anything; the status says
        sys.stderr = open(os.devnull, "w")
    if _closed(stdout):
        sys.stderr.write("inflowsim: error: standard output is closed; redirect it to "
                         "a file or /dev/null\n")
        sys.stderr.flush()
        sys.stderr = stderr
        return 2
    sys.stdout = _NamedStream(stdout, _stream_name(stdout, "standard output"))
    sys.stderr = _NamedStream(sys.stderr, _stream_name(sys.stderr, "standard error"),
                              lossy=True)
    command = None
    try:
        parser = build_parser()
        try:
            args = parser.parse_args(argv)
        except SystemExit as exc:         # --help, --version, or a refused option
            sys.stdout.flush()            # text lost on a full disk is said, not 0
            return exc.code if isinstance(exc.code, int) else 2
        command = getattr(args, "command", None)
        if not getattr(args, "_run", None):
            sys.stderr.write("inflowsim: error: choose a command "
                             "(inflowsim --help lists them)\n")
            return 2
        return _run(args)
    except BrokenPipeError:
        if not (sys.stdout.broken or sys.stderr.broken):
            raise                         # not ours: a pipe of the program's own
        _quiet(stdout)
        return 0
    except InputError as exc:             # standard output itself failing (full disk)
        _say(command, "", _one_line(exc))
        return 2
    finally:
        for named, raw in ((sys.stdout, stdout), (sys.stderr, stderr)):
            if getattr(named, "failed", False) or getattr(named, "broken", False):
                _quiet(raw)               # its unwritable rest must not fail at exit
        sys.stdout, sys.stderr = stdout, stderr


#: The thread counts a command's linear algebra runs with unless the environment sets
#: them: its matrices are small or tall and thin, and BLAS's worker threads cost
#: about 0.8 s of CPU a diagnosis of the default record without shortening it
#: (bench/startup.md).
BLAS_THREADS = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def _one_blas_thread():
    """One BLAS thread for a command run as a program (NumPy reads these once, at its
    import: in a process that has already imported it nothing is changed); a
    user's own setting is kept, and Dask's workers inherit it."""
    if "numpy" in sys.modules:
        return
    for name, value in BLAS_THREADS.items():
        os.environ.setdefault(name, value)


#: glibc's allocator for a command run as a program: blocks up to ``M_MMAP_THRESHOLD``
#: from the heap, and up to ``M_TRIM_THRESHOLD`` of freed heap kept for the next,
#: rather than each record-long array mapped from and returned to the system (its
#: pages faulted in again at every evaluation of a long record's fit: 2.1 of a
#: 2-hour diagnosis's 39 s CPU were system time).  The numbers are not touched.
ALLOCATOR = {"M_MMAP_THRESHOLD": (-3, 256 * 2 ** 20), "M_TRIM_THRESHOLD": (-1, 128 * 2 ** 20)}
#: What :func:`_tune_allocator` set in this process (``None``: nothing).
_ALLOCATOR_SET = None


def _tune_allocator():
    """:data:`ALLOCATOR` through glibc's ``mallopt`` for a command run as a program
    (NumPy not yet imported, as :func:`_one_blas_thread`), unless the environment
    sets glibc's own ``MALLOC_*_`` tunables or the C library has no ``mallopt``."""
    global _ALLOCATOR_SET
    if "numpy" in sys.modules or any(n.startswith("MALLOC_") for n in os.environ) \
            or not sys.platform.startswith("linux"):
        return
    try:
        import ctypes
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return
    mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
    done = {name: value for name, (param, value) in ALLOCATOR.items()
            if mallopt(param, value) == 1}
    _ALLOCATOR_SET = done or None


def _run(args) -> int:
    from . import progress
    from .commands._checks import check_paths
    progress.configure(getattr(args, "show_progress", None))
    try:
        check_paths(args)
        if hasattr(args, "effect_file"):
            from .commands._common import load_effects
            load_effects(args)
        code = int(args._run(args) or 0)
        sys.stdout.flush()          # a full disk under stdout is reported here, named
        return code
    except InputError as exc:
        _say(args.command, "", _one_line(exc))
        return 2
    except BrokenPipeError:
        raise
    except OSError as exc:
        # what the output checks cannot foresee about the user's files and disk (full,
        # read-only, permissions changed meanwhile) is the user's to fix: one line;
        # any other OS error is the program's, and keeps its traceback
        if not _users_os_error(exc):
            raise
        where = f"{exc.filename}: " if exc.filename else ""
        _say(args.command, where, exc.strerror or str(exc))
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("inflowsim: interrupted\n")
        return 130


def _say(command, where, what):
    """The one error line (``inflowsim CMD: error: ...``) on stderr, whatever
    becomes of stderr itself."""
    prefix = f"inflowsim {command}" if command else "inflowsim"
    try:
        sys.stderr.write(f"{prefix}: error: {_one_line(f'{where}{what}')}\n")
        sys.stderr.flush()
    except (OSError, ValueError):
        pass


def _closed(stream) -> bool:
    """``stream`` is missing (Python's ``sys.stdout`` when fd 1 was closed at start)
    or its file descriptor is not open."""
    if stream is None:
        return True
    try:
        fd = stream.fileno()
    except (AttributeError, OSError, ValueError):
        return False                      # not a file (a test's capture): usable
    try:
        os.fstat(fd)
    except OSError:
        return True
    return False


def _quiet(stream):
    """After a broken pipe: point the stream's descriptor at /dev/null so the
    interpreter's last flush says nothing."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, stream.fileno())
        os.close(devnull)
    except (AttributeError, OSError, ValueError):
        pass


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

    def __init__(self, stream, name, lossy=False):
        self._stream, self._name, self._lossy = stream, name, lossy
        self.broken = self.failed = False

    def _named(self, call, *a):
        try:
            return call(*a)
        except BrokenPipeError:
            self.broken = True
            if self._lossy:
                return None
            raise
        except OSError as exc:
            if self._lossy:               # stderr: messages lost, the status still says
                self.failed = True
                return None
            # the stream is the user's (a file, a device, a disk): any failure to
            # write it is theirs to fix, said in one line
            self.failed = True
            raise InputError(f"{self._name}: "
                             f"{exc.strerror or os.strerror(exc.errno or 0) or exc}") \
                from exc

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


#: Longest error line [characters]: a message quoting a 100,000-character argument
#: keeps its start and end.
MAX_LINE = 1000


def _one_line(exc) -> str:
    text = " ".join(str(exc).split())
    if len(text) > MAX_LINE:
        half = MAX_LINE // 2 - 10
        text = f"{text[:half]} ... ({len(text) - 2 * half:,} characters) ... {text[-half:]}"
    return text


if __name__ == "__main__":
    raise SystemExit(main())
