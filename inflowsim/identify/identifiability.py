"""What a record determines, before any candidate is judged (CIFER's measures).

For a fit, the information matrix ``M = 2 Re sum_w G^H S^-1 G`` (``model.md``
section 7) over *every* parameter of the structure, free or fixed, at the
estimates, gives:

- the **Cramer-Rao bound** ``sigma_i = sqrt((M_ee^-1)_ii)`` of each estimated
  parameter and its **insensitivity** ``1 / sqrt(M_ii)`` (the bound if every other
  parameter were known), each also as a percentage of the estimate (Tischler and
  Remple, *Aircraft and Rotorcraft System Identification*, 2nd ed., section 11.3:
  ``CR% <= 20`` and ``insensitivity% <= 10`` for a parameter worth keeping);
- the **flat directions**: eigenvectors of the scaled ``M`` whose eigenvalue is
  ``RANK_TOL`` of the largest or less, the combinations the record cannot show;
- for every parameter held at a stated value (by the user or because the record
  does not determine it), its own uncertainty carried into the others' bounds
  (the "consider" covariance ``M_ee^-1 + K P_f K^T``, ``K = M_ee^-1 M_ef``, ``P_f``
  the held values' variances from their plausible ranges), and which estimates
  are **conditional** on which held values;
- the bounds a **manoeuvre** would give together with this record (given as input
  histories, e.g. :func:`inflowsim.flighttest.advice.standard_manoeuvres`: a
  doublet or 3211 on each control flown on the project's virtual airframe): what
  would determine what this record cannot.

Nothing here refits: one Jacobian of the fit's structure per record, one per
manoeuvre.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..model.params import SPECS
from .estimator import fit_state, null_directions, weight_dof, weight_factors
from .problem import Problem
from .transform import DEFAULT_BAND, dft, record_spectra, transform_weights

#: CIFER's guidelines (Tischler and Remple, section 11.3): a parameter with a
#: Cramer-Rao bound above this percentage of its estimate is poorly determined...
CR_PERCENT_LIMIT = 20.0
#: ...and one whose insensitivity is above this percentage hardly moves the cost.
INSENSITIVITY_PERCENT_LIMIT = 10.0
#: A held value whose uncertainty adds this share or more to an estimate's variance
#: makes that estimate conditional on it.
CONDITIONAL_SHARE = 0.01


@dataclass(frozen=True)
class ParameterInfo:
    """What the record says of one parameter.

    ``sigma`` the Cramer-Rao bound (``None``: not determined); ``sigma_total`` with
    the held values' uncertainty carried; ``insensitivity`` ``1/sqrt(M_ii)`` (in the
    parameter's unit); ``held`` the parameter is not estimated (``held_at`` the
    value, ``held_why`` ``"user"`` or ``"undetermined"``, ``prior_sigma`` the
    uncertainty carried into the others' bounds); ``conditional_on`` the held
    parameters whose uncertainty moves this estimate.
    """

    name: str
    estimate: float
    sigma: float | None
    sigma_total: float | None
    insensitivity: float | None
    determined: bool
    held: bool
    held_at: float | None = None
    held_why: str | None = None
    prior_sigma: float | None = None
    conditional_on: tuple = ()
    #: ``((held name, d estimate / d held value), ...)``: how the estimate moves
    #: with each held value (``-K`` of the module docstring)
    held_gain: tuple = ()

    @property
    def cr_percent(self) -> float | None:
        return _percent(self.sigma, self.estimate)

    @property
    def insensitivity_percent(self) -> float | None:
        return _percent(self.insensitivity, self.estimate)

    @property
    def flags(self) -> tuple:
        """CIFER's guideline flags: ``"cr"`` and/or ``"insensitivity"``."""
        out = []
        if self.cr_percent is not None and self.cr_percent > CR_PERCENT_LIMIT:
            out.append("cr")
        if (self.insensitivity_percent is not None
                and self.insensitivity_percent > INSENSITIVITY_PERCENT_LIMIT):
            out.append("insensitivity")
        return tuple(out)

    def to_json(self) -> dict:
        return {"estimate": self.estimate, "sigma": self.sigma,
                "sigma_total": self.sigma_total, "determined": self.determined,
                "held": self.held, "held_at": self.held_at, "held_why": self.held_why,
                "prior_sigma": self.prior_sigma,
                "insensitivity": self.insensitivity, "cr_percent": self.cr_percent,
                "insensitivity_percent": self.insensitivity_percent,
                "flags": list(self.flags), "conditional_on": list(self.conditional_on),
                "held_gain": dict(self.held_gain)}


