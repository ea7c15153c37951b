"""The diagnosis's acceptance rule: stated here, decided here, its settings an argument.

The rule, in five lines (``docs/workflow.md`` states the same five):

1. **Atoms.** Each catalogue effect the structure lacks is an atom, one per physical part
   where it has several (Glauert: ``F``, ``G``); what the record leaves flat is held, said.
2. **Lattice.** Base + one atom, and base + each pair of the ``width`` significant atoms
   of largest gain, each scored by one criterion: ``G = 2 (J_base - J) - k ln n``.
3. **Admissible.** Each atom is significant beside the others and beside any simpler atom
   it was paired with (level ``alpha``), and plausible for the rotor (``plausible_sigmas``).
4. **Accepted.** The admissible structure of largest ``G``, when ``G > schwarz_min`` and
   it takes at least ``material`` of the residual's excess over the noise (whiter).
5. **Added.** Its atom of largest gain beside the others is added; when none is, an added
   atom no longer significant beside the others is removed; the verdict says what is left.

What the terms mean, and why:

- ``J`` is the cost (12), the negative log-likelihood of the complex residuals with
  their error covariance estimated; ``k`` the parameters an atom adds, ``n`` the real
  numbers fitted (six a frequency bin).  ``G`` is Schwarz's criterion: ``G > 2`` is
  "positive evidence" (Kass and Raftery, JASA 90, 1995).  One criterion ranks every
  structure, single or pair, nested or not.
- An atom is fitted from the base estimates (so it nests the base).  Directions of it
  the record leaves flat (no information: ``c2`` on a single ``theta1s`` doublet) are
  held at neutral and said (``held``); an atom with no direction determined is not
  tried.  Holding a flat direction biases nothing else.
- *Significant beside the others*: the likelihood-ratio statistic of the structure
  against the same structure without that atom, chi-square with the atom's ``k``
  degrees of freedom (``model.md`` section 7); for a parameter whose neutral value is
  its range's edge (``flap_inertia = 0``) the 50:50 mixture of Self and Liang (1987).
  A single atom is tested against the base.  A flexible atom that a simpler one
  (fewer parameters) explains, not significant beside it while the simpler one is
  beside it, shows no physics of its own: no structure holding it is admissible
  (``explained_by``; Glauert's four in-plane gains mimic the blades' direct
  in-plane forcing, one gain ``k_mu``, on the nonlinear blade truth).
- *Plausible*: every estimate reaches its physical range within ``sigmas`` sigma, the
  range for the record's rotor (``# hub:``, :mod:`inflowsim.model.params`).
- *Material*: the structure removes at least ``material`` of the base residual's excess
  over the noise floor (its level deviance from white noise at the floor; on a record
  whose sensor noise is coloured, :data:`~inflowsim.diagnose.failures.COLOURED` times
  the floor or more, the residual's input-correlated excess, :mod:`.excess`), and the
  residual moves toward the floor (*whiter*): an effect significant only because the
  record is long, or that fits the noise, is not what the residual is made of.  Only
  the structure chosen by ``G`` is put to it: a weaker structure is never named
  because a stronger one explains a small share of a noisy excess.
- *Removed* (the ladder, :func:`inflowsim.diagnose.candidates.least_significant`): when
  nothing more is accepted, each atom the ladder added is tested beside all the others
  (the final structure against it without that atom); the least significant, if its
  p-value is ``alpha`` or more, is removed and not offered again, and the ladder goes
  on.  Forward steps judge an atom beside those added before it only; a collective
  doublet's ladder added a wake skew that the time constants and the azimuth bias,
  added after it, explain (p = 0.1 beside them).
- *Gain beside the others*: ``2 (J_without - J) - k_atom ln n``, what the atom adds to
  the structure without it.  One atom is added a rung, the one the accepted structure
  needs most; its partner is judged again on the next rung, beside it, where a
  simpler pair can still take what a flexible atom (Glauert's four in-plane gains)
  would mimic.

:func:`decide` applies the rule to a table of scored structures (:class:`Scored`, made
by :func:`inflowsim.diagnose.candidates.lattice`): the decision is data
(:class:`Decision`, with ``to_json``), and the text and reports are rendered from it.
A study varies a setting by passing ``Rule(...)``, never by patching a module.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..defaults import ALPHA
from ..errors import InputError
from .failures import COLOURED

def _statement(doc: str) -> tuple:
    """The numbered lines of the docstring's first list, each joined to one line."""
    out, cur = [], None
    for line in doc.split("What the terms mean")[0].splitlines():
        t = line.strip()
        if t[:2] in {f"{i}." for i in range(1, 10)}:
            cur = [t]
            out.append(cur)
        elif cur is not None and t:
            cur.append(t)
    return tuple(" ".join(c).replace("**", "").replace("``", "") for c in out)


