"""Immutable containers that travel: pickle, copy, and a process pool can return them.

``types.MappingProxyType`` refuses mutation but cannot be pickled, so a record, a
model or a fit holding one could not leave the process that made it (no process
pool, Dask or Ray).  :class:`FrozenDict` is the read-only mapping used instead, and
:class:`ReadOnlyArrays` makes a frozen dataclass come back from a pickle with its
arrays read-only again (numpy unpickles every array writeable).
"""
from __future__ import annotations

from typing import Iterator, Mapping

import numpy as np

__all__ = ["FrozenDict", "ReadOnlyArrays", "readonly"]


class FrozenDict(Mapping):
    """A read-only ``dict`` that pickles (the values are kept as given).

    Item assignment, deletion and attribute assignment raise, as on a
    ``mappingproxy``; ``copy()`` and ``|`` give a plain ``dict``.
    """

    __slots__ = ("_d",)

    def __init__(self, *args, **kwargs):
        object.__setattr__(self, "_d", dict(*args, **kwargs))

    def __getitem__(self, key):
        return self._d[key]

    def __iter__(self) -> Iterator:
        return iter(self._d)

    def __len__(self) -> int:
        return len(self._d)

    def __contains__(self, key) -> bool:
        return key in self._d

    def __repr__(self) -> str:
        return f"FrozenDict({self._d!r})"

    def __setattr__(self, name, value):
        raise AttributeError(f"FrozenDict is read-only (cannot set {name!r})")

    def __delattr__(self, name):
        raise AttributeError(f"FrozenDict is read-only (cannot delete {name!r})")

    def __reduce__(self):
        return (FrozenDict, (self._d,))

    def copy(self) -> dict:
        return dict(self._d)

    def __or__(self, other):
        return {**self._d, **other} if isinstance(other, Mapping) else NotImplemented

    def __ror__(self, other):
        return {**other, **self._d} if isinstance(other, Mapping) else NotImplemented


def readonly(a, dtype=float) -> np.ndarray:
    """A copy of ``a`` (as ``dtype``, default float) that cannot be written to."""
    a = np.array(a, dtype=dtype)
    a.flags.writeable = False
    return a


def _refreeze(v):
    if isinstance(v, np.ndarray):
        v.flags.writeable = False
    elif isinstance(v, FrozenDict):
        for x in v.values():
            _refreeze(x)
    elif isinstance(v, tuple):
        for x in v:
            _refreeze(x)
    return v


class ReadOnlyArrays:
    """Mixin for frozen dataclasses whose arrays are read-only: after unpickling
    (and ``copy``) the arrays, also inside :class:`FrozenDict` and tuple fields, are
    read-only again."""

    __slots__ = ()

    def __setstate__(self, state):
        if isinstance(state, tuple):          # (dict, slots) from __reduce_ex__
            state = state[0] or {}
        for v in state.values():
            _refreeze(v)
        self.__dict__.update(state)
