"""Writing files without ever corrupting or replacing a user's input.

Every file the package writes goes through :func:`atomic_path` (and the commands
check their outputs first with :func:`check_output`): an output may create a file
or replace a regular file, nothing else.  A device, FIFO, socket or folder, or a
symbolic link to one or to nothing, is refused with one line (issue #28: as root,
``--out /dev/full --force`` once replaced the device node).
"""
from __future__ import annotations

import os
import stat
import tempfile
from contextlib import contextmanager
from pathlib import Path

from .errors import InputError


def _same(a: Path, b) -> bool:
    try:
        return a.exists() and Path(b).exists() and os.path.samefile(a, b)
    except OSError:
        return False


_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISSOCK, "a socket"))


def check_replaceable(path) -> Path:
    """Refuse (``InputError``) an output ``path`` that exists and is not a regular
    file (after symbolic links): a folder, device, FIFO or socket, or a link to
    nothing (writing would create a file wherever it points)."""
    p = Path(path)
    try:
        st = os.stat(p)
    except (FileNotFoundError, NotADirectoryError):    # nothing there (the folder
        if os.path.islink(p):                           # is the caller's to check)
            raise InputError(f"{p}: is a symbolic link to nothing "
                             f"({os.readlink(p)}); give a file name") from None
        return p
    except OSError as exc:
        raise InputError(f"{p}: cannot write ({exc.strerror or exc})") from None
    if stat.S_ISREG(st.st_mode):
        return p
    kind = next((k for test, k in _KINDS if test(st.st_mode)), "not a regular file")
    link = f" (a symbolic link to {os.path.realpath(p)})" if os.path.islink(p) else ""
    if stat.S_ISDIR(st.st_mode):
        raise InputError(f"{p}: is a folder{link}; give a file name")
    raise InputError(f"{p}: is {kind}{link}; an output may replace a regular file "
                     "only")


def check_output(path, overwrite: bool = False, protect=()) -> Path:
    """Refuse (``InputError``) an output ``path`` that is one of the inputs in
    ``protect``, that exists and is not a regular file (:func:`check_replaceable`),
    that exists unless ``overwrite``, or whose folder does not exist.  Commands
    call it before any work; every writer calls it again."""
    p = Path(path)
    for q in protect:
        if _same(p, q):
            raise InputError(f"{p}: refusing to write over the input file {q}")
    check_replaceable(p)
    if p.exists() and not overwrite:
        raise InputError(f"{p}: exists; choose another name or pass --force")
    _check_parent(p)
    return p


def check_folder(path) -> Path:
    """Refuse (``InputError``) an output folder that cannot be made or written:
    a regular file, a missing parent, no write permission."""
    d = Path(path)
    if d.exists():
        if not d.is_dir():
            raise InputError(f"{d}: exists and is not a folder")
        check_writable(d)
        return d
    _check_parent(d)
    return d


def _check_parent(p: Path) -> None:
    """The folder ``p`` would be created in exists and can be written."""
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"{p}: folder {parent} does not exist")
    check_writable(parent)


def check_writable(folder) -> Path:
    """Refuse (``InputError``) a folder this process cannot create files in.

    Tries it (a probe file, removed at once) rather than reading permission bits:
    that is the only answer that holds for ACLs, read-only mounts and root."""
    f = Path(folder)
    try:
        fd, probe = tempfile.mkstemp(prefix=".inflowsim-probe.", dir=f)
    except OSError as exc:
        raise InputError(f"{f}: cannot write in this folder "
                         f"({exc.strerror or exc})") from None
    os.close(fd)
    os.unlink(probe)
    return f


def umask() -> int:
    """The process's file-creation mask (read without changing it for long)."""
    m = os.umask(0o022)
    os.umask(m)
    return m


