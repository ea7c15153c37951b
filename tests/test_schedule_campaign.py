"""Schedules from campaigns (issue #26 item 3): the ``inflowsim campaign`` command's
``schedule.json`` against truths whose parameters change with speed.  Costly
(records and joint fits at several speeds): behind ``slow``."""
import contextlib
import io
import json

import numpy as np
import pytest

from inflowsim.cli import main
from inflowsim.data.record import write_record
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record
from inflowsim.model.params import PUMA
from inflowsim.model.schedule import read_schedule
from inflowsim.physics.theory import pitt_peters_time_constants

STRUCTURE = "basic+separate-time-constants"
SPEEDS = (0.10, 0.15, 0.20, 0.275, 0.35)


def _truth(mu):
    """The linear truth at ``mu``: Pitt-Peters time constants (like 1/mu), the
    Puma's flap frequency and Lock number (constants)."""
    tau0, tau_cs = pitt_peters_time_constants(mu)
    return {"lambda_beta2": 1.06, "n_beta": 0.987, "tau0": tau0, "tau_cs": tau_cs}


def _campaign(folder, out):
    for i, mu in enumerate(SPEEDS):
        for j, mans in enumerate(((Manoeuvre(channel="theta0", shape="3211", width=0.3),
                                   Manoeuvre(channel="theta1s", t_start=9.0)),
                                  (Manoeuvre(channel="theta1c"),))):
            rec = virtual_record(VirtualTest(
                structure=STRUCTURE, parameters=_truth(mu), constants=PUMA.with_mu(mu),
                manoeuvres=mans, duration=16.0, dt=1 / 64, seed=10 * i + j, hold="zoh"))
            write_record(rec, folder / f"mu{mu}_{j}.csv")
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["campaign", str(folder), "--out", str(out), "--workers", "0",
                     "--model", STRUCTURE, "--candidates", "time-delay", "--max-steps",
                     "0", "--quiet", "--json"])
    assert code == 0
    return json.loads(buf.getvalue())


@pytest.mark.slow
def test_a_campaign_recovers_the_truths_parameter_trends(tmp_path):
    """Five speeds, two records each, a linear truth whose inflow time constants
    follow Pitt-Peters (4/(3 pi mu), 32/(45 pi mu)) and whose flap parameters are
    constants: the command's schedule gives the truth within 3 of its bounds at
    every speed flown and between them, finds the time constants not constant and
    the flap parameters constant."""
    (tmp_path / "records").mkdir()
    doc = _campaign(tmp_path / "records", tmp_path / "out")
    sch = read_schedule(doc["tables"]["schedule"])
    assert sch.structure == STRUCTURE and sch.mu_range == (0.10, 0.35)
    grid = sorted(set(SPEEDS) | {0.125, 0.175, 0.2375, 0.3125})
    for name in ("tau0", "tau_cs"):
        p = sch[name]
        assert not p.constant and p.order >= 1
        for mu in grid:
            assert abs(sch(mu)[name] - _truth(mu)[name]) < 3 * p.bound(mu), (name, mu)
            assert p.bound(mu) < 0.05 * _truth(mu)[name]      # bounds that tell
    for name in ("lambda_beta2", "n_beta"):
        p = sch[name]
        assert p.constant, (name, p.constant_p)
        for mu in grid:
            assert abs(sch(mu)[name] - _truth(mu)[name]) < 3 * p.bound(mu), (name, mu)
            assert p.bound(mu) < 0.01 * _truth(mu)[name]
    assert doc["schedule"]["parameters"]["tau0"]["constant_adequate"] is False
    assert "## Schedules" in open(doc["tables"]["report"]).read()


EQ14_MUS = (0.10, 0.15, 0.25, 0.35)
EQ14_CONTROLS = ("theta0", "theta1c", "theta1s")


