"""The stepping algorithms, written once: run here by the Simulator, translated
into the FMU's C (``fmu/inflow_algorithms.c``) by :mod:`inflowsim.fmu.pyc`.

Each function below is written in a small subset of Python that reads the same in
both languages: flat float vectors (row-major matrices, their sizes passed as
arguments), ``int`` and ``float`` scalars declared by annotation, ``for ... in
range``, ``while``, ``if``, scalar arithmetic, the functions of :mod:`math`, module
constants, and the primitives of :class:`P` (matrix products, ``y += alpha x``,
Horner's rule, largest entries, the 1-norm, an LU solve: NumPy here, a few lines of
hand-written C in ``fmu/inflow_numerics.[ch]`` and ``fmu/inflow_model.h``, the only
numerics written twice).  :func:`algorithm`
names each function's C function and the size arguments that are compile-time
constants in the FMU (``IFS_NA``: the augmented ``[x; u]``).

So the Simulator and the FMU step by the same operations in the same order; they
differ only where a primitive's NumPy sums in another order than the C loop (a
few units of the last place).  ``tests/test_fmu_algorithms.py`` compiles the
generated C and compares it with these functions on the same inputs.

Single-sourced here: the Taylor rule's term count (:func:`taylor_count`), what the
Taylor step needs from ``a`` and ``b`` (:func:`taylor_prepare`: ``[a b]`` by rows and
by columns, the 1-norms that bound its terms) and the Taylor step itself
(:func:`taylor_step`: the FMU's step of a communication remainder; on the identity
the Simulator's ``[phi gam]`` after ``set_dt``), the
matrix exponential (:func:`expm`, Pade [13/13] with scaling and squaring) and the
``mu`` table's segment ends (:func:`mu_edges`), fit: its segments and their parts
(:func:`mu_fit`; the interpolation matrices :func:`cheb_matrices`,
:func:`power_fit`), check (:func:`mu_check`), part search (:func:`mu_parts`,
:func:`mu_part`) and evaluation (:func:`mu_eval`, the parts: what a change of
``mu`` reads; the FMU's with its inputs held, :func:`mu_eval_held`: ``phi``, and
``gam u`` from the segment's power coefficients of ``gam u``, ``gam`` itself when
read, :func:`mu_eval_range`; :func:`mu_eval_coarse`, the segments' ``[a b]`` the FMU reads
rarely).  Each side's own are the primitives only; in the step's hot path
``P.fhorner`` (here one dot product of the powers, in C Horner's rule with fused
multiply-adds, its AVX2 variant :data:`FMA4`) and the Taylor step's matrix-vector
products (in C the step's dot product, ``fmu/inflow_model.h``).
"""
from __future__ import annotations

import math
import struct
from dataclasses import dataclass

import numpy as np

from ..physics import loads as _loads

#: Taylor series of a step: the next term bounded by this times |[x; u]| ...
TAYLOR_TOL = 1e-17
#: ... within this many terms, else the matrix exponential.
TAYLOR_MAX_TERMS = 30
#: The diagonal [13/13] Pade approximant's coefficients ``b_k`` of ``X^k`` (Higham
#: 2005): ``exp(X) ~ (V - U)^-1 (V + U)``, ``V`` the even and ``U`` the odd part.
PADE13 = (64764752532480000.0, 32382376266240000.0, 7771770303897600.0,
          1187353796428800.0, 129060195264000.0, 10559470521600.0, 670442572800.0,
          33522128640.0, 1323241920.0, 40840800.0, 960960.0, 16380.0, 182.0, 1.0)
#: :func:`expm` scales its argument to a 1-norm at most this (``theta_13``: the
#: [13/13] approximant's backward error is then below the unit roundoff, Higham
#: 2005, Table 2.3).
EXPM_NORM = 5.371920351148152

#: The C names of the constants the functions read (``inflow_vars.h``, generated
#: from :func:`inflowsim.simulate.mutable.c_defines`); other constants are written
#: into the C as numbers or ``static const`` arrays.
C_MACROS = {"TAYLOR_TOL": "IFS_TAYLOR_TOL", "TAYLOR_MAX_TERMS": "IFS_KMAX"}

#: The functions the C is generated from, in order: ``(function, C name, static,
#: {size argument: C constant})``.
ALGORITHMS = []
#: ``{C name: [Variant, ...]}``: further C versions of a registered function.
VARIANTS = {}
#: ``{C name: (C attribute macro, ...)}``: the hot path's (``fmu/inflow_numerics.h``):
#: ``IFS_FLATTEN`` inlines every call in the function (where a call costs as much as
#: the work), ``IFS_HOT`` compiles it for AVX2 and the baseline, chosen at load time.
ATTRIBUTES = {}


@dataclass(frozen=True)
class Variant:
    """Another C version of an algorithm: its name ``C name + suffix``, compiled
    where the macro ``guard`` is defined, with the C ``attribute`` (a target), the
    primitives ``{name: other name}`` replaced; ``what`` says what it is for."""
    suffix: str
    guard: str
    attribute: str
    primitives: dict
    what: str


