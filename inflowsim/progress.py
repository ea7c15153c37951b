"""Progress on long work: what is being done and how far, on standard error.

One place decides whether anything is shown, the commands' ``--quiet`` and
``--progress`` (:func:`configure`): by default progress is shown when standard
error is a terminal and not otherwise (a log file or a pipe gets none);
``--progress`` asks for it anyway, ``--quiet`` silences it.  Standard output never
carries progress.  Warnings are not progress: they are written whatever the setting
(:func:`warn`).

The library's long functions take ``progress``: ``None`` (silent, the default), a
callable given one-line messages (the library's own convention, kept for callers'
functions), or :data:`SHOW`, the commands' choice, which draws ``tqdm`` bars.  A long
step asks :func:`bar` for its bar and steps it; a message is :func:`say`.
"""
from __future__ import annotations

import sys

__all__ = ["SHOW", "configure", "shown", "say", "warn", "bar"]

#: None: show when standard error is a terminal; True: always; False: never
_MODE: list = [None]


def configure(show: bool | None = None) -> None:
    """Set whether progress is shown.

    Parameters
    ----------
    show : bool or None
        ``True`` (``--progress``): always; ``False`` (``--quiet``): never; ``None``
        (the default): when standard error is a terminal.
    """
    _MODE[0] = show


def shown() -> bool:
    """Whether progress is shown now (:func:`configure`, else standard error is a
    terminal)."""
    if _MODE[0] is not None:
        return bool(_MODE[0])
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


def _write(msg: str) -> None:
    from tqdm import tqdm
    tqdm.write(msg, file=sys.stderr)        # above any bar being drawn
    sys.stderr.flush()


def say(msg: str) -> None:
    """One line of progress (what is being done) on standard error, when shown.

    Parameters
    ----------
    msg : str
        The line, without its newline.
    """
    if shown():
        _write(msg)


#: The ``progress`` argument the commands pass: messages through :func:`say`, bars
#: drawn by tqdm.
SHOW = say


def warn(msg: str) -> None:
    """A warning on standard error, shown whatever the progress setting.

    Parameters
    ----------
    msg : str
        The line, without its newline (``"warning: "`` is prefixed).
    """
    _write(f"warning: {msg}")


class _Lines:
    """A bar for a caller's own ``progress`` function: one message per step."""

    def __init__(self, report, total, desc):
        self.report, self.total, self.desc, self.n, self.note = report, total, desc, 0, ""

    def update(self, n=1):
        self.n += n
        shown_total = f"/{self.total}" if self.total else ""
        self.report(f"{self.desc}: {self.n}{shown_total} {self.note}".rstrip())

    def set_postfix_str(self, note, refresh=True):
        self.note = note

    def set_description_str(self, desc, refresh=True):
        self.desc = desc

    def close(self):
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


class _Nothing(_Lines):
    def __init__(self):
        super().__init__(None, 0, "")

    def update(self, n=1):
        pass


def bar(progress, total: int | None, desc: str, unit: str = "step"):
    """A progress bar for one long step (use as a context manager; ``update()`` per
    item, ``set_postfix_str(note)`` for what the item is).

    Parameters
    ----------
    progress : None, callable or SHOW
        ``None``: nothing; :data:`SHOW`: a ``tqdm`` bar on standard error when
        progress is shown; another callable: given one line per step.
    total : int or None
        Number of steps (``None``: unknown, a counter).
    desc : str
        What is being done (``"ladder basic: trying candidates"``).
    unit : str
        What one step is (``"fit"``, ``"record"`` ...).
    """
    if progress is None or total == 0:
        return _Nothing()
    if progress is not SHOW:
        return _Lines(progress, total, desc)
    from tqdm import tqdm
    return tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, disable=not shown(),
                leave=False, dynamic_ncols=True, mininterval=0.2)
