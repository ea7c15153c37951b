"""Polynomials held as data: several outputs, each a sum of coefficients times
monomials of a few variables, evaluated together.

Generated derivations (:mod:`inflowsim.physics.lead_lag_terms`) write their
results in this form rather than as code: Python evaluates it in a few array
operations, and the FMU's generator (:mod:`inflowsim.fmu.codegen`) prints the same
tables into C with a loop of the same operations in the same order, so the two
agree to the last bit and a table of thousands of terms compiles in no time (the
expanded expressions did not: ``model.md`` 9.1).

Each monomial is the product of its variables taken left to right (``(0, 0, 3)``
is ``v0 * v0 * v3``; ``()`` is 1); each output is the sum of its terms
``coefficient * monomial`` in the order the table lists them.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Polynomials:
    """``n_out`` polynomials of the variables :attr:`variables`.

    Attributes
    ----------
    name : str
        What it computes (a run-time call of the FMU is named after it).
    variables : tuple of str
        The variables, in the order :meth:`__call__` takes their values.
    n_out : int
        Number of outputs.
    monomials : tuple of tuple of int
        Each monomial as the indices of its variables (with repeats).
    terms : tuple of (int, int, float)
        ``(output, monomial, coefficient)``, each output's terms in summation order.
    """

    name: str
    variables: tuple
    n_out: int
    monomials: tuple
    terms: tuple
    _arrays: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        n = len(self.variables)
        depth = max((len(m) for m in self.monomials), default=0)
        # index n: the value 1 (a shorter monomial padded)
        idx = np.full((max(depth, 1), len(self.monomials)), n, dtype=np.intp)
        for j, m in enumerate(self.monomials):
            idx[: len(m), j] = m
        out = np.array([t[0] for t in self.terms], dtype=np.intp)
        mono = np.array([t[1] for t in self.terms], dtype=np.intp)
        coef = np.array([t[2] for t in self.terms], dtype=float)
        object.__setattr__(self, "_arrays", (idx, out, mono, coef))

    @property
    def depth(self) -> int:
        """Variables in the longest monomial (at least 1)."""
        return self._arrays[0].shape[0]

    def index_rows(self) -> np.ndarray:
        """``(depth, len(monomials))``: each monomial's variable indices, padded with
        ``len(variables)`` (the value 1)."""
        return self._arrays[0]

    def prefix_tree(self) -> tuple:
        """``(parent, variable, node)``: every monomial and each of its prefixes
        once as a node, node 0 the value 1 and node ``j`` its ``parent[j]`` (an
        earlier node) times the variable ``variable[j]``; ``node[i]`` is monomial
        ``i``'s node.  One multiply per node, and each monomial's multiplies in the
        order of :meth:`__call__` (left to right: the same double)."""
        nodes = {(): 0}
        parent, variable, node = [0], [-1], []
        for m in self.monomials:
            for j in range(1, len(m) + 1):
                if m[:j] not in nodes:
                    nodes[m[:j]] = len(parent)
                    parent.append(nodes[m[:j - 1]])
                    variable.append(m[j - 1])
            node.append(nodes[m])
        return tuple(parent), tuple(variable), tuple(node)

    def term_arrays(self) -> tuple:
        """``(output, monomial, coefficient)`` of every term, as three arrays."""
        return self._arrays[1:]

    def __call__(self, values) -> np.ndarray:
        """The outputs at ``values`` (one per variable): floats, or sympy
        expressions (an array of dtype object) for symbols."""
        idx, out, mono, coef = self._arrays
        try:
            v = np.array(list(values) + [1.0], dtype=float)
        except TypeError:                                   # symbols
            return self._symbolic(values)
        # each monomial's variables multiplied left to right (a reduction over the
        # first axis takes the rows in order), as the generated C
        m = np.multiply.reduce(v[idx], axis=0)
        return np.bincount(out, weights=coef * m[mono], minlength=self.n_out)

    def _symbolic(self, values):
        import sympy
        v = [sympy.sympify(x) for x in values]
        m = [sympy.Mul(*(v[i] for i in mon)) for mon in self.monomials]
        y = [sympy.Integer(0)] * self.n_out
        for o, j, c in self.terms:
            y[o] = y[o] + c * m[j]
        return np.array(y, dtype=object)

    @property
    def empty(self) -> tuple:
        """The outputs without a term (identically zero)."""
        have = {t[0] for t in self.terms}
        return tuple(o for o in range(self.n_out) if o not in have)


__all__ = ["Polynomials"]