#: The mu table's evaluation with the CPU's fused multiply-adds four at once
#: (``IFS_MU_FMA4``: x86-64 with GNU C; the FMU takes it where the CPU has AVX2 and
#: FMA, else the C library's ``fma``: one rounding either way, the same numbers).
FMA4 = Variant("_fma", "IFS_MU_FMA4", '__attribute__((target("avx2,fma")))',
               {"fhorner": "fhorner_fma"}, "the same with the CPU's AVX2 and FMA "
               "(ifs_fhorner_fma; chosen at run time where the CPU has them)")


def algorithm(c_name: str, sizes=None, static: bool = False, variants=(), attributes=()):
    """Register a function of this module for translation into C as ``c_name``;
    ``sizes``: arguments that are a C constant expression in the FMU (dropped from
    the C signature); ``variants``: further C versions (:class:`Variant`);
    ``attributes``: C attribute macros (:data:`ATTRIBUTES`)."""
    def register(f):
        ALGORITHMS.append((f, c_name, static, dict(sizes or {})))
        if variants:
            VARIANTS[c_name] = list(variants)
        if attributes:
            ATTRIBUTES[c_name] = tuple(attributes)
        return f
    return register


# The physics' own iteration, run by the Simulator's model and translated into the
# FMU's C with the stepping: the speed through the disc (the mass-flow parameter by
# Newton's method on the trim inflow).
algorithm("ifs_momentum_newton", static=True)(_loads.momentum_newton)
algorithm("ifs_flow_speed")(_loads.flow_speed)


def _rows(v: np.ndarray, rows: int, cols: int, ld: int) -> np.ndarray:
    """The ``rows`` x ``cols`` view of the flat ``v`` whose rows are ``ld`` apart."""
    if rows == 0:
        return v[:0].reshape(0, cols)
    if v.size >= rows * ld:
        return v[:rows * ld].reshape(rows, ld)[:, :cols]
    if (rows - 1) * ld + cols > v.size:
        raise IndexError("a vector shorter than its rows")
    return np.lib.stride_tricks.as_strided(v, (rows, cols), (ld * v.strides[0], v.strides[0]))


class Vec:
    """Annotation: a flat float vector (``double *`` in C), written in place."""


class CVec:
    """Annotation: a flat float vector read only (``const double *``)."""


class Entries:
    """Annotation: ``entries(ctx, mu, out) -> int``, the exact values at ``mu``
    written into ``out`` (0, or -1 where there are none); C's ``IfsMuEntries``."""


class Ctx:
    """Annotation: what :class:`Entries` is given (``void *`` in C)."""


_POWERS = {}


def _powers_buffer(deg: int):
    """A vector of ``deg + 1`` doubles, written by packing floats into its buffer (a
    fifth of the cost of ``np.power(y, k, out=)``, bench/simulator.md): P.fhorner's."""
    if deg not in _POWERS:
        v = np.empty(deg + 1)
        _POWERS[deg] = (v, struct.Struct(f"{deg + 1}d").pack_into, memoryview(v).cast("B"))
    return _POWERS[deg]


