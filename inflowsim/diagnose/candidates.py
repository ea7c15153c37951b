"""The selection's decision seen per atom: the tables and the words (:class:`Candidate`,
:func:`describe`), rendered from a :class:`~inflowsim.diagnose.rule.Decision`'s rows.

The rule itself, its settings and its steps are :mod:`inflowsim.diagnose.rule`; this
module only renders what it decided.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..model.effects import CATALOGUE
from .rule import Decision, Scored, explained_pairs, ranked, row_order


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
        swap = {by if x == atom else x for x in row.atoms}
        g = next((r.schwarz_gain for r in decision.rows if set(r.atoms) == swap), None)
        where = "" if by in row.atoms or g is None else (
            f", and does as well in its place (Schwarz gain {g:.1f} against "
            f"{row.schwarz_gain:.1f})")
        words.append(f"{atom} explained by the simpler {by}: not significant beside "
                     f"it{where}")
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
        if {"material", "whiter"} & set(failed) and row.input_share is not None:
            seen = (f"{row.input_before:.1f} -> {row.input_after:.1f} "
                    f"({row.input_noise:.1f} for noise)")
            lim = row.input_level(rule)
            if rule.input_familywise and any(lp >= math.log10(lim) for _, lp in row.beside):
                words.append(f"its input-correlated excess ({seen}) is read only at p < "
                             f"{lim:.2g} ({rule.alpha:g} over the {row.tried} atoms "
                             f"tried)")
            else:
                words.append(f"nor its input-correlated excess, {seen}")
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
    by Schwarz gain (equal within the rule's ``tie``: its stated order,
    :func:`.rule.ranked`); failed fits last."""
    added = set(decision.added)
    lim = math.log10(decision.rule.alpha)
    beside_any = {}
    for a, b in explained_pairs(decision.rows, decision.rule):
        beside_any.setdefault(a, b)
    out, rows = [], []
    for r in decision.rows:
        if len(r.atoms) != 1:
            continue
        rows.append(r)
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
    # the added first, then by Schwarz gain, equal within the rule's tie by its
    # stated order (rule.ranked); failed fits last
    pairs = list(zip(out, rows))
    groups = [[t for t in pairs if t[0].error is None and t[0].accepted],
              [t for t in pairs if t[0].error is None and not t[0].accepted]]
    ok = [c for g in groups for c, _ in ranked(g, lambda t: t[0].schwarz_gain,
                                               lambda t: row_order(t[1]),
                                               decision.rule.tie)]
    return ok + [c for c, _ in pairs if c.error is not None]


__all__ = ["Candidate", "describe", "candidates_of"]