@dataclass(frozen=True)
class FlatDirection:
    """A combination of parameters the record cannot show: ``components``
    ``((name, weight), ...)`` (unit vector in scaled parameters, largest first)."""

    relative_eigenvalue: float
    components: tuple

    def to_json(self) -> dict:
        return {"relative_eigenvalue": self.relative_eigenvalue,
                "components": {n: w for n, w in self.components}}


@dataclass(frozen=True)
class ManoeuvreGain:
    """The bounds of ``parameters`` with a standard manoeuvre flown in addition to
    the record: ``sigma_after`` ``((name, sigma or None), ...)``."""

    manoeuvre: str
    sigma_after: tuple

    def to_json(self) -> dict:
        return {"manoeuvre": self.manoeuvre, "sigma_after": dict(self.sigma_after)}


@dataclass(frozen=True)
class Identifiability:
    """What one record (or several fitted together) determines of a structure."""

    structure: str
    parameters: tuple
    flat_directions: tuple
    quiet_inputs: tuple
    manoeuvres: tuple = ()

    def __getitem__(self, name) -> ParameterInfo:
        return next(p for p in self.parameters if p.name == name)

    @property
    def undetermined(self) -> tuple:
        """Names the record does not determine (held or without a bound)."""
        return tuple(p.name for p in self.parameters if not p.determined)

    @property
    def poorly_determined(self) -> tuple:
        return tuple(p.name for p in self.parameters if p.determined and p.flags)

    def best_manoeuvre(self, name):
        """``(manoeuvre, sigma)`` that bounds ``name`` best, or ``None``."""
        best = None
        for m in self.manoeuvres:
            s = dict(m.sigma_after).get(name)
            if s is not None and (best is None or s < best[1]):
                best = (m.manoeuvre, s)
        return best

    def to_json(self) -> dict:
        return {"structure": self.structure,
                "parameters": {p.name: p.to_json() for p in self.parameters},
                "undetermined": list(self.undetermined),
                "poorly_determined": list(self.poorly_determined),
                "flat_directions": [d.to_json() for d in self.flat_directions],
                "quiet_inputs": list(self.quiet_inputs),
                "manoeuvres": [m.to_json() for m in self.manoeuvres]}


def _percent(x, est):
    if x is None or est == 0 or not np.isfinite(x):
        return None
    return float(100.0 * x / abs(est))


def prior_sigma(name, constants) -> float | None:
    """A held value's own uncertainty: its plausible range (for the rotor's hub)
    taken as plus or minus two sigma."""
    spec = SPECS.get(name)
    rng = spec.plausible_range(constants.omega, constants.hub) if spec else None
    return None if rng is None else float((rng[1] - rng[0]) / 4.0)


def _information(prob, S):
    """The information, each record's discounted for its residual covariance
    estimated from its own bins (``sum_r M_r (nu_r - m) / (nu_r + m)``, the
    estimator's finite-sample bound, exact for one record: ``model.md`` section 7),
    and the degrees-of-freedom factor."""
    st = fit_state(prob, prob.theta0(), S)
    blocks = prob.jacobian(st.theta, st.weights, st.nus, st.bases, central=True)
    n_data = sum(b.shape[0] for b in blocks)
    lost = blocks[0].shape[1] + sum(Q.shape[1] for Q in st.bases)
    factors = weight_factors(weight_dof([b.shape[0] for b in blocks], S, lost))
    M = sum(2.0 * (c / g) * b.T @ b for b, (c, g) in zip(blocks, factors))
    return M, n_data / max(n_data - lost, 1)


def _determined(M):
    """Indices in no flat direction, and the flat directions ``(w_rel, vec)``."""
    dead, flat = null_directions(M)
    return [i for i in range(M.shape[0]) if i not in dead], flat