class P:
    """The primitives (``ifs_<name>`` in ``fmu/inflow_numerics.c``): whole-vector
    operations that NumPy does at once here.  Vectors are flat float64 arrays;
    ``n`` x ``n`` matrices are row-major."""

    @staticmethod
    def new(size: int) -> np.ndarray:
        """A zero vector of ``size`` (a local array in C)."""
        return np.zeros(size)

    @staticmethod
    def empty(size: int) -> np.ndarray:
        """A vector of ``size`` whose entries are written before they are read (a
        local array in C, not zeroed)."""
        return np.empty(size)

    @staticmethod
    def copy(dst: np.ndarray, src: np.ndarray, size: int) -> None:
        dst[:size] = src[:size]

    @staticmethod
    def scale(x: np.ndarray, alpha: float, size: int) -> None:
        """``x *= alpha``."""
        x[:size] *= alpha

    @staticmethod
    def axpy(y: np.ndarray, alpha: float, x: np.ndarray, size: int) -> None:
        """``y += alpha x``."""
        y[:size] += alpha * x[:size]

    @staticmethod
    def matmul(a: np.ndarray, b: np.ndarray, c: np.ndarray, n: int) -> None:
        """``c = a b`` (``n`` x ``n``; ``c`` not ``a`` or ``b``)."""
        np.matmul(a[:n * n].reshape(n, n), b[:n * n].reshape(n, n),
                  out=c[:n * n].reshape(n, n))

    @staticmethod
    def gemm(a: np.ndarray, b: np.ndarray, c: np.ndarray, rows: int, inner: int, cols: int,
             ldb: int, ldc: int) -> None:
        """``c = a b``: ``a`` ``rows`` x ``inner`` (rows ``inner`` apart), ``b``
        ``inner`` x ``cols`` (rows ``ldb`` apart), ``c`` ``rows`` x ``cols`` (rows
        ``ldc`` apart; not ``a`` or ``b``)."""
        _rows(c, rows, cols, ldc)[:] = (a[:rows * inner].reshape(rows, inner)
                                        @ _rows(b, inner, cols, ldb))

    @staticmethod
    def horner(p: np.ndarray, deg: int, x: np.ndarray, nx: int, out: np.ndarray, cols: int,
               ldp: int, ldo: int) -> None:
        """``out[i, e] = sum_k p[k, e] x[i]^k`` for ``i < nx``, ``e < cols`` (rows ``k =
        0 .. deg`` of ``p``, ``ldp`` apart; the rows of ``out`` ``ldo`` apart) by
        Horner's rule, from ``k = deg`` down."""
        pk = _rows(p, deg + 1, cols, ldp)
        xs = x[:nx, None]
        acc = np.repeat(pk[deg][None, :], nx, axis=0)
        for k in range(deg - 1, -1, -1):
            acc *= xs
            acc += pk[k]
        _rows(out, nx, cols, ldo)[:] = acc

    @staticmethod
    def fhorner(q: np.ndarray, deg: int, y: float, out: np.ndarray, cols: int,
                ld: int) -> None:
        """``out[e] = sum_k q[k, e] y^k`` for ``e < cols`` (rows ``k = 0 .. deg`` of
        ``q``, ``ld`` apart): in C Horner's rule with fused multiply-adds, four
        entries a vector; here the powers of ``y`` times ``q`` in one dot product
        (a fifth of the cost of Horner's rule in NumPy)."""
        pw = [1.0, y]
        for _ in range(deg - 1):
            pw.append(pw[-1] * y)
        powers, pack, buf = _powers_buffer(deg)
        pack(buf, 0, *pw[:deg + 1])
        rows = (q[:(deg + 1) * cols].reshape(deg + 1, cols) if ld == cols
                else _rows(q, deg + 1, cols, ld))
        powers.dot(rows, out=out[:cols])

    @staticmethod
    def gemv_cols(a: np.ndarray, x: np.ndarray, y: np.ndarray, rows: int, cols: int,
                  lda: int) -> None:
        """``y[r] = sum_c a[c lda + r] x[c]`` for ``r < rows``: ``a`` by columns (``cols``
        of them, ``lda`` apart; the step's ``gam u``).  In C the columns' multiples
        summed in order, four rows a vector."""
        y[:rows] = _rows(a, cols, rows, lda).T @ x[:cols]

    @staticmethod
    def taylor_first(ab: np.ndarray, z: np.ndarray, r: float, w: np.ndarray, n: int,
                     rl: int, cols: int) -> None:
        """``w = ([a b] z) r``: ``[a b]`` by rows (``n`` rows ``rl`` apart), ``z`` ``rl``
        x ``cols``, ``w`` ``n`` x ``cols`` (row-major).  In C the step's dot product
        (``ifs_rows``, ``cols`` 1)."""
        out = w[:n * cols].reshape(n, cols)
        np.dot(ab[:n * rl].reshape(n, rl), z[:rl * cols].reshape(rl, cols), out=out)
        out *= r

    @staticmethod
    def taylor_term(ab: np.ndarray, w: np.ndarray, s: float, w_next: np.ndarray,
                    acc: np.ndarray, n: int, ld: int, cols: int) -> None:
        """``w_next = (a w) s`` and ``acc += w_next``: ``a`` the first ``n`` columns of
        ``[a b]`` stored by columns (column ``j`` at ``ab[j ld:]``), ``w``, ``w_next``
        and ``acc`` ``n`` x ``cols`` (row-major)."""
        # (np.dot: a third of np.matmul's call on these small arrays)
        nxt = w_next[:n * cols].reshape(n, cols)
        np.dot(ab[:n * ld].reshape(n, ld)[:, :n].T, w[:n * cols].reshape(n, cols), out=nxt)
        nxt *= s
        acc[:n * cols] += w_next[:n * cols]

    @staticmethod
    def absmax(x: np.ndarray, size: int) -> float:
        """The largest ``|x|`` (0 for none)."""
        return float(np.max(np.abs(x[:size]), initial=0.0))

    @staticmethod
    def absdiffmax(x: np.ndarray, y: np.ndarray, size: int) -> float:
        """The largest ``|x - y|`` (0 for none; NaN if a difference is)."""
        return float(np.max(np.abs(x[:size] - y[:size]), initial=0.0))

    @staticmethod
    def norm1(a: np.ndarray, rows: int, cols: int) -> float:
        """The largest column sum of ``|a|`` (``rows`` x ``cols``); NaN if any
        entry is."""
        return float(np.abs(a[:rows * cols].reshape(rows, cols)).sum(axis=0).max(initial=0.0))

    @staticmethod
    def lu_solve(n: int, a: np.ndarray, nrhs: int, b: np.ndarray, tol: float) -> int:
        """Solve ``A X = B`` in place (``a`` ``n`` x ``n`` destroyed, ``b`` ``n`` x
        ``nrhs`` overwritten by ``X``), LU with partial pivoting; -1 if a pivot is
        below ``tol`` times the largest ``|A|`` entry."""
        # the pivots from scipy's LU (LAPACK's partial pivoting, as the C), the
        # solution from NumPy's solve: scipy's lu_solve takes milliseconds on a
        # loaded machine (threaded LAPACK on a small matrix)
        from scipy.linalg import lu_factor      # (imported here: see discrete.zoh)
        m = a[:n * n].reshape(n, n)
        amax = float(np.max(np.abs(m), initial=0.0))
        if not (amax > 0.0 and math.isfinite(amax)):
            return -1
        lu, _ = lu_factor(m, check_finite=False)
        if not np.min(np.abs(np.diag(lu))) > tol * amax:
            return -1
        rhs = b[:n * nrhs].reshape(n, nrhs)
        rhs[:] = np.linalg.solve(m, rhs)
        return 0


