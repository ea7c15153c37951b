"""The selection: which effect the diagnosis adds, by one rule with one settings object.

The rule is the five steps of this module, in order (:data:`STEPS`): :func:`atoms`,
:func:`lattice`, :func:`admissible`, :func:`accepted` and :func:`added`.  Each step's
docstring opens with its line of the rule; :data:`STATEMENT` renders the five lines
from them (the reports print it).  Every number the decision uses is a field of
:class:`Rule`, passed as ``rule=`` to :func:`select`, :func:`decide`,
:func:`inflowsim.diagnose.diagnose` and :func:`inflowsim.diagnose.ladder` and read
from it by the measurements (:mod:`.failures`, :mod:`.excess`, :mod:`.lpm`): a study
varies a setting by passing ``Rule(...)``, never by patching a module.

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
  against the same structure without that atom, over the larger fit's ``kappa k``
  read as ``F(k, d)`` (:func:`lr_test`; ``k`` the atom's degrees of freedom,
  ``kappa`` and ``d`` for ``S`` estimated from the record's bins, ``model.md``
  section 7; ``Rule(calibrated=False)``: chi-square, which passes 1e-3 4.4 times as
  often as said on null records); for a
  parameter whose neutral value is its range's edge (``flap_inertia = 0``) the 50:50
  mixture of Self and Liang (1987).
  A single atom is tested against the base.  A flexible atom that a simpler one
  (fewer parameters) explains, not significant beside it while the simpler one is
  beside it, shows no physics of its own there: no structure holding it is
  admissible (``explained_by``; Glauert's four in-plane gains mimic the blades'
  direct in-plane forcing, one gain ``k_mu``, on the nonlinear blade truth) unless,
  in a structure without the simpler atom, the simpler atom in its place scores at
  least ``schwarz_min`` less (``G``): beside another atom the flexible one then
  shows what the simpler one cannot take (the pair test is made at the base, where
  a partner's part of the residual can hide it).
- *Paired*: the pairs are those of the ``width`` atoms of largest gain that pass
  ``alpha`` alone read as chi-square (:func:`screen`: a screen, looser than the
  calibrated reading, so that what only a pair makes significant is fitted) and, for
  each implausible one among them, the next plausible one.  An implausible
  atom takes no plausible one's place: alone it is never admissible and only a pair
  can make it plausible, so it is paired, and its place is given to the next
  plausible atom too (a collective-only record's lag coupling, significant at -0.03
  outside its range, held a place and the truth's azimuth bias and separate time
  constants were never fitted together; the ladder named a wake skew and a delay
  instead).  Pairing plausible atoms first instead would drop the implausible one a
  pair makes plausible (the separate time constants beside Glauert's ``F`` on a
  hidden-Glauert record).
- *Plausible*: every estimate reaches its physical range within ``sigmas`` sigma, the
  range for the record's rotor (``# hub:``, :mod:`inflowsim.model.params`).
- *Material*: the structure removes at least ``material`` of the base residual's excess
  over the noise, and the residual moves toward the noise (*whiter*): an effect
  significant only because the record is long, or that fits the noise, is not what
  the residual is made of.  The excess is seen two ways (:mod:`.excess`).  Its
  *level*: the level deviance from white noise at the floor, which sees an error
  spread over the band (the 2/rev flap raising ``beta1c``'s power 1.9 times) and, as
  a deviance, rises when a fit takes the residual below the floor.  Its
  *input-correlated part*: the residual's power in the span of the inputs'
  transforms times smooth functions of frequency, where a model error ``dH U`` lies
  whatever its band, over the residual's level outside that span.  On a white-noise
  record a structure passes both tests where either view passes both
  (``Rule.input_view``); on a record whose sensor noise is coloured (``Rule.coloured``
  times the floor or more) the floor says little and only the input-correlated part
  is seen.  The second view is taken only by a structure whose every atom is
  significant (at ``alpha``; at ``alpha`` over the atoms tried alone where
  ``Rule.input_familywise``, the guard the chi-square reading needs: a null record's
  delay, p = 1.6e-4 of nine atoms so read and 1.2e-3 calibrated, its level at the
  noise, its input-correlated excess 46.4 -> 40.9 against 37.8 for noise, was named
  without it).  The level alone refused
  the lead-lag on three hingeless records (its likelihood-ratio statistic 20-54,
  p 6e-6 and less, eight atoms tried): there the base residual's level is at the
  floor in every channel, 0.72-1.30 of it, and a level over 41 bins scatters by 16 %
  a channel, as much as the lag moves it; fitting the lag lowers it further and the
  level deviance rose.  Its input-correlated part, 43-70 against 31 for noise, the
  lag takes to 25-41.  Neither view passes a structure that fits the noise (the base
  at the noise in both, or a share below ``material``), nor one significant because
  the record is long while the residual is made of something else (a small share
  of both).  Only the structure chosen by ``G`` is put to it: a weaker structure is
  never named because a stronger one explains a small share of a noisy excess.
- *Removed* (the ladder, :func:`least_significant`): when nothing more is accepted,
  each atom the ladder added is tested beside all the others (the final structure
  against it without that atom); the least significant, if its p-value is ``alpha``
  or more, is removed and not offered again, and the ladder goes on.  Forward steps
  judge an atom beside those added before it only; a collective doublet's ladder
  added a wake skew that the time constants and the azimuth bias, added after it,
  explain (p = 0.1 beside them).
- *Ties*: every ranking (structures by ``G``, atoms by gain beside the others, the
  start of a pair by cost, removals by p-value) takes scores within ``tie`` of the
  best as equal, settled by fewer parameters fitted, then fewer offered (the more
  specific claim: Glauert's four in-plane gains where the hub-velocity coupling's six
  fit the same), then the catalogue's order (:func:`ranked`).  Rounding decides
  nothing: two interchangeable atoms fit the same to 1e-12, which side is ahead by
  rounding changed with the Jacobian's difference step.
- *Gain beside the others*: ``2 (J_without - J) - k_atom ln n``, what the atom adds to
  the structure without it.  One atom is added a rung, the one the accepted structure
  needs most; its partner is judged again on the next rung, beside it, where a
  simpler pair can still take what a flexible atom (Glauert's four in-plane gains)
  would mimic.

- *Indistinguishable* (said, not deciding): the added atom's own fit against each
  other admissible single atom's, a non-nested comparison by Vuong's test (Vuong
  1989, Econometrica 57): the per-bin differences of the two fits' costs ``J``, their
  mean over its standard error, ``z``; the record cannot tell them apart where
  ``|z| < z_(1 - alpha/2)`` (:func:`vuong_z`, :attr:`Decision.vuong`).  The
  servos' first-order part and a pure delay are one phase lag inside a band below
  the servos' frequency: on a coloured-noise record the delay is named and only this
  says that the servos fit as well.

The decision is data (:class:`Decision`, with ``to_json``; a stored table is decided
again by :func:`decide`), and the text and reports are rendered from it
(:mod:`.candidates`).  This module imports none of the diagnosis's measurements: the
fits (``fit_fn``) and the excess measure (``judge``, :func:`.excess.judge`) are
arguments.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace

import numpy as np

from ..defaults import ALPHA, MAX_STEPS
from ..errors import InputError
from ..model.effects import CATALOGUE
from ..model.presets import theory_parameters
from ..model.structure import Structure
from ..progress import bar
from .tails import binom_pmf, chi2_logsf, chi2_sf, f_logsf, f_sf


# -- the settings ---------------------------------------------------------------------
#: What the material test measures on a white-noise record (studies may ask the other).
WHITE_MEASURES = ("level", "deviance")
#: The tests of lines 3 and 4, in the order they are stated.
TESTS = ("determined", "significant", "own", "plausible", "parsimonious", "material",
         "whiter")


@dataclass(frozen=True)
class Rule:
    """Every setting of the selection (the five steps of :mod:`inflowsim.diagnose.rule`)
    and of the measurements it decides on.

    Attributes
    ----------
    alpha : float
        Level of each likelihood-ratio test [-] (line 3), and of the residual tests
        the failures, the verdict and the conditional marking make.  Indistinguishable:
        the added atom and an admissible rival of its step, Vuong's ``|z|`` below the
        normal quantile ``1 - alpha/2`` (two-sided; :func:`vuong_z`).
    width : int
        Significant atoms of largest gain paired with each other, and one more
        plausible atom for each implausible one among them (line 2).
    plausible_sigmas : float
        An estimate within this many sigma of its range is plausible [-] (line 3);
        the verdict's stand-ins use the same.
    stand_in_share : float
        Named effects that together remove less than this share of the excess
        over the floor are stand-ins (the verdict, line 5) [-].
    schwarz_min : float
        Schwarz gain the accepted structure must exceed [-] (line 4).
    material : float
        Share of the base residual's excess over the noise the accepted structure
        must remove [-] (line 4).
    white_measure : {"level", "deviance"}
        The excess on white-noise records: the level deviance (default) or the
        per-bin deviance (kept for studies).
    input_view : bool
        On a white-noise record the excess is also seen in its input-correlated
        part (:mod:`.excess`): a structure whose atoms are each significant and
        that takes at least ``material`` of that part and lowers it passes line 4's
        two tests though the level deviance does not fall; ``False``: the level
        alone.  The level
        resolves an error spread over the band (the 2/rev flap raising
        ``beta1c``'s power 1.9 times); on the hingeless rotor's lag records
        (``bench/rotor-physics.md``) the lag's statistic is 20-54 while the base
        residual's level is 0.72-1.30 of the floor in every channel of the three
        it refused, and its input-correlated excess 43-70 against 31 for noise,
        which the lag takes to 25-41.
    input_familywise : bool
        The second view (``input_view``) asks each atom to be significant at
        ``alpha`` over the atoms tried alone (Bonferroni); ``False`` (default): at
        ``alpha``, as every other test.  The guard the chi-square reading
        (``calibrated`` false) needs: so read, a null record's delay is p 1.6e-4
        of nine atoms and its input-correlated excess takes it; read calibrated it
        is 1.2e-3, not significant.  On the 576 null and 312 hidden records of
        ``bench/rotor-physics.md`` read calibrated, the two settings differ on two
        records: the 2/rev flap hidden on the hingeless rotor (64 Hz white, p
        1.6e-4 and 2.0e-4 of 14 atoms), named at ``alpha`` only.
    calibrated : bool
        Read every likelihood-ratio statistic that decides (lines 3 to 5) for ``S``
        estimated from the record's own bins (the fit's ``lr``: over ``kappa k`` as
        ``F(k, d)``, ``model.md`` section 7); ``False``: as chi-square, which on
        null records passes 1e-2 2.4 times and 1e-3 4.4 times as often as it says
        (``bench/studies/lr-calibration.md``).  Line 2's screen (:func:`screen`)
        reads chi-square either way.  A stored table's p-values are those it was
        fitted with: :func:`decide` does not change the reading.
    coloured : float
        In-band sensor noise this many times the floor or more makes the excess the
        input-correlated one (0: every record) [-].  Over the 136 white-noise
        records of ``bench/detection.py`` the ratio is 0.57-1.68; a 2 Hz low-pass
        in the data system puts it at 29-830 on its 128 coloured null records.
    tie : float
        Scores (``G``, gains beside the others) this close are equal [-] (lines 2-5,
        :func:`ranked`).  The estimator stops when a step lowers the cost by at most
        ``1e-7 n_f`` (``n_f`` the fit's frequency bins; ``_lm`` in
        :mod:`inflowsim.identify.estimator`); converging faster than halving, the
        rest of the descent is below that last step, so each ``J`` lies within
        ``1e-7 n_f`` above its minimum and a difference of two scores, ``2 (J_a -
        J_b)``, is known to ``2e-7 n_f``.  ``2e-3`` is that for ``n_f = 1e4``, a
        2-hour record in the default band (1.35 Hz wide, ``1/T`` apart;
        ``bench/long.md``); on the README's 27 s record (37 bins) it leaves 270
        times the bound to searches that crawl.  A thousand times below
        ``schwarz_min``: no evidence either way.
    max_steps : int
        Rungs the ladder adds at most, and atoms it removes at most (line 5) [-].
    max_lag : int
        Lags [bins] of the residual's correlation across frequency (the structure
        tests of :mod:`.failures`).
    floor_over_band : float
        The noise floor is measured from this many times the band's upper edge [-] ...
    floor_min_hz : float
        ... and from this frequency at least [Hz] ...
    nyquist_share : float
        ... to this share of the Nyquist frequency [-] (also where the in-band noise
        estimate ends, :mod:`.lpm`) ...
    floor_min_bins : int
        ... where it holds this many transform bins at least [-].
    floor_subbands : int
        Sub-bands of the floor band: the floor is the median of their levels, so
        rotor harmonics in a few of them do not raise it [-].
    lpm_span : float
        The in-band noise's trend (:mod:`.lpm`) is fitted from the band's lower edge
        to this many times its upper edge [-].
    degrees : int
        Legendre polynomials per input (degrees 0 .. ``degrees - 1``) of the smooth
        response error the input-correlated excess measures (:mod:`.excess`) [-].
    """

    alpha: float = ALPHA
    width: int = 4
    plausible_sigmas: float = 3.0
    stand_in_share: float = 0.5
    schwarz_min: float = 2.0
    material: float = 0.10
    white_measure: str = "level"
    input_view: bool = True
    input_familywise: bool = False
    calibrated: bool = True
    coloured: float = 3.0
    tie: float = 2e-3
    max_steps: int = MAX_STEPS
    max_lag: int = 6
    floor_over_band: float = 5.0
    floor_min_hz: float = 5.0
    nyquist_share: float = 0.8
    floor_min_bins: int = 20
    floor_subbands: int = 8
    lpm_span: float = 4.0
    degrees: int = 3

    def __post_init__(self):
        if not 0 < self.alpha < 1:
            raise InputError(f"alpha = {self.alpha:g}: give a level between 0 and 1")
        for name in ("width", "max_steps"):
            v = getattr(self, name)
            if int(v) != v or v < 0:
                raise InputError(f"{name} = {v!r}: give a whole number >= 0")
        for name in ("max_lag", "floor_min_bins", "floor_subbands", "degrees"):
            v = getattr(self, name)
            if int(v) != v or v < 1:
                raise InputError(f"{name} = {v!r}: give a whole number >= 1")
        if self.plausible_sigmas < 0 or not 0 <= self.material < 1:
            raise InputError("plausible_sigmas >= 0 and 0 <= material < 1, please")
        if not self.tie >= 0:
            raise InputError(f"tie = {self.tie!r}: give a score difference >= 0")
        if not 0 < self.nyquist_share <= 1 or self.lpm_span < 1:
            raise InputError("0 < nyquist_share <= 1 and lpm_span >= 1, please")
        for name in ("input_view", "input_familywise", "calibrated"):
            if not isinstance(getattr(self, name), bool):
                raise InputError(f"{name} = {getattr(self, name)!r}: give true or false")
        if self.white_measure not in WHITE_MEASURES:
            raise InputError(f"white_measure {self.white_measure!r}: choose "
                             f"{' or '.join(WHITE_MEASURES)}")

    def to_json(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}


#: The rule as the library applies it by default.
DEFAULT_RULE = Rule()

#: Keyword arguments (and command-line options: ``--alpha``, ``--max-steps``) that
#: set one field of the rule where given, beside ``rule=``: name -> field.
LEGACY = {"alpha": "alpha", "max_steps": "max_steps"}


def rule_with(rule: Rule | None = None, **given) -> Rule:
    """``rule`` (default :data:`DEFAULT_RULE`) with the fields :data:`LEGACY` names
    set where a value is given.

    Parameters
    ----------
    rule : Rule, optional
        The settings (default :data:`DEFAULT_RULE`).
    **given
        ``alpha`` [-], ``max_steps`` [-]: ``None`` keeps the rule's.
    """
    unknown = sorted(set(given) - set(LEGACY))
    if unknown:
        raise TypeError(f"rule_with: no setting {', '.join(unknown)}")
    rule = rule or DEFAULT_RULE
    changes = {LEGACY[k]: v for k, v in given.items()
               if v is not None and v != getattr(rule, LEGACY[k])}
    return replace(rule, **changes) if changes else rule


def rule_from_json(doc: dict) -> Rule:
    """The settings a decision's JSON records (``Decision.to_json()["rule"]``; the
    fields a stored one lacks take their defaults)."""
    return Rule(**doc)


# -- the table the steps fill -----------------------------------------------------------
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
    input_before, input_after, input_noise : float or None
        The same three of the input-correlated excess where it is a second view
        of a white-noise record's excess (:attr:`Rule.input_view`; ``None``: not
        measured).
    measure : str
        What the excess measures (``"level deviance"``, ``"input-correlated excess"``,
        ``"deviance"``).
    error : str or None
        Why the structure could not be fitted or judged (then never admissible).
    fit : IdentResult
        Its fit (not in the JSON).
    bins : tuple of float
        Its cost ``J`` per frequency bin, all records' bins in turn, where given
        (not in the JSON); else :meth:`costs_per_bin` takes them from ``fit`` when
        Vuong's test compares it with a rival.
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
    #: ``((atom, simpler atom that explains it), ...)``, set by :func:`admissible`
    explained_by: tuple = ()
    excess_before: float | None = None
    excess_after: float | None = None
    excess_noise: float | None = None
    measure: str = "level deviance"
    #: the input-correlated excess of the base residual, this structure's and
    #: noise's, where it is line 4's second view (a white-noise record; ``None``:
    #: not measured)
    input_before: float | None = None
    input_after: float | None = None
    input_noise: float | None = None
    #: atoms fitted alone on its lattice (set by :func:`admissible`; 0: not counted)
    tried: int = field(compare=False, default=0)
    error: str | None = None
    fit: object = field(repr=False, compare=False, default=None)
    #: the fit's cost ``J`` per frequency bin where given (not in the JSON)
    bins: tuple = field(repr=False, compare=False, default=())

    def costs_per_bin(self) -> tuple:
        """Its cost ``J`` per frequency bin: :attr:`bins`, else :func:`bin_costs` of
        its fit (computed where compared, not kept: on a 2-hour record each row's
        would hold some 10^4 numbers); ``()`` without either (a stored table's)."""
        return self.bins or bin_costs(self.fit)

    @property
    def share(self) -> float | None:
        """Share of the base residual's excess over noise this structure removes."""
        if self.excess_before is None or self.excess_after is None:
            return None
        room = self.excess_before - self.excess_noise
        return (self.excess_before - self.excess_after) / room if room > 0 else 0.0

    @property
    def input_share(self) -> float | None:
        """Share of the base residual's input-correlated excess over noise this
        structure removes, where measured as the second view."""
        if self.input_before is None or self.input_after is None:
            return None
        room = self.input_before - self.input_noise
        return (self.input_before - self.input_after) / room if room > 0 else 0.0

    def takes_input(self, rule: Rule = DEFAULT_RULE) -> bool:
        """The second view passes line 4's two tests: each atom is significant at
        :meth:`input_level` (``rule.alpha``; over the atoms tried, :attr:`tried`,
        where ``rule.input_familywise``), the base
        residual's input-correlated excess is above noise's, this structure removes
        at least ``rule.material`` of it, and lowers it (never where
        ``rule.input_view`` is false: a stored table decided again without the
        second view)."""
        share = self.input_share
        lim = math.log10(self.input_level(rule))
        return (rule.input_view and share is not None and bool(self.beside)
                and all(lp < lim for _, lp in self.beside)
                and self.input_before > self.input_noise
                and share >= rule.material and self.input_after < self.input_before)

    def input_level(self, rule: Rule = DEFAULT_RULE) -> float:
        """The level each atom's p-value must be below for the second view [-]."""
        return rule.alpha / max(self.tried, 1) if rule.input_familywise else rule.alpha

    def failed(self, rule: Rule = DEFAULT_RULE) -> tuple:
        """The tests of lines 3-4 (:data:`TESTS`) this structure fails, as data.
        ``material`` and ``whiter`` are those of the excess (:attr:`measure`),
        passed both where the second view passes them (:meth:`takes_input`)."""
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
        if self.takes_input(rule):
            return tuple(out)
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
            **{f"input_{k}": (doc.get("input_correlated") or {}).get(j)
               for k, j in (("before", "excess_before"), ("after", "excess_after"),
                            ("noise", "excess_of_noise"))},
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
                "input_correlated": None if self.input_before is None else {
                    "atoms_tried": self.tried,
                    "excess_before": self.input_before,
                    "excess_after": self.input_after,
                    "excess_of_noise": self.input_noise,
                    "share_of_excess": self.input_share},
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
    #: ``((atom, z), ...)``: Vuong's z of the added atom's fit against each other
    #: admissible single atom's (positive: the added one fits better), largest
    #: ``|z|`` last; ``()`` where nothing is added or the rows keep no per-bin costs
    vuong: tuple = ()

    @property
    def indistinguishable(self) -> tuple:
        """``((atom, z), ...)`` of :attr:`vuong` the record cannot tell from the
        added atom: ``|z|`` below the normal quantile at ``1 - alpha / 2``."""
        crit = vuong_critical(self.rule.alpha)
        return tuple((a, z) for a, z in self.vuong if abs(z) < crit)

    @property
    def chosen(self) -> Scored | None:
        return None if self.best is None else self.rows[self.best]

    @property
    def added(self) -> tuple:
        """The atom the rule adds (line 5, :func:`added`), as a 1-tuple; ``()``."""
        return added(self)

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
                "vuong": [{"atom": a, "vuong_z": z,
                           "indistinguishable": abs(z) < vuong_critical(self.rule.alpha)}
                          for a, z in self.vuong],
                "indistinguishable_from": [a for a, _ in self.indistinguishable],
                "structures": [r.to_json(self.rule) for r in self.rows]}


