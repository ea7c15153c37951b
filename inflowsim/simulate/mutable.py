"""The discrete matrices tabulated in the advance ratio, and the Taylor rule of a
step of another length: one description for the Simulator and the FMU.

Why a table and not polynomials: the descriptor ``E, A, B`` of Eq. (8) is a
polynomial in ``mu`` and ``1/V`` (the momentum gain ``L`` of Eq. (19) is
``diag(a0 s/(2 V), -2 a0 s/V, -2 a0 s/V)``, ``V = mu``), and the state space
``a = Omega E(mu)^-1 A(mu)`` is rational in ``mu``; the zero-order hold
``exp([[a, b], [0, 0]] dt)`` is analytic in ``mu`` on ``[MU_LO, MU_HI]`` with its
nearest singularity at ``mu = 0``.  So the discrete matrices are interpolated on
``SEGMENTS`` segments that grow geometrically with ``mu`` (each the same number of
its widths away from 0), by a polynomial of degree ``DEGREE`` in the local
variable ``x in [-1, 1]`` through exact builds at the Chebyshev-Gauss nodes,
stored as power coefficients.  A table is used only if it agrees with exact
builds at every segment's midpoint to ``TOLERANCE`` of each block's largest
entry; otherwise a flight-condition change rebuilds exactly.

What a flight-condition change evaluates is a finer table made from that one
without another exact build: each segment cut into ``SPLIT`` equal parts in
``x``, on each the segment's polynomial interpolated again at the part's
``FINE_DEGREE + 1`` Chebyshev-Gauss nodes, in the part's own local variable ``y``
(:func:`~.algorithms.mu_eval`).  Over a 32nd of its segment the degree-7
polynomial is a cubic to within 1e-13 of each block's largest entry (the worst
error against the exact hold, 1.1e-13 against 2.8e-14 for the segments alone,
``glauert``; ``bench/fmu_mu_accuracy.py``: a tenth of ``TOLERANCE``), and a
change of ``mu`` costs three multiply-adds per entry instead of seven multiplies
and seven adds (the FMU's Horner rule uses fused multiply-adds; issue #38,
bench/fmu.md).  The part holding ``mu`` is found from a table of equal cells
(:func:`~.algorithms.mu_part`).

The FMU's C builds the same table at run time for its tunable parameters: the
segment ends, the fit, the check, the part search and the evaluation are
:mod:`.algorithms`' ``mu_edges``, ``mu_fit``, ``mu_check``, ``mu_parts``,
``mu_part`` and ``mu_eval``, which :class:`MuTable` runs and the C is generated
from (``fmu/inflow_algorithms.c``); its constants (``IFS_MU_LO`` ...
``IFS_TAYLOR_TOL``) are generated from this module into ``inflow_vars.h``
(:func:`c_defines`), so the two cannot drift.  Only the evaluation's last primitive
differs: here a dot product of the powers of the part's local variable, in the C
Horner's rule with fused multiply-adds (the step's hot path).

A step of another length ``r`` (the FMU's communication remainder, the
Simulator's :meth:`~inflowsim.simulate.simulator.Simulator.set_dt`) is the Taylor
series of the solution (:func:`inflowsim.simulate.algorithms.taylor_step`) with as
many terms as make the next one at most ``TAYLOR_TOL`` times ``|[x; u]|`` (1-norms;
:func:`taylor_terms`, which is :func:`inflowsim.simulate.algorithms.taylor_count`:
the FMU's C is generated from both), at most ``TAYLOR_MAX_TERMS``; beyond that,
the matrix exponential.
"""
from __future__ import annotations

import math

import numpy as np

from ..model.params import MU_MAX
from ..physics.loads import MU_MIN
from .algorithms import (TAYLOR_MAX_TERMS, TAYLOR_TOL, mu_check, mu_edges, mu_eval, mu_fit,
                         mu_parts)
from .algorithms import taylor_count as taylor_terms