@algorithm("ifs_taylor_count")
def taylor_count(norm_a: float, norm_ab: float, r: float) -> int:
    """Terms of the Taylor series of a step of length ``|r|`` [s] of ``x' = a x +
    b u``, ``norm_a = |a|``, ``norm_ab = |[a b]|`` (1-norms): the first ``k`` whose
    next term is bounded by ``TAYLOR_TOL |[x; u]|`` (term ``k`` is at most ``(|a|
    r)^(k-1) |[a b]| r / k!`` of it); 0 if more than ``TAYLOR_MAX_TERMS`` would be
    needed."""
    bound: float = norm_ab * math.fabs(r)
    q: float = norm_a * math.fabs(r)
    for k in range(1, TAYLOR_MAX_TERMS + 1):
        if bound * q / (k + 1) <= TAYLOR_TOL:
            return k
        bound *= q / (k + 1)
    return 0


@algorithm("ifs_taylor_prepare", sizes={"n": "IFS_NX", "m": "IFS_NU", "rl": "IFS_RL",
                                        "ld": "IFS_LD"})
def taylor_prepare(a: CVec, b: CVec, abr: Vec, abc: Vec, norms: Vec, n: int, m: int, rl: int,
                   ld: int) -> None:
    """What the Taylor step of ``x' = a x + b u`` (:func:`taylor_step`) needs from ``a``
    (``n`` x ``n``) and ``b`` (``n`` x ``m``, row-major): ``[a b]`` by rows into
    ``abr`` (``n`` rows ``rl`` apart) and by columns into ``abc`` (``n + m`` columns
    ``ld`` apart), the padding zero; and the 1-norms that bound its terms
    (:func:`taylor_count`), ``norms[0] = |a|`` and ``norms[1] = |[a b]|`` [1/s] (NaN
    if an entry is).  The FMU's after a build or a change of ``mu``
    (``fmu/inflow_model.c``), the Simulator's
    :class:`~inflowsim.simulate.discrete.TaylorZoh`."""
    for i in range(n * rl):
        abr[i] = 0.0
    for i in range((n + m) * ld):
        abc[i] = 0.0
    for i in range(n):
        for j in range(n):
            abr[i * rl + j] = a[i * n + j]
            abc[j * ld + i] = a[i * n + j]
        for j in range(m):
            abr[i * rl + n + j] = b[i * m + j]
            abc[(n + j) * ld + i] = b[i * m + j]
    norms[0] = P.norm1(a, n, n)
    norms[1] = P.norm1(abr, n, rl)


@algorithm("ifs_taylor_step", sizes={"n": "IFS_NX", "rl": "IFS_RL", "ld": "IFS_LD",
                                     "cols": "1"}, attributes=("IFS_HOT",))
def taylor_step(abr: CVec, abc: CVec, nk: int, r: float, z: Vec, n: int, rl: int, ld: int,
                cols: int) -> None:
    """The step of length ``r`` [s] (either sign) of ``x' = a x + b u`` with ``u``
    held, by ``nk`` terms of the Taylor series of the solution (:func:`taylor_count`):
    ``x(r) = x + sum_k w_k``, ``w_1 = r (a x + b u)``, ``w_k = (r / k) a w_(k-1)``
    (the ``k``-th derivative times ``r^k / k!``; each term bounded by the one
    before, so nothing overflows).  ``z``: ``[x; u]`` (``rl`` rows of ``cols``
    columns, row-major), its first ``n`` rows overwritten by the new states;
    ``[a b]`` by rows in ``abr`` (``n`` rows ``rl`` apart) and by columns in ``abc``
    (``ld`` apart).  The FMU's step of a communication interval that changes from
    frame to frame (one column); on the columns of the identity ``[phi gam]``, the
    Simulator's step after ``set_dt``
    (:class:`inflowsim.simulate.discrete.TaylorZoh`)."""
    w0 = P.new(ld * cols)                 # (zero: its padding is copied to acc)
    w1 = P.empty(ld * cols)
    acc = P.empty(ld * cols)
    P.taylor_first(abr, z, r, w0, n, rl, cols)           # w_1 = r [a b] z
    P.copy(acc, w0, ld * cols)
    for k in range(2, nk + 1):
        if k % 2 == 0:
            P.taylor_term(abc, w0, r / k, w1, acc, n, ld, cols)
        else:
            P.taylor_term(abc, w1, r / k, w0, acc, n, ld, cols)
    P.axpy(z, 1.0, acc, n * cols)