#: The rule's five lines, from the module docstring (``docs/workflow.md`` and the
#: reports say the same; a test checks they agree).
STATEMENT = _statement(__doc__)


#: What the material test measures on a white-noise record (studies may ask the other).
WHITE_MEASURES = ("level", "deviance")
#: The tests of lines 3 and 4, in the order they are stated.
TESTS = ("determined", "significant", "own", "plausible", "parsimonious", "material",
         "whiter")


@dataclass(frozen=True)
class Rule:
    """Settings of the rule (module docstring, lines 1-5).

    Attributes
    ----------
    alpha : float
        Level of each likelihood-ratio test [-] (line 3).
    width : int
        Significant atoms of largest gain paired with each other (line 2).
    plausible_sigmas : float
        An estimate within this many sigma of its range is plausible [-] (line 3).
    schwarz_min : float
        Schwarz gain the accepted structure must exceed [-] (line 4).
    material : float
        Share of the base residual's excess over the noise the accepted structure
        must remove [-] (line 4).
    white_measure : {"level", "deviance"}
        The excess on white-noise records: the level deviance (default) or the
        per-bin deviance (kept for studies).
    coloured : float
        In-band sensor noise this many times the floor or more makes the excess the
        input-correlated one (0: every record).
    """

    alpha: float = ALPHA
    width: int = 4
    plausible_sigmas: float = 3.0
    schwarz_min: float = 2.0
    material: float = 0.10
    white_measure: str = "level"
    coloured: float = COLOURED

    def __post_init__(self):
        if not 0 < self.alpha < 1:
            raise InputError(f"alpha = {self.alpha:g}: give a level between 0 and 1")
        if int(self.width) != self.width or self.width < 0:
            raise InputError(f"width = {self.width!r}: give a whole number of atoms >= 0")
        if self.plausible_sigmas < 0 or not 0 <= self.material < 1:
            raise InputError("plausible_sigmas >= 0 and 0 <= material < 1, please")
        if self.white_measure not in WHITE_MEASURES:
            raise InputError(f"white_measure {self.white_measure!r}: choose "
                             f"{' or '.join(WHITE_MEASURES)}")

    def to_json(self) -> dict:
        return {"alpha": self.alpha, "width": self.width,
                "plausible_sigmas": self.plausible_sigmas,
                "schwarz_min": self.schwarz_min, "material": self.material,
                "white_measure": self.white_measure, "coloured": self.coloured}


#: The rule as the library applies it by default.
DEFAULT_RULE = Rule()


def rule_with(rule: Rule | None, alpha: float | None = None) -> Rule:
    """``rule`` (default :data:`DEFAULT_RULE`) with ``alpha`` where one is given."""
    from dataclasses import replace
    rule = rule or DEFAULT_RULE
    return rule if alpha is None or alpha == rule.alpha else replace(rule, alpha=alpha)


