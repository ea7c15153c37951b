"""The stepping algorithms written once (inflowsim.simulate.algorithms): the C the
FMU compiles is generated from them (inflowsim.fmu.pyc, fmu/inflow_algorithms.c),
and the Python the Simulator runs and the generated C give the same numbers on the
same inputs."""
import ctypes
import subprocess

import numpy as np
import pytest
from scipy.linalg import expm as scipy_expm

from inflowsim.errors import InputError
from inflowsim.fmu import pyc
from inflowsim.fmu.build import CFLAGS, compiler, source_dir
from inflowsim.simulate import algorithms as alg
from inflowsim.simulate import mutable
from inflowsim.simulate.discrete import TaylorZoh

NA = 16          # the presets' FMU (fmu/inflow_vars.h): 6 states and 10 inputs
NTAB, HALF0 = 224, 128  # its mu table's entries, and those of [phi gam] (inflow_numerics.h:
#                          IFS_PG_N, by columns of 8)
LD, NU, NPHI, RL = 8, 10, 48, 16  # a column's length, the inputs, phi's entries
#                                  (IFS_MU_NPHI), [x; u]'s length (IFS_RL)
ENTRIES = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_double,
                           ctypes.POINTER(ctypes.c_double))


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    src = source_dir()
    head = (src / "inflow_vars.h").read_text()
    assert "#define IFS_NX 6 " in head and "#define IFS_N_INPUTS 10 " in head   # NA ...
    so = tmp_path_factory.mktemp("alg") / "alg.so"
    # -O0: a third of the compile time; without contraction the same numbers
    flags = [("-O0" if f == "-O2" else f) for f in CFLAGS if f != "-fvisibility=hidden"]
    subprocess.run([compiler(), *flags, f"-I{src}", "-o", str(so),
                    str(src / "inflow_numerics.c"), str(src / "inflow_algorithms.c"), "-lm"],
                   check=True)
    lib = ctypes.CDLL(str(so))
    d, i, p = ctypes.c_double, ctypes.c_int, ctypes.POINTER(ctypes.c_double)
    lib.ifs_taylor_count.argtypes, lib.ifs_taylor_count.restype = (d, d, d), i
    lib.ifs_taylor_prepare.argtypes = (p, p, p, p, p)
    lib.ifs_expm.argtypes, lib.ifs_expm.restype = (p,), i
    lib.ifs_cheb_matrices.argtypes = (i, p, p)
    lib.ifs_power_fit.argtypes = (i, p, p, p, i, i, p, p, i)
    lib.ifs_mu_edges.argtypes = (d, d, p, i, p)
    lib.ifs_mu_check.argtypes = (p, i, ENTRIES, ctypes.c_void_p, ENTRIES, ctypes.c_void_p, i)
    lib.ifs_mu_check.restype = d
    lib.ifs_mu_fit.argtypes, lib.ifs_mu_fit.restype = (p, i, ENTRIES, ctypes.c_void_p, p, p), i
    lib.ifs_taylor_step.argtypes = (p, p, i, d, p)
    lib.ifs_mu_parts.argtypes = (p, i, p, p, p, p)
    lib.ifs_mu_part.argtypes, lib.ifs_mu_part.restype = (p, p, d), i
    lib.ifs_mu_eval.argtypes = (p, p, p, p, p, d, p)
    lib.ifs_mu_eval_coarse.argtypes = (p, p, p, p, d, i, i, p)
    lib.ifs_mu_eval_held.argtypes = (p, p, p, d, p)
    lib.ifs_mu_eval_range.argtypes = (p, p, d, i, i, p)
    if hasattr(lib, "ifs_mu_eval_fma"):
        lib.ifs_mu_eval_fma.argtypes = (p, p, p, p, p, d, p)
        lib.ifs_mu_eval_held_fma.argtypes = lib.ifs_mu_eval_held.argtypes
        lib.ifs_mu_eval_range_fma.argtypes = lib.ifs_mu_eval_range.argtypes
    return lib


def _p(x):
    return x.ctypes.data_as(ctypes.POINTER(ctypes.c_double))