@pytest.fixture(scope="module")
def eq14_campaign(tmp_path_factory):
    """The default virtual campaign's truth (Eq. 14 speed through the disc) at four
    speeds, a 3-2-1-1 on each control, flown at 1 deg (the campaign's default before
    0.25 deg; the figures below were measured there): the folder of records."""
    from inflowsim.flighttest.campaign import virtual_campaign
    folder = tmp_path_factory.mktemp("eq14")
    virtual_campaign(folder, mus=EQ14_MUS, controls=EQ14_CONTROLS, shapes=("3211",),
                     amplitude_deg=1.0)
    return folder


def _joint_fits(folder, model, mus=EQ14_MUS, shapes=("3211",), repeat=0):
    """Each speed's records (by default its 3-2-1-1s) of one repeat fitted together
    (the campaign's condition task)."""
    from inflowsim.campaign.work import Settings, condition_task
    from inflowsim.flighttest.campaign import campaign_items
    return [condition_task(f"mu={mu:.3f}",
                           [str(folder / it.name)
                            for it in campaign_items((mu,), EQ14_CONTROLS, shapes,
                                                     repeat + 1) if it.repeat == repeat],
                           Settings(model=model, pool=("time-delay",), max_steps=0))
            for mu in mus]


@pytest.mark.slow
def test_eq14_linearised_brings_the_truths_parameters_back(eq14_campaign):
    """The same Eq. (14) campaign fitted with the truth's physics from the
    catalogue, ``momentum-speed`` in place of glauert (and the direct in-plane
    forcing, the 2/rev flap): every speed's flap frequency within 0.5 % of the
    truth's, Lock number within 2 % (measured 0.4-0.9 %), tau0 within 10 %
    (measured 3-9 %, 1-3.6 bounds low: at mu 0.35 half of it is the truth's
    nonlinearity at 1 deg inputs, docs/campaign.md), k_V near its theory value 1;
    the schedule's tau0 falls by
    85-115 % of the truth's fall (glauert's: 48 %) and the flap's parameters are
    constant.  With glauert in its place at mu 0.10 n_beta is 20 % high and tau0
    half the truth's: the missing physics, not the noise."""
    from inflowsim.campaign.schedule import campaign_schedule
    conds = _joint_fits(eq14_campaign, SPEED_MU_STRUCTURE + "+momentum-speed")
    for c in conds:
        assert c["status"] == "ok", c.get("error")
        e = c["base_fit"]["parameters"]
        truth = _speed_mu_truth(c["mu"])
        assert abs(e["lambda_beta2"]["estimate"] / truth["lambda_beta2"] - 1) < 0.005
        assert abs(e["n_beta"]["estimate"] / truth["n_beta"] - 1) < 0.02
        assert abs(e["tau0"]["estimate"] / truth["tau0"] - 1) < 0.1, (c["mu"], e["tau0"])
        assert abs(e["k_V"]["estimate"] - 1) < 3 * e["k_V"]["sigma"] + 0.05
    sch, note = campaign_schedule(conds)
    assert note == "" and sch["lambda_beta2"].constant and sch["n_beta"].constant
    fall = sch(0.10)["tau0"] - sch(0.35)["tau0"]
    truth_fall = _speed_mu_truth(0.10)["tau0"] - _speed_mu_truth(0.35)["tau0"]
    assert 0.85 < fall / truth_fall < 1.15
    (glauert,) = _joint_fits(eq14_campaign, "glauert+flap-inertia", mus=(0.10,))
    e, truth = glauert["base_fit"]["parameters"], _speed_mu_truth(0.10)
    assert e["n_beta"]["estimate"] > 1.15 * truth["n_beta"]
    assert e["tau0"]["estimate"] < 0.7 * truth["tau0"]