# -- 1. Atoms ---------------------------------------------------------------------------
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
    """**Atoms.** Each catalogue effect the structure lacks is an atom, one per physical part
    where it has several (Glauert: ``F``, ``G``); what the record leaves flat is held, said.

    The atoms of ``base_fit``'s structure: each applicable effect of ``pool``
    (:func:`applicable`), split into its parts (``Effect.parts``; only the first
    where a later part acts through it, ``Effect.parts_in_order``); and each part of
    an effect of the structure that the base holds whole at neutral values (added on
    an earlier rung without it).  What the record leaves flat is held when the atom
    is fitted (:func:`lattice`).

    Parameters
    ----------
    base_fit : FitResult
        The base structure's fit.
    pool : list of str, optional
        Candidate effects (default the catalogue's offered ones).
    """
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
            # a later part acting only through an earlier one waits for it
            out += [Atom(name, p) for p in (parts[:1] if eff.parts_in_order else parts)]
    return out


# -- 2. Lattice -------------------------------------------------------------------------
def lattice(records, base_fit, band_hz, fit_fn, pool=None, judge=None,
            rule: Rule = DEFAULT_RULE, progress=None) -> tuple:
    """**Lattice.** Base + one atom, and base + each pair of the ``width`` atoms of
    largest gain passing ``alpha`` alone as chi-square and, for each implausible one
    among them (only a pair can make it plausible), the next plausible one, each
    scored by one criterion: ``G = 2 (J_base - J) - k ln n``.

    Every atom of :func:`atoms` is fitted alone from the base estimates (every
    structure nests the base: the start reproduces its fit), holding the directions
    the record leaves flat (:func:`inflowsim.identify.estimator.null_directions`: no
    information, so holding them biases nothing else), then each pair of the
    ``rule.width`` atoms of largest gain passing :func:`screen` and, for each
    implausible one among them, the next plausible one (:func:`paired`), from the
    better of the two alone.  Each structure is a :class:`Scored` row; where it is
    admissible (a single atom: always) ``judge(fit)`` measures its residual's excess
    for line 4.

    Parameters
    ----------
    records : list of Record
        The records the fits are made on.
    base_fit : FitResult
        The base structure's fit.
    band_hz : (float, float)
        Analysis band [Hz].
    fit_fn : callable
        ``fit_fn(records, structure, band_hz=, start=, fixed=)`` -> FitResult.
    pool : list of str, optional
        Candidate effects (default the catalogue's offered ones).
    judge : callable, optional
        ``judge(fit)`` -> ``{"deviance", "white_deviance", "measure"}`` (``judge(None)``:
        the base's), :func:`inflowsim.diagnose.excess.judge`; ``None``: not measured.
    rule : Rule
        The settings.
    progress : callable, optional
        Progress (:mod:`inflowsim.progress`): a bar per lattice.
    """
    found = []
    alone = atoms(base_fit, pool)
    name = base_fit.structure.name
    with bar(progress, len(alone), f"{name}: trying each effect", "fit") as b:
        for atom in alone:
            b.set_postfix_str(atom.label)
            found.append((atom, _single(records, base_fit, atom, band_hz, fit_fn, rule)))
            b.update()
    top = paired(found, rule)
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


