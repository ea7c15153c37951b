"""Writing files without ever corrupting or replacing a user's input."""
from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

from .errors import InputError


def _same(a: Path, b) -> bool:
    try:
        return a.exists() and Path(b).exists() and os.path.samefile(a, b)
    except OSError:
        return False


def check_output(path, overwrite: bool = False, protect=()) -> Path:
    """Refuse (``InputError``) an output ``path`` that is one of the inputs in
    ``protect``, that exists unless ``overwrite``, or whose folder does not exist.
    Commands call it before any work; every writer calls it again."""
    p = Path(path)
    for q in protect:
        if _same(p, q):
            raise InputError(f"{p}: refusing to write over the input file {q}")
    if p.exists() and not overwrite:
        raise InputError(f"{p}: exists; choose another name or pass --force")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"{p}: folder {parent} does not exist")
    return p


def safe_write_text(path, text: str, overwrite: bool = False, protect=()) -> Path:
    """Write ``text`` to ``path`` via a temporary file and an atomic rename.

    Refuses (``InputError``) to write onto any file in ``protect`` (the inputs of
    the command), and onto an existing file unless ``overwrite``.
    """
    p = check_output(path, overwrite, protect)
    if p.is_dir():
        raise InputError(f"{p}: is a directory")
    with atomic_path(p) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
    return p


@contextmanager
def atomic_path(path):
    """Yield a temporary path beside ``path``; on success it replaces ``path`` in one
    rename, on any error it is removed, so ``path`` is never left half-written."""
    p = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", dir=p.parent)
    os.close(fd)
    try:
        yield tmp
        os.replace(tmp, p)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