def _manoeuvre_spectra(sp, structure, cols):
    u = np.column_stack([np.asarray(cols.get(n, np.zeros(sp.n_samples)), dtype=float)
                         for n in structure.inputs])
    w = transform_weights(sp.n_samples, sp.hold)
    if not sp.on_grid:
        U = dft(u, sp.dt, sp.f_hz, sp.on_grid, w)
    else:
        # the inputs a manoeuvre leaves at zero (most: a collective doublet moves no
        # cyclic and no pitch or roll) transform to zero; on the record's grid a
        # column's transform is its own FFT: only the others are transformed (a
        # 2-hour record's columns take 0.1 s each), views of u's columns
        U = np.zeros((sp.f_hz.size, u.shape[1]), dtype=complex)
        for c in np.flatnonzero(np.any(u != 0, axis=0)):
            U[:, c] = dft(u[:, c:c + 1], sp.dt, sp.f_hz, True, w)[:, 0]
    return replace(sp, U=U, u_time=u, Z=np.zeros_like(sp.Z), z_time=np.zeros_like(sp.z_time))


def identifiability(records, fit, band_hz=DEFAULT_BAND, hold=None,
                    manoeuvres=None) -> Identifiability:
    """What ``records`` determine of ``fit``'s structure, at its estimates.

    Parameters
    ----------
    records : Record or list of Record
        The records ``fit`` was made from.
    fit : FitResult
    band_hz : (float, float)
        The band of the fit [Hz].
    hold : str, optional
        Intersample behaviour the fit assumed (default each record's own).
    manoeuvres : callable, optional
        ``(n_samples, dt, constants) -> [(label, {column: perturbation})]``:
        manoeuvres (input histories over the first record's length and step)
        whose added information is reported for the parameters the record leaves
        undetermined or poorly determined, e.g.
        :func:`inflowsim.flighttest.advice.standard_manoeuvres`; ``None``: none.
    """
    recs = records if isinstance(records, (list, tuple)) else [records]
    s = fit.structure
    spectra = [record_spectra(r, s.inputs, band_hz, hold=hold) for r in recs]
    ties = [tuple(t) for t in fit.ties]
    prob = Problem(s, spectra, fit.parameters, fixed=(), ties=ties)
    S = [np.asarray(x) for x in fit.S]
    M, dof = _information(prob, S)
    names = list(prob.free_names)
    groups = prob.free
    fixed = set(fit.fixed or ())
    free_ok = {n for n in fit.free if fit.sigma.get(n) is not None}
    est_idx = [i for i, g in enumerate(groups) if names[i] in free_ok]
    held_idx = [i for i in range(len(groups)) if i not in est_idx]
    ok, flat = _determined(M)
    k0 = spectra[0].constants
    P = np.array([(prior_sigma(groups[i][0], k0) or 0.0) ** 2 for i in held_idx])

    cov = np.full((len(names), len(names)), np.nan)
    cov_total = cov.copy()
    gain = np.zeros((len(est_idx), len(held_idx)))
    if est_idx:
        Mee = M[np.ix_(est_idx, est_idx)]
        inv = np.linalg.pinv(Mee, hermitian=True)
        cov[np.ix_(est_idx, est_idx)] = inv * dof
        if held_idx:
            gain = inv @ M[np.ix_(est_idx, held_idx)]
        # the held values' uncertainty is not the noise's: no degrees-of-freedom factor
        cov_total[np.ix_(est_idx, est_idx)] = inv * dof + gain @ np.diag(P) @ gain.T

    theta = prob.theta0()
    out = []
    for i, g in enumerate(groups):
        name = names[i]
        ins = float(np.sqrt(dof / M[i, i])) if M[i, i] > 0 else None
        if i in est_idx:
            j = est_idx.index(i)
            share = (gain[j] ** 2) * P / max(cov[i, i], 1e-300)
            cond = tuple(names[held_idx[q]] for q in np.argsort(-share)
                         if share[q] >= CONDITIONAL_SHARE)
            out.append(ParameterInfo(name, float(theta[i]), float(np.sqrt(cov[i, i])),
                                     float(np.sqrt(cov_total[i, i])), ins, True, False,
                                     conditional_on=cond,
                                     held_gain=tuple((names[h], float(-gain[j, q]))
                                                     for q, h in enumerate(held_idx))))
        else:
            determined = i in ok and g[0] in fixed
            out.append(ParameterInfo(name, float(theta[i]), None, None, ins, determined,
                                     held=True, held_at=float(theta[i]),
                                     held_why="user" if determined else "undetermined",
                                     prior_sigma=prior_sigma(g[0], k0)))
    quiet = tuple(n for j, n in enumerate(s.inputs)
                  if all(np.max(np.abs(sp.U[:, j])) == 0 for sp in spectra))
    flat_dirs = tuple(FlatDirection(w, tuple(
        (names[q], float(v[q])) for q in np.argsort(-np.abs(v)) if abs(v[q]) > 0.1))
        for w, v in flat)
    ident = Identifiability(s.name, tuple(out), flat_dirs, quiet)
    wanted = [i for i, p in enumerate(out) if not p.determined or p.flags]
    if not wanted or not manoeuvres:
        return ident
    gains = []
    sp0 = spectra[0]
    for label, cols in manoeuvres(sp0.n_samples, sp0.dt, sp0.constants):
        msp = _manoeuvre_spectra(sp0, s, cols)
        del cols               # its columns are in msp (a 2-hour record's: 47 MB)
        mp = Problem(s, [msp], fit.parameters, fixed=(), ties=ties)
        Mm, _ = _information(mp, [S[0]])
        # one manoeuvre's record-long arrays alive at a time (the next is made
        # while these names still hold this one's)
        del msp, mp
        Mt = M + Mm
        ok_t, _ = _determined(Mt)
        inv_t = np.linalg.pinv(Mt[np.ix_(ok_t, ok_t)], hermitian=True)
        after = []
        for i in wanted:
            sig = (float(np.sqrt(inv_t[ok_t.index(i), ok_t.index(i)] * dof))
                   if i in ok_t else None)
            after.append((names[i], sig))
        gains.append(ManoeuvreGain(label, tuple(after)))
    return replace(ident, manoeuvres=tuple(gains))