@dataclass(frozen=True)
class Scored:
    """One structure of the lattice: the base plus ``atoms``, fitted and scored.

    Attributes
    ----------
    atoms : tuple of str
        The atoms added (an effect's name, or ``"effect (p1, p2)"`` for one part).
    effects : tuple of str
        The catalogue effects they belong to.
    structure : str
        The structure fitted.
    dof : int
        Parameters added, ``k`` (held ones not counted).
    statistic : float
        ``2 (J_base - J)`` [-].
    schwarz_gain : float
        ``G = 2 (J_base - J) - k ln n`` [-].
    beside : tuple
        ``((atom, log10 p), ...)``: each atom's likelihood-ratio p-value beside the
        others (a single atom: against the base).
    implausible : tuple
        ``((parameter, estimate, sigma, low, high, why), ...)`` of estimates outside
        their range by more than the rule's sigmas (empty: plausible).
    held : tuple
        Parameters of the atoms held at neutral: directions the record leaves flat
        and, for a part, the effect's other parts.
    flat : tuple
        Of ``held``, the parameters held because the record leaves them flat.
    excess_before, excess_after : float or None
        The base residual's excess measure and this structure's (``None``: not
        measured); ``excess_noise`` what noise alone gives.
    measure : str
        What the excess measures (``"level deviance"``, ``"input-correlated excess"``,
        ``"deviance"``).
    error : str or None
        Why the structure could not be fitted or judged (then never admissible).
    fit : IdentResult
        Its fit (not in the JSON).
    """

    atoms: tuple
    effects: tuple
    structure: str
    dof: int
    statistic: float = 0.0
    schwarz_gain: float = -math.inf
    beside: tuple = ()
    #: ``((atom, gain beside the others), ...)``; a single atom: its own gain
    beside_gain: tuple = ()
    implausible: tuple = ()
    held: tuple = ()
    flat: tuple = ()
    #: ``((atom, simpler atom that explains it), ...)``, set by :func:`decide`
    explained_by: tuple = ()
    excess_before: float | None = None
    excess_after: float | None = None
    excess_noise: float | None = None
    measure: str = "level deviance"
    error: str | None = None
    fit: object = field(repr=False, compare=False, default=None)

    @property
    def share(self) -> float | None:
        """Share of the base residual's excess over noise this structure removes."""
        if self.excess_before is None or self.excess_after is None:
            return None
        room = self.excess_before - self.excess_noise
        return (self.excess_before - self.excess_after) / room if room > 0 else 0.0

    def failed(self, rule: Rule = DEFAULT_RULE) -> tuple:
        """The tests of lines 3-4 (:data:`TESTS`) this structure fails, as data."""
        if self.error is not None:
            return ("determined",)
        out = []
        lim = math.log10(rule.alpha)
        if any(lp >= lim for _, lp in self.beside) or not self.beside:
            out.append("significant")
        if self.explained_by:
            out.append("own")
        if self.implausible:
            out.append("plausible")
        if self.schwarz_gain <= rule.schwarz_min:
            out.append("parsimonious")
        share = self.share
        if share is not None and (self.excess_before <= self.excess_noise
                                  or share < rule.material):
            out.append("material")
        if self.excess_after is not None and self.excess_after >= self.excess_before:
            out.append("whiter")
        return tuple(out)

    def admissible(self, rule: Rule = DEFAULT_RULE) -> bool:
        """Line 3: fitted, each atom significant beside the others, plausible."""
        return not {"determined", "significant", "own", "plausible"} & set(
            self.failed(rule))

    @classmethod
    def from_json(cls, doc: dict) -> "Scored":
        """A row from its JSON (without its fit): a stored table can be decided
        again by :func:`decide` under other settings."""
        return cls(
            atoms=tuple(doc["atoms"]), effects=tuple(doc["effects"]),
            structure=doc["structure"], dof=int(doc["dof"]),
            statistic=float(doc["statistic"]), schwarz_gain=float(doc["schwarz_gain"]),
            beside=tuple((a, float(v)) for a, v in doc["log10_p_beside_others"].items()),
            beside_gain=tuple((a, float(v)) for a, v in doc["gain_beside_others"].items()),
            implausible=tuple((x["parameter"], x["estimate"], x["sigma"], x["low"],
                               x["high"], x["why"]) for x in doc["implausible"]),
            held=tuple(doc["held_at_neutral"]), flat=tuple(doc["not_determined"]),
            explained_by=tuple(doc.get("explained_by", {}).items()),
            excess_before=doc["excess_before"], excess_after=doc["excess_after"],
            excess_noise=doc["excess_of_noise"], measure=doc["measure"],
            error=doc.get("error"))

    def to_json(self, rule: Rule = DEFAULT_RULE) -> dict:
        return {"atoms": list(self.atoms), "effects": list(self.effects),
                "structure": self.structure, "dof": self.dof,
                "statistic": self.statistic, "schwarz_gain": self.schwarz_gain,
                "log10_p_beside_others": dict(self.beside),
                "gain_beside_others": dict(self.beside_gain),
                "implausible": [{"parameter": n, "estimate": e, "sigma": s, "low": lo,
                                 "high": hi, "why": w}
                                for n, e, s, lo, hi, w in self.implausible],
                "held_at_neutral": list(self.held), "not_determined": list(self.flat),
                "explained_by": dict(self.explained_by),
                "share_of_excess": self.share, "measure": self.measure,
                "excess_before": self.excess_before, "excess_after": self.excess_after,
                "excess_of_noise": self.excess_noise,
                "admissible": self.admissible(rule), "failed": list(self.failed(rule)),
                **({"error": self.error} if self.error else {})}


