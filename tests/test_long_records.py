"""Long records (issue #26): the band's work is done without full-length
temporaries, and it gives what the direct computation gives on normal records.

The eigen-decomposition route of the frequency response against the per-frequency
solve, the blocked evaluation against one block, the batched local-polynomial
noise against the loop it replaced, the streamed end-state least squares against
``lstsq``, the column-by-column transform against the 2-D FFT."""
import numpy as np
import pytest

from conftest import TWO_AXES, virtual
from inflowsim.data.record import find_trim, perturbations
from inflowsim.diagnose import diagnose, failures, lpm
from inflowsim.identify import evaluate, freqmodel, record_spectra
from inflowsim.identify.transform import dft
from inflowsim.model.build import build_model
from inflowsim.model.presets import preset_parameters
from inflowsim.model.structure import Structure

CASES = [  # structure of the truth and the fitted model, hold
    ("glauert", "continuous"),
    ("glauert", "zoh"),
    ("glauert+time-delay", "continuous"),
    ("glauert+flap-inertia", "continuous"),
    ("glauert+time-delay", "zoh"),
]


def _record(structure, hold):
    return virtual(structure="glauert", dt=1 / 64, seed=5, manoeuvres=TWO_AXES, hold=hold)


def _model(structure, rec):
    s = Structure.parse(structure)
    p = dict(preset_parameters("glauert", rec.constants, "paper"))
    extra = {"delay": 0.02, "flap_inertia": 0.3}
    return build_model(s, {n: p.get(n, extra.get(n)) for n in s.parameters}, rec.constants)


def _rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@pytest.mark.parametrize("structure,hold", CASES)
def test_eigen_route_equals_the_solve(structure, hold):
    rec = _record(structure, hold)
    m = _model(structure, rec)
    sp = record_spectra(rec, m.inputs, (0.2256, 1.58))
    y_e, nu_e, _ = freqmodel.flap_response(m, sp, method="eig")
    y_s, nu_s, _ = freqmodel.flap_response(m, sp, method="solve")
    assert _rel(y_e, y_s) < 1e-10 and _rel(nu_e, nu_s) < 1e-10


def test_blocks_equal_one_evaluation(monkeypatch):
    rec = _record("glauert+time-delay", "continuous")
    m = _model("glauert+time-delay", rec)
    sp = record_spectra(rec, m.inputs, (0.2256, 8.0))
    whole = freqmodel.flap_response(m, sp)
    monkeypatch.setattr(freqmodel, "BLOCK", 37)
    parts = freqmodel.flap_response(m, sp)
    assert _rel(parts[0], whole[0]) < 1e-13 and _rel(parts[1], whole[1]) < 1e-13
    cost = evaluate(rec, m.structure, dict(m.parameters)).cost
    monkeypatch.setattr(freqmodel, "BLOCK", 16384)
    assert evaluate(rec, m.structure, dict(m.parameters)).cost == pytest.approx(cost,
                                                                                 rel=1e-12)


def _lpm_loop(Z, U, half=lpm.LPM_HALF, degree=lpm.LPM_DEGREE):
    """The bin-by-bin local polynomial method the batched one replaced."""
    nf, p = Z.shape
    out = np.full((nf, p), np.nan)
    j = np.arange(-half, half + 1) / half
    P = np.vander(j, degree + 1, increasing=True)
    scale = np.abs(U).max(axis=0)
    U = U[:, scale > 0] / scale[scale > 0]
    for k in range(half, nf - half):
        w = slice(k - half, k + half + 1)
        X = np.hstack([P] + [U[w, [i]] * P for i in range(U.shape[1])])
        Q, s, _ = np.linalg.svd(X, full_matrices=False)
        r = int(np.sum(s > 1e-9 * s[0]))
        if r >= 2 * half + 1:
            continue
        e = Z[w] - Q[:, :r] @ (Q[:, :r].conj().T @ Z[w])
        out[k] = np.sum(np.abs(e) ** 2, axis=0) / (2 * half + 1 - r)
    return out


