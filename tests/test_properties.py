"""Property-based checks (hypothesis) of structures, models and records."""
import numpy as np
from hypothesis import given, settings, strategies as st

from inflowsim import PUMA, Structure, build_model, theory_parameters
from inflowsim.data.record import Record, format_record, parse_record

PAPER_EFFECTS = ["separate-time-constants", "hub-velocity-coupling", "glauert",
                 "azimuth-bias", "time-delay"]


@st.composite
def structures(draw):
    effs = draw(st.lists(st.sampled_from(PAPER_EFFECTS), unique=True))
    if "glauert" in effs and "hub-velocity-coupling" in effs:
        effs.remove("hub-velocity-coupling")
    return effs


@given(structures(), st.randoms())
def test_structure_is_a_set(effs, rnd):
    shuffled = list(effs)
    rnd.shuffle(shuffled)
    a, b = Structure(tuple(effs)), Structure(tuple(shuffled))
    assert a == b and a.parameters == b.parameters
    assert Structure.parse(a.name) == a
    assert len(set(a.parameters)) == len(a.parameters)


@settings(max_examples=40, deadline=None)
@given(structures(), st.floats(0.1, 0.5), st.floats(0.5, 1.5), st.floats(1.0, 1.3))
def test_theory_models_are_stable_and_consistent(effs, mu, nb, lb2):
    k = PUMA.with_mu(mu)
    p = theory_parameters(Structure(tuple(effs)), k) | {"n_beta": nb, "lambda_beta2": lb2}
    m = build_model(Structure(tuple(effs)), p, k)
    assert np.all(np.isfinite(m.a)) and m.is_stable()
    # the SI model reproduces the descriptor: E x_dot = Omega A x for every state
    np.testing.assert_allclose(m.E @ m.a, k.omega * m.A, atol=1e-9 * np.max(np.abs(m.A)) * k.omega)


finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


@settings(max_examples=30, deadline=None)
@given(st.lists(st.tuples(finite, finite), min_size=4, max_size=30), st.floats(1e-4, 1.0))
def test_record_text_round_trip(values, dt):
    t = np.arange(len(values)) * dt
    v = np.array(values)
    rec = Record.from_arrays(t, {"beta0": v[:, 0], "theta0": v[:, 1]},
                             {"omega": 27.5, "mu": 0.249, "a0": 5.73, "solidity": 0.0917})
    back = parse_record(format_record(rec))
    np.testing.assert_allclose(back["beta0"], rec["beta0"], rtol=1e-11, atol=1e-300)
    np.testing.assert_allclose(back.t, t, rtol=1e-11, atol=1e-15)