#: Advance-ratio range of the table: the forward-flight momentum model's
#: (:data:`inflowsim.physics.loads.MU_MIN`, :data:`inflowsim.model.params.MU_MAX`).
MU_LO = MU_MIN
MU_HI = MU_MAX
#: Geometric segments and the polynomial degree on each.
SEGMENTS = 16
DEGREE = 7
#: Each segment's parts in the evaluated table, and their degree.
SPLIT = 32
FINE_DEGREE = 3
#: A table is used only if its check at the segment midpoints is within this
#: fraction of each block's largest entry.
TOLERANCE = 1e-12
#: A knot this close to a segment end [-] is on it (its kink is outside every
#: segment's nodes); a segment narrower would round its local variable away.
KNOT_GAP = 1e-9
#: Equal cells of ``[MU_LO, MU_HI]`` whose first parts start the part search
#: (:func:`~.algorithms.mu_parts`): narrower than any part without knots (the
#: first segment's ``1/SPLIT``, 3.3e-4, against 2.0e-4), so that a search takes a
#: step at most.
GUESS_CELLS = 2048
# The Taylor rule's constants TAYLOR_TOL and TAYLOR_MAX_TERMS live with its
# algorithm (.algorithms, the one source of the Simulator's and the FMU's
# taylor_terms); imported above.


def knot_edges(knots) -> list:
    """The ``knots`` (where a parameter schedule held beyond its range has a kink)
    that become extra segment ends, ascending: those inside ``(MU_LO, MU_HI)``
    farther than ``KNOT_GAP`` from every geometric end and from each other (one that
    near is on that end already).  The generated C gets exactly these
    (``IFS_MU_KNOTS``)."""
    geo = [MU_LO * math.pow(MU_HI / MU_LO, s / SEGMENTS) for s in range(SEGMENTS + 1)]
    out = []
    for k in sorted(float(k) for k in knots):
        if MU_LO < k < MU_HI and all(abs(x - k) > KNOT_GAP for x in geo + out):
            out.append(k)
    return out


def edges(knots=()) -> list:
    """Segment ends ``MU_LO q^s``, ``q = (MU_HI/MU_LO)^(1/SEGMENTS)`` (the C's
    ``pow`` expression, so the same doubles), and the :func:`knot_edges` of
    ``knots``, ascending: a kink on a segment end keeps every segment's polynomial
    smooth, and a segment split in two is only more accurate:
    :func:`~.algorithms.mu_edges`, the C's too."""
    k = np.array(knot_edges(knots), dtype=float)
    e = np.zeros(SEGMENTS + len(k) + 1)
    mu_edges(MU_LO, MU_HI, k, len(k), e, SEGMENTS)
    return [float(v) for v in e]


