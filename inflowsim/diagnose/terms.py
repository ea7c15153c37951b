"""Where the missing term lives: a score test of every single-entry addition.

When no catalogue effect explains a residual, the question becomes *which term of
the equations* the data want.  At the base fit, every single-entry addition

* to each equation of Eq. (1)'s blocks -- the flap equation
  ``C beta' + D beta = H_lambda lambda + H_u u + k v`` and the inflow equation
  ``D_tau lambda' + lambda = L c + ... + k v`` -- with ``v`` any one flap angle,
  flap rate (azimuth time), inflow or input (azimuth units), and
* to the measurement map, ``beta_m,i = (C x)_i + k v`` with ``v`` a state
  (``beta``, ``lambda``) or an input (feedthrough),

is tested by the score (Lagrange-multiplier) statistic of its coefficient ``k`` at
``k = 0`` (Rao, 1948; Silvey, 1959).  No refit: with ``J_b`` the sensitivities of
the weighted residual ``r`` (cost Eq. (12): ``J = |r|^2 + sum n_f ln|S|``) to the
base's free parameters and ``j`` that to ``k``, both projected orthogonally to the
end-effect nuisance (as the estimator's bounds, :mod:`inflowsim.identify.problem`),
the score of the log-likelihood is ``s = -2 j' r`` and the information
``I = 2 [j J_b]' [j J_b]``, so

``LM = s' (I_ee - I_eb I_bb^-1 I_be)^-1 s = 2 (P j)' r)^2 / |P j|^2``

with ``P`` the projection orthogonal to ``J_b`` (Neyman's C(alpha) form: it stays
valid where the base fit stopped a hair short of the optimum).  Under the null it
is chi-square with one degree of freedom; it is divided by the same
degrees-of-freedom factor the bounds use (``S`` is estimated from residuals that
lost the fitted parameters and end states).  For a small effect it approaches the
likelihood-ratio statistic ``2 (J_base - J_refit)`` of the refit with ``k`` free.
The one-step (Gauss-Newton) estimate ``-(P j)' r / |P j|^2`` gives the term's sign.

The p-values are adjusted for the number of entries tested by Holm's step-down
method (Holm, 1979), which holds the family-wise error at ``alpha`` without
assuming independence; an entry whose sensitivity lies in the span of the base's
own parameters (``|P j|^2`` below ``1e-8 |j|^2``) cannot be told from them and is
reported untestable (not counted).

The sensitivities ``j`` are central differences of the same frequency model the
estimator fits (:func:`inflowsim.identify.freqmodel.flap_response`: holds, delays
and end effects included) with the one entry perturbed in the structured equations
(:mod:`inflowsim.model.equations`); the measurement map is linear in its entries
and is differentiated exactly.  An input feedthrough with a time-shifted flap
channel uses the shift's phase (exact without shifts).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..channels import FLAP, FLAP_RATE, INFLOW, INPUTS, N_BASE_INPUTS
from ..identify.estimator import _records, _spectra, _state
from ..identify.freqmodel import _continuous_input, flap_response
from ..identify.problem import Problem, _stack
from ..errors import InputError
from ..identify.transform import DEFAULT_BAND, record_spectra
from ..model.build import apply_effects, model_from_equations
from .tails import chi2_sf

__all__ = ["ALPHA", "Term", "MissingTerms", "missing_terms", "physics_group",
           "BLOCKS"]

#: Family-wise level of the map (after the Holm correction).
ALPHA = 1e-3
#: The blocks of equations tested, in display order.
BLOCKS = ("flap", "inflow", "measurement")
#: Relative information left after projecting off the base's parameters below which
#: an entry cannot be told from them.
CONFOUNDED = 1e-8
#: Central-difference step of an entry [descriptor units].
STEP = 1e-6

_KIND_OF = {**{n: "flap" for n in FLAP}, **{n: "rate" for n in FLAP_RATE},
            **{n: "inflow" for n in INFLOW}, **{n: "input" for n in INPUTS}}
_PITCH = set(INPUTS[:3])
_HUB = {"muz", "q", "p", "qdot", "pdot"}


def physics_group(block: str, equation: str, variable: str) -> str:
    """The physics a term in ``equation`` (of ``block``) proportional to
    ``variable`` stands for: what would give one."""
    kind = _KIND_OF[variable]
    own = equation == variable or (kind == "rate" and variable == f"{equation}_prime")
    if block == "flap":
        if kind == "flap":
            return "flap stiffness (hinge spring)" if own else \
                "flap-to-pitch coupling (delta-3)"
        if kind == "rate":
            return "flap damping" if own else "flap-rate coupling (lag or gyroscopic)"
        if kind == "inflow":
            return "inflow feedback on the flap"
        if variable in _PITCH:
            return "control coupling (pitch-link or rigging)"
        if variable in _HUB:
            return "hub-motion coupling of the flap"
        return "in-plane velocity forcing of the flap"
    if block == "inflow":
        if kind in ("flap", "rate"):
            return "flap-to-inflow loading (wake)"
        if kind == "inflow":
            return "inflow gain" if own else "inflow coupling (wake skew)"
        if variable in _PITCH:
            return "pitch-to-inflow loading"
        if variable in _HUB:
            return "hub-motion inflow coupling (Glauert F)"
        return "in-plane velocity inflow coupling (Glauert G)"
    if kind == "flap":
        if own:
            return "sensor gain"
        if {equation, variable} == {"beta1c", "beta1s"}:
            return "sensor phasing (azimuth)"
        return "sensor cross-talk"
    if kind == "inflow":
        return "unmeasurable inflow term (no sensor sees inflow: the model lacks one)"
    return "sensor feedthrough of an input"


@dataclass(frozen=True)
class Term:
    """One tested entry: ``equation`` of ``block`` gains ``coefficient * variable``.

    ``statistic`` the score statistic (chi-square, 1 dof); ``p_value`` its tail
    probability; ``p_adjusted`` Holm's over the entries tested; ``sign`` of the
    one-step estimate ``coefficient`` (descriptor units: azimuth time, inputs in
    azimuth units; on the right-hand side of the equation); ``testable`` False
    where the entry cannot be told from the base's own parameters; ``gradient``
    ``dJ/dk`` of the cost (12) at ``k = 0`` (``S`` and the base's parameters held).
    """

    block: str
    equation: str
    variable: str
    statistic: float
    p_value: float
    p_adjusted: float
    sign: int
    coefficient: float
    group: str
    testable: bool = True
    gradient: float = 0.0

    def significant(self, alpha: float = ALPHA) -> bool:
        return self.testable and self.p_adjusted <= alpha

    def where(self) -> str:
        """``"the beta1s equation"``, ``"the recorded beta1c"``."""
        if self.block == "measurement":
            return f"the recorded {self.equation}"
        return f"the {self.equation} equation"

    def to_json(self, alpha: float = ALPHA) -> dict:
        return {"block": self.block, "equation": self.equation, "variable": self.variable,
                "statistic": float(self.statistic), "p_value": float(self.p_value),
                "p_adjusted": float(self.p_adjusted), "sign": int(self.sign),
                "coefficient": float(self.coefficient), "group": self.group,
                "testable": bool(self.testable), "gradient": float(self.gradient),
                "significant": bool(self.significant(alpha))}


@dataclass(frozen=True)
class MissingTerms:
    """The score map of a base fit: every tested entry, most significant first.

    ``rows`` as dicts (``equation, variable, statistic, p_value, sign, group`` and
    the rest of :meth:`Term.to_json`); ``significant`` those whose Holm-adjusted
    p-value is at most ``alpha``; ``equations`` and ``variables`` the axes of the
    map (:func:`inflowsim.report.terms.missing_terms_plot`).
    """

    structure: str
    terms: tuple
    alpha: float
    n_tested: int
    equations: tuple          # ((block, equation), ...)
    variables: tuple
    correction: str = "holm"

    @property
    def rows(self) -> tuple:
        return tuple(t.to_json(self.alpha) for t in self.terms)

    @property
    def significant(self) -> tuple:
        return tuple(t for t in self.terms if t.significant(self.alpha))

    def to_json(self) -> list:
        return list(self.rows)

    def grid(self) -> np.ndarray:
        """``-log10 p`` (unadjusted) per ``(equation, variable)``; NaN where the
        entry was not tested or not testable."""
        out = np.full((len(self.equations), len(self.variables)), np.nan)
        ri = {e: i for i, e in enumerate(self.equations)}
        ci = {v: j for j, v in enumerate(self.variables)}
        for t in self.terms:
            if t.testable:
                out[ri[(t.block, t.equation)], ci[t.variable]] = -np.log10(
                    max(t.p_value, 1e-300))
        return out

    def describe(self, limit: int = 3) -> list[str]:
        """Sentences for the text output: the significant terms (at most
        ``limit``), or that none is."""
        sig = self.significant
        if not sig:
            return [f"no single added term is significant (score test of {self.n_tested} "
                    f"entries, Holm-corrected at {self.alpha:g})"]
        out = []
        for t in sig[:limit]:
            out.append(f"the data want a term in {t.where()} proportional to {t.variable} "
                       f"(sign {'+' if t.sign > 0 else '-'}, score {t.statistic:.1f}, "
                       f"p = {t.p_adjusted:.2g} after Holm over {self.n_tested} entries): "
                       f"{'an' if t.group[0] in 'aeiou' else 'a'} {t.group} would give one")
        if len(sig) > limit:
            out.append(f"... and {len(sig) - limit} more significant entries")
        return out


def _entries(inputs):
    """``[(block, row, variable), ...]`` in map order."""
    states = FLAP + FLAP_RATE + INFLOW
    out = []
    for block, rows in (("flap", FLAP), ("inflow", INFLOW)):
        out += [(block, i, v) for i in range(3) for v in states + tuple(inputs)]
    out += [("measurement", i, v) for i in range(3) for v in FLAP + INFLOW + tuple(inputs)]
    return out


def _perturb(eq, block, i, variable, k):
    """``eq`` with ``k * variable`` added to the right-hand side of row ``i`` of
    ``block``'s equation."""
    kind = _KIND_OF[variable]
    if kind == "input":
        j = INPUTS.index(variable)
    else:
        j = {"flap": FLAP, "rate": FLAP_RATE, "inflow": INFLOW}[kind].index(variable)
    if block == "flap":
        # C beta' + D beta on the left: a right-hand term enters them negated
        name, sign = {"flap": ("d", -1), "rate": ("c", -1), "inflow": ("h_lambda", 1),
                      "input": ("h_u", 1)}[kind]
    else:
        name, sign = {"flap": ("p_beta", 1), "rate": ("p_dbeta", 1),
                      "inflow": ("p_lambda", 1), "input": ("p_u", 1)}[kind]
    m = np.array(getattr(eq, name), dtype=float)
    m[i, j] += sign * k
    return eq.with_(**{name: m})


def _predicted(model, sp, nu):
    y_u, y_nu, _ = flap_response(model, sp)
    return y_u + y_nu @ nu


def _feedthrough(model, sp, i, j):
    """``d Y_i / d D_ij``: input ``j``'s transform as flap channel ``i`` records it."""
    d = float(model.delays[i]) - float(model.input_delays[j])
    if d == 0:
        return sp.U[:, j]
    if sp.hold == "continuous":
        return _continuous_input(sp, d)[:, j]
    return np.exp(-2j * np.pi * sp.f_hz * d) * sp.U[:, j]


def missing_terms(records, fit, band_hz=DEFAULT_BAND, hold=None,
                  alpha: float = ALPHA) -> MissingTerms:
    """Score map of every single-entry addition at a base fit.

    Parameters
    ----------
    records : Record or sequence of Record
        The records ``fit`` was made on (same order).
    fit : FitResult
        The base fit (:func:`inflowsim.identify.identify`).
    band_hz : (float, float)
        The band the fit was made with [Hz] (snapped again to each record's grid).
    hold : str, optional
        The hold override the fit was made with.
    alpha : float
        Family-wise level of the Holm-corrected map.

    Returns
    -------
    MissingTerms
        Every entry, ranked by statistic; untestable ones last.
    """
    recs = _records(records)
    s = fit.structure
    # the in-plane inputs where every record has them: the entries a structure
    # without them cannot reach are the ones a hidden in-plane term would want
    inplane = s.uses_inplane or all(all(c in r.channels for c in INPUTS[N_BASE_INPUTS:])
                                    for r in recs)
    inputs = INPUTS if inplane else INPUTS[:N_BASE_INPUTS]
    n_in = len(inputs)
    spectra = _spectra(recs, s, band_hz, None, hold)
    if len(spectra) != len(fit.data) or any(
            sp.f_hz.shape != d.f_hz.shape or not np.allclose(sp.f_hz, d.f_hz)
            for sp, d in zip(spectra, fit.data)):
        raise InputError("missing terms: give the records, band and hold the base fit "
                         "was made with (its frequencies differ)")
    full = spectra if n_in == s.n_inputs else [
        record_spectra(r, inputs, band_hz, None, hold) for r in recs]
    prob = Problem(s, spectra, dict(fit.parameters), fixed=tuple(fit.fixed),
                   ties=tuple(fit.ties))
    theta = prob.theta0()
    st = _state(prob, theta, list(fit.S))
    if prob.free:
        jb = np.vstack(prob.jacobian(theta, st.weights, st.nus, st.bases, central=True))
    else:
        jb = np.zeros((sum(r.size for r in st.r), 0))
    r = np.concatenate(st.r)
    entries = _entries(inputs)
    je = np.empty((r.size, len(entries)))
    row0 = 0
    p = prob.params(theta)
    for sp, W, nu, Q, rr in zip(full, st.weights, st.nus, st.bases, st.r):
        k = sp.constants
        eq, meas = apply_effects(s, p, k)
        m0 = model_from_equations(s, p, eq, meas, k, n_inputs=n_in)
        blk = je[row0:row0 + rr.size]          # rows of je: filled in place
        for col, (block, i, v) in enumerate(entries):
            if block == "measurement":
                if _KIND_OF[v] == "input":
                    dy = np.zeros((sp.f_hz.size, 3), dtype=complex)
                    dy[:, i] = _feedthrough(m0, sp, i, INPUTS.index(v))
                else:
                    c = np.zeros_like(m0.c)
                    c[i, (FLAP + INFLOW).index(v)] = 1.0
                    dy = _predicted(replace(m0, c=c), sp, nu)
            else:
                mp = model_from_equations(s, p, _perturb(eq, block, i, v, STEP), meas, k,
                                          n_inputs=n_in)
                mm = model_from_equations(s, p, _perturb(eq, block, i, v, -STEP), meas, k,
                                          n_inputs=n_in)
                dy = (_predicted(mp, sp, nu) - _predicted(mm, sp, nu)) / (2 * STEP)
            blk[:, col] = -_stack(dy @ W.T)
        _minus_projection(blk, Q)       # the nuisance end states, as the estimator
        row0 += rr.size
    return _table(s, entries, je, jb, r, st, alpha, inputs)


#: Largest temporary of the projections [bytes]: a 2-hour record's 162 columns of
#: sensitivities are 76 MB; beyond this they are projected in place, in row blocks
#: (the same products, row by row); a normal record's as one product.
BLOCK_BYTES = 32 * 2 ** 20


def _minus_projection(x, Q):
    """``x - Q (Q^T x)`` written over ``x`` (returned); in row blocks when ``x``
    holds more than :data:`BLOCK_BYTES`."""
    c = Q.T @ x
    if x.nbytes <= BLOCK_BYTES:
        x -= Q @ c
        return x
    rows = max(1, BLOCK_BYTES // (8 * max(x.shape[1], 1)) // 4)
    for i in range(0, x.shape[0], rows):
        x[i:i + rows] -= Q[i:i + rows] @ c
    return x


def _table(s, entries, je, jb, r, st, alpha, inputs):
    # projection off the base's parameters (scaled SVD: undetermined directions
    # of the base are dropped, as the estimator's bounds do)
    if jb.shape[1]:
        scale = np.linalg.norm(jb, axis=0)
        scale[scale == 0] = 1.0
        u, sv, _ = np.linalg.svd(jb / scale, full_matrices=False)
        ub = u[:, sv > 1e-9 * max(sv.max(), 1e-300)]
    grad = 2.0 * (je.T @ r)
    raw = np.einsum("ij,ij->j", je, je)
    if jb.shape[1] and je.nbytes > BLOCK_BYTES:
        pe = _minus_projection(je, ub)   # in place: je is not needed after
    elif jb.shape[1]:
        pe = je - ub @ (ub.T @ je)
    else:
        pe = je
    n_data = r.size
    lost = (np.linalg.matrix_rank(jb) if jb.shape[1] else 0) + sum(Q.shape[1]
                                                                   for Q in st.bases)
    dof = n_data / max(n_data - lost, 1)
    num = pe.T @ r
    den = np.einsum("ij,ij->j", pe, pe)
    testable = (raw > 0) & (den > CONFOUNDED * raw)
    with np.errstate(divide="ignore", invalid="ignore"):
        stat = np.where(testable, 2.0 * num ** 2 / np.where(testable, den, 1.0) / dof, 0.0)
        coef = np.where(testable, -num / np.where(testable, den, 1.0), 0.0)
    pval = np.where(testable, chi2_sf(stat, 1), 1.0)
    padj = np.ones_like(pval)
    idx = np.flatnonzero(testable)
    m = idx.size
    if m:
        order = idx[np.argsort(pval[idx], kind="stable")]
        running = 0.0
        for rank, e in enumerate(order):
            running = max(running, min(1.0, (m - rank) * pval[e]))
            padj[e] = running
    rows = []
    for col, (block, i, v) in enumerate(entries):
        eq_name = (INFLOW if block == "inflow" else FLAP)[i]
        rows.append(Term(block, eq_name, v, float(stat[col]), float(pval[col]),
                         float(padj[col]), int(np.sign(coef[col]) or 1), float(coef[col]),
                         physics_group(block, eq_name, v), bool(testable[col]),
                         float(grad[col])))
    rows.sort(key=lambda t: (not t.testable, -t.statistic))
    eqs = tuple((b, n) for b in BLOCKS for n in (INFLOW if b == "inflow" else FLAP))
    variables = FLAP + FLAP_RATE + INFLOW + tuple(inputs)
    return MissingTerms(structure=s.name, terms=tuple(rows), alpha=float(alpha),
                        n_tested=int(m), equations=eqs, variables=variables)