def test_python_and_generated_c_agree(lib):
    """One body for every algorithm: the Python function and its generated C on the
    same inputs, within 1e-12 (the same operations; NumPy's primitives may sum in
    another order), the term counts equal."""
    rng = np.random.default_rng(40)
    # the Taylor rule's term count: integers, equal
    for na, nab, r in [(5.0, 9.0, 1e-3), (80.0, 300.0, 0.01), (1e3, 2e3, 1.0), (0.0, 0.0, 0.1),
                       *rng.uniform(0, 200, (40, 3)) * [1, 2, 0.002]]:
        assert lib.ifs_taylor_count(na, nab, r) == alg.taylor_count(na, nab, r)
    # the Taylor step: the FMU's layout ([a b] by padded rows and by padded columns,
    # one column [x; u]) against the Python on the same arrays, and the Simulator's
    # use (the columns of the identity) against scipy's exponential
    nx, rl, ld = 6, 16, 8
    a = rng.standard_normal((nx, nx)) * 20 - 40 * np.eye(nx)
    b = rng.standard_normal((nx, NA - nx)) * 10
    ab = np.hstack([a, b])
    # its preparation: [a b] by padded rows and columns (over a stale fill), the norms
    abr, abc, norms = np.full(nx * rl, 7.0), np.full(NA * ld, 7.0), np.zeros(2)
    cabr, cabc, cnorms = abr.copy(), abc.copy(), norms.copy()
    alg.taylor_prepare(a.ravel(), b.ravel(), abr, abc, norms, nx, NA - nx, rl, ld)
    lib.ifs_taylor_prepare(_p(a.ravel()), _p(b.ravel()), _p(cabr), _p(cabc), _p(cnorms))
    assert np.array_equal(abr, cabr) and np.array_equal(abc, cabc)
    assert np.array_equal(norms, cnorms)
    rows, cols = abr.reshape(nx, rl), abc.reshape(NA, ld)
    assert np.array_equal(rows[:, :NA], ab) and not rows[:, NA:].any()
    assert np.array_equal(cols[:, :nx], ab.T) and not cols[:, nx:].any()
    assert norms[0] == np.abs(a).sum(axis=0).max() and norms[1] == np.abs(ab).sum(axis=0).max()
    for r in (4e-3, -1.5e-3, 0.02):
        nk = alg.taylor_count(norms[0], norms[1], r)
        z = np.zeros(rl)
        z[:NA] = rng.standard_normal(NA)
        py, c = z.copy(), z.copy()
        alg.taylor_step(abr, abc, nk, r, py, nx, rl, ld, 1)
        lib.ifs_taylor_step(_p(abr), _p(abc), nk, r, _p(c))
        want = scipy_expm(np.vstack([ab, np.zeros((NA - nx, NA))]) * r)[:nx] @ z[:NA]
        assert 0 < nk and np.array_equal(py[nx:], z[nx:]) and np.array_equal(c[nx:], z[nx:])
        assert np.max(np.abs(py - c)) <= 1e-13 * np.max(np.abs(want))
        assert np.max(np.abs(py[:nx] - want)) <= 1e-12 * np.max(np.abs(want))
        phi, gam = TaylorZoh(a, b)(abs(r))
        want = scipy_expm(np.vstack([ab, np.zeros((NA - nx, NA))]) * abs(r))[:nx]
        assert np.max(np.abs(np.hstack([phi, gam]) - want)) <= 1e-12 * np.max(np.abs(want))
    # the exponential of an augmented [[a b] dt; 0 0] and of a large-norm matrix
    # (squarings), both against scipy too
    for scale in (0.01, 0.3, 4.0):
        m = np.zeros((NA, NA))
        m[:6] = rng.standard_normal((6, NA)) * scale
        m[:6, :6] -= 2 * scale * np.eye(6)
        py, c = m.reshape(-1).copy(), m.reshape(-1).copy()
        assert alg.expm(py, NA) == 0 and lib.ifs_expm(_p(c)) == 0
        want = scipy_expm(m).reshape(-1)
        top = np.max(np.abs(want))
        assert np.max(np.abs(py - c)) <= 1e-12 * top
        assert np.max(np.abs(py - want)) <= 1e-12 * top
    bad = np.full(NA * NA, np.nan)
    assert alg.expm(bad.copy(), NA) == -1 and lib.ifs_expm(_p(bad.copy())) == -1
    # the table's fit: the interpolation matrices, then a fit of values with rows
    # apart (the C fits the parts from rows of a wider array)
    for n in (5, 8):
        ch, tt, cch, ctt = (np.zeros(n * n) for _ in range(4))
        alg.cheb_matrices(n, ch, tt)
        lib.ifs_cheb_matrices(n, _p(cch), _p(ctt))
        assert np.max(np.abs(ch - cch)) <= 1e-15 and np.array_equal(tt, ctt)
        cols, ldf, ldo = 7, 11, 9
        f = rng.standard_normal(n * ldf)
        out, cout = np.zeros(n * ldo), np.zeros(n * ldo)
        alg.power_fit(n, ch, tt, f, cols, ldf, np.zeros(n * cols), out, ldo)
        lib.ifs_power_fit(n, _p(ch), _p(tt), _p(f), cols, ldf, _p(np.zeros(n * cols)),
                          _p(cout), ldo)
        assert np.max(np.abs(out - cout)) <= 1e-12 * np.max(np.abs(out))
        # ... and the fit interpolates: the polynomial at the nodes is the values
        x = np.cos(np.pi * (np.arange(n) + 0.5) / n)
        coef = out.reshape(n, ldo)[:, :cols]
        vals = np.vander(x, n, increasing=True) @ coef
        np.testing.assert_allclose(vals, f.reshape(n, ldf)[:, :cols], rtol=0, atol=1e-13)
    # the table's segment ends, with a schedule's knots: the same doubles
    for knots in ((), (0.12, 0.3, 0.45), (0.1, 0.2 + 1e-12, 0.49)):
        kn = np.array(mutable.knot_edges(knots))
        e = np.zeros(mutable.SEGMENTS + len(kn) + 1)
        lib.ifs_mu_edges(mutable.MU_LO, mutable.MU_HI, _p(kn), len(kn), _p(e))
        geo = [mutable.MU_LO * (mutable.MU_HI / mutable.MU_LO) ** (s / mutable.SEGMENTS)
               for s in range(mutable.SEGMENTS + 1)]
        assert list(e) == mutable.edges(knots)
        np.testing.assert_allclose(e, sorted(geo + list(kn)), rtol=1e-15)
    # the table's segments and parts, of entries analytic on [0.1, 0.5]
    k = np.arange(NTAB)

    def exact(ctx, mu, out):
        out[:NTAB] = np.sin((1 + k % 7) * mu) / mu + np.exp(-mu * (k % 5))
        return 0

    def c_exact(ctx, mu, out):
        return exact(ctx, mu, np.ctypeslib.as_array(out, (NTAB,)))

    edge = np.array(mutable.edges())
    nseg = len(edge) - 1
    shapes = (nseg * (mutable.DEGREE + 1) * NTAB,
              nseg * mutable.SPLIT * (mutable.FINE_DEGREE + 1) * HALF0)
    (pp, pq), (cp, cq) = [tuple(np.zeros(s) for s in shapes) for _ in range(2)]
    assert alg.mu_fit(edge, nseg, exact, None, pp, pq, mutable.DEGREE, mutable.FINE_DEGREE,
                      mutable.SPLIT, NTAB, HALF0) == 0
    assert lib.ifs_mu_fit(_p(edge), nseg, ENTRIES(c_exact), None, _p(cp), _p(cq)) == 0
    for py, c in ((pp, cp), (pq, cq)):
        assert np.max(np.abs(py - c)) <= 1e-12 * np.max(np.abs(py))
    # the part search and the table's evaluation (what a mu change reads): the parts
    # of bisection, at their starts too, and their segments (within the rounding of
    # a cell's start the part before: mu is then at most a few units of the last
    # place outside its [-1, 1]); the values, of the parts (with and without the
    # CPU's fused multiply-adds: the same numbers) and of [a b]
    npart = nseg * mutable.SPLIT
    parts = [np.zeros(n) for n in (npart + 1, npart, npart, mutable.GUESS_CELLS)]
    cparts = [np.zeros_like(a) for a in parts]
    table = (npart, mutable.GUESS_CELLS, mutable.MU_LO, mutable.MU_HI)
    alg.mu_parts(edge, nseg, *parts, *table, mutable.SPLIT)
    lib.ifs_mu_parts(_p(edge), nseg, *map(_p, cparts))
    assert all(np.array_equal(a, b) for a, b in zip(parts, cparts))
    pstart, pmid, pscale, guess = parts
    assert np.array_equal(pstart[:-1:mutable.SPLIT], edge[:-1]) and pstart[-1] == np.inf
    # a step at most: each cell narrower than any part
    assert np.max(np.diff(guess)) <= 1 and np.min(np.diff(edge)) / mutable.SPLIT > (
        mutable.MU_HI - mutable.MU_LO) / mutable.GUESS_CELLS
    fma = hasattr(lib, "ifs_mu_eval_fma") and {"avx2", "fma"} <= set(
        open("/proc/cpuinfo").read().split())
    for mu in (*edge, *pstart[1:-1:7], *rng.uniform(mutable.MU_LO, mutable.MU_HI, 20)):
        j = alg.mu_part(pstart, guess, mu, *table)
        assert j == lib.ifs_mu_part(_p(pstart), _p(guess), mu)
        assert j in (int(np.searchsorted(pstart, mu, side="right")) - 1,
                     int(np.searchsorted(pstart, mu * (1 + 1e-15), side="right")) - 1)
        assert j // mutable.SPLIT == min(int(np.searchsorted(edge, mu, side="right")) - 1,
                                         nseg - 1)
        assert -1 - 1e-12 <= (mu - pmid[j]) * pscale[j] <= 1 + 1e-12
        py, c, cf = np.zeros(HALF0), np.zeros(HALF0), np.zeros(HALF0)
        alg.mu_eval(pstart, pmid, pscale, list(guess), pq, mu, py, *table,
                    mutable.FINE_DEGREE, HALF0)
        lib.ifs_mu_eval(*map(_p, parts), _p(cq), mu, _p(c))
        assert np.max(np.abs(py - c)) <= 1e-12 * np.max(np.abs(c))
        if fma:
            lib.ifs_mu_eval_fma(*map(_p, parts), _p(cq), mu, _p(cf))
            assert np.array_equal(c, cf)
        # a mu change with the inputs held: phi alone (mu_eval's numbers) and g = gam
        # u from the segment's power coefficients of gam u (made for the segment, then
        # kept), gam when it is read (mu_eval_range: mu_eval's numbers); the model's
        # block [phi gam], [x; u], g, gq, its segment plus one and mu; the table's
        # segment ends and parts one after the other
        u = rng.normal(size=NU) * (rng.uniform(size=NU) > 0.2)
        gam = c[NPHI:].reshape(NU, LD).T
        gu = np.max(np.abs(gam) @ np.abs(u))
        coarse = np.zeros(HALF0 - NPHI)      # gam of the segment's polynomials
        lib.ifs_mu_eval_coarse(_p(edge), _p(pstart), _p(guess), _p(cp), mu, NPHI,
                               HALF0 - NPHI, _p(coarse))
        coarse = coarse.reshape(NU, LD).T
        block = np.concatenate([edge, *parts])
        seg = j // mutable.SPLIT
        at = HALF0 + RL + LD
        tail = at + (mutable.DEGREE + 1) * LD
        for make in ((True, False) if fma else (False,)):
            held, rng_ = ((lib.ifs_mu_eval_held_fma, lib.ifs_mu_eval_range_fma) if make
                          else (lib.ifs_mu_eval_held, lib.ifs_mu_eval_range))
            cm = np.full(tail + 4, 7.0)
            cm[HALF0 + 6:HALF0 + 6 + NU] = u
            cm[tail] = -1.0 - nseg          # none made
            held(_p(block), _p(cq), _p(cp), mu, _p(cm))
            assert cm[tail] == seg + 1 and cm[tail + 1] == mu
            assert np.array_equal(cm[:NPHI], c[:NPHI]) and np.all(cm[NPHI:HALF0] == 7.0)
            g = cm[HALF0 + RL:at].copy()
            assert np.max(np.abs(g - coarse @ u)) <= 1e-14 * gu
            assert np.max(np.abs(g - gam @ u)) <= 1e-10 * gu
            cm[at] += 1.0                   # gq kept for the segment: so 1 more in g_0
            for state in (seg + 1, -seg - 1):    # (negative: gam evaluated since)
                cm[tail] = state
                held(_p(block), _p(cq), _p(cp), mu, _p(cm))
                assert cm[tail] == seg + 1 and abs(cm[HALF0 + RL] - 1.0 - g[0]) <= 1e-13 * gu
            cm[at] -= 1.0
            ch = cm[:HALF0].copy()
            rng_(_p(block[nseg + 1:]), _p(cq), mu, NPHI, HALF0 - NPHI, _p(ch))
            assert np.array_equal(ch, c)
        pm = np.full(tail + 4, 7.0)
        pm[HALF0 + 6:HALF0 + 6 + NU] = u
        pm[tail] = 0.0
        alg.mu_eval_held(block, pq, pp.ravel(), mu, pm, nseg, *table, mutable.SPLIT,
                         mutable.DEGREE, mutable.FINE_DEGREE, HALF0, NTAB, NPHI, LD, 6, NU, RL)
        held(_p(block), _p(cq), _p(cp), mu, _p(cm))
        assert np.max(np.abs(pm[:tail + 2] - cm[:tail + 2])) <= 1e-12 * np.max(np.abs(cm))
        alg.mu_eval_range(block[nseg + 1:], pq, mu, NPHI, HALF0 - NPHI, pm, *table,
                          mutable.FINE_DEGREE, HALF0)
        assert np.max(np.abs(pm[:HALF0] - c)) <= 1e-12 * np.max(np.abs(c))
        py, c = np.zeros(NTAB - HALF0), np.zeros(NTAB - HALF0)
        alg.mu_eval_coarse(edge, pstart, guess, pp, mu, HALF0, NTAB - HALF0, py, *table,
                           mutable.SPLIT, mutable.DEGREE, NTAB)
        lib.ifs_mu_eval_coarse(_p(edge), _p(pstart), _p(guess), _p(cp), mu, HALF0,
                               NTAB - HALF0, _p(c))
        assert np.max(np.abs(py - c)) <= 1e-12 * np.max(np.abs(c))
        exact(None, mu, want := np.zeros(NTAB))
        assert np.max(np.abs(c - want[HALF0:])) <= 1e-9 * np.max(np.abs(want))
    # the check: a table off by 1e-9 of the first half's scale at one mu, and a NaN

    def table(ctx, mu, out):
        exact(ctx, mu, out)
        out[5] += 1e-9 * np.max(np.abs(out[:HALF0])) * (mu > 0.3)
        out[HALF0 + 2] = np.nan if ctx and mu > 0.4 else out[HALF0 + 2]
        return 0

    for nan in (0, 1):
        def c_table(ctx, mu, out):
            return table(ctx, mu, np.ctypeslib.as_array(out, (NTAB,)))
        py = alg.mu_check(edge, nseg, exact, None, table, nan, HALF0, NTAB)
        c = lib.ifs_mu_check(_p(edge), nseg, ENTRIES(c_exact), None, ENTRIES(c_table),
                             nan, HALF0)
        assert (np.isnan(py) and np.isnan(c)) if nan else py == pytest.approx(c, rel=1e-12)
        assert nan or 0.9e-9 < py < 1.1e-9


def test_the_translator_refuses_what_it_cannot_translate():
    """Outside the subset: one line naming the statement and where it is."""
    def f(a: alg.Vec, n: int) -> None:
        for i, v in enumerate(a):
            a[i] = v

    alg.ALGORITHMS.append((f, "ifs_bad", False, {}))
    try:
        with pytest.raises(InputError, match="outside the subset"):
            pyc.algorithms_c()
    finally:
        alg.ALGORITHMS.pop()


def test_the_flow_speed_is_the_physics_one(lib):
    """The speed through the disc (inflowsim.physics.loads.flow_speed, the mass-flow
    parameter by Newton's method) translated: the same numbers, hover to mu = 0.5."""
    from inflowsim.physics import loads as ld
    d, i = ctypes.c_double, ctypes.c_int
    lib.ifs_flow_speed.argtypes, lib.ifs_flow_speed.restype = (i, d, d), d
    for mu in (0.0, 1e-3, 0.05, 0.2, 0.5):
        for ct in (1e-4, 0.0065, 0.05):
            assert lib.ifs_flow_speed(1, mu, ct) == ld.flow_speed(1, mu, ct)
            assert lib.ifs_flow_speed(0, mu, ct) == mu
