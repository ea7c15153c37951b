"""Candidate fits made cheap enough to offer the appended-state effects (issues #35,
#38): the flap response of a model whose appended states drive nothing, taken from
its leading states; the Levenberg-Marquardt step that holds a parameter at its
range limit; a start equal to an earlier one reported, not run again."""
import numpy as np
import pytest

from conftest import TWO_AXES, virtual
from inflowsim.identify import freqmodel as fm
from inflowsim.identify.estimator import _step, as_records, spectra_of
from inflowsim.model.build import build_model
from inflowsim.model.presets import theory_parameters
from inflowsim.model.structure import Structure


def _spectra(structure, hold):
    rec = (virtual(structure="glauert", seed=1, manoeuvres=TWO_AXES) if hold == "continuous"
           else virtual(structure="glauert", seed=1, manoeuvres=TWO_AXES, hold=hold, dt=0.02))
    s = Structure.parse(structure)
    return s, spectra_of(as_records(rec), s, (0.2256, 1.58), None)[0]


def _worst(a, b):
    return max(np.max(np.abs(x - y)) / np.max(np.abs(y)) for x, y in zip(a, b))


@pytest.mark.parametrize("structure,hold", [
    ("basic+lead-lag", "continuous"), ("glauert+lead-lag+time-delay", "continuous"),
    ("basic+flap-inertia+lead-lag", "continuous"), ("basic+lead-lag", "zoh")])
def test_states_that_drive_nothing_are_left_out_of_the_flap_response(structure, hold):
    s, sp = _spectra(structure, hold)
    p = theory_parameters(s, sp.constants)
    p["k_flap_lag"] = 0.0                     # the lag states driven, driving nothing
    if "delay" in p:
        p["delay"] = 0.03
    m = build_model(s, p, sp.constants)
    lead = fm.leading(m)
    n = m.a.shape[0] - 6
    assert lead.a.shape == (n, n) and lead.end_basis.shape == (n, 6)
    fast = fm.flap_response(m, sp)
    plain = fm._flap_response(m, sp, "solve")          # every state, each bin solved
    assert _worst(fast[:2], plain[:2]) < 1e-10


@pytest.mark.parametrize("structure,change", [
    ("basic+lead-lag", {}), ("basic+servo-actuators", {}), ("basic+flap-inertia", {}),
    ("glauert", {}), ("basic+servo-actuators", {"servo_tau": 5e-6})])
def test_coupled_states_are_kept(structure, change):
    s, sp = _spectra(structure, "continuous")
    m = build_model(s, {**theory_parameters(s, sp.constants), **change}, sp.constants)
    assert fm.leading(m) is m


def test_a_parameter_pushed_past_its_limit_is_held_in_the_step():
    rng = np.random.default_rng(3)
    J = rng.normal(size=(40, 4))
    H, g = J.T @ J, J.T @ rng.normal(size=40)
    damp = 1e-3 * np.diag(H)
    free = np.linalg.solve(H + np.diag(damp), -g)
    none = np.zeros(4, bool)
    # no parameter at a limit: the plain damped solve, number for number
    assert np.array_equal(_step(H, g, damp, none, none), free)
    # at a limit with the step pointing inside: the plain solve too
    at = np.sign(free) > 0                     # at the lower limit, stepping up
    assert np.array_equal(_step(H, g, damp, at, none), free)
    # at a limit with the step pointing out: held, the rest solved without it
    i = int(np.argmin(free))
    assert free[i] < 0
    lo = none.copy()
    lo[i] = True
    got = _step(H, g, damp, lo, none)
    keep = ~lo
    want = np.linalg.solve(H[np.ix_(keep, keep)] + np.diag(damp[keep]), -g[keep])
    assert got[i] == 0.0 and np.array_equal(got[keep], want)


def test_a_start_equal_to_an_earlier_one_is_reported_with_its_cost(monkeypatch):
    from inflowsim.identify import estimator, identify
    rec = virtual(structure="glauert", seed=1, manoeuvres=TWO_AXES)
    s = Structure.parse("basic+lead-lag")
    from inflowsim.model.effects import CATALOGUE
    neutral = CATALOGUE["lead-lag"].neutral_values(rec.constants)
    runs = []
    real = estimator.fit_from

    def counted(prob, theta, max_iter=100, report=None):
        runs.append(max_iter)
        return real(prob, theta, max_iter, report)
    monkeypatch.setattr(estimator, "fit_from", counted)
    # started at neutral (a saddle: its theory start is tried too), k_flap_lag held
    # there: the theory start is the plain start again
    fit = identify(rec, s, start=neutral, fixed={n: None for n in neutral})
    labels = [label for label, _ in fit.starts]
    assert labels[:2] == ["start", "start, lead-lag at theory"]
    assert fit.starts[0][1] == fit.starts[1][1]
    assert runs.count(estimator.SHORT_RUN) == len(fit.starts) - 1