def paired(found, rule: Rule = DEFAULT_RULE) -> list:
    """Line 2's atoms to pair: ``[(atom, row), ...]`` of the single rows (``found``,
    ``(atom, Scored)`` pairs) passing :func:`screen` at ``rule.alpha``, by gain: the
    ``rule.width`` of largest gain and, for each implausible one among them, the
    next plausible one.

    An implausible atom takes no plausible one's place: alone it is never admissible
    and only a pair can make it plausible, so it is paired, and the place it holds is
    given to the next plausible atom too.  (A collective-only record's ``glauert``
    rung: the lag's coupling, significant at -0.03 outside its range, held the
    fourth place and the truth's ``azimuth-bias + separate-time-constants`` was never
    fitted; the ladder named a wake skew and a delay instead.)  Every pair of the
    ``width`` atoms of largest gain is still made: pairing plausible atoms first
    would drop the implausible one a pair makes plausible (the separate time
    constants, ``tau_cs`` far out alone, beside Glauert's ``F`` on a hidden-Glauert
    record's ``azimuth-bias`` rung).

    Parameters
    ----------
    found : sequence of (Atom, Scored)
        Each atom and its single row.
    rule : Rule
        The settings.
    """
    lim = math.log10(rule.alpha)
    def best_first(pairs):
        return ranked(pairs, lambda t: t[1].schwarz_gain, lambda t: row_order(t[1]),
                      rule.tie)
    top = best_first((a, r) for a, r in found if r.error is None and screen(r) < lim)
    out = top[:rule.width]
    more = sum(1 for _, r in out if r.implausible)
    out += [(a, r) for a, r in top[rule.width:] if not r.implausible][:more]
    return best_first(out)