@algorithm("ifs_expm", sizes={"n": "IFS_NA"})
def expm(a: Vec, n: int) -> int:
    """``exp(A)`` of the ``n`` x ``n`` matrix ``a`` (row-major), overwritten by the
    result: scaling and squaring with the diagonal [13/13] Pade approximant, scaled
    to 1-norm at most ``EXPM_NORM`` (Higham 2005).  -1 (``a`` partly overwritten)
    if ``a`` is not finite or the solve fails."""
    nn: int = n * n
    norm: float = P.norm1(a, n, n)
    if not math.isfinite(norm):
        return -1
    s: int = 0
    while norm > EXPM_NORM and s < 64:
        norm *= 0.5
        s += 1
    P.scale(a, math.ldexp(1.0, -s), nn)
    x2 = P.new(n * n)
    x4 = P.new(n * n)
    x6 = P.new(n * n)
    u = P.new(n * n)
    v = P.new(n * n)
    t = P.new(n * n)
    P.matmul(a, a, x2, n)
    P.matmul(x2, x2, x4, n)
    P.matmul(x4, x2, x6, n)
    # odd part U = X [X^6 (b13 X^6 + b11 X^4 + b9 X^2) + b7 X^6 + b5 X^4 + b3 X^2 + b1]
    P.axpy(t, PADE13[13], x6, nn)
    P.axpy(t, PADE13[11], x4, nn)
    P.axpy(t, PADE13[9], x2, nn)
    P.matmul(x6, t, v, n)
    P.axpy(v, PADE13[7], x6, nn)
    P.axpy(v, PADE13[5], x4, nn)
    P.axpy(v, PADE13[3], x2, nn)
    for i in range(n):
        v[i * n + i] += PADE13[1]
    P.matmul(a, v, u, n)
    # even part V = X^6 (b12 X^6 + b10 X^4 + b8 X^2) + b6 X^6 + b4 X^4 + b2 X^2 + b0
    P.scale(t, 0.0, nn)
    P.axpy(t, PADE13[12], x6, nn)
    P.axpy(t, PADE13[10], x4, nn)
    P.axpy(t, PADE13[8], x2, nn)
    P.matmul(x6, t, v, n)
    P.axpy(v, PADE13[6], x6, nn)
    P.axpy(v, PADE13[4], x4, nn)
    P.axpy(v, PADE13[2], x2, nn)
    for i in range(n):
        v[i * n + i] += PADE13[0]
    P.copy(t, v, nn)                       # (V - U)^-1 (V + U)
    P.axpy(t, -1.0, u, nn)
    P.copy(a, v, nn)
    P.axpy(a, 1.0, u, nn)
    if P.lu_solve(n, t, n, a, 1e-300) != 0:
        return -1
    while s > 0:
        P.matmul(a, a, t, n)
        P.copy(a, t, nn)
        s -= 1
    return 0


@algorithm("ifs_cheb_matrices")
def cheb_matrices(n: int, ch: Vec, tt: Vec) -> None:
    """Chebyshev interpolation at ``n`` nodes as two ``n`` x ``n`` matrices
    (row-major): ``ch`` gives the Chebyshev coefficients ``sum_j ch[k, j] f_j`` of
    the polynomial through ``f_j`` at the Chebyshev-Gauss nodes ``cos(pi (j + 1/2) /
    n)``, ``tt`` the power coefficients ``tt[i, k]`` of ``T_k(x)``."""
    for i in range(n * n):
        tt[i] = 0.0
    tt[0] = 1.0
    if n > 1:
        tt[n + 1] = 1.0
    for k in range(2, n):
        for i in range(n):
            tt[i * n + k] = ((2.0 * tt[(i - 1) * n + k - 1] if i > 0 else 0.0)
                             - tt[i * n + k - 2])
    for k in range(n):
        for j in range(n):
            ch[k * n + j] = (math.cos(math.pi * k * (j + 0.5) / n) * (1.0 if k == 0 else 2.0)
                             / n)


@algorithm("ifs_power_fit")
def power_fit(n: int, ch: CVec, tt: CVec, f: CVec, cols: int, ldf: int, work: Vec,
              out: Vec, ldo: int) -> None:
    """The power coefficients (rows 0 .. ``n - 1`` of ``out``, ``cols`` entries
    each, rows ``ldo`` apart) of the polynomials of degree ``n - 1`` through the
    values ``f`` (row ``j``: at node ``j``, rows ``ldf`` apart) at the
    Chebyshev-Gauss nodes: the Chebyshev coefficients (into ``work``, ``n`` x
    ``cols``), then the power coefficients, ``tt (ch f)`` (:func:`cheb_matrices`)."""
    P.gemm(ch, f, work, n, n, cols, ldf, cols)
    P.gemm(tt, work, out, n, n, cols, cols, ldo)