def safe_write_text(path, text: str, overwrite: bool = False, protect=()) -> Path:
    """Write ``text`` to ``path`` via a temporary file and an atomic rename.

    Refuses (``InputError``) to write onto any file in ``protect`` (the inputs of
    the command), and onto an existing file unless ``overwrite``.
    """
    p = check_output(path, overwrite, protect)
    with atomic_path(p) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
    return p


@contextmanager
def atomic_path(path):
    """Yield a temporary path beside ``path``; on success it replaces ``path`` in one
    rename, on any error it is removed, so ``path`` is never left half-written.

    ``path`` must be new or a regular file (:func:`check_replaceable`, checked again
    here: the commands' early check may be minutes old).  A symbolic link to a
    regular file is written through: the file it points to is replaced, the link
    stays.  An OS error while writing (a full disk) names ``path``, not the
    temporary file."""
    p = check_replaceable(path)
    if os.path.islink(p):
        p = Path(os.path.realpath(p))
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", dir=p.parent)
    except OSError as exc:
        raise InputError(f"{p}: cannot write ({exc.strerror or exc})") from None
    os.close(fd)
    try:
        yield tmp
        # mkstemp makes the file 0600; a written file gets the mode open() would give
        os.chmod(tmp, 0o666 & ~umask())
        check_replaceable(p)        # nothing else took the name meanwhile
        os.replace(tmp, p)
    except OSError as exc:
        _remove(tmp)
        if exc.errno is not None and exc.filename in (None, tmp):
            raise type(exc)(exc.errno, exc.strerror or os.strerror(exc.errno),
                            str(path)) from exc
        raise
    except BaseException:
        _remove(tmp)
        raise


def _remove(tmp):
    if os.path.exists(tmp):
        os.unlink(tmp)


#: Largest input file read [bytes], by kind: a record of
#: :data:`inflowsim.data.record.MAX_SAMPLES` rows of its columns fits in the first;
#: parameter files, schedules, designs and manifests are a few kB, effect files
#: a few hundred lines.  A judgement: a larger file is refused before it is read.
MAX_INPUT_BYTES = {"record": 1 << 30, "json": 16 << 20, "manifest": 16 << 20,
                   "effect": 1 << 20}

#: Deepest nesting of lists and objects accepted in an input JSON or TOML file: every
#: file the package reads is at most four deep.
MAX_NESTING = 32


def check_input_file(path, what: str = "file", kind: str = "json") -> Path:
    """Refuse (``InputError``) an input ``path`` that is empty, missing, not a
    regular file (a folder, FIFO, device or socket: refused before anything opens
    it, so nothing blocks), or larger than ``MAX_INPUT_BYTES[kind]``."""
    if path is None or not str(path).strip():
        raise InputError(f"{what} {str(path)!r}: an empty file name")
    p = Path(path)
    try:
        st = os.stat(p)
    except FileNotFoundError:
        raise InputError(f"{p}: no such {'file' if what == 'record' else what}") from None
    except OSError as exc:
        raise InputError(f"{p}: cannot read ({exc.strerror or exc})") from None
    if not stat.S_ISREG(st.st_mode):
        kind_of = next((k for test, k in _KINDS if test(st.st_mode)), "not a regular file")
        raise InputError(f"{p}: is {kind_of}; the {what} must be a regular file")
    limit = MAX_INPUT_BYTES[kind]
    if st.st_size > limit:
        raise InputError(f"{p}: {st.st_size:,} bytes; a {what} larger than "
                         f"{limit:,} bytes is refused")
    return p


def read_input_bytes(path, what: str = "file", kind: str = "json") -> bytes:
    """The bytes of the input ``path`` after :func:`check_input_file` (one line,
    naming the file, for any problem reading it)."""
    p = check_input_file(path, what, kind)
    try:
        with p.open("rb") as f:
            data = f.read(MAX_INPUT_BYTES[kind] + 1)
    except OSError as exc:
        raise InputError(f"{p}: cannot read ({exc.strerror or exc})") from None
    if len(data) > MAX_INPUT_BYTES[kind]:
        raise InputError(f"{p}: a {what} larger than {MAX_INPUT_BYTES[kind]:,} bytes "
                         "is refused")
    return data