@pytest.mark.slow
def test_the_virtual_campaign_of_the_nonlinear_truth(eq14_campaign):
    """The nonlinear blade-element truth (``flighttest --campaign``'s records) at
    four speeds, its joint per-condition fits (the campaign's ``condition_task``)
    and their schedule.  The truth's flap frequency is a constant and its
    Pitt-Peters time constants fall like 1/mu.  What the schedule finds: the
    flap frequency constant; tau0 falling (not constant) by about half the truth's
    fall, and within 3 of its bounds of the truth's value at the two upper
    speeds.  (At 0.10-0.15 the glauert fit's tau0 is 25-40 % below the truth's:
    the truth's Eq. (14) is more than the paper's Glauert terms, and the rest goes
    into the equivalent linear parameters, see
    ``test_eq14_linearised_brings_the_truths_parameters_back``; the schedule
    reports what the fits estimate.)"""
    from inflowsim.campaign.schedule import campaign_schedule
    conds = _joint_fits(eq14_campaign, "glauert")
    sch, note = campaign_schedule(conds)
    assert sch is not None and note == ""
    assert sch["lambda_beta2"].constant
    tau = sch["tau0"]
    assert not tau.constant
    m = np.linspace(0.10, 0.35, 26)
    v = np.array([tau.value(x) for x in m])
    assert np.all(np.diff(v) < 0)
    truth = lambda x: pitt_peters_time_constants(x)[0]
    # (measured: 48 % of the truth's fall from 0.10 to 0.35; the fits' tau0 at the
    # lowest speed is the equivalent linear parameter, not the truth's)
    assert v[0] - v[-1] > 0.4 * (truth(0.10) - truth(0.35))
    for mu in (0.25, 0.35):
        assert abs(sch(mu)["tau0"] - truth(mu)) < 3 * tau.bound(mu)
    # the schedule passes through the joint estimates it was fitted to
    for c in conds:
        e = c["base_fit"]["parameters"]["tau0"]
        assert abs(sch(c["mu"])["tau0"] - e["estimate"]) < 3 * max(e["sigma"],
                                                                   tau.bound(c["mu"]))


#: The speed-mu truth's physics in the catalogue: flap inertia, the 2/rev flap, and
#: the blades' direct answer to the in-plane hub velocity the body's motion makes
#: in the cyclic records (without it lambda_beta2 and n_beta come out 2-5 bounds
#: high: bench/identify.md, "Joint single-axis records").
SPEED_MU_STRUCTURE = ("basic+separate-time-constants+flap-inertia+second-harmonic-flap"
                      "+advance-ratio-perturbation")


@pytest.fixture(scope="module")
def speed_mu_campaign(tmp_path_factory):
    """The individual-blade truth with the trim mu as the speed through the disc
    (``flighttest --campaign --speed mu``): periodic coefficients, blade-element
    loads, flap measured in multiblade coordinates, body motion, noise, but its
    linearisation is inside the catalogue (``tests/test_linearise.py``), so its
    parameters at every speed are known: Pitt-Peters time constants, the
    flap frequency and Lock number, flap inertia 1, the 2/rev flap at theory.
    Five speeds, a 3-2-1-1 on each control, joint fits per speed, the schedule."""
    from inflowsim.campaign.schedule import campaign_schedule
    from inflowsim.flighttest.campaign import virtual_campaign
    folder = tmp_path_factory.mktemp("speed_mu")
    virtual_campaign(folder, mus=SPEEDS, controls=EQ14_CONTROLS, shapes=("3211",),
                     speed="mu", amplitude_deg=1.0)   # 1 deg: as the figures were measured
    conds = _joint_fits(folder, SPEED_MU_STRUCTURE, SPEEDS)
    sch, note = campaign_schedule(conds)
    assert sch is not None and note == ""
    return conds, sch


def _speed_mu_truth(mu):
    from inflowsim.flighttest.bladesim import RotorSpec
    from inflowsim.flighttest.linearise import truth_parameters
    return dict(truth_parameters(RotorSpec(constants=PUMA.with_mu(mu))), k_beta2=1.0)