def describe(ident: Identifiability) -> list[str]:
    """Lines for a text report, rendered from the data."""
    lines = []
    for p in ident.parameters:
        if p.determined and not p.held and not p.flags and not p.conditional_on:
            continue
        if not p.determined:
            line = f"{p.name}: not determined by this record: held at {p.held_at:.4g}"
            if p.prior_sigma is not None:
                line += f" (uncertainty {p.prior_sigma:.2g} carried into the other bounds)"
            best = ident.best_manoeuvre(p.name)
            if best:
                line += f"; a {best[0]} would determine it (sigma {best[1]:.2g})"
        elif p.held:
            # fixed by the user, or a part of an effect the ladder has not added
            line = f"{p.name}: held fixed at {p.held_at:.4g} (not estimated)"
        else:
            line = f"{p.name} = {p.estimate:.4g} +- {p.sigma:.2g}"
            if p.flags:
                line += (f" (CR {p.cr_percent:.0f} %, insensitivity "
                         f"{p.insensitivity_percent:.0f} %: poorly determined)")
                best = ident.best_manoeuvre(p.name)
                if best and best[1] < 0.5 * p.sigma:
                    line += f"; a {best[0]} would bound it to {best[1]:.2g}"
            if p.conditional_on:
                line += (f"; conditional on the held {', '.join(p.conditional_on)} "
                         f"(bound with their uncertainty {p.sigma_total:.2g})")
        lines.append(line)
    if ident.quiet_inputs and lines:
        lines.append(f"the record does not move {', '.join(ident.quiet_inputs)} in the band")
    return lines


__all__ = ["CR_PERCENT_LIMIT", "INSENSITIVITY_PERCENT_LIMIT", "CONDITIONAL_SHARE",
           "ParameterInfo", "FlatDirection", "ManoeuvreGain", "Identifiability",
           "prior_sigma", "identifiability", "describe"]