@pytest.mark.parametrize("m", [1, 3, 9])
def test_batched_local_polynomial_equals_the_loop(m, monkeypatch):
    rng = np.random.default_rng(m)
    Z = rng.standard_normal((300, 3)) + 1j * rng.standard_normal((300, 3))
    U = rng.standard_normal((300, m)) + 1j * rng.standard_normal((300, m))
    U[:, 0] *= 0.0                       # a dead input is dropped, as before
    monkeypatch.setattr(lpm, "_BLOCK", 50)
    a, b = lpm.local_polynomial_noise(Z, U), _lpm_loop(Z, U)
    assert np.array_equal(np.isnan(a), np.isnan(b))
    ok = np.isfinite(b)
    assert ok.any() == (m < 9) and np.allclose(a[ok], b[ok], rtol=1e-12, atol=0)


def test_streamed_end_states_equal_lstsq(monkeypatch):
    rng = np.random.default_rng(2)
    y_nu = rng.standard_normal((500, 3, 6)) + 1j * rng.standard_normal((500, 3, 6))
    y_nu[:, :, 5] = y_nu[:, :, 4]         # a dependent column: the minimum-norm answer
    e = rng.standard_normal((500, 3)) + 1j * rng.standard_normal((500, 3))
    whole = failures._end_states(y_nu, e)
    monkeypatch.setattr(failures, "STREAM_BINS", 64)
    assert np.allclose(failures._end_states(y_nu, e), whole, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("structure,hold", [c for c in CASES if c[1] == "continuous"])
def test_streamed_floor_power_equals_the_whole(structure, hold, monkeypatch):
    # the floor band's residual power block by block (end-state responses never
    # held whole) against the whole arrays and lstsq.  Continuous records only: a
    # held record's end-state responses over this band are near rank-deficient,
    # where the QR's lstsq (its cutoff from R's 2kG rows) and the whole lstsq (from
    # all rows) keep different directions, before this change as after
    rec = _record(structure, hold)
    m = _model(structure, rec)
    sp = record_spectra(rec, m.inputs, (5.0, 25.6), hold=hold, require_motion=False)
    y_u, y_nu, _ = freqmodel.flap_response(m, sp)
    e = sp.Z - y_u
    whole = np.abs(e - y_nu @ failures._end_states(y_nu, e)) ** 2
    monkeypatch.setattr(failures, "STREAM_BINS", 97)
    assert sp.f_hz.size > 3 * 97
    parts = failures._floor_power_streamed(m, sp)
    assert parts.shape == whole.shape and np.allclose(parts, whole, rtol=1e-9, atol=0)
    floor, *_ = failures.noise_floor(rec, m, (0.2256, 1.58), hold, sp.f_hz[:5],
                                     check_colour=False)
    monkeypatch.setattr(failures, "STREAM_BINS", 16384)
    floor_whole, *_ = failures.noise_floor(rec, m, (0.2256, 1.58), hold, sp.f_hz[:5],
                                           check_colour=False)
    assert np.allclose(floor, floor_whole, rtol=1e-9, atol=0)


def test_transform_by_column_and_by_block(monkeypatch):
    rng = np.random.default_rng(3)
    x = rng.standard_normal((1000, 4))
    k = np.arange(3, 40)
    on = dft(x, 0.01, k / 10.0, True)
    assert np.array_equal(on, np.fft.rfft(x, axis=0)[k])
    f = np.array([0.31, 0.77, 1.4])
    whole = np.exp(-2j * np.pi * np.outer(f, np.arange(1000)) * 0.01) @ x
    import inflowsim.identify.transform as tr
    monkeypatch.setattr(tr, "_DFT_BLOCK", 77)
    assert np.allclose(dft(x, 0.01, f, False), whole, rtol=1e-12, atol=1e-12)


def test_perturbations_are_shared_and_read_only():
    rec = _record("glauert", "continuous")
    trim = find_trim(rec)
    a = perturbations(rec, trim, ("theta0", "q"))
    assert perturbations(rec, trim, ("theta0", "q")) is a
    with pytest.raises(ValueError):
        a[0, 0] = 1.0
    assert np.array_equal(a[:, 1], rec["q"] - trim.values["q"])


@pytest.mark.parametrize("base", ["basic", "empirical"])
def test_diagnosis_same_by_either_route(base, monkeypatch):
    """The decisions by the eigen route equal those of the per-frequency solve.

    A well-determined fit (``basic``) ends at the same point: cost to 1e-9,
    estimates to 1e-5 of their bounds.  A fit with a flat valley
    (``empirical`` on this record: ``tau0`` within 2 of its bound of 2) stops
    where rounding at 1e-16 leads it inside the optimiser's tolerance, as any
    change of summation order does: there, the cost to 1e-5 (a thousandth of
    a unit of log-likelihood) and the estimates to 0.05 of their bounds."""
    rec = _record("glauert", "continuous")
    pool = ["flap-inertia", "time-delay"]
    fast = diagnose(rec, base, pool=pool, assess=False)   # the decisions (no map)
    monkeypatch.setattr(freqmodel, "EIG_COND", 0.0)      # every response solved
    slow = diagnose(rec, base, pool=pool, assess=False)
    assert fast.missing_effect == slow.missing_effect
    assert [c.effect for c in fast.candidates] == [c.effect for c in slow.candidates]
    assert [c.accepted for c in fast.candidates] == [c.accepted for c in slow.candidates]
    rel, in_sigma = (1e-9, 1e-5) if base == "basic" else (1e-5, 0.05)
    assert fast.fit.cost == pytest.approx(slow.fit.cost, rel=rel)
    for n, v in slow.fit.parameters.items():
        sig = slow.fit.sigma.get(n) or abs(v)
        assert abs(fast.fit.parameters[n] - v) < in_sigma * sig, n


def test_thin_svd_equals_numpys():
    # the QR route of a tall matrix's SVD (a long record's end-state columns) gives
    # NumPy's numbers bit for bit, its U in Fortran order; a rank-deficient one too
    from inflowsim.identify.problem import thin_svd
    rng = np.random.default_rng(4)
    A = rng.standard_normal((5000, 12)) * np.logspace(0, -6, 12)
    B = A.copy()
    B[:, 11] = B[:, 3] - 2 * B[:, 7]
    for X in (A, B):
        got, ref = thin_svd(X), np.linalg.svd(X, full_matrices=False)
        assert got[0].flags.f_contiguous
        for g, r in zip(got, ref):
            np.testing.assert_array_equal(g, r)
    F = np.asfortranarray(A)
    thin_svd(F)
    assert np.array_equal(F, A)                   # not overwritten unless asked


def test_nuisance_by_the_qr_route_equals_the_plain_one(monkeypatch):
    # every record's nuisance, basis and residual by thin_svd's route (a 2-hour
    # record's) against NumPy's SVD (a normal record's), on the same problem
    from inflowsim.identify import problem
    rec = _record("glauert", "continuous")
    m = _model("glauert+time-delay", rec)
    sp = record_spectra(rec, m.inputs, (0.2256, 1.58))
    prob = problem.Problem(m.structure, [sp], dict(m.parameters))
    resp = prob.responses(prob.theta0())
    W = [problem.Problem.weight(np.array([[2.0, 0.3, 0.1], [0.3, 1.0, 0.2],
                                          [0.1, 0.2, 0.5]]))]
    plain = prob.solve_nuisance(resp, W)
    monkeypatch.setattr(problem, "THIN_ROWS", 0)
    fast = prob.solve_nuisance(resp, W)
    assert 6 * sp.f_hz.size >= 4 * plain[0][1].shape[1]         # the route was taken
    for a, b in zip(plain[0], fast[0]):
        np.testing.assert_array_equal(a, b)


def test_spectra_made_for_one_use_are_not_kept():
    from inflowsim.identify import transform
    rec = _record("glauert", "continuous")
    once = record_spectra(rec, ("theta0",), (5.0, 25.6), require_motion=False, keep=False)
    assert not any(k[0] == ("theta0",) for k in transform._SPECTRA.get(rec, {}))
    kept = record_spectra(rec, ("theta0",), (5.0, 25.6), require_motion=False)
    assert kept is not once and np.array_equal(kept.Z, once.Z)
    assert record_spectra(rec, ("theta0",), (5.0, 25.6), require_motion=False,
                          keep=False) is kept


def test_candidates_judged_against_the_base_floors_as_by_their_own_analyses():
    # line 4 measures a candidate against the base's floors: taking them (not
    # measuring the candidate's own) gives the numbers of its full analyses
    from inflowsim.diagnose.excess import judge
    from inflowsim.diagnose.failures import analyses_of, level_deviance, structure_statistic
    from inflowsim.identify import identify
    rec = _record("glauert", "continuous")
    base = identify(rec, "basic")
    cand = identify(rec, "glauert")
    ras = analyses_of([rec], base, (0.2256, 1.58))
    got = judge([rec], (0.2256, 1.58), base, ras)(cand)
    own = analyses_of([rec], cand, (0.2256, 1.58), check_colour=False)[0]
    assert not np.array_equal(own.floor, ras[0].floor)        # its own floor differs
    taken = analyses_of([rec], cand, (0.2256, 1.58), check_colour=False, floors_of=ras)[0]
    assert taken.floor is ras[0].floor
    assert (taken.U is ras[0].U) == (taken.inputs == ras[0].inputs)   # the same inputs
    np.testing.assert_array_equal(taken.error, own.error)
    np.testing.assert_array_equal(taken.U, own.U)
    assert got["deviance"] == level_deviance(own, ras[0].floor)
    assert got["structure"] == structure_statistic(own, ras[0].floor)


def _colored_by_index(prob, st, blocks, cov):
    """The coloured sandwich as it was written, each lag's bins by index arrays."""
    from inflowsim.identify.estimator import HALF_WINDOW
    from inflowsim.identify.problem import unstack
    V = np.zeros_like(cov)
    for sp, blk, r in zip(prob.spectra, blocks, st.r):
        Vr = np.zeros_like(cov)      # per record, as the sandwich sums (its factor g)
        nf = sp.f_hz.size
        lmax = int(np.ceil(nf ** (1 / 3)))
        h = blk.shape[0] // 2
        G = (blk[:h] + 1j * blk[h:]).reshape(nf, 3, -1)
        e = unstack(r, nf)
        for j in range(-lmax, lmax + 1):
            k = np.arange(max(j, 0), nf + min(j, 0))
            prod = e[k][:, :, None] * e[k - j].conj()[:, None, :]
            cs = np.concatenate([np.zeros((1, 3, 3), complex), np.cumsum(prod, axis=0)])
            lo = np.clip(np.arange(k.size) - HALF_WINDOW, 0, k.size)
            hi = np.clip(np.arange(k.size) + HALF_WINDOW + 1, 0, k.size)
            R = (cs[hi] - cs[lo]) / (hi - lo)[:, None, None]
            w = 1 - abs(j) / (lmax + 1)
            RG = (R @ G[k - j]).reshape(-1, G.shape[2])
            Vr += 2.0 * w * np.real(G[k].reshape(-1, G.shape[2]).conj().T @ RG)
        V += Vr
    return cov @ V @ cov


def test_coloured_sandwich_by_slices_equals_by_index():
    from types import SimpleNamespace
    from inflowsim.identify.estimator import _colored
    rng = np.random.default_rng(6)
    spectra, blocks, rs = [], [], []
    for nf in (37, 400):
        spectra.append(SimpleNamespace(f_hz=np.zeros(nf)))
        blocks.append(rng.standard_normal((6 * nf, 5)))
        rs.append(rng.standard_normal(6 * nf))
    prob, st = SimpleNamespace(spectra=spectra), SimpleNamespace(r=rs)
    cov = np.linalg.inv(sum(b.T @ b for b in blocks))
    np.testing.assert_array_equal(_colored(prob, st, blocks, cov),
                                  _colored_by_index(prob, st, blocks, cov))


def test_manoeuvre_transforms_skip_only_the_quiet_inputs():
    # a standard manoeuvre's inputs at zero are not transformed: the same U as
    # transforming every column
    from inflowsim.flighttest.advice import standard_manoeuvres
    from inflowsim.identify.identifiability import _manoeuvre_spectra
    from inflowsim.identify.transform import transform_weights
    rec = _record("glauert", "continuous")
    s = Structure.parse("glauert")
    sp = record_spectra(rec, s.inputs, (0.2256, 1.58))
    label, cols = next(iter(standard_manoeuvres(sp.n_samples, sp.dt, sp.constants)))
    msp = _manoeuvre_spectra(sp, s, cols)
    assert 0 < np.count_nonzero(np.any(msp.u_time != 0, axis=0)) < len(s.inputs)
    whole = dft(msp.u_time, sp.dt, sp.f_hz, True, transform_weights(sp.n_samples, sp.hold))
    np.testing.assert_array_equal(msp.U, whole)
