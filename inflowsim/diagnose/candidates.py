"""The rule's lattice (:mod:`inflowsim.diagnose.rule`, lines 1-2): atoms, fitted alone
and in pairs, scored.

:func:`atoms` lists what may be added to a structure: each effect of the catalogue it
lacks (and may take: no alternative of it is in), one atom per physical part where
the effect has several (``Effect.parts``), and a part of an effect already in the
structure but held at neutral there (added on an earlier rung without it).
:func:`lattice` fits each atom alone from the base estimates (every candidate nests
the base: the start reproduces its fit), holding the directions the record leaves
flat (:func:`inflowsim.identify.estimator.null_directions`: no information, so
holding them biases nothing else), then each pair of the ``width`` significant atoms
of largest Schwarz gain, from the better of the two alone.  Every structure becomes a
row of data (:class:`~inflowsim.diagnose.rule.Scored`); the rule decides on the
rows (:func:`~inflowsim.diagnose.rule.decide`), and :class:`Candidate`, one per atom,
is the view the tables and text render.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from .tails import chi2_logsf, chi2_sf

from ..errors import InputError
from ..model.effects import CATALOGUE
from ..model.presets import theory_parameters
from ..model.structure import Structure
from ..progress import bar
from .rule import DEFAULT_RULE, Decision, Rule, Scored, explained_pairs


@dataclass(frozen=True)
class Atom:
    """One effect, or one physical part of one (``params`` its parameters)."""

    effect: str
    params: tuple

    @property
    def whole(self) -> bool:
        return set(self.params) == set(CATALOGUE[self.effect].parameters)

    @property
    def label(self) -> str:
        """``"glauert"`` whole, ``"glauert (k0p, kc, ks)"`` for one part."""
        return self.effect if self.whole else f"{self.effect} ({', '.join(self.params)})"


def applicable(structure: Structure, pool=None) -> list[str]:
    """Effects not in ``structure`` that may be added to it (``pool``, default the
    catalogue's offered effects)."""
    out = []
    for name in pool or [n for n, e in CATALOGUE.items() if e.offered]:
        if name not in CATALOGUE:
            from ..model.structure import unknown_effect
            raise InputError(unknown_effect(name))
        if name in structure.effects:
            continue
        if excluded(name, structure.effects):
            continue
        out.append(name)
    return out


def excluded(name: str, effects) -> bool:
    """``name`` may not join ``effects``: one of them names the other an alternative
    (either way round: an effect written later, or outside the package, may name a
    catalogue effect that does not name it back)."""
    alts = CATALOGUE[name].alternatives
    return any(e in alts or name in CATALOGUE[e].alternatives
               for e in effects if e in CATALOGUE)


def atoms(base_fit, pool=None) -> list[Atom]:
    """The atoms that may be added to ``base_fit``'s structure (rule, line 1): each
    applicable effect of ``pool``, split into its parts; and each part of an effect
    of the structure that the base holds whole at neutral values."""
    s = base_fit.structure
    held = set(base_fit.fixed or ())
    out = []
    for name in pool or [n for n, e in CATALOGUE.items() if e.offered]:
        if name not in CATALOGUE:
            from ..model.structure import unknown_effect
            raise InputError(unknown_effect(name))
        eff = CATALOGUE[name]
        parts = [tuple(p) for p in eff.parts] or [tuple(eff.parameters)]
        if name in s.effects:
            out += [Atom(name, p) for p in parts if len(parts) > 1 and set(p) <= held]
        elif not excluded(name, s.effects):
            out += [Atom(name, p) for p in parts]
    return out


def nested_start(base_fit, structure: Structure, constants) -> dict:
    """Start values for ``structure`` reproducing ``base_fit`` where it nests:
    base estimates, the new effects' neutral values, and a superseded ``tau``
    copied into ``tau0`` and ``tau_cs``."""
    start = theory_parameters(structure, constants)
    for e in structure.effects:
        start.update({n: v for n, v in CATALOGUE[e].neutral_values(constants).items()
                      if n in start})
    for n, v in base_fit.parameters.items():
        if n in start:
            start[n] = v
    if "tau" in base_fit.parameters and "tau0" in start and "tau0" not in base_fit.parameters:
        start["tau0"] = start["tau_cs"] = base_fit.parameters["tau"]
    return start


def lr_test(j_base, j_new, dof, boundary=0):
    """``(statistic, dof, log10 p)`` of ``2 (J_base - J_new)``: chi-square with ``dof``
    degrees of freedom, or for ``boundary`` parameters at the edge of their range
    the mixture ``2^-b sum_i C(b, i) chi2(dof - b + i)`` (Self and Liang)."""
    stat = max(0.0, 2.0 * (j_base - j_new))
    d = max(dof, 1)
    if not boundary:
        return stat, d, float(chi2_logsf(stat, d) / np.log(10))
    b = min(boundary, d)
    if stat == 0.0:
        return stat, d, 0.0
    from scipy import stats                   # the binomial weights only here
    p = sum(stats.binom.pmf(i, b, 0.5) * (chi2_sf(stat, d - b + i) if d - b + i > 0
                                         else 0.0) for i in range(b + 1))
    return stat, d, float(np.log10(max(p, 1e-300)))


def schwarz_gain(j_base, j_new, dof, n_freq) -> float:
    """``2 (J_base - J_new) - dof ln(n_data)``, ``n_data = 6 n_freq`` the real numbers
    fitted (three complex channels a bin): the criterion candidates rank by."""
    return float(2.0 * (j_base - j_new) - dof * np.log(6 * n_freq))




def _boundary(atom: Atom, held=()) -> int:
    return sum(1 for n in CATALOGUE[atom.effect].boundary
               if n in atom.params and n not in held)


def _implausible(atom: Atom, fit, constants, held, sigmas) -> tuple:
    """``((name, estimate, sigma, low, high, why), ...)`` of the atom's estimates
    outside their range by more than ``sigmas`` sigma."""
    ranges = CATALOGUE[atom.effect].plausible_ranges(constants)
    out = []
    for n in atom.params:
        if n in held or n not in ranges:
            continue
        est, sig = float(fit.parameters[n]), fit.sigma.get(n)
        lo, hi, why = ranges[n]
        if sig is not None and (est + sigmas * sig < lo or est - sigmas * sig > hi):
            out.append((n, est, float(sig), float(lo), float(hi), why))
    return tuple(out)


def _structure_for(base, names):
    s = base
    for e in names:
        if e not in s.effects:
            s = s.with_effect(e)
    return s


def _fit_with(records, base_fit, start_fit, add, band_hz, fit_fn):
    """Fit ``base + add`` (atoms) from ``start_fit``'s estimates (the new atoms at
    neutral), what neither frees held: ``(fit, held, flat)``, the flat directions of
    the atoms held at neutral, or :class:`InputError` when none is determined."""
    names = dict.fromkeys(a.effect for a in add)
    s = _structure_for(start_fit.structure, names)
    k = base_fit.constants[0]
    start = nested_start(start_fit, s, k)
    free = {n for a in add for n in a.params}
    # what the start held stays held (the base's, and a first atom's flat directions)
    fixed = {n: float(start_fit.parameters[n]) for n in (start_fit.fixed or ())
             if n in s.parameters and n not in free}
    # an effect's parts not added stay at neutral
    other = tuple(n for e in names for n in CATALOGUE[e].parameters
                  if n not in free and n not in start_fit.parameters)
    fixed.update({n: start[n] for n in other})
    fit = fit_fn(records, s, band_hz=band_hz, start=start, fixed=fixed or None)
    flat = tuple(n for n in free if fit.sigma.get(n) is None)
    if flat:
        for a in add:
            if all(n in flat for n in a.params):
                raise InputError(f"{a.label}: not determined by the record (no "
                                 "information in any of its directions)")
        fixed.update({n: start[n] for n in flat})
        fit = fit_fn(records, s, band_hz=band_hz, start=start, fixed=fixed)
    return fit, other + flat, flat


def _row(base_fit, add, fit, held, flat, beside, rule, beside_gain=None) -> Scored:
    dof = sum(len(a.params) for a in add) - len(flat)
    k = base_fit.constants[0]
    return Scored(
        atoms=tuple(a.label for a in add),
        effects=tuple(dict.fromkeys(a.effect for a in add)),
        structure=fit.structure.name, dof=dof,
        statistic=max(0.0, 2.0 * float(base_fit.cost - fit.cost)),
        schwarz_gain=schwarz_gain(base_fit.cost, fit.cost, dof, fit.n_freq),
        beside=beside,
        beside_gain=(beside_gain if beside_gain is not None else
                     ((add[0].label, schwarz_gain(base_fit.cost, fit.cost, dof,
                                                  fit.n_freq)),)),
        implausible=tuple(x for a in add for x in
                          _implausible(a, fit, k, held, rule.plausible_sigmas)),
        held=tuple(held), flat=tuple(flat), fit=fit)


def _single(records, base_fit, atom, band_hz, fit_fn, rule) -> Scored:
    try:
        fit, held, flat = _fit_with(records, base_fit, base_fit, (atom,), band_hz, fit_fn)
    except InputError as exc:
        s = _structure_for(base_fit.structure, (atom.effect,))
        return Scored((atom.label,), (atom.effect,), s.name, len(atom.params),
                      error=str(exc))
    dof = len(atom.params) - len(flat)
    lp = lr_test(base_fit.cost, fit.cost, dof, _boundary(atom, held))[2]
    return _row(base_fit, (atom,), fit, held, flat, ((atom.label, lp),), rule)


def _pair(records, base_fit, a, b, ra, rb, band_hz, fit_fn, rule) -> Scored | None:
    """``base + a + b`` from the better of the two alone; ``None`` where they cannot
    go together."""
    if excluded(a.effect, (b.effect,)):
        return None
    (x, rx), (y, ry) = sorted(((a, ra), (b, rb)), key=lambda t: t[1].fit.cost)
    try:
        fit, held, flat = _fit_with(records, base_fit, rx.fit, (y,), band_hz, fit_fn)
    except InputError:
        return None
    held = tuple(dict.fromkeys(tuple(n for n in rx.held if n not in y.params) + held))
    flat = tuple(dict.fromkeys(rx.flat + flat))
    # each atom beside the other: the pair against the other alone
    dy = len(y.params) - len([n for n in flat if n in y.params])
    dx = rx.dof
    beside = ((x.label, lr_test(ry.fit.cost, fit.cost, dx, _boundary(x, held))[2]),
              (y.label, lr_test(rx.fit.cost, fit.cost, dy, _boundary(y, held))[2]))
    ln_n = np.log(6 * fit.n_freq)
    gains = ((x.label, float(2 * (ry.fit.cost - fit.cost) - dx * ln_n)),
             (y.label, float(2 * (rx.fit.cost - fit.cost) - dy * ln_n)))
    order = sorted(((x, rx), (y, ry)), key=lambda t: -dict(gains)[t[0].label])
    add = tuple(t[0] for t in order)
    rank = [u.label for u in add]
    return _row(base_fit, add, fit, held, flat,
                tuple(sorted(beside, key=lambda t: rank.index(t[0]))), rule,
                tuple(sorted(gains, key=lambda t: rank.index(t[0]))))


def lattice(records, base_fit, band_hz, fit_fn, pool=None, judge=None,
            rule: Rule = DEFAULT_RULE, progress=None) -> tuple:
    """Lines 1-2 of the rule: every atom alone, then the pairs of the ``rule.width``
    significant atoms of largest gain; each a :class:`~.rule.Scored` row, measured by
    ``judge(fit)`` (the residual's excess, :func:`inflowsim.diagnose.search.diagnose`)
    where it is admissible."""
    found = []
    alone = atoms(base_fit, pool)
    name = base_fit.structure.name
    with bar(progress, len(alone), f"{name}: trying each effect", "fit") as b:
        for atom in alone:
            b.set_postfix_str(atom.label)
            found.append((atom, _single(records, base_fit, atom, band_hz, fit_fn, rule)))
            b.update()
    lim = math.log10(rule.alpha)
    top = sorted(((a, r) for a, r in found if r.error is None and r.beside[0][1] < lim),
                 key=lambda t: -t[1].schwarz_gain)[:rule.width]
    rows = [r for _, r in found]
    pairs = [(a, ra, b, rb) for i, (a, ra) in enumerate(top) for b, rb in top[i + 1:]]
    with bar(progress, len(pairs), f"{name}: trying pairs", "fit") as b:
        for a, ra, c, rc in pairs:
            b.set_postfix_str(f"{a.label} with {c.label}")
            r = _pair(records, base_fit, a, c, ra, rc, band_hz, fit_fn, rule)
            if r is not None:
                rows.append(r)
            b.update()
    if judge is None:
        return tuple(rows)
    base = judge(None)
    out = []
    for r in rows:
        if r.error is None and (len(r.atoms) == 1 or r.admissible(rule)):
            new = judge(r.fit)
            r = _measured(r, base, new)
        out.append(r)
    return tuple(out)


def _measured(row: Scored, base: dict, new: dict) -> Scored:
    return replace(row, excess_before=float(base["deviance"]),
                   excess_after=float(new["deviance"]),
                   excess_noise=float(base["white_deviance"]), measure=base["measure"])


# -- the view per atom ------------------------------------------------------------------
@dataclass(frozen=True)
class Candidate:
    """One atom as the tables show it: its fit alone, and what the decision made of it.

    ``accepted``: it is among the atoms the rule adds; ``reason`` is rendered from the
    rows (:func:`describe`); ``explained_by`` an atom beside which it is not
    significant while that one is beside it (from their pair's row).
    """

    effect: str
    atom: str
    structure: str
    cost_reduction: float
    statistic: float
    dof: int
    log10_p: float
    significant: bool
    physics: str
    added: dict                      # {name: (estimate, sigma)} of the effect's parameters
    fit: object = field(repr=False, compare=False, default=None)
    error: str | None = None
    schwarz_gain: float = 0.0
    plausible: bool = False
    share: float = 0.0
    whiteness_before: float = 0.0
    whiteness_after: float = 0.0
    accepted: bool = False
    reason: str = ""
    held: tuple = ()
    measure: str = "level deviance"
    explained_by: str | None = None
    failed: tuple = ()

    @property
    def whiter(self) -> bool:
        return self.whiteness_after < self.whiteness_before

    def to_json(self) -> dict:
        return {"effect": self.effect, "atom": self.atom,
                "cost_reduction": self.cost_reduction,
                "significant": self.significant, "accepted": self.accepted,
                "reason": self.reason, "failed": list(self.failed),
                "statistic": self.statistic, "dof": self.dof,
                "log10_p_value": self.log10_p, "schwarz_gain": self.schwarz_gain,
                "plausible": self.plausible, "share_of_excess": self.share,
                "held_at_neutral": list(self.held),
                "deviance_before": self.whiteness_before,
                "deviance_after": self.whiteness_after, "measure": self.measure,
                "explained_by": self.explained_by, "physics": self.physics,
                "structure": self.structure,
                "parameters": {n: {"estimate": e, "sigma": s} for n, (e, s) in self.added.items()},
                **({"error": self.error} if self.error else {})}


def describe(row: Scored, decision: Decision) -> str:
    """Why a row is, or is not, what the rule adds: words rendered from its data."""
    rule = decision.rule
    if row.error is not None:
        return row.error
    chosen = decision.chosen
    if decision.accepted and row == decision.added_row:
        via = "" if row == chosen else (
            f" (the accepted structure is {' + '.join(chosen.atoms)}; the rest is judged "
            "on the next rung, beside it)")
        return "accepted" + via + _held_words(row)
    if decision.accepted and row == chosen:
        return (f"accepted structure (Schwarz gain {row.schwarz_gain:.1f}); "
                f"{decision.added[0]} is added first, as it adds most beside the others")
    words = []
    lim = math.log10(rule.alpha)
    for atom, lp in row.beside:
        if lp >= lim:
            what = "not significant" if len(row.atoms) == 1 else \
                f"{atom} not significant beside the others"
            words.append(f"{what} (p = {10 ** lp:.2g} >= {rule.alpha:g})")
    for n, e, s, lo, hi, why in row.implausible:
        words.append(f"implausible: {n} = {e:.4g} +- {s:.2g} is outside [{lo:g}, {hi:g}]: "
                     f"{why}")
    for atom, by in row.explained_by:
        words.append(f"{atom} explained by the simpler {by}: not significant beside it")
    failed = row.failed(rule)
    if not words and chosen is not None and row != chosen and \
            not (decision.accepted and set(row.atoms) <= set(chosen.atoms)):
        words.append(f"admissible, but {' + '.join(chosen.atoms)} scores more (Schwarz "
                     f"gain {chosen.schwarz_gain:.1f} against {row.schwarz_gain:.1f})")
    if row == chosen:
        if "parsimonious" in failed:
            words.append(f"not worth its {row.dof} parameter(s): Schwarz gain "
                         f"{row.schwarz_gain:.1f} <= {rule.schwarz_min:g}")
        if "material" in failed:
            if row.excess_before <= row.excess_noise:
                words.append(f"the base residual has no excess over the noise "
                             f"({row.measure} {row.excess_before:.1f} <= "
                             f"{row.excess_noise:.1f} for noise): nothing to explain")
            else:
                words.append(f"explains {100 * row.share:.1f} % of the residual's excess "
                             f"({row.measure}; < {100 * rule.material:g} %)")
        if "whiter" in failed:
            words.append(f"does not move the residual toward the noise ({row.measure} "
                         f"{row.excess_before:.1f} -> {row.excess_after:.1f})")
    return "; ".join(words) + _held_words(row)


def _held_words(row: Scored) -> str:
    words = []
    if row.flat:
        words.append(f"{', '.join(row.flat)} not determined by the record")
    other = [n for n in row.held if n not in row.flat]
    if other:
        words.append(f"{', '.join(other)} another part of the effect, not added")
    return f" ({'; '.join(words)}: held at neutral)" if words else ""


def candidates_of(decision: Decision) -> list[Candidate]:
    """One :class:`Candidate` per atom (the single rows), the added ones first, then
    by Schwarz gain; failed fits last."""
    added = set(decision.added)
    lim = math.log10(decision.rule.alpha)
    beside_any = {}
    for a, b in explained_pairs(decision.rows, decision.rule):
        beside_any.setdefault(a, b)
    out = []
    for r in decision.rows:
        if len(r.atoms) != 1:
            continue
        eff = CATALOGUE[r.effects[0]]
        by = dict(r.explained_by).get(r.atoms[0]) or beside_any.get(r.atoms[0])
        fit = r.fit
        lp = r.beside[0][1] if r.beside else 0.0
        added_params = {} if fit is None else {
            n: (float(fit.parameters[n]), fit.sigma.get(n)) for n in eff.parameters
            if n in fit.parameters}
        share = r.share
        out.append(Candidate(
            effect=r.effects[0], atom=r.atoms[0], structure=r.structure,
            cost_reduction=0.0 if fit is None else r.statistic / 2.0,
            statistic=r.statistic, dof=r.dof, log10_p=lp,
            significant=bool(r.error is None and lp < lim), physics=eff.physics,
            added=added_params, fit=fit, error=r.error,
            schwarz_gain=r.schwarz_gain if fit is not None else 0.0,
            plausible=r.error is None and not r.implausible,
            share=0.0 if share is None else float(share),
            whiteness_before=r.excess_before or 0.0,
            whiteness_after=r.excess_after or 0.0,
            accepted=r.atoms[0] in added, reason=describe(r, decision),
            held=r.held, measure=r.measure, explained_by=by,
            failed=r.failed(decision.rule)))
    return sorted(out, key=lambda c: (c.error is not None, not c.accepted,
                                      -c.schwarz_gain if c.error is None else 0.0))


def offered_effects() -> list:
    """The catalogue's effects offered as candidates."""
    return [n for n, e in CATALOGUE.items() if e.offered]


def atom_of(label: str) -> Atom:
    """The :class:`Atom` of a label (``"glauert"``, ``"glauert (k0p, kc, ks)"``)."""
    if " (" in label:
        effect, rest = label.split(" (", 1)
        return Atom(effect, tuple(n.strip() for n in rest.rstrip(")").split(",")))
    return Atom(label, tuple(CATALOGUE[label].parameters))


def least_significant(records, fit, labels, band_hz, hold=None,
                      rule: Rule = DEFAULT_RULE):
    """``(atom, fit without it, log10 p)`` of the atom of ``labels`` (added to
    ``fit``'s structure on a ladder) least significant beside the others, where its
    p-value is ``rule.alpha`` or more; ``None`` when every one is significant."""
    from ..identify import identify
    worst = None
    held = set(fit.fixed or ())
    for label in dict.fromkeys(labels):
        atom = atom_of(label)
        if atom.effect not in fit.structure.effects:
            continue
        free = [n for n in atom.params if n not in held]
        if not free:
            continue
        k = fit.constants[0]
        neutral = CATALOGUE[atom.effect].neutral_values(k)
        rest_of_effect = [n for n in CATALOGUE[atom.effect].parameters
                          if n not in atom.params and n not in held]
        if rest_of_effect:           # a part: hold it at neutral, keep the effect
            s = fit.structure
            fixed = {n: float(fit.parameters[n]) for n in held}
            fixed.update({n: float(neutral[n]) for n in atom.params})
        else:
            s = fit.structure.without_effect(atom.effect)
            fixed = {n: float(fit.parameters[n]) for n in held if n in s.parameters}
        start = {n: float(v) for n, v in fit.parameters.items() if n in s.parameters}
        try:
            f = identify(records, s, band_hz=band_hz, start=start, fixed=fixed or None,
                         hold=hold)
        except InputError:
            continue
        lp = lr_test(f.cost, fit.cost, len(free), _boundary(atom, held))[2]
        if lp >= math.log10(rule.alpha) and (worst is None or lp > worst[2]):
            worst = (label, f, lp)
    return worst


__all__ = ["Atom", "applicable", "excluded", "atoms", "nested_start", "lr_test",
           "schwarz_gain", "lattice", "Candidate", "describe", "candidates_of",
           "offered_effects", "atom_of", "least_significant"]
