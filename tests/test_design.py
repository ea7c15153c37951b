"""Optimal input design (``inflowsim.flighttest.design``, issue #25 item 3)."""
import json
import math

import numpy as np
import pytest

from inflowsim.flighttest.virtual import VirtualTest, virtual_record
from inflowsim.identify import identify
from inflowsim.flighttest.design import design_input, optimise_powers


def test_multiplicative_algorithm_keeps_budgets_and_raises_the_criterion():
    rng = np.random.default_rng(0)
    p, n = 4, 12
    info = []
    for _ in range(n):
        g = rng.standard_normal((2, p))
        info.append(g.T @ g)
    info = np.array(info)
    blocks = [np.arange(0, 6), np.arange(6, 12)]
    w, gain = optimise_powers(info, blocks, interest_idx=[0, 1])
    assert gain > 0
    for b in blocks:
        assert w[b].sum() == pytest.approx(1.0) and np.all(w[b] >= 0)

    def crit(w):
        M = np.einsum("k,kpq->pq", w, info)
        return -np.linalg.slogdet(np.linalg.inv(M)[:2, :2])[1]
    # no random split of the same budgets does better
    for _ in range(200):
        r = rng.random(n)
        for b in blocks:
            r[b] /= r[b].sum()
        assert crit(r) <= crit(w) + 1e-9


@pytest.fixture(scope="module")
def design():
    return design_input("glauert", interest=["kc", "ks"], duration=20.0)


@pytest.mark.slow
def test_design_shrinks_the_bounds_it_promises(design):
    """Flown through the virtual flight test and identified, the designed input
    gives bounds within 30 % of those promised, far below the doublet's."""
    d = design
    assert d.limit_kind == "peak"
    assert all(0.999 * math.radians(1.0) <= pk <= math.radians(1.0) for pk in d.peak)
    for n in d.interest:
        assert d.sigma_after[n] < 0.3 * d.sigma_before[n]
    rec = virtual_record(VirtualTest(structure=d.structure, parameters=d.parameters,
                                     manoeuvres=d.manoeuvres(), duration=d.duration,
                                     dt=d.dt, noise_flap=d.noise_flap, seed=5))
    for c, pk in zip(d.channels, d.peak):
        assert np.max(np.abs(rec[c] - rec[c][0])) <= d.limit
    fit = identify(rec, d.structure, start=d.parameters, multistart=False)
    assert fit.converged
    for n in d.interest:
        assert fit.sigma[n] == pytest.approx(d.sigma_after[n], rel=0.3)
    # and the doublet's promise holds too
    from inflowsim.flighttest.virtual import Manoeuvre
    dbl = virtual_record(VirtualTest(structure=d.structure, parameters=d.parameters,
                                     manoeuvres=(Manoeuvre(),), duration=d.duration,
                                     noise_flap=d.noise_flap, seed=5))
    fit0 = identify(dbl, d.structure, start=d.parameters, multistart=False)
    for n in d.interest:
        assert fit0.sigma[n] == pytest.approx(d.sigma_before[n], rel=0.3)


def test_design_command(tmp_path, capsys):
    from inflowsim.cli import main
    out = tmp_path / "d.json"
    assert main(["design", "-m", "basic", "--channels", "theta0", "--duration", "9",
                 "--out", str(out), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc == json.loads(out.read_text())
    assert {"sigma_before", "sigma_after", "channels", "interest"} <= set(doc)
    rec = tmp_path / "r.csv"
    assert main(["flighttest", "--truth", "linear", "-m", "basic", "--design", str(out),
                 "--out", str(rec)]) == 0
    assert "designed multisine" in rec.read_text().splitlines()[6]
    capsys.readouterr()
    for bad in (["--interest", "kc"], ["--limit-deg", "0"], ["--add", "nonsense"]):
        assert main(["design", "-m", "basic", *bad]) == 2
        err = capsys.readouterr().err.splitlines()
        assert err[-1].startswith("inflowsim design: error: ") and len(err) <= 2
    (tmp_path / "bad.json").write_text("{}")
    assert main(["flighttest", "--truth", "linear", "--design", str(tmp_path / "bad.json"),
                 "--out", str(tmp_path / "x.csv")]) == 2


def test_peak_bound_is_an_upper_bound_and_tight():
    from inflowsim.data.inputs import multisine_plan, multisine_unit
    from inflowsim.flighttest.design import peak_bound
    rng = np.random.default_rng(1)
    for _ in range(5):
        h = tuple(sorted(rng.choice(np.arange(3, 60), 7, replace=False).tolist()))
        wts = tuple(rng.uniform(0.05, 1.0, 7).tolist())
        w, ph, grid = multisine_plan(1 / 17.0, h, wts, ())
        b = peak_bound(1 / 17.0, h, w, ph)
        fine = np.max(np.abs(multisine_unit(np.linspace(0, 17.0, 400_001), 1 / 17.0,
                                            h, w, ph)))
        assert fine <= b < fine * (1 + 1e-5)
        assert grid <= b


def test_design_respects_the_peak_limit():
    """Per control the designed signal never exceeds the amplitude limit, in
    continuous time and in the record flown with it, and uses it (within 1 %)."""
    d = design_input("basic", channels=["theta0", "theta1s"], duration=9.0,
                     limit_deg=0.7)
    lim = math.radians(0.7)
    assert d.limit == pytest.approx(lim) and d.limit_kind == "peak"
    for m, pk, a in zip(d.manoeuvres(), d.peak, d.amplitudes):
        t = np.linspace(m.t_start - 0.5, m.t_start + m.length + 0.5, 100_001)
        top = np.max(np.abs(m.signal(t)))
        assert top <= lim and top > 0.99 * lim and pk <= lim
        assert top <= sum(a) * (1 + 1e-12)      # the amplitudes are the signal's
    rec = virtual_record(VirtualTest(structure=d.structure, parameters=d.parameters,
                                     manoeuvres=d.manoeuvres(), duration=d.duration,
                                     dt=d.dt, noise_flap=d.noise_flap))
    for c in d.channels:
        assert np.max(np.abs(rec[c] - rec[c][0])) <= lim