def screen(row: Scored) -> float:
    """Line 2's screen of a single row: ``log10 p`` of its statistic against the base
    read as chi-square (the Self and Liang mixture on a boundary), whatever
    ``Rule.calibrated``.

    The screen only chooses which pairs are fitted; every test that decides (lines 3
    and 5) reads the statistic as the rule says.  Read as chi-square it passes more
    than the calibrated reading (4.4 times ``alpha`` at 1e-3 on null records), as a
    screen should: read calibrated, a collective-only record's separate time
    constants (p 1.7e-4 as chi-square, 1.4e-3 calibrated) were never paired with the
    truth's azimuth bias (the pair's ``G`` 462) and the ladder named a wake skew and a
    delay instead.  With ``calibrated`` false it is the row's own p-value.
    """
    label = row.atoms[0]
    b = (_boundary(atom_of(label), row.held) if label.partition(" (")[0] in CATALOGUE
         else 0)
    return lr_test(row.statistic / 2.0, 0.0, row.dof, b)[2]


def _measured(row: Scored, base: dict, new: dict) -> Scored:
    second = {} if "input" not in base else dict(
        input_before=float(base["input"]), input_after=float(new["input"]),
        input_noise=float(base["input_noise"]))
    return replace(row, excess_before=float(base["deviance"]),
                   excess_after=float(new["deviance"]),
                   excess_noise=float(base["white_deviance"]), measure=base["measure"],
                   **second)


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