@pytest.mark.parametrize("structure", [
    "basic+servo-actuators", "basic+lead-lag", "glauert+servo-actuators+lead-lag",
    "basic+flap-inertia+servo-actuators+lead-lag", "basic+peters-he-10+servo-actuators",
    "basic+flap-inertia+peters-he-6", "basic+wake-distortion-lag+servo-actuators"])
def test_appended_blocks_filled_in_place_are_the_stacked_ones_bit_for_bit(structure):
    from inflowsim.model.build import apply_effects
    import importlib
    eqs = importlib.import_module("inflowsim.model.equations")
    from inflowsim.model.params import PUMA
    s = Structure.parse(structure)
    k = PUMA.with_trim({"theta0": 0.17, "theta1c": 0.01, "theta1s": -0.05, "beta0": 0.06,
                        "beta1c": 0.01, "beta1s": 0.0, "muz": -0.02})
    p = theory_parameters(s, k)
    p.update({n: 0.03 for n in ("azimuth_bias",) if n in p})
    eq, _ = apply_effects(s, p, k)
    assert eq.blocks and all(eqs._float_block(bl) for bl in eq.blocks)
    fast = eqs._with_blocks_float(eq, s.second_order)
    plain = eqs._with_blocks_stacked(eq, s.second_order)
    for x, y in zip(fast, plain):
        assert x.shape == y.shape and x.dtype == y.dtype and x.flags.c_contiguous
        assert np.array_equal(x, y) and np.array_equal(np.signbit(x), np.signbit(y))


def test_a_later_part_that_acts_through_an_earlier_one_waits_for_it():
    from types import SimpleNamespace
    from inflowsim.diagnose.rule import atoms
    base = SimpleNamespace(structure=Structure.parse("basic"), fixed=())
    got = {a.label for a in atoms(base, ["servo-actuators", "lead-lag", "glauert"])}
    assert got == {"servo-actuators (servo_tau)", "lead-lag (k_flap_lag)",
                   "glauert (c1, c2, c3, c4)", "glauert (k0p, kc, ks)"}
    # once the first part is in (the second held at neutral), the second is tried
    lag = SimpleNamespace(structure=Structure.parse("basic+lead-lag"),
                          fixed=("nu_zeta", "zeta_lag"))
    assert [a.label for a in atoms(lag, ["lead-lag"])] == ["lead-lag (nu_zeta, zeta_lag)"]


def _plain_eig_products(m, sp):
    """The eigen path's products as first written: each formed, then assigned."""
    groups = fm.shift_groups(m)
    inp = np.empty((len(groups), sp.f_hz.size, m.a.shape[0]), dtype=complex)
    for g, (_, tau) in enumerate(groups):
        inp[g] = fm.continuous_input(sp, tau - float(m.input_delays[0])) @ m.b.T
    s, zs, ze = fm._terms(sp)
    q, u0, u1 = m.end_input, sp.u_time[0], sp.u_time[-1]
    if np.count_nonzero(q):
        inp += (np.outer(zs, q @ u0) + np.outer(ze, q @ u1))[None]
    lam, V, Vi = fm._eig(m.a)
    P, C, n, k = m.end_basis, m.c[:3], m.a.shape[0], m.end_basis.shape[1]
    r = 1.0 / (s[:, None] - lam)
    vp = Vi @ P
    y_u = np.empty((sp.f_hz.size, 3), dtype=complex)
    y_nu = np.zeros((sp.f_hz.size, 3, 2 * k * len(groups)), dtype=complex)
    for g, (rows, _) in enumerate(groups):
        cv = C[rows] @ V
        y_u[:, rows] = ((inp[g] @ Vi.T) * r) @ cv.T
        e = (r @ (cv.T[:, :, None] * vp[:, None, :]).reshape(n, -1)).reshape(-1, len(rows), k)
        y_nu[:, rows, 2 * k * g:2 * k * g + k] = zs[:, None, None] * e
        y_nu[:, rows, 2 * k * g + k:2 * k * (g + 1)] = ze[:, None, None] * e
    return y_u, y_nu


@pytest.mark.parametrize("structure", ["glauert", "glauert+lead-lag",
                                       "basic+flap-inertia+servo-actuators",
                                       "glauert+delay-beta1c"])