@pytest.mark.slow
def test_schedules_recover_the_blade_truths_parameters(speed_mu_campaign):
    """The schedules of the time constants, the flap frequency and the Lock number
    hold the truth's values within 3 of their bounds at every speed flown and
    between them (measured: within 2.3), say the time constants are not constant
    and the flap's are, with bounds that tell (under 10 % and 0.5 %); the 2/rev
    flap's scale reaches its theory value where it matters (mu 0.35)."""
    conds, sch = speed_mu_campaign
    grid = (0.10, 0.125, 0.15, 0.175, 0.2, 0.2375, 0.275, 0.3125, 0.35)
    for name, constant, rel in (("tau0", False, 0.1), ("tau_cs", False, 0.1),
                                ("lambda_beta2", True, 0.005), ("n_beta", True, 0.005)):
        p = sch[name]
        assert p.constant is constant, (name, p.constant_p)
        for mu in grid:
            truth = _speed_mu_truth(mu)[name]
            assert abs(sch(mu)[name] - truth) < 3 * p.bound(mu), (name, mu)
            assert p.bound(mu) < rel * truth, (name, mu)
    high = conds[-1]["base_fit"]["parameters"]["k_beta2"]
    assert abs(high["estimate"] - 1.0) < 3 * high["sigma"] and high["sigma"] < 0.1
    # the trim the conditions flew at (fixed pitch; the flap's trim moves with mu):
    # a least-squares cubic within 3e-4 rad of each condition's (measured: 2.0e-4,
    # the coning; the disc tilt beta1c moves by 0.11 rad over the range)
    from inflowsim.physics.bladeelement import TRIM_KEYS
    assert sch.trim_columns == TRIM_KEYS and all(t.order == 3 for t in sch.trim)
    for c in conds:
        got = sch.trim_values(c["mu"])
        assert all(abs(got[k] - v) < 3e-4 for k, v in c["trim"].items()), c["mu"]
    assert max(t.residual for t in sch.trim) < 3e-4


@pytest.mark.slow
def test_in_its_linear_range_the_eq14_truths_trends_are_recovered(tmp_path):
    """The default truth (Eq. 14) flown in its linear range: 0.25 deg 3-2-1-1s with
    the noise scaled alike (2.5e-5 rad: the same signal-to-noise as 1 deg and
    1e-4), four speeds, fitted with the truth's physics from the catalogue
    (``momentum-speed``, the direct in-plane forcing, the 2/rev flap, flap inertia)
    and scheduled in 1/mu: the schedules of tau0, tau_cs, the flap frequency and
    the Lock number hold the truth's values within 3 of their bounds at the speeds
    flown and between them (measured: within 2.1; at 1 deg the same fits sit up to
    3.6 bounds off at mu 0.35, the truth's nonlinearity)."""
    from inflowsim.campaign.schedule import campaign_schedule
    from inflowsim.flighttest.campaign import virtual_campaign
    virtual_campaign(tmp_path, mus=EQ14_MUS, controls=EQ14_CONTROLS, shapes=("3211",),
                     amplitude_deg=0.25, noise=2.5e-5)
    conds = _joint_fits(tmp_path, SPEED_MU_STRUCTURE + "+momentum-speed")
    sch, note = campaign_schedule(conds, variables=("1/mu",))
    assert note == ""
    grid = (0.10, 0.125, 0.15, 0.2, 0.25, 0.3, 0.35)
    for name in ("tau0", "tau_cs", "lambda_beta2", "n_beta"):
        p = sch[name]
        for mu in grid:
            truth = _speed_mu_truth(mu)[name]
            assert abs(sch(mu)[name] - truth) < 3 * p.bound(mu), (name, mu)
            assert p.bound(mu) < 0.05 * truth, (name, mu)
    assert not sch["tau0"].constant and sch["n_beta"].constant