def lr_test(j_base, j_new, dof, boundary=0, calibration=None):
    """``(statistic, dof, log10 p)`` of ``2 (J_base - J_new)``, read with the larger
    fit's ``calibration = (kappa, d)`` (:attr:`~inflowsim.identify.FitResult.lr`):
    ``statistic / (kappa dof)`` as ``F(dof, d)``, or for ``boundary`` parameters at
    the edge of their range the mixture ``2^-b sum_i C(b, i) F(dof - b + i, d)``
    (Self and Liang); ``None`` or ``d`` infinite: chi-square, ``kappa`` 1
    (``model.md`` section 7)."""
    stat = max(0.0, 2.0 * (j_base - j_new))
    d = max(dof, 1)
    kappa, dd = (1.0, math.inf) if calibration is None else calibration
    x = stat / kappa

    def tail(k):
        if not math.isfinite(dd):
            return chi2_sf(x, k)
        return f_sf(x / k, k, dd)

    if not boundary:
        if not math.isfinite(dd):
            return stat, d, float(chi2_logsf(x, d) / np.log(10))
        return stat, d, float(f_logsf(x / d, d, dd) / np.log(10))
    b = min(boundary, d)
    if stat == 0.0:
        return stat, d, 0.0
    p = sum(binom_pmf(i, b, 0.5) * (tail(d - b + i) if d - b + i > 0 else 0.0)
            for i in range(b + 1))
    return stat, d, float(np.log10(max(p, 1e-300)))