@dataclass(frozen=True)
class Decision:
    """The rule applied to a lattice: ``rows`` ranked (admissible first, by ``G``),
    ``best`` the index of the admissible row of largest ``G`` (``None``: none
    admissible), ``accepted`` whether it passed line 4."""

    rows: tuple
    best: int | None
    accepted: bool
    rule: Rule = DEFAULT_RULE

    @property
    def chosen(self) -> Scored | None:
        return None if self.best is None else self.rows[self.best]

    @property
    def added(self) -> tuple:
        """The atom the rule adds (line 5): the accepted structure's atom of largest
        gain beside the others, as a 1-tuple; ``()`` when nothing is accepted."""
        if not self.accepted:
            return ()
        c = self.chosen
        gains = dict(c.beside_gain) or {c.atoms[0]: c.schwarz_gain}
        return (max(c.atoms, key=lambda a: gains.get(a, -math.inf)),)

    @property
    def added_row(self) -> Scored | None:
        """The added atom's own row (fitted alone): the ladder's next rung."""
        if not self.accepted:
            return None
        return next((r for r in self.rows if r.atoms == self.added), None)

    @property
    def effects(self) -> tuple:
        """The effects of the accepted structure, the added atom's first; ``()``."""
        if not self.accepted:
            return ()
        first = self.added_row.effects if self.added_row is not None else ()
        return tuple(dict.fromkeys(first + self.chosen.effects))

    def to_json(self) -> dict:
        c = self.chosen
        return {"rule": self.rule.to_json(), "criterion": "schwarz_gain",
                "best": None if c is None else list(c.atoms),
                "accepted": self.accepted, "added": list(self.added),
                "best_failed": [] if c is None else
                [t for t in c.failed(self.rule) if t in ("parsimonious", "material",
                                                         "whiter")],
                "structures": [r.to_json(self.rule) for r in self.rows]}


def explained_pairs(rows, rule: Rule = DEFAULT_RULE) -> list:
    """``[(a, b), ...]``: atom ``a`` is explained by atom ``b`` where, in their pair's
    row, ``a`` is not significant beside ``b`` while ``b`` is beside ``a``."""
    lim = math.log10(rule.alpha)
    out = []
    for r in rows:
        if len(r.atoms) != 2 or r.error is not None:
            continue
        lp = dict(r.beside)
        for a, b in (r.atoms, r.atoms[::-1]):
            if lp[a] >= lim and lp[b] < lim:
                out.append((a, b))
    return out


def explain(rows, rule: Rule = DEFAULT_RULE) -> tuple:
    """The rows with ``explained_by`` set (line 3): an atom is explained by a simpler
    atom (fewer parameters, from their single rows) when, in their pair, it is not
    significant beside it while the simpler one is significant beside it."""
    from dataclasses import replace
    dof = {r.atoms[0]: r.dof for r in rows if len(r.atoms) == 1}
    by = {}
    for a, b in explained_pairs(rows, rule):
        if a in dof and b in dof and dof[b] < dof[a]:
            by.setdefault(a, b)
    return tuple(replace(r, explained_by=tuple((a, by[a]) for a in r.atoms if a in by))
                 for r in rows)


def rule_from_json(doc: dict) -> Rule:
    """The settings a decision's JSON records (``Decision.to_json()["rule"]``)."""
    return Rule(**doc)


def decide(rows, rule: Rule = DEFAULT_RULE) -> Decision:
    """Lines 3-5 of the rule on scored structures (the module docstring)."""
    rows = explain(rows, rule)

    def key(r):
        return (not r.admissible(rule), -r.schwarz_gain, r.dof)
    rows = tuple(sorted(rows, key=key))
    if not rows or not rows[0].admissible(rule):
        return Decision(rows, None, False, rule)
    failed = set(rows[0].failed(rule))
    return Decision(rows, 0, not failed & {"parsimonious", "material", "whiter"}, rule)


__all__ = ["STATEMENT", "WHITE_MEASURES", "TESTS", "Rule", "DEFAULT_RULE", "rule_with",
           "Scored", "Decision", "explained_pairs", "explain", "rule_from_json", "decide"]
