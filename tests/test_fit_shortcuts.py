"""The shortcuts inside a fit's model evaluations give the numbers of the plain
path, bit for bit, and keep its refusals (issue #29: diagnose's CPU time).

A fit builds thousands of models of one structure: the problem remembers its
last responses, checks parameters only where a value could fail, assembles float
blocks in place and remembers base equations and eigen-decompositions.
Rounding-level differences would move the estimates by far more than rounding
(the search stops at a tolerance), so each shortcut must reproduce the plain
computation exactly.  The Jacobian, by the resolvent since issue #38, is held to
its definition at the differences' accuracy instead.
"""
import functools

import numpy as np
import pytest

from inflowsim import PUMA, build_model, preset_parameters
from inflowsim.errors import InputError
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record
from inflowsim.identify.estimator import _relax_S
from inflowsim.identify.freqmodel import flap_response
from inflowsim.identify.problem import Problem
from inflowsim.identify.transform import record_spectra
from inflowsim.model.build import _base_equations, apply_effects, base_equations
from inflowsim.model.equations import assemble
from inflowsim.model.structure import Structure

TWO = (Manoeuvre("theta1s", "doublet", np.radians(1.0), 2.0, 0.4),
       Manoeuvre("theta1c", "doublet", np.radians(1.0), 8.0, 0.4))


def _record(structure, p, seed=0, hold="continuous"):
    return virtual_record(VirtualTest(structure=structure, parameters=p, manoeuvres=TWO,
                                      noise_flap=1e-4, seed=seed, duration=8.0,
                                      hold=hold))