def _lr(fit, rule):
    """How the rule reads a likelihood ratio against ``fit``: ``None`` (chi-square)
    unless ``rule.calibrated``, then the fit's calibration (chi-square for a fit
    without one, a study's own ``fit_fn``)."""
    return getattr(fit, "lr", None) if rule.calibrated else None


def schwarz_gain(j_base, j_new, dof, n_freq) -> float:
    """``2 (J_base - J_new) - dof ln(n_data)``, ``n_data = 6 n_freq`` the real numbers
    fitted (three complex channels a bin): the criterion candidates rank by."""
    return float(2.0 * (j_base - j_new) - dof * np.log(6 * n_freq))


# -- ties -------------------------------------------------------------------------------
def ranked(items, score, order, tie) -> list:
    """``items`` best first, ties settled by ``order``, not by rounding: of the items
    left, the next is the first by ``order`` of those whose ``score`` is within
    ``tie`` of the largest left.

    Every ranking of the rule uses it (the structures by ``G``, a structure's atoms by
    gain beside the others, the atoms to pair, the start of a pair, the removal):
    scores within the fits' precision (``Rule.tie``) are equal, so which of two
    interchangeable atoms is ahead by 1e-12 decides nothing.

    Parameters
    ----------
    items : iterable
        What is ranked.
    score : callable
        ``score(item)`` -> float, larger better (``-inf`` last).
    order : callable
        ``order(item)`` -> sort key, smaller first: the stated order among equals
        (:func:`row_order`, :func:`atom_order`).
    tie : float
        Scores this close are equal (in the scores' units).
    """
    left = list(items)
    scores = [float(score(x)) for x in left]
    out = []
    while left:
        top = max(scores)
        near = [i for i, v in enumerate(scores) if v >= top - tie or v == top]
        i = min(near, key=lambda j: order(left[j]))
        out.append(left.pop(i))
        scores.pop(i)
    return out


def _place(label: str) -> tuple:
    """An atom's place in the catalogue: its effect's position (effects outside it
    after), then its part's."""
    effect, _, rest = label.partition(" (")
    names = list(CATALOGUE)
    if effect not in names:
        return (len(names), effect, 0)
    parts = [tuple(p) for p in CATALOGUE[effect].parts]
    params = tuple(n.strip() for n in rest.rstrip(")").split(",")) if rest else ()
    return (names.index(effect), "", parts.index(params) if params in parts else 0)


def _offered(label: str) -> int:
    """The parameters an atom offers (held ones too)."""
    effect, _, rest = label.partition(" (")
    if rest:
        return len(rest.split(","))
    return len(CATALOGUE[effect].parameters) if effect in CATALOGUE else 0


def row_order(row: Scored) -> tuple:
    """Among structures of equal score: fewer parameters fitted (``dof``), then fewer
    offered (held ones too: the more specific claim), then the catalogue's order of
    their atoms (:data:`CATALOGUE`'s, the paper's effects first)."""
    return (row.dof, sum(_offered(a) for a in row.atoms),
            tuple(sorted(_place(a) for a in row.atoms)), row.atoms)


def atom_order(label: str, flat=()) -> tuple:
    """Among atoms of equal gain: fewer parameters fitted (those in ``flat`` not),
    then fewer offered, then the catalogue's order."""
    n = _offered(label)
    params = atom_of(label).params if label.partition(" (")[0] in CATALOGUE else ()
    return (n - sum(1 for p in params if p in flat), n, _place(label), label)




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
    free = dict.fromkeys(n for a in add for n in a.params)
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
    lp = lr_test(base_fit.cost, fit.cost, dof, _boundary(atom, held), _lr(fit, rule))[2]
    return _row(base_fit, (atom,), fit, held, flat, ((atom.label, lp),), rule)


def _pair(records, base_fit, a, b, ra, rb, band_hz, fit_fn, rule) -> Scored | None:
    """``base + a + b`` from the better of the two alone; ``None`` where they cannot
    go together."""
    if excluded(a.effect, (b.effect,)):
        return None
    # the better alone by cost (in G's units, 2 J), a tie by the stated order
    (x, rx), (y, ry) = ranked(((a, ra), (b, rb)), lambda t: -2.0 * t[1].fit.cost,
                              lambda t: row_order(t[1]), rule.tie)
    try:
        fit, held, flat = _fit_with(records, base_fit, rx.fit, (y,), band_hz, fit_fn)
    except InputError:
        return None
    held = tuple(dict.fromkeys(tuple(n for n in rx.held if n not in y.params) + held))
    flat = tuple(dict.fromkeys(rx.flat + flat))
    # each atom beside the other: the pair against the other alone
    dy = len(y.params) - len([n for n in flat if n in y.params])
    dx = rx.dof
    cal = _lr(fit, rule)
    beside = ((x.label, lr_test(ry.fit.cost, fit.cost, dx, _boundary(x, held), cal)[2]),
              (y.label, lr_test(rx.fit.cost, fit.cost, dy, _boundary(y, held), cal)[2]))
    ln_n = np.log(6 * fit.n_freq)
    gains = ((x.label, float(2 * (ry.fit.cost - fit.cost) - dx * ln_n)),
             (y.label, float(2 * (rx.fit.cost - fit.cost) - dy * ln_n)))
    order = ranked(((x, rx), (y, ry)), lambda t: dict(gains)[t[0].label],
                   lambda t: atom_order(t[0].label, flat), rule.tie)
    add = tuple(t[0] for t in order)
    rank = [u.label for u in add]
    return _row(base_fit, add, fit, held, flat,
                tuple(sorted(beside, key=lambda t: rank.index(t[0]))), rule,
                tuple(sorted(gains, key=lambda t: rank.index(t[0]))))


# -- 3. Admissible ----------------------------------------------------------------------
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