def test_the_eigen_products_written_in_place_are_the_plain_ones_bit_for_bit(structure):
    from inflowsim.identify.problem import Problem, stack
    s, sp = _spectra(structure, "continuous")
    p = theory_parameters(s, sp.constants)
    p.update({n: 0.02 * (i + 1) for i, n in enumerate(("delay_beta0", "delay_beta1c",
                                                       "delay_beta1s")) if n in p})
    m = fm.leading(build_model(s, p, sp.constants))
    got = fm._flap_response(m, sp, "auto")
    assert len(fm.shift_groups(m)) > 1 or structure != "glauert+delay-beta1c"
    for x, y in zip(got[:2], _plain_eig_products(m, sp)):
        x, y = (np.ascontiguousarray(v).view(float) for v in (x, y))
        assert np.array_equal(x, y) and np.array_equal(np.signbit(x), np.signbit(y))
    # the weighted residual stacked without temporaries: stack() of the plain one
    prob = Problem(s, [sp], p)
    W = np.linalg.inv(np.linalg.cholesky(np.array([[2.0, 0.3, 0.1], [0.3, 1.0, 0.2],
                                                   [0.1, 0.2, 0.5]])))
    nu = np.linspace(-1.0, 1.0, got[1].shape[2])
    want = stack((sp.Z - got[0] - got[1] @ nu) @ W.T)
    assert np.array_equal(prob._weighted([got[:2]], [W], [nu])[0], want)


@pytest.mark.parametrize("structure,hold,change,solve", [
    ("glauert+lead-lag", "continuous", {"k_flap_lag": 0.0}, False),
    ("basic+flap-inertia", "continuous", {}, False),
    ("glauert+time-delay", "continuous", {"delay": 0.03}, False),
    ("basic+delay-beta1c+delay-theta1s", "zoh", {"delay_beta1c": 0.013,
                                                 "delay_theta1s": -0.021}, False),
    ("basic+delay-beta1c+delay-theta1s", "continuous", {"delay_beta1c": 0.01}, True)])
def test_derivatives_by_the_resolvent_equal_differences_of_responses(
        structure, hold, change, solve, monkeypatch):
    # dy = dC R x + C R (dA R x + dx): leading states kept where a step couples
    # them (k_flap_lag = 0), the end-state manifold moving, time shifts of
    # continuous and held records, two shift groups, and each bin solved where
    # the eigenvectors are not to be trusted (a held record's shifts off whole
    # samples: there its response has a kink in the shift)
    from inflowsim.identify.problem import TYPICAL
    if solve:
        monkeypatch.setattr(fm, "EIG_COND", 0.0)
        monkeypatch.setattr(fm, "_EIGS", {})
    s, sp = _spectra(structure, hold)
    p = {**theory_parameters(s, sp.constants), **change}
    names = list(s.parameters)
    m0 = build_model(s, p, sp.constants)
    nu = np.random.default_rng(1).standard_normal(fm.flap_response(m0, sp)[1].shape[2])

    def y(q):
        y_u, y_nu, _ = fm.flap_response(build_model(s, q, sp.constants), sp)
        return y_u + y_nu @ nu
    pairs, ref = [], []
    for n in names:
        h = 1e-6 * max(abs(p[n]), TYPICAL.get(n, 0.1))
        pairs.append((build_model(s, {**p, n: p[n] + h}, sp.constants),
                      build_model(s, {**p, n: p[n] - h}, sp.constants), 2 * h))
        d = [(y({**p, n: p[n] + H}) - y({**p, n: p[n] - H})) / (2 * H)
             for H in (1e3 * h, 5e2 * h)]
        ref.append((4 * d[1] - d[0]) / 3)                     # Richardson
    got = fm.flap_derivatives(m0, pairs, sp, nu)
    W = np.linalg.cholesky(np.array([[2.0, 0.3, 0.1], [0.3, 1.0, 0.2], [0.1, 0.2, 0.5]]))
    weighted = fm.flap_derivatives(m0, pairs, sp, nu, W)
    top = max(np.max(np.abs(r)) for r in ref)
    for i, r in enumerate(ref):
        # a parameter without influence (nu_zeta at k_flap_lag = 0) at rounding
        scale = max(np.max(np.abs(r)), 1e-12 * top)
        assert np.max(np.abs(got[:, :, i] - r)) <= 1e-6 * scale, names[i]
        assert np.max(np.abs(weighted[:, :, i] - r @ W.T)) <= 1e-6 * scale * 3, names[i]
