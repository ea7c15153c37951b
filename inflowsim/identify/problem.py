"""The fit problem: free-parameter vector, weighted residuals, nuisance elimination.

Residuals of record ``r`` at frequency ``w``: ``eps = Z - (y_u + y_nu nu)``
(:mod:`.freqmodel`), weighted by ``S^-1/2`` (``S = L L^H``, ``e = L^-1 eps``) and
stacked as real numbers ``[Re e; Im e]`` so that ``|r|^2 = sum eps^H S^-1 eps``.
The end-effect nuisance ``nu`` (real) is the weighted linear least-squares
solution for the current parameters (variable projection); the residual is the
part of the data orthogonal to the nuisance columns.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ..model.build import models_unchecked
from ..model.params import SPECS, check_constants, check_parameters
from ..model.structure import Structure
from .freqmodel import flap_derivatives, flap_response

#: Typical magnitudes (finite-difference step scale and LM scaling floor).
TYPICAL = {"delay": 0.01, "azimuth_bias": 0.05, "tau": 1.0, "tau0": 1.0, "tau_cs": 1.0}
#: Relative floor on S (noise-free data would drive ln|S| to minus infinity).
S_FLOOR = 1e-14
#: Parameter vectors whose responses :meth:`Problem.responses` remembers: a fit
#: evaluates the same ``theta`` again right after (``S`` re-estimated, the
#: forward-difference Jacobian's base point), and the responses do not depend on ``S``.
MEMO = 4
MEMO_BYTES = 16 * 2 ** 20
#: Bytes of responses one step of a Jacobian by differences evaluates together
#: (:meth:`Problem._jacobian_by_differences`): every point of a normal record's at once
#: (a 26.6 s record's band: 37 bins, 60 kB a point), a few of a 2-hour record's
#: (9 750 bins, 14 MB a point).
POINT_BYTES = 32 * 2 ** 20


class Problem:
    """Structure, records and the free / fixed / tied parameter map.

    ``theta`` (free values) -> full parameter dict: each free entry sets one
    parameter or one tie group; fixed parameters keep their values.

    Attributes
    ----------
    models_alone : bool
        The responses are those of the structure's models alone (class attribute;
        True): :meth:`jacobian` differentiates the models' matrices through the
        resolvent.  A subclass whose responses are not (its own
        :meth:`_responses_many`: the map of missing terms' augmented problems, with
        an input feedthrough and lagged terms outside the models' matrices) sets it
        False and is differenced as a whole (:meth:`_jacobian_by_differences`).
    """

    models_alone: bool = True

    def __init__(self, structure, spectra, values: dict, fixed=(), ties=()):
        self.structure = Structure.parse(structure)
        self.spectra = list(spectra)
        names = self.structure.parameters
        self.values = {n: float(values[n]) for n in names}
        self.fixed = tuple(fixed)
        groups, seen = [], set()
        for tie in ties:
            tie = tuple(tie)
            if len(tie) < 2:
                raise InputError(f"tie {tie}: name at least two parameters")
            for n in tie:
                if n not in names:
                    raise InputError(f"tie: {n} is not a parameter of {self.structure.name} "
                                     f"(its parameters: {', '.join(names)})")
                if n in seen:
                    raise InputError(f"tie: {n} appears in two ties; merge them")
                if n in self.fixed:
                    raise InputError(f"tie: {n} is also fixed; fix or tie it, not both")
                seen.add(n)
            groups.append(tie)
        self.free = []          # list of tuples of parameter names
        for n in names:
            if n in self.fixed or n in seen and not any(g[0] == n for g in groups):
                continue
            self.free.append(next((g for g in groups if g[0] == n), (n,)))
        self.free_names = tuple(g[0] if len(g) == 1 else "=".join(g) for g in self.free)
        self.n_freq = sum(sp.f_hz.size for sp in self.spectra)
        self._memo = {}                 # theta bytes -> responses (MEMO most recent)
        self._constants_ok = [False] * len(self.spectra)
        self._fixed_ok = False          # every parameter passed check_parameters once
        self._bounds = None
        self._box = None                # (lo, hi): values every tied parameter allows

    # -- parameter vector -------------------------------------------------------
    def theta0(self) -> np.ndarray:
        return np.array([self.values[g[0]] for g in self.free], dtype=float)

    def params(self, theta) -> dict:
        p = dict(self.values)
        for g, v in zip(self.free, theta):
            for n in g:
                p[n] = float(v)
        return p

    def bounds(self):
        """``(lo, hi)`` of the free values: each parameter's allowed range, an open
        lower end moved inside by ``1e-9`` of its size."""
        if self._bounds is None:
            lo, hi = [], []
            for g in self.free:
                s = SPECS[g[0]]
                span = max(abs(s.lower), 1.0) if math.isfinite(s.lower) else 1.0
                lo.append(s.lower + (1e-9 * span if s.lower_open else 0.0))
                hi.append(s.upper)
            self._bounds = np.array(lo), np.array(hi)
            for x in self._bounds:
                x.flags.writeable = False
        return self._bounds

    def log_mask(self) -> np.ndarray:
        """Free parameters searched in ``log`` (positive by definition: time
        constants, ``lambda_beta2``, ``n_beta``), so a step can never cross zero."""
        return np.array([SPECS[g[0]].lower == 0 and SPECS[g[0]].lower_open
                         for g in self.free], dtype=bool)

    def typical(self, theta) -> np.ndarray:
        return np.array([max(abs(v), TYPICAL.get(g[0], 0.1))
                         for g, v in zip(self.free, theta)])

    # -- model evaluation -------------------------------------------------------
    def responses(self, theta, remember=True):
        """Per record ``(y_u, y_nu)`` (read-only arrays); :class:`InputError` for invalid
        parameters.  The last :data:`MEMO` parameter vectors' responses are
        remembered (``remember=False``: only looked up, as for the Jacobian's
        perturbed points, each used once)."""
        key = np.asarray(theta, dtype=float).tobytes()
        out = self._memo.get(key)
        if out is not None:
            return out
        out = self._responses(theta)
        if remember:
            # at most MEMO vectors, and past the last two at most MEMO_BYTES (a
            # 2-hour record's responses are 6 MB a vector)
            size = sum(y_u.nbytes + y_nu.nbytes for y_u, y_nu in out)
            while self._memo and (len(self._memo) >= MEMO or len(self._memo) >= 2 and
                                  (len(self._memo) + 1) * size > MEMO_BYTES):
                del self._memo[next(iter(self._memo))]
            self._memo[key] = out
        return out

    def _responses(self, theta):
        return self._responses_many([theta])[0]

    def _checked(self, theta):
        """The parameter dict of ``theta``, checked as :func:`build_model` would."""
        p = self.params(theta)
        # the checks build_model makes, once: the constants per record for the
        # problem's life; the parameters once per evaluation (the same for every
        # record), unless every fixed value has passed before and the free ones lie
        # inside the range of every parameter they set (they would pass again)
        for i, sp in enumerate(self.spectra):
            if not self._constants_ok[i]:
                check_constants(sp.constants)
                self._constants_ok[i] = True
            if i == 0 and not (self._fixed_ok and self._inside(theta)):
                p = check_parameters(p, self.structure.parameters)
                self._fixed_ok = True
        return p

    def _responses_many(self, thetas):
        """:meth:`responses` of several parameter vectors (not remembered), each
        record's models built together (:func:`models_unchecked`)."""
        ps = [self._checked(t) for t in thetas]
        per_record = [[flap_response(m, sp) for m in
                       models_unchecked(self.structure, ps, sp.constants)]
                      for sp in self.spectra]
        out = []
        for j in range(len(thetas)):
            resp = []
            for rec in per_record:
                y_u, y_nu, _ = rec[j]
                y_u.flags.writeable = False
                y_nu.flags.writeable = False
                resp.append((y_u, y_nu))
            out.append(resp)
        return out

    def _inside(self, theta) -> bool:
        """Every free value finite and inside the allowed range of each parameter it
        sets (:func:`~inflowsim.model.params.check_parameters` would pass it)."""
        if self._box is None:
            lo, hi = [], []
            for g in self.free:
                specs = [SPECS[n] for n in g]
                lo.append(max(np.nextafter(s.lower, np.inf) if s.lower_open else s.lower
                              for s in specs))
                hi.append(min(s.upper for s in specs))
            self._box = [float(x) for x in lo], [float(x) for x in hi]
        lo, hi = self._box
        # as Python floats: a dozen comparisons cost less than numpy's reductions
        # (a NaN compares false; an infinity lies outside every finite limit and is
        # refused by isfinite)
        return all(math.isfinite(t) and a <= t <= b
                   for t, a, b in zip(np.asarray(theta, dtype=float).tolist(), lo, hi))

    @staticmethod
    def weight(S):
        """``L^-1`` with ``S = L L^H``."""
        return np.linalg.inv(np.linalg.cholesky(S))

    def solve_nuisance(self, resp, weights):
        """Per record: nuisance ``nu``, orthonormal nuisance basis ``Q`` and the
        projected weighted residual ``r``."""
        out = []
        for sp, (y_u, y_nu), W in zip(self.spectra, resp, weights):
            b = stack((sp.Z - y_u) @ W.T)
            U, s, Vt = thin_svd(stack_columns(W @ y_nu), overwrite_a=True)
            keep = s > s[0] * 1e-10 if s.size and s[0] > 0 else np.zeros(s.size, bool)
            # every column kept (the rule) of a Fortran-ordered U (:func:`thin_svd`'s):
            # U itself, not the copy U[:, keep] would make (in the same order, so
            # the products below are the same numbers)
            Uk, sk, Vk = (U, s, Vt) if keep.all() and U.flags.f_contiguous else \
                (U[:, keep], s[keep], Vt[keep])
            c = Uk.T @ b
            nu = Vk.T @ (c / sk)
            out.append((nu, Uk, b - Uk @ c))
        return out

    def eps(self, resp, nus):
        """Unweighted complex residuals ``(nf, 3)`` per record."""
        return [sp.Z - y_u - y_nu @ nu for sp, (y_u, y_nu), nu in
                zip(self.spectra, resp, nus)]

    def estimate_S(self, eps):
        out = []
        for sp, e in zip(self.spectra, eps):
            S = (e.T @ e.conj()) / e.shape[0]
            power = np.real(np.trace(sp.Z.T @ sp.Z.conj())) / (3 * sp.Z.shape[0])
            S = 0.5 * (S + S.conj().T) + S_FLOOR * power * np.eye(3)
            out.append(S)
        return out

    def cost(self, r_list, S_list) -> float:
        """Cost (12): ``sum_w eps^H S^-1 eps + n_freq ln|S|`` summed over records."""
        j = 0.0
        for sp, r, S in zip(self.spectra, r_list, S_list):
            j += float(r @ r) + sp.f_hz.size * float(np.log(np.real(np.linalg.det(S))))
        return j

    def direct(self, theta, weights, nus):
        """Weighted stacked residual at fixed nuisance (for the Kaufman Jacobian)."""
        return self._weighted(self.responses(theta, remember=False), weights, nus)

    def _weighted(self, resp, weights, nus):
        out = []
        for sp, (y_u, y_nu), W, nu in zip(self.spectra, resp, weights, nus):
            # sp.Z - y_u - y_nu @ nu, weighted and stacked, without its temporaries
            # (the same operations; a 2-hour record's Jacobian point: 0.5 of 2 ms)
            e = np.subtract(sp.Z, y_u)
            e -= y_nu @ nu
            out.append(_stack2(e @ W.T))
        return out

    def jacobian(self, theta, weights, nus, bases, central=True):
        """Sensitivities of the projected weighted residuals to ``theta``.

        The flap transforms' derivatives at the fixed nuisance by the resolvent
        (:func:`.freqmodel.flap_derivatives`: ``dy = dC R x + C R (dA R x + dx)``),
        the small matrices' changes (state, output, input and end-state maps, time
        shifts) taken as differences of the models at steps ``1e-6`` of each
        parameter's typical size: central ones (``central``) or forward, one-sided
        at a range limit; then weighted and projected orthogonally to the nuisance
        columns (Kaufman's variable-projection Jacobian).  Returns one block per
        record, ``(2 nf 3, p)``.

        A problem whose responses are not those of its models alone
        (:attr:`models_alone` False: the map of missing terms' augmented problems,
        whose entries include an input feedthrough and lagged terms outside the
        model's matrices) is differenced as a whole (:meth:`_jacobian_by_differences`).
        """
        if not self.models_alone:
            return self._jacobian_by_differences(theta, weights, nus, bases, central)
        lo, hi = self.bounds()
        h = 1e-6 * self.typical(theta)
        points, plan = [theta], []         # the models built: theta, then each step's
        for i in range(theta.size):
            up, dn = theta[i] + h[i] <= hi[i], theta[i] - h[i] >= lo[i]
            ip = im = 0
            if up:
                ip = len(points)
                points.append(theta.copy())
                points[-1][i] += h[i]
            if not up or central and dn:
                im = len(points)
                points.append(theta.copy())
                points[-1][i] -= h[i]
            plan.append((ip, im, (theta[i] + h[i] if ip else theta[i])
                         - (theta[i] - h[i] if im else theta[i])))
        ps = [self._checked(t) for t in points]
        out = []
        for sp, W, nu, Q in zip(self.spectra, weights, nus, bases):
            models = models_unchecked(self.structure, ps, sp.constants)
            dy = flap_derivatives(models[0], [(models[ip], models[im], step)
                                              for ip, im, step in plan], sp, nu, W)
            # stacked as the residual is ([Re; Im] of (nf, 3) row by row); the
            # residual is data minus model: d r / d theta = -(d model)
            half = dy.shape[0] * 3
            blk = np.empty((2 * half, theta.size))
            np.negative(dy.real, out=blk[:half].reshape(dy.shape))
            np.negative(dy.imag, out=blk[half:].reshape(dy.shape))
            del dy
            blk -= Q @ (Q.T @ blk)
            out.append(blk)
        return out

    def _direct_many(self, thetas, weights, nus):
        """:meth:`direct` of each parameter vector, the ones not remembered evaluated
        together."""
        resp = [self._memo.get(np.asarray(t, dtype=float).tobytes()) for t in thetas]
        todo = [j for j, r in enumerate(resp) if r is None]
        for j, r in zip(todo, self._responses_many([thetas[j] for j in todo])):
            resp[j] = r
        return [self._weighted(r, weights, nus) for r in resp]

    def _point_bytes(self) -> int:
        """Bytes of the temporaries one parameter vector's responses take at once
        (every record, :func:`.freqmodel.flap_response`): the resolvent and its
        denominator ``(nf, n)``, the input terms, and the end-state responses
        ``(nf, 3, 2 k)`` with their half ``(nf, 3, k)``, complex; ``k <= n``."""
        n = len(self.structure.states)
        m = len(self.structure.inputs)
        return sum(16 * sp.f_hz.size * (4 * n + 2 * m + 3 + 9 * n) for sp in self.spectra)

    def _jacobian_by_differences(self, theta, weights, nus, bases, central=True):
        """:meth:`jacobian` of a problem whose responses are not its models' alone:
        central differences of the full model (discretisation, delays, end terms
        included) with steps ``1e-6`` of each parameter's typical size, one-sided
        at a range limit; then projected orthogonally to the nuisance columns
        (Kaufman's variable-projection Jacobian).  Returns one block per record,
        ``(2 nf 3, p)``.
        """
        lo, hi = self.bounds()
        h = 1e-6 * self.typical(theta)
        blocks = [np.empty((2 * 3 * sp.f_hz.size, theta.size)) for sp in self.spectra]
        # every point first (evaluated together), then the differences
        points, plan, base = [], [], None
        for i in range(theta.size):
            tp, tm = theta.copy(), theta.copy()
            up, dn = theta[i] + h[i] <= hi[i], theta[i] - h[i] >= lo[i]
            if central and up and dn:
                tp[i] += h[i]
                tm[i] -= h[i]
                plan.append((len(points), len(points) + 1, 2 * h[i]))
                points += [tp, tm]
                continue
            if base is None:
                base = len(points)
                points.append(theta)
            if up:
                tp[i] += h[i]
                plan.append((len(points), base, h[i]))
                points.append(tp)
            else:
                tm[i] -= h[i]
                plan.append((base, len(points), h[i]))
                points.append(tm)
        # the points in runs of at most POINT_BYTES of responses: each run's
        # responses are reduced to its weighted residuals (small) before the next
        # is evaluated, so a long record's Jacobian holds a few points' responses at
        # once, not all of them (the same numbers: each point is evaluated alone or
        # in a stack alike)
        per = max(1, POINT_BYTES // max(self._point_bytes(), 1))
        res = []
        for j in range(0, len(points), per):
            res += self._direct_many(points[j:j + per], weights, nus)
        for i, (ip, im, step) in enumerate(plan):
            for blk, a, b in zip(blocks, res[ip], res[im]):
                blk[:, i] = (a - b) / step
        out = []
        for blk, Q in zip(blocks, bases):
            # the residual is data minus model: d r / d theta = -(d model)
            out.append(blk - Q @ (Q.T @ blk))
        return out


def stack(x):
    """``(nf, 3)`` -> ``(2 nf 3,)``; ``(nf, 3, k)`` -> ``(2 nf 3, k)`` (real, imag)."""
    x = np.asarray(x)
    if x.ndim == 3:
        x = x.reshape(-1, x.shape[2])
        return np.vstack([x.real, x.imag])
    return np.concatenate([x.real.ravel(), x.imag.ravel()])


def _stack2(x):
    """:func:`stack` of ``(nf, 3)``: the real parts then the imaginary, each copied
    once into the result."""
    out = np.empty(2 * x.size)
    np.copyto(out[:x.size].reshape(x.shape), x.real)
    np.copyto(out[x.size:].reshape(x.shape), x.imag)
    return out


def stack_columns(x):
    """:func:`stack` of ``(nf, 3, k)``, ``(2 nf 3, k)`` in Fortran order (as LAPACK
    takes it: :func:`thin_svd`)."""
    n, k = x.shape[0] * x.shape[1], x.shape[2]
    out = np.empty((2 * n, k), order="F")
    x = x.reshape(n, k)
    out[:n] = x.real
    out[n:] = x.imag
    return out


#: Rows from which :func:`thin_svd` factors a tall matrix itself (below: NumPy's
#: ``svd``, the same numbers; a 26.6 s record's nuisance columns have 222 rows, a
#: 2-hour record's 58 512).
THIN_ROWS = 4096


def thin_svd(A, overwrite_a=False):
    """``numpy.linalg.svd(A, full_matrices=False)`` of a tall ``A`` ``(m, k)``
    (real; ``overwrite_a``: ``A`` may be overwritten).

    LAPACK's ``gesdd`` factors a matrix of many more rows than columns as ``A = Q
    R`` (``geqrf``, ``orgqr``), takes the SVD of ``R`` and returns ``Q`` times its
    left vectors; done here in the same steps (the same numbers, bit for bit on
    this machine's OpenBLAS), without NumPy's copies of ``A`` and of ``U`` in and
    out of Fortran order: 6.5 ms against 11 ms for the 58 512 x 12 end-state
    columns of a 2-hour record, which a fit factors at every evaluation.  ``U`` is
    in Fortran order.  Below :data:`THIN_ROWS` rows, or not 4 times as many rows
    as columns, NumPy's.
    """
    m, k = A.shape
    if m < THIN_ROWS or m < 4 * k or k == 0:
        return np.linalg.svd(A, full_matrices=False)
    from scipy.linalg import lapack
    qr, tau, _, info = lapack.dgeqrf(np.asfortranarray(A, dtype=float),
                                     overwrite_a=overwrite_a)
    if info != 0:
        return np.linalg.svd(A, full_matrices=False)
    R = np.triu(qr[:k])
    Q, _, info = lapack.dorgqr(qr, tau, overwrite_a=True)
    if info != 0:
        return np.linalg.svd(A, full_matrices=False)
    u, s, vt = np.linalg.svd(R)
    return np.matmul(Q, u, out=np.empty((m, k), order="F")), s, vt


def unstack(r, nf):
    """Inverse of the real stacking for one record: ``(nf, 3)`` complex."""
    h = r.size // 2
    return (r[:h] + 1j * r[h:]).reshape(nf, 3)


__all__ = ["TYPICAL", "S_FLOOR", "MEMO", "Problem", "stack", "stack_columns", "thin_svd",
           "unstack"]