@algorithm("ifs_mu_edges", sizes={"segments": "IFS_MU_SEG"})
def mu_edges(lo: float, hi: float, knots: CVec, nknots: int, e: Vec, segments: int) -> None:
    """The segment ends of the table in ``mu`` (``segments + nknots + 1``): ``lo
    q^s``, ``q = (hi/lo)^(1/segments)``, and the ``knots`` (ascending, inside ``(lo,
    hi)``, none on a geometric end: :func:`inflowsim.simulate.mutable.knot_edges`),
    merged in ascending order."""
    g: int = 0
    k: int = 0
    for i in range(segments + nknots + 1):
        if k < nknots and (g > segments or knots[k] < lo * math.pow(hi / lo, g / segments)):
            e[i] = knots[k]
            k += 1
        else:
            e[i] = lo * math.pow(hi / lo, g / segments)
            g += 1


@algorithm("ifs_mu_fit", sizes={"deg": "IFS_MU_DEG", "fdeg": "IFS_MU_FDEG",
                                "split": "IFS_MU_SPLIT", "ntab": "IFS_MU_NTAB",
                                "nfine": "IFS_MU_HALF0"})
def mu_fit(edge: CVec, nseg: int, entries: Entries, ctx: Ctx, p: Vec, q: Vec, deg: int,
           fdeg: int, split: int, ntab: int, nfine: int) -> int:
    """The table in ``mu`` (:mod:`inflowsim.simulate.mutable`): on each of the
    ``nseg`` segments ``[edge[s], edge[s + 1]]`` the power coefficients ``p[s, k,
    e]`` (``k = 0 .. deg`` in the local variable ``x in [-1, 1]``) of the
    polynomials through the ``ntab`` exact ``entries`` at the segment's
    Chebyshev-Gauss nodes; then of each of its ``split`` equal parts in ``x`` the
    power coefficients ``q[s split + c, k, e]`` (``k = 0 .. fdeg``, in the part's
    own local variable, the first ``nfine`` entries) of the polynomials through the
    segment's polynomials (Horner's rule) at the part's Chebyshev-Gauss nodes.  -1
    where ``entries`` has no values."""
    n: int = deg + 1
    nf: int = fdeg + 1
    ch = P.new((deg + 1) * (deg + 1))
    tt = P.new((deg + 1) * (deg + 1))
    chf = P.new((fdeg + 1) * (fdeg + 1))
    ttf = P.new((fdeg + 1) * (fdeg + 1))
    f = P.new((deg + 1) * ntab)
    work = P.new((deg + 1) * ntab)
    xs = P.new(fdeg + 1)                    # a part's nodes in the segment's x
    cheb_matrices(n, ch, tt)
    cheb_matrices(nf, chf, ttf)
    for seg in range(nseg):
        lo: float = edge[seg]
        hi: float = edge[seg + 1]
        for j in range(n):
            xj: float = math.cos(math.pi * (j + 0.5) / n)
            if entries(ctx, 0.5 * (lo + hi) + 0.5 * (hi - lo) * xj, f[j * ntab:]) != 0:
                return -1
        power_fit(n, ch, tt, f, ntab, ntab, work, p[seg * n * ntab:], ntab)
        for c in range(split):
            for j in range(nf):
                xs[j] = (2 * c + 1 + math.cos(math.pi * (j + 0.5) / nf)) / split - 1.0
            P.horner(p[seg * n * ntab:], deg, xs, nf, f, nfine, ntab, ntab)
            power_fit(nf, chf, ttf, f, nfine, ntab, work, q[(seg * split + c) * nf * nfine:],
                      nfine)
    return 0


_PARTS = {"npart": "IFS_MU_NPART", "nguess": "IFS_MU_NGUESS", "lo": "IFS_MU_LO",
          "hi": "IFS_MU_HI"}


@algorithm("ifs_mu_parts", sizes={**_PARTS, "split": "IFS_MU_SPLIT"})
def mu_parts(edge: CVec, nseg: int, pstart: Vec, pmid: Vec, pscale: Vec, guess: Vec,
             npart: int, nguess: int, lo: float, hi: float, split: int) -> None:
    """The parts of :func:`mu_fit` in ``mu`` (``npart = nseg split``): ``pstart``
    where each starts (a segment's first on the segment's start), then ``inf`` (the
    last part holds the rest); ``pmid`` and ``pscale`` the part's local variable ``y
    = (mu - pmid[j]) pscale[j]`` (the part's ``[-1, 1]``); ``guess[c]`` the part
    holding the start of cell ``c`` of ``nguess`` equal cells of ``[lo, hi]``, where
    :func:`mu_part` starts looking (the cells narrower than any part without
    knots: a step at most)."""
    for seg in range(nseg):
        e0: float = edge[seg]
        e1: float = edge[seg + 1]
        for c in range(split):
            pstart[seg * split + c] = e0 + (e1 - e0) * c / split
            pmid[seg * split + c] = e0 + (e1 - e0) * (2 * c + 1) / (2 * split)
            pscale[seg * split + c] = 2 * split / (e1 - e0)
    pstart[npart] = math.inf
    j: int = 0
    for c in range(nguess):
        at: float = lo + (hi - lo) * c / nguess
        while at >= pstart[j + 1]:
            j += 1
        guess[c] = float(j)