def admissible(rows, rule: Rule = DEFAULT_RULE) -> tuple:
    """**Admissible.** Each atom is significant beside the others and beside any simpler atom
    it was paired with (level ``alpha``) unless, in place of it, that atom scores
    ``schwarz_min`` less, and plausible for the rotor (``plausible_sigmas``).

    The rows with ``explained_by`` set: an atom is explained by a simpler atom (fewer
    parameters, from their single rows) when, in their pair, it is not significant
    beside it while the simpler one is significant beside it.  The explanation is
    judged where the atom stands: in a structure without the simpler atom, it holds
    unless the lattice's structure with the simpler atom in its place scores at
    least ``schwarz_min`` less (``G``): then the atom shows physics of its own
    beside its partner, which the simpler one does not take.  (A collective
    doublet's Glauert rung: the separate time constants were explained by the wake
    distortion in their pair, G 97, yet beside the azimuth bias they scored G 462
    against the wake distortion's 281 there; held out, the ladder named a wake skew
    and a delay that leads in their place.)  Where the lattice lacks that structure,
    the explanation holds.  Which rows are then admissible is
    :meth:`Scored.admissible` (the tests of :data:`TESTS` it fails,
    :meth:`Scored.failed`).

    Parameters
    ----------
    rows : sequence of Scored
        The lattice's rows.
    rule : Rule
        The settings.
    """
    dof = {r.atoms[0]: r.dof for r in rows if len(r.atoms) == 1}
    by = {}
    for a, b in explained_pairs(rows, rule):
        if a in dof and b in dof and dof[b] < dof[a] and b not in by.get(a, ()):
            by.setdefault(a, []).append(b)
    gain = {frozenset(r.atoms): r.schwarz_gain for r in rows if r.error is None}

    def explains(r, a, b):
        """``b`` explains ``a`` in ``r``: their pair, or ``b`` in ``a``'s place
        scoring within ``schwarz_min`` of ``r`` (or not in the lattice)."""
        if b in r.atoms:
            return True
        g = gain.get(frozenset(b if x == a else x for x in r.atoms))
        return g is None or r.schwarz_gain - g <= rule.schwarz_min

    def explained(r):
        out = []
        for a in r.atoms:
            b = next((b for b in by.get(a, ()) if explains(r, a, b)), None)
            if b is not None:
                out.append((a, b))
        return tuple(out)
    tried = sum(1 for r in rows if len(r.atoms) == 1 and r.error is None)
    return tuple(replace(r, explained_by=explained(r), tried=tried) for r in rows)


# -- 4. Accepted ------------------------------------------------------------------------
def accepted(rows, rule: Rule = DEFAULT_RULE) -> Decision:
    """**Accepted.** The admissible structure of largest ``G``, when ``G > schwarz_min`` and
    it takes at least ``material`` of the residual's excess over the noise, in its level
    or, each atom significant at ``alpha`` over the atoms tried, in its input-correlated
    part, and lowers it (whiter).  Scores within ``tie`` are equal: fewer parameters
    first, then the catalogue's order.

    The rows ranked (admissible first, by ``G``, equal within ``tie`` settled by
    :func:`row_order`, :func:`ranked`), the first ``best`` where it is admissible,
    accepted where it fails none of line 4's tests.

    Parameters
    ----------
    rows : sequence of Scored
        The rows as :func:`admissible` left them.
    rule : Rule
        The settings.
    """
    def best_first(rows):
        return ranked(rows, lambda r: r.schwarz_gain, row_order, rule.tie)
    rows = tuple(best_first(r for r in rows if r.admissible(rule))
                 + best_first(r for r in rows if not r.admissible(rule)))
    if not rows or not rows[0].admissible(rule):
        return Decision(rows, None, False, rule)
    failed = set(rows[0].failed(rule))
    d = Decision(rows, 0, not failed & {"parsimonious", "material", "whiter"}, rule)
    return replace(d, vuong=vuong_of(d))


def vuong_of(decision: Decision) -> tuple:
    """``((atom, z), ...)``: the added atom's own fit (its single row) against each
    other admissible single atom of the same step, by Vuong's test (:func:`vuong_z`
    of their per-bin costs; positive: the added atom fits better), ``|z|`` ascending
    (ties by the rows' order).  ``()`` where nothing is added, or the rows keep no
    per-bin costs (a stored table's: :meth:`Scored.from_json`).

    Parameters
    ----------
    decision : Decision
        What :func:`accepted` decided (before the comparison).
    """
    own = decision.added_row
    mine = own.costs_per_bin() if own is not None else ()
    if not mine:
        return ()
    out = []
    for r in decision.rows:
        if (len(r.atoms) == 1 and r is not own and r.atoms != own.atoms
                and r.admissible(decision.rule)):
            theirs = r.costs_per_bin()
            if len(theirs) == len(mine):
                out.append((r.atoms[0], vuong_z(mine, theirs)))
    return tuple(sorted(out, key=lambda t: abs(t[1])))


def bin_costs(fit) -> tuple:
    """A fit's cost ``J`` (12) per frequency bin: ``eps_k^H S^-1 eps_k + ln|S|``
    with ``eps_k`` the bin's complex residual (end effects eliminated) and ``S`` its
    record's residual covariance; their sum is the fit's ``J`` (to 1e-12 on a 27-bin
    virtual record).  ``()`` for a fit without its records' data.

    Parameters
    ----------
    fit : FitResult
        The fit (``data``: each record's ``Z``, ``Y`` [rad s] and ``S`` [rad^2 s^2]).
    """
    out = []
    for d in getattr(fit, "data", None) or ():
        eps = np.asarray(d.Z) - np.asarray(d.Y)
        S = np.asarray(d.S)
        q = np.real(np.einsum("ki,ij,kj->k", eps.conj(), np.linalg.inv(S), eps))
        out.append(q + float(np.log(np.real(np.linalg.det(S)))))
    return tuple(float(x) for x in np.concatenate(out)) if out else ()