def _same(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def _block_assembly(eq, second_order):
    """The descriptor matrices by np.block, as assemble made them before."""
    z, i3 = np.zeros((3, 3)), np.eye(3)
    if not second_order:
        return (np.block([[eq.c, z], [-eq.p_dbeta, eq.d_tau]]),
                np.block([[-eq.d, eq.h_lambda], [eq.p_beta, eq.p_lambda - i3]]),
                np.vstack([eq.h_u, eq.p_u]))
    return (np.block([[i3, z, z], [z, eq.d_tau, z], [z, z, eq.m2]]),
            np.block([[z, z, i3], [eq.p_beta, eq.p_lambda - i3, eq.p_dbeta],
                      [-eq.d, eq.h_lambda, -eq.c]]),
            np.vstack([np.zeros_like(eq.h_u), eq.p_u, eq.h_u]))


@pytest.mark.parametrize("structure", ["basic", "glauert+time-delay", "empirical",
                                       "basic+flap-inertia+hub-velocity-coupling",
                                       "basic+second-harmonic-flap+azimuth-bias"])
def test_assembly_in_place_equals_np_block(structure):
    s = Structure.parse(structure)
    p = preset_parameters(s)
    rng = np.random.default_rng(1)
    p = {n: v * (1 + 0.1 * rng.standard_normal()) for n, v in p.items()}
    eq, _ = apply_effects(s, p, PUMA)
    for got, want in zip(assemble(eq, s.second_order), _block_assembly(eq, s.second_order)):
        assert _same(got, want)


def test_assembly_of_symbols_still_goes_through_np_block():
    """The FMU's generator runs assemble on object arrays: those keep np.block."""
    s = Structure.parse("glauert")
    eq, _ = apply_effects(s, preset_parameters(s), PUMA)
    obj = eq.with_(**{n: getattr(eq, n).astype(object) for n in ("c", "d", "p_u")})
    for got, want in zip(assemble(obj, False), assemble(eq, False)):
        assert got.dtype == object
        assert np.array_equal(got.astype(float), want)


def test_remembered_base_equations_are_copies():
    p = preset_parameters("basic")
    first = base_equations(p, PUMA)
    keep = first.p_u.copy()
    first.p_u[:] = 99.0                    # an effect editing its own copy in place
    again = base_equations(p, PUMA)
    assert _same(again.p_u, keep) and again.p_u is not first.p_u


def test_base_equations_in_parts_are_the_plain_ones():
    """Remembered in parts (inflow rows, flap rows, D, the time constants), each
    parameter moved in turn as a Jacobian does: the numbers of the plain function."""
    p = preset_parameters("basic")
    k = PUMA
    for n in (None, "n_beta", "lambda_beta2", "tau", None):
        q = dict(p)
        if n is not None:
            q[n] = p[n] * (1 + 1e-6)
        got = base_equations(q, k)
        want = _base_equations(k.mu, k.a0s, k.flow_speed, q["n_beta"], q["lambda_beta2"],
                               q["tau"])
        for f in ("m2", "c", "d", "h_lambda", "h_u", "d_tau", "p_dbeta", "p_beta",
                  "p_lambda", "p_u"):
            assert _same(getattr(got, f), getattr(want, f)), (n, f)


def test_models_made_without_the_dataclass_init_have_every_field():
    """The models and equations a fit makes skip the frozen dataclass's __init__:
    every field is still set, and the model pickles as one made by __init__."""
    import dataclasses
    import pickle

    from inflowsim.model.build import Model
    from inflowsim.model.equations import Equations
    m = build_model("glauert+time-delay", preset_parameters("glauert+time-delay"), PUMA)
    assert set(vars(m)) == {f.name for f in dataclasses.fields(Model)}
    eq = base_equations(preset_parameters("basic"), PUMA)
    assert set(vars(eq)) == {f.name for f in dataclasses.fields(Equations)}
    again = pickle.loads(pickle.dumps(m))
    assert _same(again.a, m.a) and not again.a.flags.writeable
    assert dict(again.parameters) == dict(m.parameters)


@functools.lru_cache(maxsize=None)
def _spectra(structure):
    p = preset_parameters(structure)
    if "delay" in p:
        p["delay"] = 0.0437
    return record_spectra(_record(structure, p), Structure.parse(structure).inputs), p


def _problem(structure, ties=()):
    sp, p = _spectra(structure)
    return Problem(structure, [sp], dict(p), ties=ties), sp, dict(p)


def test_remembered_responses_are_the_fresh_ones():
    prob, sp, p = _problem("glauert+time-delay")
    theta = prob.theta0()
    r1 = prob.responses(theta)
    assert prob.responses(theta.copy()) is r1          # remembered
    fresh = flap_response(build_model(prob.structure, p, sp.constants), sp)
    assert _same(r1[0][0], fresh[0]) and _same(r1[0][1], fresh[1])
    with pytest.raises(ValueError):                     # nobody can edit them
        r1[0][0][0, 0] = 0.0


def test_values_outside_a_range_are_still_refused():
    """The parameter check is skipped only where it would pass: a tied value inside
    the first name's range but outside the second's, and a non-finite one, fail."""
    prob, _, _ = _problem("glauert+time-delay", ties=[("c1", "delay")])
    theta = prob.theta0()
    prob.responses(theta)                               # every value checked once
    i = prob.free_names.index("c1=delay")
    for bad, words in ((5.0, "delay = 5 is outside"), (np.nan, "must be finite")):
        t = theta.copy()
        t[i] = bad
        with pytest.raises(InputError, match=words):
            prob.responses(t)


def test_jacobian_equals_the_difference_of_directs():
    """The Jacobian (by the resolvent, the small matrices differenced) equals its
    definition column by column: central differences of the weighted residual at
    the fixed nuisance, projected, at steps large enough that rounding does not
    count (1e-4 of each typical size: truncation about 1e-8), to 1e-6 of each
    column's largest entry with the matrices' central differences, 1e-5 with the
    forward ones the search takes (their truncation, the step 1e-6); a column at
    the differences' noise (a parameter without influence) to 1e-10 of the
    largest entry."""
    prob, _, _ = _problem("glauert+time-delay")
    st = _relax_S(prob, prob.theta0(), rounds=1)
    Js = [prob.jacobian(st.theta, st.weights, st.nus, st.bases, central=c)[0]
          for c in (True, False)]
    lo, hi = prob.bounds()
    h = 1e-4 * prob.typical(st.theta)
    Q = st.bases[0]
    B = np.empty_like(Js[0])
    for i in range(st.theta.size):
        tp, tm = st.theta.copy(), st.theta.copy()
        tp[i] += h[i]
        tm[i] -= h[i]
        assert lo[i] <= tm[i] and tp[i] <= hi[i]
        B[:, i] = (prob.direct(tp, st.weights, st.nus)[0]
                   - prob.direct(tm, st.weights, st.nus)[0]) / (tp[i] - tm[i])
    B -= Q @ (Q.T @ B)
    for J, rtol in zip(Js, (1e-6, 1e-5)):
        tol = np.maximum(rtol * np.max(np.abs(B), axis=0), 1e-10 * np.max(np.abs(B)))
        assert (np.max(np.abs(J - B), axis=0) <= tol).all()