def read_input_text(path, what: str = "file", kind: str = "json",
                    encoding: str = "utf-8") -> str:
    """:func:`read_input_bytes` decoded (``InputError`` naming the byte where the
    text is not ``encoding``)."""
    data = read_input_bytes(path, what, kind)
    try:
        return data.decode(encoding)
    except UnicodeDecodeError as exc:
        raise InputError(f"{path}: not UTF-8 text (byte {exc.start})") from None


def check_nesting(doc, source: str, limit: int = MAX_NESTING):
    """Refuse a parsed document nested deeper than ``limit`` (walked without
    recursion); return ``doc``."""
    stack = [(doc, 1)]
    while stack:
        node, depth = stack.pop()
        if isinstance(node, dict):
            node = list(node.values())
        elif not isinstance(node, list):
            continue
        if depth > limit:
            raise InputError(f"{source}: nested more than {limit} deep; not a file "
                             "this program writes")
        stack.extend((v, depth + 1) for v in node if isinstance(v, (dict, list)))
    return doc


def _bracket_depth(text: str) -> int:
    """The deepest nesting of ``[``/``{`` in JSON ``text`` outside strings."""
    import re
    depth = deepest = 0
    for m in re.finditer(r'"(?:[^"\\]|\\.)*"|[\[{]|[\]}]', text):
        c = m.group()[0]
        if c in "[{":
            depth += 1
            deepest = max(deepest, depth)
        elif c in "]}":
            depth -= 1
    return deepest


def parse_json(text: str, source: str, **kw):
    """``json.loads(text, **kw)`` refusing (one line naming ``source``) text that is
    not JSON or that nests deeper than :data:`MAX_NESTING` (checked before parsing:
    the parser recurses)."""
    import json
    if _bracket_depth(text) > MAX_NESTING:
        raise InputError(f"{source}: nested more than {MAX_NESTING} deep; not a file "
                         "this program writes")
    try:
        return json.loads(text, **kw)
    except RecursionError:
        raise InputError(f"{source}: nested too deeply") from None
    except json.JSONDecodeError as exc:
        raise InputError(f"{source}: not valid JSON ({exc.msg}, line {exc.lineno})") \
            from None
    except ValueError as exc:
        raise InputError(f"{source}: not valid JSON ({exc})") from None


def read_json(path, what: str = "file"):
    """The JSON document in the input ``path``: regular file, size and nesting
    limits, UTF-8 (a byte-order mark allowed)."""
    return parse_json(read_input_text(path, what, "json", "utf-8-sig"), str(path))


def json_text(doc) -> str:
    """``doc`` as JSON text (indented, newline-terminated) that every parser reads:
    NaN and infinities become ``null`` (JSON has no such numbers), NumPy arrays and
    scalars become lists and numbers."""
    import json
    return json.dumps(_plain(doc), indent=2, allow_nan=False) + "\n"


def _plain(o):
    import math

    from collections.abc import Mapping

    import numpy as np
    if isinstance(o, Mapping):
        return {str(k): _plain(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_plain(v) for v in o]
    if isinstance(o, np.ndarray):
        return [_plain(v) for v in o.tolist()]
    if isinstance(o, (np.bool_,)):
        return bool(o)
    if isinstance(o, (np.integer,)):
        return int(o)
    if isinstance(o, (float, np.floating)):
        x = float(o)
        return x if math.isfinite(x) else None
    if o is None or isinstance(o, (str, int, bool)):
        return o
    if hasattr(o, "to_json"):
        return _plain(o.to_json())
    raise TypeError(f"cannot write {type(o).__name__} as JSON")


__all__ = ["check_replaceable", "check_output", "check_folder", "check_writable", "umask",
           "safe_write_text", "atomic_path", "json_text"]