@algorithm("ifs_mu_part", sizes=_PARTS)
def mu_part(pstart: CVec, guess: CVec, mu: float, npart: int, nguess: int, lo: float,
            hi: float) -> int:
    """The part holding ``mu`` (:func:`mu_parts`; ``pstart[j] <= mu < pstart[j +
    1]``, the first below ``lo``): from its cell's guess, a step or none (within the
    rounding of the cell's start the part before it: its polynomial holds there
    too)."""
    c: int = int((mu - lo) * (nguess / (hi - lo)))
    if c < 0:
        c = 0
    if c >= nguess:
        c = nguess - 1
    j: int = int(guess[c])
    while mu >= pstart[j + 1]:
        j += 1
    return j


@algorithm("ifs_mu_eval", sizes={**_PARTS, "fdeg": "IFS_MU_FDEG", "cols": "IFS_MU_HALF0"},
           variants=(FMA4,), attributes=("IFS_FLATTEN",))
def mu_eval(pstart: CVec, pmid: CVec, pscale: CVec, guess: CVec, q: CVec, mu: float, out: Vec,
            npart: int, nguess: int, lo: float, hi: float, fdeg: int, cols: int) -> None:
    """The table at ``mu`` (:func:`mu_fit`'s parts ``q``, ``cols`` entries each) into
    ``out``: the part holding ``mu`` (:func:`mu_part`), ``mu``'s local variable
    ``y`` there, then the part's polynomials at ``y`` (Horner's rule with fused
    multiply-adds in C).  A change of ``mu``: the Simulator's
    :meth:`~inflowsim.simulate.simulator.Simulator.set_mu`, the FMU's ``[phi gam]``."""
    j: int = mu_part(pstart, guess, mu, npart, nguess, lo, hi)
    y: float = (mu - pmid[j]) * pscale[j]
    P.fhorner(q[j * (fdeg + 1) * cols:], fdeg, y, out, cols, cols)


@algorithm("ifs_mu_eval_range", sizes={**_PARTS, "fdeg": "IFS_MU_FDEG", "cols": "IFS_MU_HALF0"},
           variants=(FMA4,), attributes=("IFS_FLATTEN",))
def mu_eval_range(parts: CVec, q: CVec, mu: float, first: int, size: int, out: Vec,
                  npart: int, nguess: int, lo: float, hi: float, fdeg: int,
                  cols: int) -> None:
    """Entries ``first .. first + size - 1`` of :func:`mu_eval`'s at ``mu`` into the
    same entries of ``out``, the same numbers (the same part, ``y`` and Horner's
    rule); ``parts`` :func:`mu_parts`' ``pstart``, ``pmid``, ``pscale`` and ``guess``
    one after the other (as the FMU's table holds them).  The FMU's ``gam`` after
    :func:`mu_eval_held` left it out."""
    j: int = mu_part(parts, parts[3 * npart + 1:], mu, npart, nguess, lo, hi)
    y: float = (mu - parts[npart + 1 + j]) * parts[2 * npart + 1 + j]
    P.fhorner(q[j * (fdeg + 1) * cols + first:], fdeg, y, out[first:], size, cols)


@algorithm("ifs_mu_eval_held", sizes={**_PARTS, "nseg": "IFS_MU_NSEG", "split": "IFS_MU_SPLIT",
                                      "deg": "IFS_MU_DEG", "fdeg": "IFS_MU_FDEG",
                                      "cols": "IFS_MU_HALF0", "ntab": "IFS_MU_NTAB",
                                      "nphi": "IFS_MU_NPHI", "ng": "IFS_LD", "nx": "IFS_NX",
                                      "nu": "IFS_NU", "rl": "IFS_RL"},
           variants=(FMA4,), attributes=("IFS_FLATTEN",))
