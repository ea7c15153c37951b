"""Results of pure functions remembered by key, the last few, most recent last:
every model a fit builds asks for the same parts of its equations again."""
from __future__ import annotations


class Recent:
    """The results of the last ``size`` keys (:meth:`get`)."""

    def __init__(self, size: int):
        self.size = size
        self._made: dict = {}

    def get(self, key, make):
        """``make()``, remembered under ``key``; a key that cannot be hashed (constants
        holding symbols, in code generation) is made and not remembered."""
        made = self._made
        try:
            # an empty dict's pop returns the default without hashing the key
            hash(key)
        except TypeError:
            return make()
        out = made.pop(key, None)
        if out is None:
            out = make()
            if len(made) >= self.size:
                try:
                    del made[next(iter(made))]
                except (KeyError, RuntimeError, StopIteration):
                    pass
        made[key] = out
        return out

    def clear(self):
        """Forget every result (what they were made with has changed)."""
        self._made.clear()


__all__ = ["Recent"]
