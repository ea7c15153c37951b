"""Writing files without ever corrupting or replacing a user's input."""
from __future__ import annotations

import os
import tempfile
from pathlib import Path

from .errors import InputError


def _same(a: Path, b) -> bool:
    try:
        return a.exists() and Path(b).exists() and os.path.samefile(a, b)
    except OSError:
        return False


def safe_write_text(path, text: str, overwrite: bool = False, protect=()) -> Path:
    """Write ``text`` to ``path`` via a temporary file and an atomic rename.

    Refuses (``InputError``) to write onto any file in ``protect`` (the inputs of
    the command), and onto an existing file unless ``overwrite``.
    """
    p = Path(path)
    for q in protect:
        if _same(p, q):
            raise InputError(f"{p}: refusing to write over the input file {q}")
    if p.exists() and not overwrite:
        raise InputError(f"{p}: exists; choose another name or pass --force")
    if p.exists() and p.is_dir():
        raise InputError(f"{p}: is a directory")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"{p}: folder {parent} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{p.name}.", dir=parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8", newline="\n") as f:
            f.write(text)
        os.replace(tmp, p)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return p