@pytest.mark.slow
def test_the_default_campaign_flies_the_eq14_truth_in_its_linear_range(tmp_path):
    """The default virtual campaign (its input amplitude and 1e-4 rad noise; a
    doublet, a 3-2-1-1 and a sweep on each control), two repeats, at the speeds
    where 1 deg moved the truth most (0.10, 0.35); each speed's records of a repeat
    fitted together with the truth's physics from the catalogue: tau0, tau_cs and
    the flap frequency within 3 bounds of the truth's small-perturbation values in
    every fit, the Lock number within 0.5 %, and tau0 without a bias (its mean
    deviation over the four fits within 1.5 bounds).  The same records at 1 deg
    (the default before): tau0 on average more than 1.5 bounds low, the truth's
    amplitude nonlinearity (bench/amplitude.md: 2.4-2.6 bounds over 5 seeds, 0.3
    and -1.2 at 0.25 deg)."""
    from inflowsim.flighttest.campaign import CAMPAIGN_SHAPES, virtual_campaign
    mus = (0.10, 0.35)
    mean_z = {}
    for label, kw in (("default", {}), ("1 deg", {"amplitude_deg": 1.0})):
        folder = tmp_path / label.replace(" ", "")
        virtual_campaign(folder, mus=mus, controls=EQ14_CONTROLS, repeats=2, workers=1,
                         **kw)
        z_tau0 = []
        for repeat in (0, 1):
            for c in _joint_fits(folder, SPEED_MU_STRUCTURE + "+momentum-speed", mus,
                                 CAMPAIGN_SHAPES, repeat):
                assert c["status"] == "ok", c.get("error")
                assert len(c["records"]) == len(EQ14_CONTROLS) * len(CAMPAIGN_SHAPES)
                e, truth = c["base_fit"]["parameters"], _speed_mu_truth(c["mu"])
                z = {n: (e[n]["estimate"] - truth[n]) / e[n]["sigma"]
                     for n in ("tau0", "tau_cs", "n_beta")}
                if label == "default":
                    assert all(abs(v) < 3 for v in z.values()), (c["mu"], repeat, z)
                    assert abs(e["lambda_beta2"]["estimate"] / truth["lambda_beta2"]
                               - 1) < 0.005
                z_tau0.append(z["tau0"])
        mean_z[label] = float(np.mean(z_tau0))
    assert abs(mean_z["default"]) < 1.5, mean_z
    assert mean_z["1 deg"] < -1.5, mean_z


@pytest.mark.slow
def test_the_default_campaigns_schedule_recovers_the_eq14_truth_and_flies(tmp_path):
    """The default virtual campaign as `flighttest --campaign` writes it (the default
    truth, six speeds, a doublet, a 3-2-1-1 and a sweep on each control, 0.25 deg,
    1e-4 rad noise), each speed's nine records fitted together with the truth's
    physics from the catalogue, the schedule in 1/mu with the trim:

    - every condition holds tau0, tau_cs and the flap frequency within 3 bounds of
      the truth's small-perturbation values (measured: within 2.7);
    - the schedules of tau0, tau_cs and the Lock number hold the truth within 3 of
      their bounds at and between the speeds (measured 2.2), with bounds under 5 %;
      tau0 is found not constant;
    - the flap frequency's schedule is within 1 % (measured 0.85 %) but not within
      its pooled bound (3.6 bounds at mu 0.35): its per-condition estimates drift
      from -1.5 to +2.4 bounds with speed, the model error of the high-speed
      conditions (bench/amplitude.md), which pooling six conditions makes visible;
      AIC takes that drift for a slope where the constant test finds none: with the
      criterion chi2 (the lowest order the scatter allows) every schedule holds the
      truth within 3 of its bounds (measured 1.9);
    - and the schedule's FMU flies examples/simulator_loop.c from hover, with
      momentum-speed's coupling computed in its C at each tabulated mu about the
      trim the schedule gives there."""
    from inflowsim.campaign.schedule import campaign_schedule
    from inflowsim.flighttest.campaign import CAMPAIGN_SHAPES, MUS, virtual_campaign
    virtual_campaign(tmp_path / "rec")
    conds = _joint_fits(tmp_path / "rec", SPEED_MU_STRUCTURE + "+momentum-speed", MUS,
                        CAMPAIGN_SHAPES)
    for c in conds:
        assert c["status"] == "ok", c.get("error")
        assert len(c["records"]) == 9
        e, truth = c["base_fit"]["parameters"], _speed_mu_truth(c["mu"])
        for n in ("tau0", "tau_cs", "n_beta"):
            assert abs(e[n]["estimate"] - truth[n]) < 3 * e[n]["sigma"], (c["mu"], n)
    sch, note = campaign_schedule(conds, variables=("1/mu",))
    assert note == "" and sch.trim, note
    for mu in np.linspace(0.10, 0.35, 11):
        truth = _speed_mu_truth(mu)
        for name in ("tau0", "tau_cs", "lambda_beta2"):
            p = sch[name]
            assert abs(sch(mu)[name] - truth[name]) < 3 * p.bound(mu), (name, mu)
            assert p.bound(mu) < 0.05 * truth[name], (name, mu)
        assert abs(sch(mu)["n_beta"] / truth["n_beta"] - 1) < 0.01, mu
    assert not sch["tau0"].constant
    # the lowest order the scatter allows (criterion chi2) keeps the flap frequency
    # constant, as the constant test finds it: then every schedule holds the truth
    # within 3 of its bounds (measured 1.9)
    strict, _ = campaign_schedule(conds, criterion="chi2", variables=("1/mu",))
    assert strict["n_beta"].order == 0 and sch["n_beta"].constant
    for mu in np.linspace(0.10, 0.35, 11):
        truth = _speed_mu_truth(mu)
        for name in ("tau0", "tau_cs", "lambda_beta2", "n_beta"):
            assert abs(strict(mu)[name] - truth[name]) < 3 * strict[name].bound(mu), \
                (name, mu)
    _fly(sch, tmp_path / "fly")