class MuTable:
    """The entries ``f(mu)`` of a matrix-valued function tabulated on ``[MU_LO,
    MU_HI]``.

    Parameters
    ----------
    exact : callable
        ``mu -> ndarray`` (any shape; the same at every ``mu``): the exact matrices.
    blocks : sequence of slices
        Row ranges whose entries share one scale in the check (each block's error
        relative to its largest entry): all rows, or two ranges that split them.
    knots : sequence of float
        Where ``exact`` has a kink (a parameter schedule's range ends): segment ends
        (:func:`edges`).

    ``ok`` says whether the check passed (``err`` the worst relative error found).
    :meth:`into` writes the interpolant at ``mu`` into an array of the same shape:
    the finer table's (``SPLIT`` parts of each segment, degree ``FINE_DEGREE``),
    which is the one checked.
    """

    def __init__(self, exact, blocks=(slice(None),), knots=()):
        self.edges = edges(knots)
        nseg = len(self.edges) - 1
        # the first node's values (mu_fit's first call, the same doubles) give the size
        lo, hi = self.edges[0], self.edges[1]
        mu0 = 0.5 * (lo + hi) + 0.5 * (hi - lo) * math.cos(math.pi * (0 + 0.5) / (DEGREE + 1))
        first = {mu0: np.asarray(exact(mu0), dtype=float)}
        self.shape = first[mu0].shape
        ntab = int(np.prod(self.shape))

        def entries(ctx, mu, out):
            v = first.pop(mu, None)
            out[:ntab] = (np.asarray(exact(mu), dtype=float) if v is None else v).ravel()
            return 0

        # the segments' and their parts' coefficients: the C's fit (mu_fit)
        p = np.zeros(nseg * (DEGREE + 1) * ntab)
        q = np.zeros(nseg * SPLIT * (FINE_DEGREE + 1) * ntab)
        mu_fit(np.asarray(self.edges, dtype=float), nseg, entries, None, p, q, DEGREE,
               FINE_DEGREE, SPLIT, ntab, ntab)
        self._p = p.reshape(nseg, DEGREE + 1, ntab)          # [segment, degree, entry]
        self._q = q                  # [part, degree, entry], flat
        self._ntab, self._nseg = ntab, nseg
        npart = nseg * SPLIT
        pstart, pmid, pscale = np.zeros(npart + 1), np.zeros(npart), np.zeros(npart)
        guess = np.zeros(GUESS_CELLS)
        mu_parts(np.asarray(self.edges, dtype=float), nseg, pstart, pmid, pscale, guess, npart,
                 GUESS_CELLS, MU_LO, MU_HI, SPLIT)
        # (lists: cheaper to index)
        self._parts = [[float(v) for v in a] for a in (pstart, pmid, pscale, guess)]
        self._npart = npart
        # the check between the nodes (mu_check, the C's): blocks as entry ranges
        rows = np.arange(self.shape[0] if self.shape else 1)
        ranges = [(int(rows[b][0]), int(rows[b][-1]) + 1) for b in blocks if len(rows[b])]
        if ([r for pair in ranges for r in pair][1:-1] != [r for pair in ranges[1:]
                                                         for r in (pair[0], pair[0])]
                or len(ranges) > 2 or ranges[0][0] != 0 or ranges[-1][1] != len(rows)):
            raise ValueError("MuTable: blocks are the rows in one or two ranges")
        split = ranges[1][0] * ntab // len(rows) if len(ranges) == 2 else ntab

        def values(ctx, mu, out):
            self.into(mu, out)
            return 0

        worst = mu_check(np.asarray(self.edges, dtype=float), nseg, entries, None, values,
                         None, split, ntab)
        worst = math.inf if worst < 0.0 else worst
        self.err = float(worst)
        self.ok = bool(self.err <= TOLERANCE)

    def covers(self, mu: float) -> bool:
        return MU_LO <= mu <= MU_HI

    def into(self, mu: float, out: np.ndarray) -> None:
        """``out[:] = f(mu).ravel()`` (``out`` a C-contiguous float vector; ``mu``
        within the table): :func:`~.algorithms.mu_eval`, the FMU's evaluation (its
        segment, part and polynomials; here one dot product of the powers of the
        part's local variable with its coefficients)."""
        pstart, pmid, pscale, guess = self._parts
        mu_eval(pstart, pmid, pscale, guess, self._q, mu, out, self._npart, GUESS_CELLS, MU_LO,
                MU_HI, FINE_DEGREE, self._ntab)


def c_defines() -> list:
    """The lines of ``inflow_vars.h`` that give the C these constants."""
    return ["/* the mu table and the Taylor remainder: inflowsim.simulate.mutable, shared "
            "with the Simulator */",
            f"#define IFS_MU_LO {MU_LO!r}",
            f"#define IFS_MU_HI {MU_HI!r}",
            f'#define IFS_MU_RANGE "[{MU_LO:g}, {MU_HI:g}]"  /* for messages */',
            f"#define IFS_MU_SEG {SEGMENTS}",
            f"#define IFS_MU_DEG {DEGREE}",
            f"#define IFS_MU_SPLIT {SPLIT}",
            f"#define IFS_MU_FDEG {FINE_DEGREE}",
            f"#define IFS_MU_TOL {TOLERANCE!r}",
            f"#define IFS_MU_KNOT_GAP {KNOT_GAP!r}",
            f"#define IFS_MU_NGUESS {GUESS_CELLS}  /* cells of the part guess */",
            f"#define IFS_TAYLOR_TOL {TAYLOR_TOL!r}",
            f"#define IFS_KMAX {TAYLOR_MAX_TERMS}  /* most Taylor terms of a remainder "
            "step */"]


__all__ = ["MuTable", "edges", "knot_edges", "taylor_terms",
           "c_defines", "MU_LO", "MU_HI", "SEGMENTS", "DEGREE", "SPLIT", "FINE_DEGREE",
           "TOLERANCE", "KNOT_GAP", "GUESS_CELLS", "TAYLOR_TOL", "TAYLOR_MAX_TERMS"]
