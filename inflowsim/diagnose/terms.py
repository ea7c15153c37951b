"""Where the missing term lives: a score test of every single-entry addition.

When no catalogue effect explains a residual, the question becomes *which term of
the equations* the data want.  At the base fit, every single-entry addition

* to each equation of Eq. (1)'s blocks -- the flap equation
  ``C beta' + D beta = H_lambda lambda + H_u u + k v`` and the inflow equation
  ``D_tau lambda' + lambda = L c + ... + k v`` -- with ``v`` any one flap angle,
  flap rate (azimuth time), inflow or input (azimuth units), and
* to the measurement map, ``beta_m,i = (C x)_i + k v`` with ``v`` a state
  (``beta``, ``lambda``) or an input (feedthrough), and
* to the blade pitch (block ``"pitch"``, :data:`PITCH_FEEDS`): the blade's pitch
  gains ``k`` times the blade's own flap angle, flap rate or inflow, which in
  multiblade coordinates is ``theta0 += k v0`` (row ``theta0``, ``v0`` the coning
  harmonic's ``beta0``, ``beta0'`` or ``lambda0``) or ``theta1c += k v1c``,
  ``theta1s += k v1s`` (row ``theta1``, variable ``beta1``, ``beta1_prime`` or
  ``lambda1``): one coefficient entering every flap and inflow row the pitch
  enters, by the pitch's columns of ``H_u`` and ``P_u`` (a pitch-flap coupling:
  delta-3, blade torsion or a flexible control system alike; a single row's entry
  holds only a part of it, issue #36),

and each flap, flap-rate and inflow variable ``v`` *lagged* (:data:`LAGGED`, in the
flap and inflow rows and the recorded flap: ``Term.lag``): a slow state ``w`` with
``T w' + w = v`` and ``k w`` in the row, one ``T`` for all, the corner at the band's
lowest frequency (:func:`lag_time`: across the band the term acts as an integral of
``v``; rotor speed through the governor, a slow elastic or engine state -- no
constant entry is one),

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

**Robust to absorbing parameters** (issue #36).  A base parameter shared by
several equations (the flap frequency ``lambda_beta2`` and ``n_beta`` of every
flap row, the inflow's ``tau``) soaks up part of a term that acts in some rows
only, and the score test at that biased fit blames the rows it left wrong (a
cyclic term's score lands in the coning row).  So, by default:

1. the shared parameters are freed per row group (:data:`GROUPS`: the coning row
   and the cyclic flap rows, the uniform and the cyclic inflow rows; each a free
   offset of the parameter in the first-harmonic rows, :func:`shared_parameters`),
   the base refitted with them, and the score test made at that fit with the
   offsets among the base's parameters (``MissingTerms.freed``: the values per
   group and the likelihood ratio of freeing them);
2. at each of the two fits, the base and the freed, the :data:`CONFIRM` entries
   of largest score are refitted, each with its coefficient and every other
   parameter free, and ranked first by the likelihood-ratio statistic of that
   refit (``Term.refit_statistic``); where the first entry is significant and
   its first group (step 4) holds more than one entry, or an entry in the inflow
   equation or on an inflow variable, the lagged entries of every inflow variable
   in each row the refitted entries lie in are refitted too, started at unit gain
   (a base whose inflow time constant slowed to a slow state it absorbs leaves
   other entries of the rows standing in for the lagged one, whose own score is
   then near zero, and the cost flat in its coefficient at zero: a saddle a refit
   from zero stays on), and all ranked again; the entry whose refit lowers the
   cost most wins;
3. the map is the freed fit's only where freeing the shared parameters lowers the
   cost beside the best single entry: where the freed fit's first entry with the
   offsets (their likelihood ratio plus its refit's) beats the base fit's first
   entry alone by more than the chi-square point of the offsets' number at
   :data:`FREED_LEVEL` (``MissingTerms.made_freed``, ``freed_gain``).  Otherwise a
   single entry takes up what freeing does (a term that acts in the cyclic rows
   only, as a pitch-flap coupling on a record that moves one cyclic, is soaked up
   by the cyclic rows' own offsets, and the freed fit's map is left with noise):
   the map is the base fit's;
4. the refitted entries whose likelihood-ratio statistic lies within :data:`TIE`
   (3.84, chi-square one degree of freedom at 95 %) of the first's are reported
   with it as the map's first group (``Term.first_group``,
   :attr:`MissingTerms.first_group`): the record cannot tell them apart (a
   likelihood-ratio confidence set for which entry it is), and the text names
   them all.

**What the map names** (:attr:`MissingTerms.determination`, ``answer``): one
entry only where its first entry is significant (its score, Holm-adjusted, or its
refit's likelihood ratio, Bonferroni-adjusted over the entries tested) and alone
in the first group (``"determined"``); where other entries tie with it
(``"tied"``) or nothing is significant (``"not-significant"``: no excess a single
entry takes up) the text says which entry it is is not determined, and no entry
is named.

A stiffness in the cyclic rows alone is, in the data, the shared parameter moved
plus a coning term: no single entry can place it, and step 1 absorbs it (the
freed values report it); where the coning row's own stiffness takes it up as well
(step 3 keeps the base fit), that entry's text says the record hardly tells it
from the other rows' own term moved the other way.

A pitch entry's sensitivity is the sum of its rows' entries' sensitivities
weighted by the pitch's columns (the model is linear in the entries at ``k = 0``);
its confirming refit perturbs every row.  Where an appended block routes a pitch
input through its own states (servo actuators) the feedback would enter that
block: such pitch entries are not tested (their sensitivity is zero).

A lagged entry's model is the base's with one appended state (a
:class:`~inflowsim.model.equations.StateBlock`: ``e = T``, ``a = -1``, ``a_z``
picking ``v``, ``k`` into the row, or into the recorded flap through ``to_output``),
the confirming refit's model too; its state is at rest at the record's ends (``w =
0``: the record starts in trim and the slow state has come back by its end;
:func:`_lag_model`).  Its transform is then ``W = V / (1 + j omega T)`` exactly, ``V``
the variable's with its end effects, so with continuous inputs and first-order
flapping (whose end-state basis no entry moves) the entry's column at ``k = 0`` is
the constant entry's times that factor per bin, before the weighting and the
nuisance projection; otherwise (held inputs: the sampled model; flap inertia: the
quasi-steady flap rates at the ends move with a constant entry) it is differentiated
like the others.  At rest, not steady (``w = v`` at the ends, as a catalogue block's
states): the base's fitted end states hold inflow parts the flap hardly sees (the fast
inflow forgets them), which through a slow state would swamp the column.

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
from scipy import special

from ..channels import FLAP, FLAP_RATE, INFLOW, INPUTS, N_BASE_INPUTS
from ..defaults import ALPHA       # the map's family-wise level: the rule's alpha
from ..identify.estimator import fit_from, as_records, spectra_of, fit_state
from ..identify.freqmodel import continuous_input, flap_response
from ..identify.problem import Problem, stack
from ..errors import InputError
from ..identify.transform import DEFAULT_BAND, record_spectra
from ..channels import input_scale
from ..model.build import apply_effects, model_from_equations, steady_manifold
from ..model.equations import StateBlock, rotation
from .tails import chi2_sf

__all__ = ["ALPHA", "Term", "MissingTerms", "missing_terms", "physics_group",
           "BLOCKS", "PITCH_ROWS", "PITCH_FEEDS", "TIE", "LAGGED", "LAGGED_BLOCKS",
           "lag_time"]

#: The blocks of equations tested, in display order: the flap and inflow
#: equations, the recorded flap, and the blade pitch (a term fed back into a pitch
#: input, entering every row that input enters).
BLOCKS = ("flap", "inflow", "measurement", "pitch")
#: The rows of the ``"pitch"`` block: the collective and the cyclic blade pitch.
PITCH_ROWS = ("theta0", "theta1")
#: What a ``"pitch"`` entry feeds into the blade pitch, per row and variable:
#: ``(pitch input index in INPUTS, state), ...``.  The blade's pitch gains ``k``
#: times the blade's own flap angle, flap rate or inflow, which in multiblade
#: coordinates is the collective from the coning-harmonic state and both cyclics
#: each from its own component (``theta1c += k beta1c``, ``theta1s += k beta1s``).
PITCH_FEEDS = {
    ("theta0", "beta0"): ((0, "beta0"),),
    ("theta0", "beta0_prime"): ((0, "beta0_prime"),),
    ("theta0", "lambda0"): ((0, "lambda0"),),
    ("theta1", "beta1"): ((1, "beta1c"), (2, "beta1s")),
    ("theta1", "beta1_prime"): ((1, "beta1c_prime"), (2, "beta1s_prime")),
    ("theta1", "lambda1"): ((1, "lambda1c"), (2, "lambda1s")),
}
#: The variables of the lagged entries (:func:`lag_time`): the flap angles, flap
#: rates and inflow, each driving a slow state of its own.  Not the inputs: a
#: lagged input is a servo or a filter of the input, which the catalogue's own
#: state blocks model where it matters (servo actuators).
LAGGED = FLAP + FLAP_RATE + INFLOW
#: The blocks with lagged entries: the rows of the flap and inflow equations and the
#: recorded flap.
LAGGED_BLOCKS = ("flap", "inflow", "measurement")
#: The effect name of a lagged entry's appended state (:class:`StateBlock`).
LAG_BLOCK = "lagged-entry"
#: Relative information left after projecting off the base's parameters below which
#: an entry cannot be told from them.
CONFOUNDED = 1e-8
#: Central-difference step of an entry [descriptor units].
STEP = 1e-6
#: The entries of largest score statistic refitted to confirm the map's order.
CONFIRM = 6
#: Levenberg-Marquardt iterations of a confirming refit.
REFIT_ITERATIONS = 30
#: Typical size of a shared parameter's offset in one row group, relative to the
#: parameter (finite-difference steps).
TYPICAL_SHARED = 0.1
#: Refitted entries whose likelihood-ratio statistic lies within this of the
#: first's are reported with it, as one group the record cannot tell apart (the
#: chi-square one-degree-of-freedom 95 % point: a likelihood-ratio confidence set
#: for which entry it is).
TIE = 3.84
#: The level of the test that keeps the shared parameters freed per row group for
#: the map: freeing them must lower the cost beside the best single entry by more
#: than the chi-square point of their number at this level (else a single entry
#: takes up what freeing them does, and the map is made at the base fit).
FREED_LEVEL = 0.05

_KIND_OF = {**{n: "flap" for n in FLAP}, **{n: "rate" for n in FLAP_RATE},
            **{n: "inflow" for n in INFLOW}, **{n: "input" for n in INPUTS},
            "beta1": "flap", "beta1_prime": "rate", "lambda1": "inflow"}
_PITCH = set(INPUTS[:3])
_HUB = {"muz", "q", "p", "qdot", "pdot"}


def lag_time(band_hz=DEFAULT_BAND) -> float:
    """The lagged entries' one time constant ``T = 1 / (2 pi f_lo)`` [s]: the corner
    of the lag at the analysis band's lowest frequency ``f_lo`` (0.706 s for the
    default band, 0.2256-1.58 Hz).

    Across the band the lag ``1 / (1 + j 2 pi f T)`` turns from -45 degrees at its
    bottom to -82 at its top (the default band) and its gain falls as ``1 / f``: the
    term acts as an integral of its variable, what a state slower than the band
    driven by it does (rotor speed through the governor, a slow elastic or engine
    state), and what neither a constant entry (phase 0) nor a rate entry (+90
    degrees) can.  A slower state looks the same in the band up to its gain (which
    the coefficient takes up); a state faster than the band acts as the constant
    entry there.  One ``T``, fixed by the band alone: two a decade apart would tie
    with each other in the band's factor of seven.
    """
    return 1.0 / (2.0 * np.pi * float(band_hz[0]))


def physics_group(block: str, equation: str, variable: str, lag: float | None = None) -> str:
    """What a term in ``equation`` (of ``block``) proportional to ``variable`` *is*:
    the kind of entry (a stiffness, a damping, a forcing, a sensor's gain ...),
    never a guess at its cause where several causes give the same entry (a
    cross flap-rate term comes from servo lags, blade lag or gyroscopic coupling
    alike; issue #36).  ``lag`` [s]: a lagged entry, a slow state ``w`` with
    ``T w' + w = variable`` in the equation (:func:`lag_time`)."""
    kind = _KIND_OF[variable]
    if lag:
        what = {"flap": "flap angle", "rate": "flap rate", "inflow": "inflow"}[kind]
        into = {"flap": "the flap", "inflow": "the inflow",
                "measurement": "the recorded flap"}[block]
        return (f"slow state driven by the {what}, forcing {into} (a first-order "
                f"lag of {lag:.3g} s)")
    own = equation == variable or (kind == "rate" and variable == f"{equation}_prime")
    if block == "flap":
        if kind == "flap":
            return "flap stiffness" if own else "cross-flap stiffness"
        if kind == "rate":
            return "flap damping" if own else "cross flap-rate term"
        if kind == "inflow":
            return "inflow forcing of the flap"
        if variable in _PITCH:
            return "pitch forcing of the flap"
        if variable in _HUB:
            return "hub-motion forcing of the flap"
        return "in-plane velocity forcing of the flap"
    if block == "inflow":
        if kind == "flap":
            return "flap forcing of the inflow"
        if kind == "rate":
            return "flap-rate forcing of the inflow"
        if kind == "inflow":
            return "inflow gain" if own else "cross-inflow coupling"
        if variable in _PITCH:
            return "pitch forcing of the inflow"
        if variable in _HUB:
            return "hub-motion forcing of the inflow"
        return "in-plane velocity forcing of the inflow"
    if block == "pitch":
        return {"flap": "pitch-flap coupling", "rate": "pitch-flap-rate coupling",
                "inflow": "pitch-inflow coupling"}[kind] + \
            f" ({'collective' if equation == 'theta0' else 'cyclic'}: the blade pitch " \
            "follows the blade's own " + {"flap": "flap angle", "rate": "flap rate",
                                          "inflow": "inflow"}[kind] + ")"
    if kind == "flap":
        return "sensor gain" if own else "sensor cross-talk"
    if kind == "inflow":
        return "inflow in the recorded flap (no sensor sees inflow: the model lacks a term)"
    return "input feedthrough to the recorded flap"


@dataclass(frozen=True)
class Term:
    """One tested entry: ``equation`` of ``block`` gains ``coefficient * variable``.

    ``statistic`` the score statistic (chi-square, 1 dof); ``p_value`` its tail
    probability; ``p_adjusted`` Holm's over the entries tested; ``sign`` of the
    one-step estimate ``coefficient`` (descriptor units: azimuth time, inputs in
    azimuth units; on the right-hand side of the equation); ``testable`` False
    where the entry cannot be told from the base's own parameters; ``gradient``
    ``dJ/dk`` of the cost (12) at ``k = 0`` (``S`` and the base's parameters held),
    at the fit the map is made at; ``refit_statistic`` ``2 (J - J_refit)`` of the
    confirming refit with the entry free (``None``: not refitted) and
    ``refit_coefficient`` its estimate; ``group`` what kind of entry it is
    (:func:`physics_group`); ``lag`` a lagged entry's time constant (a slow state
    driven by ``variable``, :func:`lag_time`) or ``None``.
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
    refit_statistic: float | None = None
    refit_coefficient: float | None = None
    #: in the map's first group: refitted, and its refit statistic within
    #: :data:`TIE` of the first entry's (the record cannot tell them apart)
    first_group: bool = False
    #: the refit's likelihood ratio as a test (chi-square, one degree of freedom,
    #: divided by the map's degrees-of-freedom factor), Bonferroni over the entries
    #: tested (``None``: not refitted)
    refit_p_adjusted: float | None = None
    #: a lagged entry: the time constant ``T`` [s] of the slow state ``w``, ``T w' +
    #: w = variable``, the equation gaining ``coefficient * w`` (:func:`lag_time`);
    #: ``None``: the variable itself
    lag: float | None = None

    @property
    def label(self) -> str:
        """The variable, or for a lagged entry ``"lambda0 lagged 0.706 s"``."""
        return self.variable if not self.lag else f"{self.variable} lagged {self.lag:.3g} s"

    @property
    def direction(self) -> int:
        """The sign of the term: its refit's estimate where refitted, else the
        one-step estimate's (:attr:`sign`, which may differ where the score is small:
        a term a base parameter absorbed)."""
        return int(np.sign(self.refit_coefficient)) if self.refit_coefficient else self.sign

    @property
    def key(self) -> tuple:
        """``(block, equation, variable, lag)``: the entry (a lagged one beside the
        constant one of its variable)."""
        return (self.block, self.equation, self.variable, self.lag)

    def significant(self, alpha: float = ALPHA) -> bool:
        """Its score test, Holm-adjusted, or its refit's likelihood ratio,
        Bonferroni-adjusted, at most ``alpha`` (the refit is the exact test where the
        term is large and the score's local approximation falls short)."""
        return self.testable and (self.p_adjusted <= alpha or (
            self.refit_p_adjusted is not None and self.refit_p_adjusted <= alpha))

    def where(self) -> str:
        """``"the beta1s equation"``, ``"the recorded beta1c"``."""
        if self.block == "measurement":
            return f"the recorded {self.equation}"
        if self.block == "pitch":
            return ("the collective pitch" if self.equation == "theta0" else
                    "the cyclic pitch (each cyclic from its own component)")
        return f"the {self.equation} equation"

    def to_json(self, alpha: float = ALPHA) -> dict:
        return {"block": self.block, "equation": self.equation, "variable": self.variable,
                "statistic": float(self.statistic), "p_value": float(self.p_value),
                "p_adjusted": float(self.p_adjusted), "sign": int(self.sign),
                "coefficient": float(self.coefficient), "group": self.group,
                "testable": bool(self.testable), "gradient": float(self.gradient),
                "refit_statistic": (None if self.refit_statistic is None
                                    else float(self.refit_statistic)),
                "refit_coefficient": (None if self.refit_coefficient is None
                                      else float(self.refit_coefficient)),
                "first_group": bool(self.first_group),
                "refit_p_adjusted": (None if self.refit_p_adjusted is None
                                     else float(self.refit_p_adjusted)),
                "significant": bool(self.significant(alpha)),
                "lag": None if not self.lag else float(self.lag)}


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
    #: how many entries lead the ranking by a confirming refit
    confirmed: int = 0
    #: the shared parameters freed per row group: ``((parameter, where, value
    #: elsewhere, value there, statistic, p), ...)`` (empty: none shared, or that
    #: fit failed)
    freed: tuple = ()
    #: whether the map is made at the freed fit: freeing them lowers the cost
    #: beside the best single entry by more than the chi-square 95 % point of their
    #: number (``freed_gain``); else at the base fit (:func:`missing_terms`)
    made_freed: bool = False
    #: ``2 (J(best entry) - J(best entry, shared freed))`` over the base fit: what
    #: freeing adds beside the best single entry (``None``: not compared)
    freed_gain: float | None = None
    #: the degrees-of-freedom factor the statistics are divided by for their tests
    dof: float = 1.0
    #: the lagged entries' time constant ``T`` [s] (:func:`lag_time`; ``None``: none
    #: tested) and their variables (the map's further columns, :attr:`columns`)
    lag: float | None = None
    lagged: tuple = ()

    @property
    def columns(self) -> tuple:
        """The map's columns ``((variable, lag), ...)``: every variable (``lag``
        ``None``), then the lagged ones (:attr:`lagged`, ``lag`` :attr:`lag`)."""
        return tuple((v, None) for v in self.variables) + tuple(
            (v, self.lag) for v in self.lagged)

    @property
    def rows(self) -> tuple:
        return tuple(t.to_json(self.alpha) for t in self.terms)

    @property
    def significant(self) -> tuple:
        return tuple(t for t in self.terms if t.significant(self.alpha))

    @property
    def first_group(self) -> tuple:
        """The entries leading the map that the record cannot tell apart: the first
        and every refitted entry whose refit statistic is within :data:`TIE` of its
        (just the first where none is, or nothing was refitted)."""
        return tuple(t for t in self.terms if t.first_group) or self.terms[:1]

    @property
    def determination(self) -> str:
        """Whether the map names one entry: ``"determined"`` (its first entry is
        significant and the record tells it from every other refitted entry),
        ``"tied"`` (significant, but other entries' refits lie within :data:`TIE`
        of it: the record cannot tell which), ``"not-significant"`` (no entry is:
        the record shows no excess a single entry takes up)."""
        if not self.terms or not self.terms[0].significant(self.alpha):
            return "not-significant"
        return "determined" if len(self.first_group) == 1 else "tied"

    @property
    def answer(self):
        """The entry the map names (:class:`Term`), or ``None`` where it does not
        determine one (:attr:`determination`)."""
        return self.terms[0] if self.determination == "determined" else None

    @property
    def equation(self):
        """``(block, equation)`` every entry of a significant first group lies in
        (the equation is determined where the variable may not be: a tie within one
        equation), or ``None``."""
        if self.determination == "not-significant":
            return None
        rows = {(t.block, t.equation) for t in self.first_group}
        return next(iter(rows)) if len(rows) == 1 else None

    def answer_json(self) -> dict:
        """``{"determination", "entry", "equation", "first_group", "made_freed",
        "freed_gain"}``: what the map names (``"missing_terms_answer"``): ``entry``
        the determined entry's ``{"block", "equation", "variable", "group"}`` or
        ``None``; ``equation`` the ``{"block", "equation"}`` of :attr:`equation` or
        ``None``; ``first_group`` the entries the record cannot tell apart from the
        first."""
        def named(t):
            return {"block": t.block, "equation": t.equation, "variable": t.variable,
                    "group": t.group, "lag": None if not t.lag else float(t.lag)}
        a = self.answer
        eq = self.equation
        return {"determination": self.determination,
                "entry": None if a is None else named(a),
                "equation": None if eq is None else {"block": eq[0], "equation": eq[1]},
                "first_group": [named(t) for t in self.first_group],
                "made_freed": bool(self.made_freed),
                "freed_gain": None if self.freed_gain is None else float(self.freed_gain)}

    def to_json(self) -> list:
        return list(self.rows)

    def freed_json(self) -> list:
        """The freed shared parameters as JSON rows (``"missing_terms_freed"``)."""
        return [{"parameter": n, "rows": w, "value_elsewhere": a, "value_in_rows": b,
                 "statistic": st, "p_value": pv} for n, w, a, b, st, pv in self.freed]

    def grid(self) -> np.ndarray:
        """``-log10 p`` (unadjusted) per ``(equation, column)`` (:attr:`columns`: the
        variables, then the lagged ones); NaN where the entry was not tested or not
        testable."""
        out = np.full((len(self.equations), len(self.columns)), np.nan)
        ri = {e: i for i, e in enumerate(self.equations)}
        ci = {c: j for j, c in enumerate(self.columns)}
        for t in self.terms:
            c = (t.variable, t.lag or None)
            if t.testable and (t.block, t.equation) in ri and c in ci:
                out[ri[(t.block, t.equation)], ci[c]] = -np.log10(max(t.p_value, 1e-300))
        return out

    def describe_freed(self) -> list[str]:
        """The shared parameters freed per row group, when freeing them is
        significant (level ``alpha``): one sentence, else none."""
        if not self.freed or self.freed[0][5] > self.alpha:
            return []
        each = "; ".join(f"{n} {b:.4g} in {w} against {a:.4g} elsewhere"
                         for n, w, a, b, _, _ in self.freed)
        how = ("the map is made with them so freed" if self.made_freed else
               "but a single entry takes that up as well (beside the best entry, "
               f"freeing them has a likelihood ratio of {self.freed_gain or 0.0:.1f} "
               f"only, below the chi-square point of {len(self.freed)} at "
               f"{FREED_LEVEL:g}): the map is made at the base fit")
        return [f"the shared parameters want other values per row group (likelihood "
                f"ratio {self.freed[0][4]:.1f}, p = {self.freed[0][5]:.2g}): {each}; "
                + how]

    def _own_note(self, t) -> str:
        """For a row's own stiffness, damping or inflow gain on a map made at the
        base fit where shared parameters act in every row of its block: that it is
        hardly told from the other row group's own term moved the other way (the
        shared parameter moved with it)."""
        own = t.block in ("flap", "inflow") and not t.lag and (
            t.variable == t.equation or t.variable == f"{t.equation}_prime")
        if not own or self.made_freed or not any(
                f" {t.block} " in w for _, w, *_ in self.freed):
            return ""
        return (" (the shared parameters act in every row of the block: the record "
                "hardly tells it from the other rows' own term moved the other way, "
                "see the values per row group)")

    def describe(self, limit: int = 3) -> list[str]:
        """Sentences for the text output: the significant terms (at most
        ``limit``), or that none is."""
        sig = self.significant
        out = self.describe_freed()
        if not sig:
            return out + [f"no single added term is significant (score test of "
                          f"{self.n_tested} entries, Holm-corrected at {self.alpha:g}, "
                          "and the refits of the first): where a term is missing is "
                          "not determined"]
        if self.determination == "not-significant":
            out.append("the first entry is not significant: where a term is missing is "
                       "not determined (the significant entries below are not told "
                       "from it)")
        group = list(self.first_group)
        if len(group) > 1:
            out.append("the record cannot tell apart the first " + str(len(group)) +
                       " entries (their refits lower the cost to within "
                       f"{TIE:g} of each other): a term in " + ", or in ".join(
                           f"{t.where()} proportional to {t.label}" for t in group)
                       + ("; which of them is not determined" if self.equation is None
                          else f"; all in {group[0].where()}: the equation is "
                          "determined, the variable not"))
        for t in sig[:limit]:
            refit = ("" if t.refit_statistic is None else
                     f", refit likelihood ratio {t.refit_statistic:.1f}, p = "
                     f"{t.refit_p_adjusted:.2g} after Bonferroni")
            out.append(f"the data want a term in {t.where()} proportional to {t.label} "
                       f"(sign {'+' if t.direction > 0 else '-'}, score {t.statistic:.1f}, "
                       f"p = {t.p_adjusted:.2g} after Holm over {self.n_tested} "
                       f"entries{refit}): {'an' if t.group[0] in 'aeiou' else 'a'} "
                       f"{t.group}{self._own_note(t)}")
        if len(sig) > limit:
            out.append(f"... and {len(sig) - limit} more significant entries")
        return out


def _rows(block):
    """The row names of ``block``."""
    return {"inflow": INFLOW, "pitch": PITCH_ROWS}.get(block, FLAP)


def _entries(inputs, lag=None):
    """``[(block, row, variable, lag), ...]`` in map order: the constant entries
    (``lag`` ``None``), then, where ``lag`` [s] is given, the lagged ones
    (:data:`LAGGED` in :data:`LAGGED_BLOCKS`; the recorded flap's of the flap and
    inflow, as its constant entries)."""
    states = FLAP + FLAP_RATE + INFLOW
    out = []
    for block, rows in (("flap", FLAP), ("inflow", INFLOW)):
        out += [(block, i, v, None) for i in range(3) for v in states + tuple(inputs)]
    out += [("measurement", i, v, None) for i in range(3)
            for v in FLAP + INFLOW + tuple(inputs)]
    out += [("pitch", PITCH_ROWS.index(e), v, None) for e, v in PITCH_FEEDS]
    if lag:
        out += [(block, i, v, float(lag)) for block in LAGGED_BLOCKS for i in range(3)
                for v in (LAGGED if block != "measurement" else FLAP + INFLOW)]
    return out


def _lagged(eq, meas, block, i, variable, k, t_az):
    """``eq`` with lagged entry ``(block, i, variable)`` appended at coefficient
    ``k``: a state ``w`` with ``t_az w' + w = variable`` (azimuth time: ``t_az = T
    Omega``) and ``k w`` on the right-hand side of row ``i`` of the flap or inflow
    equation, or in the recorded flap ``i`` (``meas``: the output map's flap block,
    azimuth bias and an effect's own terms, which the recorded flap sees ``w``
    through).  A :class:`StateBlock`: at its ends the state is steady, ``w =
    variable`` (:func:`inflowsim.model.build.steady_manifold`)."""
    a_z = np.zeros((1, 9))                          # z = (beta, lambda, beta')
    a_z[0, (FLAP + INFLOW + FLAP_RATE).index(variable)] = 1.0
    f_x, l_x, to_output = np.zeros((3, 1)), np.zeros((3, 1)), None
    if block == "flap":
        f_x[i, 0] = k
    elif block == "inflow":
        l_x[i, 0] = k
    else:
        # what the block adds to the model's flap, which the output map turns into
        # k w in recorded channel i alone
        c = np.eye(3)
        c[1:3, 1:3] = rotation(meas.azimuth_bias)
        if meas.flap_map is not None:
            c = c + np.asarray(meas.flap_map, dtype=float)[:, :3]
        to_output = np.zeros((6, 1))
        to_output[:3, 0] = np.linalg.solve(c, k * np.eye(3)[i])
    bl = StateBlock(effect=LAG_BLOCK, states=("w",), e=np.array([[float(t_az)]]),
                    a=np.array([[-1.0]]), a_z=a_z,
                    b=np.zeros((1, np.asarray(eq.h_u).shape[1])), f_x=f_x, l_x=l_x,
                    to_output=to_output)
    return eq.with_(blocks=tuple(eq.blocks) + (bl,))


def _pitch_weights(eq, j):
    """``(flap rows, inflow rows)``: how much of a term fed back into pitch input
    ``j`` enters each row of the flap and the inflow equation (the input's columns
    ``h_u``, ``p_u``); zeros where an appended block routes the input through its
    own states (a servo: the feedback would enter that block instead, not tested)."""
    if any(np.any(np.asarray(bl.b, dtype=float)[:, j] != 0) for bl in eq.blocks):
        return np.zeros(3), np.zeros(3)
    return (np.asarray(eq.h_u, dtype=float)[:, j].copy(),
            np.asarray(eq.p_u, dtype=float)[:, j].copy())


def _perturb_entry(eq, block, i, variable, k):
    """``eq`` with entry ``(block, i, variable)``'s term ``k * variable`` added: one
    row's right-hand side (:func:`_perturb`), or for the ``"pitch"`` block ``k``
    times the state(s) of :data:`PITCH_FEEDS` added to the pitch input(s) wherever
    they enter (every flap and inflow row, weighted by their columns of ``h_u`` and
    ``p_u``)."""
    if block != "pitch":
        return _perturb(eq, block, i, variable, k)
    for j, v, wf, wi in _pitch_parts(eq, i, variable):
        for r in range(3):
            eq = _perturb(eq, "flap", r, v, k * wf[r])
            eq = _perturb(eq, "inflow", r, v, k * wi[r])
    return eq


def _pitch_parts(eq, i, variable):
    """``[(input, state, flap-row weights, inflow-row weights), ...]`` of pitch
    entry ``(PITCH_ROWS[i], variable)`` (:data:`PITCH_FEEDS`) in ``eq``."""
    return [(j, v, *_pitch_weights(eq, j))
            for j, v in PITCH_FEEDS[(PITCH_ROWS[i], variable)]]


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


def _lag_model(s, p, eq, meas, k, n_in):
    """The model of ``eq`` whose last appended state is a lagged entry's
    (:func:`_lagged`), that state at rest at the record's ends (``w = 0``; every
    other state after the first six steady with it, as without it): the record
    starts in trim, and the slow state has come back by its end.

    The steady state of the lag itself (``w = variable``, as
    :func:`~inflowsim.model.build.steady_manifold` would give) would tie ``w``'s
    ends to the base's end states, whose inflow parts the flap hardly sees (fitted
    values of thousands where the fast inflow forgets them): through a slow state
    they would swamp the term's column.  At rest, the lag's transform is exactly
    ``V / (1 + j omega T)`` (continuous inputs), ``V`` its variable's with its end
    effects: at ``k = 0`` the entry's column is the constant entry's times that
    factor per bin for first-order flapping (:func:`_sensitivities` differentiates
    this model, which holds for held inputs and flap inertia too)."""
    m = model_from_equations(s, p, eq, meas, k, n_inputs=n_in)
    n = m.A.shape[0]
    if n - 1 > 6:
        P, q = steady_manifold(m.E[:-1, :-1], m.A[:-1, :-1], np.asarray(m.B)[:-1],
                               input_scale(k.omega)[:n_in])
    else:
        P, q = np.eye(6), np.zeros((6, n_in))
    return replace(m, end_basis=np.vstack([P, np.zeros((1, P.shape[1]))]),
                   end_input=np.vstack([q, np.zeros((1, n_in))]))


def _predicted(model, sp, nu):
    y_u, y_nu, _ = flap_response(model, sp)
    return y_u + y_nu @ nu


def _feedthrough(model, sp, i, j):
    """``d Y_i / d D_ij``: input ``j``'s transform as flap channel ``i`` records it."""
    d = float(model.delays[i]) - float(model.input_delays[j])
    if d == 0:
        return sp.U[:, j]
    if sp.hold == "continuous":
        return continuous_input(sp, d)[:, j]
    return np.exp(-2j * np.pi * sp.f_hz * d) * sp.U[:, j]


#: The row groups a shared parameter is freed over: the coning row and the cyclic
#: rows of the flap equation, the uniform row and the cyclic rows of the inflow
#: equation (the blocks' fields whose rows they are).
GROUPS = (("flap", (0,)), ("flap", (1, 2)), ("inflow", (0,)), ("inflow", (1, 2)))
_FIELDS = {"flap": ("m2", "c", "d", "h_lambda", "h_u"),
           "inflow": ("d_tau", "p_dbeta", "p_beta", "p_lambda", "p_u")}
_GROUP_NAMES = {("flap", (0,)): "the coning row", ("flap", (1, 2)): "the cyclic flap rows",
                ("inflow", (0,)): "the uniform inflow row",
                ("inflow", (1, 2)): "the cyclic inflow rows"}


def _touched(s, p, k, name):
    """The groups (indices into :data:`GROUPS`) whose rows parameter ``name``
    changes."""
    eq0, _ = apply_effects(s, p, k)
    v = float(p[name])
    eq1, _ = apply_effects(s, {**p, name: v + 1e-4 * max(abs(v), 1.0)}, k)
    out = []
    for g, (block, rows) in enumerate(GROUPS):
        if any(np.any(np.asarray(getattr(eq1, f), dtype=float)[list(rows)]
                      != np.asarray(getattr(eq0, f), dtype=float)[list(rows)])
               for f in _FIELDS[block]):
            out.append(g)
    return out


def shared_parameters(fit) -> tuple:
    """``((parameter, group), ...)``: each free parameter of the base model (not of
    an effect) that acts in both the first-harmonic (cyclic) rows and the
    zeroth-harmonic row of a block, with the cyclic group it is freed over
    (:data:`GROUPS`).  ``lambda_beta2`` and ``n_beta`` of the flap equation, ``tau``
    of the inflow equation in ``basic``."""
    from ..model.effects import CATALOGUE
    s = fit.structure
    own = {n for e in s.effects if e in CATALOGUE for n in CATALOGUE[e].parameters}
    tied = {n for t in fit.ties for n in t}
    k = fit.constants[0]
    out = []
    for n in s.parameters:
        if n in own or n in tied or n in set(fit.fixed) or n not in fit.sigma:
            continue
        g = _touched(s, dict(fit.parameters), k, n)
        for zero, cyc in ((0, 1), (2, 3)):
            if zero in g and cyc in g:
                out.append((n, cyc))
    return tuple(out)


class _Augmented(Problem):
    """The base's fit problem with its shared parameters freed per row group
    (``splits``: ``(parameter, group)``, each a free offset ``delta`` of the
    parameter in that group's rows) and, optionally, one entry's coefficient ``k``
    free (``entry``: ``(block, row, variable)``), appended to the free vector in
    that order.  Its responses are not its models' alone (the entry's feedthrough
    and lags): its Jacobian is differenced as a whole."""

    models_alone = False

    def __init__(self, structure, spectra, values, fixed, ties, splits, entry, n_inputs):
        super().__init__(structure, spectra, values, fixed=fixed, ties=ties)
        self.ties_given = tuple(tuple(t) for t in ties)
        self.splits = tuple(splits)
        self.entry = entry
        self.n_inputs = n_inputs
        self.n_base = len(self.free)
        self.free_names = self.free_names + tuple(f"{n}@{g}" for n, g in self.splits) \
            + (("k",) if entry is not None else ())

    @property
    def n_extra(self):
        return len(self.splits) + (self.entry is not None)

    def theta0(self):
        return np.append(super().theta0(), np.zeros(self.n_extra))

    def params(self, theta):
        return super().params(np.asarray(theta)[:self.n_base])

    def bounds(self):
        lo, hi = super().bounds()
        return (np.append(lo, np.full(self.n_extra, -np.inf)),
                np.append(hi, np.full(self.n_extra, np.inf)))

    def log_mask(self):
        return np.append(super().log_mask(), np.zeros(self.n_extra, dtype=bool))

    def typical(self, theta):
        theta = np.asarray(theta, dtype=float)
        base = super().typical(theta[:self.n_base])
        p = self.params(theta)
        extra = [max(abs(theta[self.n_base + i]), TYPICAL_SHARED * abs(p[n]), 1e-3)
                 for i, (n, _) in enumerate(self.splits)]
        if self.entry is not None:
            extra.append(max(abs(theta[-1]), 0.1))
        return np.append(base, extra)

    def _inside(self, theta):
        return super()._inside(np.asarray(theta)[:self.n_base]) and \
            bool(np.isfinite(theta).all())

    def equations(self, theta, k):
        """``(p, eq, meas)`` of ``theta`` at constants ``k``, without the entry: each
        freed group's rows from the structure at the parameter plus its offset."""
        from ..model.params import SPECS
        theta = np.asarray(theta, dtype=float)
        p = self._checked(theta)
        eq, meas = apply_effects(self.structure, p, k)
        for g in sorted({g for _, g in self.splits}):
            pg = dict(p)
            for i, (n, gg) in enumerate(self.splits):
                if gg == g:
                    pg[n] = p[n] + float(theta[self.n_base + i])
                    sp = SPECS[n]
                    if not (sp.lower < pg[n] < sp.upper or (
                            not sp.lower_open and pg[n] == sp.lower)):
                        raise InputError(f"{n} = {pg[n]:g} in {_GROUP_NAMES[GROUPS[g]]}: "
                                         "outside its range")
            eqg, _ = apply_effects(self.structure, pg, k)
            block, rows = GROUPS[g]
            new = {}
            for f in _FIELDS[block]:
                m = np.array(getattr(eq, f), dtype=float)
                m[list(rows)] = np.asarray(getattr(eqg, f), dtype=float)[list(rows)]
                new[f] = m
            eq = eq.with_(**new)
        return p, eq, meas

    def _responses_many(self, thetas):
        out = []
        for theta in thetas:
            kv = float(theta[-1]) if self.entry is not None else 0.0
            resp = []
            for sp in self.spectra:
                k = sp.constants
                p, eq, meas = self.equations(theta, k)
                if self.entry is not None:
                    block, i, v, lag = self.entry
                    if lag:
                        eq = _lagged(eq, meas, block, i, v, kv, lag * k.omega)
                    elif block != "measurement":
                        eq = _perturb_entry(eq, block, i, v, kv)
                    elif _KIND_OF[v] != "input":
                        fm = np.zeros((3, 6)) if meas.flap_map is None else \
                            np.array(meas.flap_map, dtype=float)
                        fm[i, (FLAP + INFLOW).index(v)] += kv
                        meas = meas.with_(flap_map=fm)
                if self.entry is not None and self.entry[3]:
                    m = _lag_model(self.structure, p, eq, meas, k, self.n_inputs)
                else:
                    m = model_from_equations(self.structure, p, eq, meas, k,
                                             n_inputs=self.n_inputs)
                y_u, y_nu, _ = flap_response(m, sp)
                if self.entry is not None and self.entry[0] == "measurement" and \
                        not self.entry[3] and _KIND_OF[self.entry[2]] == "input":
                    y_u = y_u.copy()
                    y_u[:, self.entry[1]] += kv * _feedthrough(
                        m, sp, self.entry[1], INPUTS.index(self.entry[2]))
                y_u.flags.writeable = False
                y_nu.flags.writeable = False
                resp.append((y_u, y_nu))
            out.append(resp)
        return out


def _fitted(prob, theta, start=None):
    """``(state, J_0, J)``: the fit of ``prob`` from ``start`` (default ``theta``)
    and the cost (12) at ``theta`` (``S`` relaxed there); ``None`` where it fails
    (or, from another start, ends above ``J_0``)."""
    try:
        _, j0, _, _ = fit_from(prob, theta, max_iter=0)
        st, j, _, _ = fit_from(prob, theta if start is None else start,
                               max_iter=REFIT_ITERATIONS)
    except (InputError, np.linalg.LinAlgError):
        return None
    if start is not None and not j <= j0:
        return None
    return st, j0, j


def _refit(prob, theta, entry, k0=0.0):
    """``(2 (J_0 - J), k)``: the likelihood-ratio statistic of ``prob``'s problem
    refitted with ``entry``'s coefficient free (every parameter free again, ``S``
    relaxed, from ``theta`` and ``k = k0``) against it at ``theta`` and ``k = 0``,
    and the refitted coefficient; ``None`` where the refit fails (an unstable model
    on the way)."""
    aug = _Augmented(prob.structure, prob.spectra, prob.params(theta), prob.fixed,
                     prob.ties_given, prob.splits, entry, prob.n_inputs)
    got = _fitted(aug, np.append(theta, 0.0), None if not k0 else np.append(theta, k0))
    if got is None:
        return None
    st, j0, j = got
    return float(2.0 * (j0 - j)), float(st.theta[-1])


def missing_terms(records, fit, band_hz=DEFAULT_BAND, hold=None,
                  alpha: float = ALPHA, confirm: int = CONFIRM,
                  free_shared: bool | str = True, lag="band") -> MissingTerms:
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
    confirm : int
        How many entries of largest score statistic are refitted (the base with
        that entry free): those lead the ranking, by the refit's likelihood-ratio
        statistic.  0: the score order alone.
    free_shared : bool or "always"
        Free the base's shared parameters per row group (:func:`shared_parameters`)
        and make the map at that fit where freeing them lowers the cost beside the
        best single entry by more than the chi-square point of their number at
        :data:`FREED_LEVEL` (both maps made, their first entries' refits compared;
        else at the base fit, the freed values still reported); ``"always"``: at
        the freed fit whatever that comparison; False: at the base fit itself.
    lag : "band", float or None
        The lagged entries' time constant [s]: ``"band"`` the corner at the band's
        lowest frequency (:func:`lag_time`), a number that, ``None`` no lagged
        entries.

    Returns
    -------
    MissingTerms
        Every entry: the refitted ones first, by their likelihood-ratio statistic,
        then the rest by score statistic; untestable ones last.
    """
    recs = as_records(records)
    s = fit.structure
    # the in-plane inputs where every record has them: the entries a structure
    # without them cannot reach are the ones a hidden in-plane term would want
    inplane = s.uses_inplane or all(all(c in r.channels for c in INPUTS[N_BASE_INPUTS:])
                                    for r in recs)
    inputs = INPUTS if inplane else INPUTS[:N_BASE_INPUTS]
    n_in = len(inputs)
    spectra = spectra_of(recs, s, band_hz, None, hold)
    if len(spectra) != len(fit.data) or any(
            sp.f_hz.shape != d.f_hz.shape or not np.allclose(sp.f_hz, d.f_hz)
            for sp, d in zip(spectra, fit.data)):
        raise InputError("missing terms: give the records, band and hold the base fit "
                         "was made with (its frequencies differ)")
    full = spectra if n_in == s.n_inputs else [
        record_spectra(r, inputs, band_hz, None, hold) for r in recs]
    splits = shared_parameters(fit) if free_shared else ()
    if isinstance(lag, str):
        if lag != "band":
            raise InputError(f"missing terms: lag {lag!r}: give 'band', seconds or None")
        lag = lag_time(band_hz)
    elif lag is not None and not float(lag) > 0:
        raise InputError(f"missing terms: lag {lag!r}: a time constant is positive [s]")
    base = _map_at(s, full, fit, (), n_in, inputs, alpha, confirm, lag)
    if not splits:
        return base
    try:
        made = _map_at(s, full, fit, splits, n_in, inputs, alpha, confirm, lag)
    except (InputError, np.linalg.LinAlgError):
        # the freed fit stopped at a range's edge (the Jacobian's central steps
        # leave it): the map is made at the base fit itself
        return base
    if not made.freed:          # the freed fit failed: made at the base fit
        return base
    # what freeing adds beside the best single entry, both over the base fit
    gain = made.freed[0][4] + _likelihood_ratio(made.terms[0]) - \
        _likelihood_ratio(base.terms[0])
    if free_shared == "always" or gain > float(special.chdtri(len(splits), FREED_LEVEL)):
        return replace(made, made_freed=True, freed_gain=float(gain))
    return replace(base, freed=made.freed, freed_gain=float(gain))


def _likelihood_ratio(t) -> float:
    """``2 (J_base - J)`` of entry ``t`` over the fit its map is made at: its
    refit's, or its score statistic where it was not refitted."""
    return t.refit_statistic if t.refit_statistic is not None else t.statistic


def _map_at(s, full, fit, splits, n_in, inputs, alpha, confirm, lag=None) -> MissingTerms:
    """The map made at the base fit with ``splits`` freed (:func:`_made_at`; at the
    base fit itself where that refit fails, ``freed`` then empty): the score table
    and its confirming refits (:func:`_confirmed`, :func:`_with_siblings`)."""
    try:
        prob, theta, st, freed, jb = _made_at(s, full, fit, splits, n_in)
    except (InputError, np.linalg.LinAlgError):
        if not splits:
            raise
        prob, theta, st, freed, jb = _made_at(s, full, fit, (), n_in)
    r = np.concatenate(st.r)
    entries = _entries(inputs, lag)
    ub = _base_basis(jb)
    # the sensitivities a few columns at a time (a 2-hour record's 162 columns are
    # 76 MB), each column's statistics kept: the same products column by column
    stats = np.empty((4, len(entries)))          # gradient, raw, numerator, denominator
    for cols in _column_chunks(entries, r.size):
        x = np.empty((r.size, len(cols)))
        row0 = 0
        for sp, W, nu, Q, rr in zip(full, st.weights, st.nus, st.bases, st.r):
            blk = x[row0:row0 + rr.size]          # a record's rows: filled in place
            _sensitivities(blk, [entries[c] for c in cols], s, prob, theta, sp, W, nu, n_in)
            _minus_projection(blk, Q)       # the nuisance end states, as the estimator
            row0 += rr.size
        stats[:, cols] = _column_statistics(x, r, ub)
        del x, blk
    table = replace(_table(s, entries, stats, jb, r, st, alpha, inputs), freed=freed or ())
    del jb, r, st
    return _with_siblings(_confirmed(table, prob, theta, confirm), prob, theta)


#: Bytes of the map's sensitivities computed at once (:func:`_column_chunks`): a
#: normal record's every column (a 26.6 s record's 162 columns are 290 kB), a few
#: of a 2-hour record's (0.47 MB a column).
MAP_BYTES = 8 * 2 ** 20


def _column_chunks(entries, rows):
    """The map's columns (indices into ``entries``) in the groups computed together:
    all of them in map order where :data:`MAP_BYTES` holds them; otherwise each
    pitch entry with the flap and inflow columns it is made of (:data:`PITCH_FEEDS`,
    each state feeds one pitch entry), then the rest in groups of at most
    :data:`MAP_BYTES`."""
    per = max(1, MAP_BYTES // (8 * max(rows, 1)))
    if per >= len(entries):
        return [list(range(len(entries)))]
    index = {e: c for c, e in enumerate(entries)}
    # each constant entry with its lagged one, which may be made from it
    lagged = {(b, i, v, None): c for c, (b, i, v, lag) in enumerate(entries) if lag}
    out, used = [], set()
    for c, (block, i, v, _) in enumerate(entries):
        if block == "pitch":
            made_of = [index[(b, r, x, None)] for _, x in PITCH_FEEDS[(PITCH_ROWS[i], v)]
                       for b in ("flap", "inflow") for r in range(3)]
            out.append(made_of + [c] + [lagged[entries[m]] for m in made_of
                                        if entries[m] in lagged])
            used.update(out[-1])
    units = [[c] + ([lagged[e]] if e in lagged else [])
             for c, e in enumerate(entries) if c not in used and not e[3]]
    chunk = []
    for u in units:
        if chunk and len(chunk) + len(u) > per:
            out.append(chunk)
            chunk = []
        chunk = chunk + u
    return out + ([chunk] if chunk else [])


def _sensitivities(blk, entries, s, prob, theta, sp, W, nu, n_in):
    """One record's weighted sensitivities to ``entries`` (central differences of
    the response, the pitch entries from the flap and inflow columns among
    ``entries``), written into the columns of ``blk``, not yet projected."""
    where = {e: c for c, e in enumerate(entries)}
    k = sp.constants
    p, eq, meas = prob.equations(theta, k)
    m0 = model_from_equations(s, p, eq, meas, k, n_inputs=n_in)
    # a lagged entry's column is its constant entry's times the lag per bin where
    # that is exact (:func:`_lag_model`: continuous inputs, first-order flapping,
    # whose end-state basis no entry moves); else differentiated
    by_lag = sp.hold == "continuous" and not s.second_order
    wanted = {(b, i, v, None) for b, i, v, lag in entries if lag} if by_lag else set()
    const = {}
    for col, (block, i, v, lag) in enumerate(entries):
        if block == "pitch":
            # linear in the entries: the rows' columns, weighted as the input
            # enters them
            blk[:, col] = sum(wf[r] * blk[:, where[("flap", r, x, None)]]
                              + wi[r] * blk[:, where[("inflow", r, x, None)]]
                              for _, x, wf, wi in _pitch_parts(eq, i, v)
                              for r in range(3))
            continue
        if lag and (block, i, v, None) in const:
            dy = const[(block, i, v, None)] / (1.0 + 2j * np.pi * sp.f_hz * lag)[:, None]
        elif lag:
            # the refit's own model (:func:`_lag_model`)
            mp, mm = (_lag_model(s, p, _lagged(eq, meas, block, i, v, h, lag * k.omega),
                                 meas, k, n_in) for h in (STEP, -STEP))
            dy = (_predicted(mp, sp, nu) - _predicted(mm, sp, nu)) / (2 * STEP)
        elif block == "measurement":
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
        if (block, i, v, lag) in wanted:
            const[(block, i, v, lag)] = dy
        blk[:, col] = -stack(dy @ W.T)
    return blk


def _made_at(s, full, fit, splits, n_in):
    """``(problem, theta, state, freed, J_b)``: the fit the map is made at (the
    base's shared parameters freed per row group ``splits``, refitted; the base fit
    itself without splits or where that refit fails), its state and the
    sensitivities of its free parameters (central differences)."""
    prob = _Augmented(s, full, dict(fit.parameters), tuple(fit.fixed), tuple(fit.ties),
                      splits, None, n_in)
    theta = prob.theta0()
    freed = None
    if splits:
        got = _fitted(prob, theta)
        if got is not None:
            st, j0, j = got
            theta = st.theta
            freed = _freed(prob, theta, 2.0 * (j0 - j))
        else:
            prob = _Augmented(s, full, dict(fit.parameters), tuple(fit.fixed),
                              tuple(fit.ties), (), None, n_in)
            theta = prob.theta0()
    if freed is None:
        st = fit_state(prob, theta, list(fit.S))
    if prob.free or prob.n_extra:
        jb = np.vstack(prob.jacobian(theta, st.weights, st.nus, st.bases, central=True))
    else:
        jb = np.zeros((sum(r.size for r in st.r), 0))
    return prob, theta, st, freed, jb


def _freed(prob, theta, statistic):
    """The shared parameters' values per row group at the freed fit: ``((parameter,
    where, value in the other rows, value in these rows, statistic, p), ...)``,
    ``statistic`` the likelihood-ratio statistic of all of them freed against the
    base (chi-square with one degree of freedom each)."""
    p = prob.params(theta)
    dof = len(prob.splits)
    pv = float(chi2_sf(max(statistic, 0.0), dof))
    return tuple((n, _GROUP_NAMES[GROUPS[g]], float(p[n]),
                  float(p[n] + theta[prob.n_base + i]), float(statistic), pv)
                 for i, (n, g) in enumerate(prob.splits))


def _confirmed(table, prob, theta, confirm):
    """``table`` with its ``confirm`` testable entries of largest score refitted
    (:func:`_refit`) and ranked first by the refit's statistic (the first group
    marked, :func:`_grouped`)."""
    head = [t for t in table.terms if t.testable][:max(int(confirm), 0)]
    if not head:
        return table
    done = _ranked([_refitted(table, prob, theta, t) for t in head])
    rest = [t for t in table.terms if t not in head]
    return replace(table, terms=tuple(_grouped(done) + rest), confirmed=len(done))


def _with_siblings(table, prob, theta):
    """``table`` (confirmed, :func:`_confirmed`) with the lagged inflow entries of
    every row its refitted entries lie in (:func:`_slow_rows`) refitted too, started
    at unit gain (the score's sign), and all ranked again: only where the first
    entry is significant and its first group holds more than one entry, or an entry
    in the inflow equation or on an inflow variable.  A slow state driven by the
    inflow is absorbed by the base's inflow time constant, which leaves other
    entries standing in for its lagged entry, whose own score is then near zero
    and the cost flat in its coefficient at zero (a saddle a refit from zero stays
    on)."""
    done = list(table.terms[:table.confirmed])
    if not table.lag or not _looks_for_slow_states(
            [t for t in done if t.first_group], table.alpha):
        return table
    keys = {t.key for t in done}
    by_key = {t.key: t for t in table.terms}
    more = []
    for key in _slow_rows(done, table.lag):
        sib = by_key.get(key)
        if sib is not None and sib.testable and sib.key not in keys:
            more.append(sib)
            keys.add(sib.key)
    if not more:
        return table
    done = [replace(t, first_group=False) for t in done]
    # started off k = 0, where an absorbed slow state leaves the cost flat in k, at
    # unit gain: the lag's gain is one at low frequency, the row then taking up the
    # variable itself
    done = _ranked(done + [_refitted(table, prob, theta, t, float(t.sign)) for t in more])
    rest = [t for t in table.terms[table.confirmed:] if t not in more]
    return replace(table, terms=tuple(_grouped(done) + rest), confirmed=len(done))


def _refitted(table, prob, theta, t, k0=0.0):
    """Entry ``t`` of ``table`` with its refit's statistic, coefficient and
    Bonferroni-adjusted p-value (unchanged where the refit fails)."""
    row = _rows(t.block).index(t.equation)
    got = _refit(prob, theta, (t.block, row, t.variable, t.lag), k0)
    return t if got is None else replace(
        t, refit_statistic=got[0], refit_coefficient=got[1],
        refit_p_adjusted=float(min(1.0, table.n_tested * chi2_sf(
            max(got[0], 0.0) / table.dof, 1))))


def _ranked(done):
    return sorted(done, key=lambda t: -(t.refit_statistic if t.refit_statistic
                                        is not None else -np.inf))


def _grouped(done):
    """``done`` (ranked refits) with those within :data:`TIE` of the first marked as
    its first group."""
    if not done or done[0].refit_statistic is None:
        return list(done)
    best = done[0].refit_statistic
    return [replace(t, first_group=True) if t.refit_statistic is not None
            and t.refit_statistic >= best - TIE else t for t in done]


def _looks_for_slow_states(group, alpha) -> bool:
    """Whether the map refits the lagged inflow entries of its refitted entries' rows
    (:func:`_with_siblings`): the first entry of its first group ``group`` (refitted
    terms, ranked) significant at ``alpha``, and ``group`` holding more than one entry,
    or an entry in the inflow equation or on an inflow variable (what a slow inflow
    state the base absorbed leaves standing in for it)."""
    return bool(group) and group[0].significant(alpha) and (
        len(group) > 1 or any(t.block == "inflow" or t.variable in INFLOW for t in group))


def _slow_rows(done, lag):
    """The keys (:attr:`Term.key`) of the lagged entries (time constant ``lag``) of
    every inflow variable in each row of ``done`` (the refitted entries) that has
    lagged entries, in their order.  The base's one parameter that lags a variable
    is the inflow's time constant: slowed to absorb a slow state driven by the
    inflow, it leaves other entries of the rows the slow state acts in standing in
    for its lagged entry, whose own score is near zero at that fit."""
    rows = dict.fromkeys((t.block, t.equation) for t in done if t.block in LAGGED_BLOCKS)
    return tuple((b, e, v, lag) for b, e in rows for v in INFLOW)


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


def _base_basis(jb):
    """Orthonormal basis of the base parameters' sensitivities (a scaled SVD:
    undetermined directions of the base are dropped, as the estimator's bounds
    do); ``None`` without free parameters."""
    if not jb.shape[1]:
        return None
    scale = np.linalg.norm(jb, axis=0)
    scale[scale == 0] = 1.0
    u, sv, _ = np.linalg.svd(jb / scale, full_matrices=False)
    return u[:, sv > 1e-9 * max(sv.max(), 1e-300)]


def _column_statistics(je, r, ub):
    """``(gradient, raw, numerator, denominator)`` of sensitivity columns ``je``
    (projected off the nuisance): ``2 J^T r``, ``|J|^2`` per column and, projected
    off the base's parameters (``ub``, :func:`_base_basis`; over ``je``, which is
    not needed after), ``P^T r`` and ``|P|^2``."""
    grad = 2.0 * (je.T @ r)
    raw = np.einsum("ij,ij->j", je, je)
    if ub is not None and je.nbytes > BLOCK_BYTES:
        pe = _minus_projection(je, ub)   # in place: je is not needed after
    elif ub is not None:
        pe = je - ub @ (ub.T @ je)
    else:
        pe = je
    return grad, raw, pe.T @ r, np.einsum("ij,ij->j", pe, pe)


def _table(s, entries, stats, jb, r, st, alpha, inputs):
    """The map from each entry's ``stats`` (:func:`_column_statistics`, ``(4,
    entries)``)."""
    grad, raw, num, den = stats
    n_data = r.size
    lost = (np.linalg.matrix_rank(jb) if jb.shape[1] else 0) + sum(Q.shape[1]
                                                                   for Q in st.bases)
    dof = n_data / max(n_data - lost, 1)
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
    lag = None
    for col, (block, i, v, lg) in enumerate(entries):
        eq_name = _rows(block)[i]
        lag = lag or lg
        rows.append(Term(block, eq_name, v, float(stat[col]), float(pval[col]),
                         float(padj[col]), int(np.sign(coef[col]) or 1), float(coef[col]),
                         physics_group(block, eq_name, v, lg), bool(testable[col]),
                         float(grad[col]), lag=lg))
    rows.sort(key=lambda t: (not t.testable, -t.statistic))
    # the map's axes: the rows of one equation or the recorded flap (the pitch
    # entries, several rows at once, are in the text and the JSON)
    eqs = tuple((b, n) for b in BLOCKS if b != "pitch" for n in _rows(b))
    variables = FLAP + FLAP_RATE + INFLOW + tuple(inputs)
    return MissingTerms(structure=s.name, terms=tuple(rows), alpha=float(alpha),
                        n_tested=int(m), equations=eqs, variables=variables,
                        dof=float(dof), lag=lag, lagged=LAGGED if lag else ())