def _fly(sch, tmp_path):
    """The schedule's FMU (``fmu build --schedule``) flown by examples/simulator_loop.c,
    unchanged, from hover to mu 0.25: its log."""
    import shutil
    import subprocess
    import zipfile
    from pathlib import Path
    from test_fmu_schedule import build_scheduled
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    tmp_path.mkdir(parents=True, exist_ok=True)
    doc = build_scheduled(sch, tmp_path)
    unz = tmp_path / "x"
    zipfile.ZipFile(doc["fmu"]).extractall(unz)
    root = Path(__file__).resolve().parents[1]
    exe = tmp_path / "loop"
    subprocess.run([cc, "-std=c99", "-O2", "-I", str(unz / "sources"), "-o", str(exe),
                    str(root / "examples" / "simulator_loop.c"), "-ldl", "-lm"], check=True)
    out = subprocess.run([str(exe), str(unz / "binaries" / "linux64" / "inflowsim.so"),
                          doc["guid"], str(tmp_path / "loop.csv")], capture_output=True,
                         text=True)
    assert out.returncode == 0, out.stderr + out.stdout
    assert "frames: 2700" in out.stdout
    rows = np.genfromtxt(tmp_path / "loop.csv", delimiter=",", names=True)
    assert rows["mu"][0] == 0.0 and rows["mu"].max() > 0.24
    assert np.all(np.isfinite(rows["thrust"]))
    return rows


@pytest.mark.slow
def test_the_blade_truths_schedule_flies_the_simulator_loop(speed_mu_campaign, tmp_path):
    """The schedule that recovers the blade truth's parameters (flap inertia, the
    2/rev flap, the direct in-plane forcing with the trim as FMU parameters; mu and
    1/mu polynomials) builds an FMU that examples/simulator_loop.c, unchanged, flies
    from hover to mu 0.25 (the trim effects use the mass-flow speed down to hover)."""
    from inflowsim.campaign.schedule import campaign_schedule
    conds, _ = speed_mu_campaign
    sch, note = campaign_schedule(conds, variables=("mu", "1/mu"))
    assert {p.variable for p in sch.parameters} == {"mu", "1/mu"}
    _fly(sch, tmp_path)