def mu_eval_held(parts: CVec, q: CVec, p: CVec, mu: float, m: Vec, nseg: int, npart: int,
                 nguess: int, lo: float, hi: float, split: int, deg: int, fdeg: int,
                 cols: int, ntab: int, nphi: int, ng: int, nx: int, nu: int,
                 rl: int) -> None:
    """A change of ``mu`` with the inputs held, the FMU's step by columns.  ``m``
    holds, one after the other, the model's ``[phi gam]`` (``cols`` entries by
    columns of ``ng``: ``phi`` the first ``nphi``, then ``gam``'s ``nu`` columns, as
    the step reads them), ``[x; u]`` (``rl``: ``u`` from ``nx``), ``g = gam u``
    (``ng``), ``gq`` (``deg + 1`` rows of ``ng``), then the segment ``gq`` was made
    for plus one (a float, as :func:`mu_parts`' ``guess``; its sign aside: 0 none)
    and the ``mu`` of the change; ``parts``: the segment ends, then
    :func:`mu_parts`' ``pstart``, ``pmid``, ``pscale`` and ``guess`` one after the
    other (as the FMU's table holds them); ``q`` and ``p`` :func:`mu_fit`'s.

    ``phi`` at ``mu`` from the part's polynomials (:func:`mu_eval`'s numbers), and
    ``g`` from ``gq``, the power coefficients of ``gam u`` on the segment holding
    ``mu`` (``gq_k = P_k u``, ``P_k`` the segment's coefficients of ``gam``, made
    again where ``mu`` left the segment ``gq`` was made for: ``(deg + 1) nu`` column
    multiples once per segment); ``gam`` itself left out (:func:`mu_eval_range`
    evaluates it when it is read).  A change costs three multiply-adds for each entry
    of ``phi`` and ``deg`` for each of ``g`` instead of three for each of ``[phi
    gam]``, and the next step no ``gam u``.  ``g`` differs from ``gam(mu) u`` by the
    segment's polynomial against the part's (``mutable``: 1e-13 of the largest
    entry) and rounding."""
    o: int = nseg + 1                        # pstart in parts
    j: int = mu_part(parts[o:], parts[o + 3 * npart + 1:], mu, npart, nguess, lo, hi)
    y: float = (mu - parts[o + npart + 1 + j]) * parts[o + 2 * npart + 1 + j]
    seg: int = j // split
    x: float = (2.0 * mu - parts[seg] - parts[seg + 1]) / (parts[seg + 1] - parts[seg])
    at: int = cols + rl + ng                 # gq in m
    tail: int = at + (deg + 1) * ng          # its segment plus one, the mu
    if int(math.fabs(m[tail])) != seg + 1:
        for k in range(deg + 1):
            P.gemv_cols(p[(seg * (deg + 1) + k) * ntab + nphi:], m[cols + nx:], m[at + k * ng:],
                        ng, nu, ng)
    m[tail] = float(seg + 1)
    m[tail + 1] = mu
    P.fhorner(q[j * (fdeg + 1) * cols:], fdeg, y, m, nphi, cols)
    P.fhorner(m[at:], deg, x, m[cols + rl:], ng, ng)


@algorithm("ifs_mu_eval_coarse", sizes={**_PARTS, "split": "IFS_MU_SPLIT", "deg": "IFS_MU_DEG",
                                        "ntab": "IFS_MU_NTAB"})
def mu_eval_coarse(edge: CVec, pstart: CVec, guess: CVec, p: CVec, mu: float, first: int,
                   size: int, out: Vec, npart: int, nguess: int, lo: float, hi: float,
                   split: int, deg: int, ntab: int) -> None:
    """Entries ``first .. first + size - 1`` of the segments' polynomials
    (:func:`mu_fit`'s ``p``, ``ntab`` entries each) at ``mu`` into ``out`` by Horner's
    rule: the segment of the part holding ``mu`` (:func:`mu_part`); the FMU's ``[a
    b]``, read rarely (a remainder step, a load)."""
    seg: int = mu_part(pstart, guess, mu, npart, nguess, lo, hi) // split
    e0: float = edge[seg]
    e1: float = edge[seg + 1]
    xs = P.new(1)
    xs[0] = (2.0 * mu - e0 - e1) / (e1 - e0)
    P.horner(p[seg * (deg + 1) * ntab + first:], deg, xs, 1, out, size, ntab, size)


@algorithm("ifs_mu_check", sizes={"ntab": "IFS_MU_NTAB"})
def mu_check(edge: CVec, nseg: int, entries: Entries, ctx: Ctx, table: Entries, tctx: Ctx,
             split: int, ntab: int) -> float:
    """The table's check: at each segment's midpoint the largest difference between
    the table's values (``table``) and the exact ``entries``, relative to the
    largest exact value of its block (entries ``[0, split)`` and ``[split, ntab)``;
    a block of zeros has none); NaN once a difference is; -1 where ``entries`` has
    no values."""
    worst: float = 0.0
    want = P.new(ntab)
    got = P.new(ntab)
    for seg in range(nseg):
        mu: float = 0.5 * (edge[seg] + edge[seg + 1])
        if entries(ctx, mu, want) != 0 or table(tctx, mu, got) != 0:
            return -1.0
        for b in range(2):
            first: int = 0 if b == 0 else split
            size: int = split if b == 0 else ntab - split
            scale: float = P.absmax(want[first:], size)
            if scale > 0.0:
                r: float = P.absdiffmax(got[first:], want[first:], size) / scale
                if r > worst or r != r:
                    worst = r
    return worst


__all__ = ["TAYLOR_TOL", "TAYLOR_MAX_TERMS", "PADE13", "EXPM_NORM", "C_MACROS", "ALGORITHMS",
           "VARIANTS", "ATTRIBUTES", "Variant", "FMA4", "algorithm", "Vec", "CVec", "Entries", "Ctx", "P",
           "taylor_prepare",
           "taylor_count", "taylor_step", "expm", "cheb_matrices", "power_fit", "mu_edges",
           "mu_fit", "mu_parts", "mu_part", "mu_eval", "mu_eval_range", "mu_eval_held",
           "mu_eval_coarse", "mu_check"]