def vuong_z(costs_a, costs_b) -> float:
    """Vuong's statistic for two non-nested fits of the same bins (Vuong 1989,
    Econometrica 57, section 5): ``d_k = J_b,k - J_a,k`` the per-bin log-likelihood
    ratio of ``a`` over ``b`` (costs are negative log-likelihoods), ``z = sqrt(n)
    mean(d) / std(d)`` [-]; positive: ``a`` fits better.  ``0`` where the fits are
    equal in every bin; ``+-inf`` where they differ by the same amount in every bin.

    Parameters
    ----------
    costs_a, costs_b : sequence of float
        The two fits' costs per bin [-], the same bins in the same order.
    """
    a, b = np.asarray(costs_a, float), np.asarray(costs_b, float)
    if a.shape != b.shape or a.ndim != 1 or a.size == 0:
        raise InputError(f"vuong_z: {a.size} bins against {b.size}: give the same "
                         "bins, one or more")
    d = b - a
    m = float(d.mean())
    sd = float(np.sqrt(max(float(np.mean(d * d)) - m * m, 0.0)))
    scale = float(np.abs(d).max())
    if sd <= 1e-12 * scale or scale == 0.0:
        return 0.0 if abs(m) <= 1e-12 * max(scale, 1e-300) else math.copysign(math.inf, m)
    return math.sqrt(d.size) * m / sd


def vuong_critical(alpha: float) -> float:
    """The two-sided normal quantile ``z_(1 - alpha/2)`` [-] (3.29 at 1e-3)."""
    from statistics import NormalDist
    return NormalDist().inv_cdf(1.0 - alpha / 2.0)


# -- 5. Added ---------------------------------------------------------------------------
def added(decision: Decision) -> tuple:
    """**Added.** Its atom of largest gain beside the others is added; when none is, an added
    atom no longer significant beside the others is removed; the verdict says what is left.

    The accepted structure's atom of largest gain beside the others, as a 1-tuple
    (``()`` when nothing is accepted); the ladder adds it, its partner judged again
    on the next rung beside it.  The removal is :func:`least_significant`, the
    verdict :mod:`inflowsim.diagnose.verdict`.

    Parameters
    ----------
    decision : Decision
        What :func:`accepted` decided.
    """
    if not decision.accepted:
        return ()
    c = decision.chosen
    gains = dict(c.beside_gain) or {c.atoms[0]: c.schwarz_gain}
    return tuple(ranked(c.atoms, lambda a: gains.get(a, -math.inf),
                        lambda a: atom_order(a, c.flat), decision.rule.tie)[:1])


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
    """Line 5's removal: ``(atom, fit without it, log10 p)`` of the atom of ``labels``
    (added to ``fit``'s structure on a ladder) least significant beside the others,
    where its p-value is ``rule.alpha`` or more; ``None`` when every one is
    significant.  p-values equal within what ``rule.tie`` in the statistic moves
    them are equal (:func:`ranked`): the atom with more parameters, then the
    catalogue's later, is removed.

    Parameters
    ----------
    records : list of Record
        The records.
    fit : FitResult
        The final structure's fit.
    labels : sequence of str
        The atoms the ladder added.
    band_hz : (float, float)
        Analysis band [Hz].
    hold : {"continuous", "zoh", "foh"}, optional
        Intersample behaviour of the records' inputs (default each record's own).
    rule : Rule
        The settings.
    """
    from ..identify import identify
    found = []
    held = set(fit.fixed or ())
    cal = _lr(fit, rule)
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
        b = _boundary(atom, held)
        lp = lr_test(f.cost, fit.cost, len(free), b, cal)[2]
        if lp >= math.log10(rule.alpha):
            # what the statistic's precision (tie) moves log10 p by
            moved = abs(lr_test(f.cost - rule.tie / 2, fit.cost, len(free), b, cal)[2] - lp)
            found.append((label, f, lp, moved))
    if not found:
        return None
    tie = max(t[3] for t in found)
    # among equals the one the stated order puts last goes (the simpler stays)
    later = sorted(range(len(found)), key=lambda i: atom_order(found[i][0], held))
    i = ranked(range(len(found)), lambda i: found[i][2], lambda i: -later.index(i),
               tie)[0]
    return found[i][:3]


# -- the steps together ---------------------------------------------------------------
def decide(rows, rule: Rule = DEFAULT_RULE) -> Decision:
    """Lines 3-5 on scored structures (a lattice's, or a stored table's rows,
    :meth:`Scored.from_json`): :func:`accepted` of :func:`admissible`.

    Parameters
    ----------
    rows : sequence of Scored
        The rows.
    rule : Rule
        The settings.
    """
    return accepted(admissible(rows, rule), rule)


def select(records, base_fit, band_hz, fit_fn, pool=None, judge=None,
           rule: Rule = DEFAULT_RULE, progress=None) -> Decision:
    """The rule, its five steps in order, on ``base_fit``: what to add to its structure.

    Parameters
    ----------
    records, base_fit, band_hz, fit_fn, pool, judge, rule, progress
        :func:`lattice`'s (lines 1 and 2), which takes them; ``rule`` also decides
        (lines 3 to 5).
    """
    rows = lattice(records, base_fit, band_hz, fit_fn, pool, judge, rule,     # 1, 2
                   progress)
    return accepted(admissible(rows, rule), rule)                              # 3, 4, 5


#: The rule's five steps, in order.
STEPS = (atoms, lattice, admissible, accepted, added)


def _line(step) -> str:
    """A step's line of the rule: its docstring's first paragraph on one line."""
    first = step.__doc__.strip().split("\n\n")[0]
    return " ".join(first.split()).replace("**", "").replace("``", "")


#: The rule's five lines, rendered from the steps' docstrings.
STATEMENT = tuple(f"{i}. {_line(s)}" for i, s in enumerate(STEPS, 1))


__all__ = ["WHITE_MEASURES", "TESTS", "Rule", "DEFAULT_RULE", "LEGACY", "rule_with",
           "rule_from_json", "Scored", "Decision", "Atom", "applicable", "excluded",
           "atoms", "nested_start", "lr_test", "schwarz_gain", "lattice", "paired",
           "explained_pairs", "admissible", "accepted", "added", "atom_of",
           "offered_effects", "least_significant", "decide", "select", "ranked",
           "row_order", "atom_order", "screen", "STEPS", "STATEMENT", "vuong_of",
           "bin_costs", "vuong_z", "vuong_critical"]
