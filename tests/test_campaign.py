"""``inflowsim campaign`` (issue #26): plans, per-record and per-condition work,
error rows, resumability, the tables and the report, and a multi-process local
Dask cluster."""
import contextlib
import io
import json
from pathlib import Path

import numpy as np
import pytest

from inflowsim.errors import InputError

from conftest import assert_user_error, run, virtual
from inflowsim.campaign import Settings, read_plan, record_task
from inflowsim.campaign.engine import run_campaign
from inflowsim.cli import main
from inflowsim.data.record import write_record
from inflowsim.diagnose import diagnose
from inflowsim.diagnose.verdict import STATUSES
from inflowsim.flighttest.virtual import Manoeuvre
from inflowsim.model.params import PUMA

POOL = ("time-delay",)
OPTS = ["--candidates", *POOL, "--max-steps", "1", "--quiet"]


def _rec(mu, channel, seed):
    return virtual(structure="glauert", constants=PUMA.with_mu(mu), dt=1 / 64,
                   duration=16.0, seed=seed, manoeuvres=(Manoeuvre(channel=channel),),
                   hold="zoh")


@pytest.fixture(scope="module")
def plan_dir(tmp_path_factory):
    d = tmp_path_factory.mktemp("plan")
    for mu, ch, seed in ((0.2, "theta1s", 1), (0.2, "theta1c", 2), (0.3, "theta1s", 3)):
        write_record(_rec(mu, ch, seed).with_meta(manoeuvre=f"doublet {ch}"),
                     d / f"mu{mu}_{ch}.csv")
    (d / "broken.csv").write_text("# mu: 0.3\nt,theta0\n0,1\n")
    return d


@pytest.fixture(scope="module")
def first(plan_dir, tmp_path_factory):
    out = tmp_path_factory.mktemp("out") / "campaign"

    def go(*extra):
        """The command, in process; ``(exit code, the --json document)``."""
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            code = main(["campaign", str(plan_dir), "--out", str(out), "--workers", "0",
                         "--json", *OPTS, *extra])
        return code, json.loads(buf.getvalue())
    return out, go


def test_old_verdicts_read_in_the_one_vocabulary():
    """Results stored before issue #39 said adequate / missing-effect: they read as
    their ladder's status, else through the documented alias."""
    from inflowsim.campaign.work import OLD_VERDICTS, current_verdict
    assert set(OLD_VERDICTS.values()) <= set(STATUSES)
    assert current_verdict({"verdict": "adequate"})["verdict"] == "no-missing-effect"
    held = {"verdict": "missing-effect", "ladder": {"verdict": {"status": "partly-explained"}}}
    assert current_verdict(held)["verdict"] == "partly-explained"
    assert current_verdict({"verdict": "error"})["verdict"] == "error"
    with pytest.raises(TypeError):
        OLD_VERDICTS["adequate"] = "x"                  # read-only


@pytest.mark.slow
def test_campaign_rows_tables_report(first, plan_dir):
    out, go = first
    code, doc = go()
    assert code == 0
    recs = {Path(r["record"]).name: r for r in doc["records"]}
    assert set(recs) == {"mu0.2_theta1s.csv", "mu0.2_theta1c.csv", "mu0.3_theta1s.csv",
                         "broken.csv"}
    bad = recs["broken.csv"]
    assert bad["status"] == "error" and bad["verdict"] == "error"
    assert "omega" in bad["error"] and bad["condition"] == "mu=0.300"
    for name, r in recs.items():
        assert {"record", "condition", "missing_effect", "verdict"} <= set(r)
        if name != "broken.csv":
            assert r["status"] == "ok" and r["estimates"]["tau0"]["sigma"] > 0
            assert r["verdict"] in STATUSES          # diagnose's vocabulary
    assert recs["mu0.2_theta1c.csv"]["manoeuvre"] == "doublet theta1c"
    conds = {c["condition"]: c for c in doc["conditions"]}
    assert set(conds) == {"mu=0.200", "mu=0.300"}
    assert len(conds["mu=0.200"]["records"]) == 2 and len(conds["mu=0.300"]["records"]) == 1
    assert doc["work"]["computed"] == {"records": 4, "conditions": 2}
    import pandas as pd
    df = pd.read_parquet(doc["tables"]["parquet"])
    assert list(df["kind"]).count("record") == 4 and list(df["kind"]).count("condition") == 2
    assert {"est_tau0", "sigma_tau0", "missing_effect", "verdict", "error"} <= set(df.columns)
    assert pd.read_csv(doc["tables"]["csv"]).shape == df.shape
    text = Path(doc["tables"]["report"]).read_text()
    assert "Estimates against mu" in text and "broken.csv" in text
    assert Path(doc["tables"]["figure"]).stat().st_size > 1000
    # the inputs are untouched and no output landed among them
    assert sorted(p.name for p in plan_dir.iterdir()) == sorted(recs)


@pytest.mark.slow
def test_campaign_decisions_equal_single_record_diagnose(first, plan_dir):
    out, go = first
    code, doc = go()
    r = next(x for x in doc["records"] if x["record"].endswith("mu0.2_theta1s.csv"))
    from inflowsim.data.record import read_record
    d = diagnose(read_record(r["record"]), "glauert", pool=list(POOL))
    assert r["missing_effect"] == d.missing_effect
    stored = json.loads(next((out / "results" / "records").glob(f"{r['key']}.json"))
                        .read_text())
    assert stored["diagnosis"]["candidates"] == json.loads(
        json.dumps(d.to_json()["candidates"]))


@pytest.mark.slow
def test_restart_does_no_work(first):
    out, go = first
    go()
    code, doc = go()                          # everything stored: nothing computed
    assert doc["work"]["computed"] == {"records": 0, "conditions": 0}
    assert doc["work"]["reused"] == {"records": 4, "conditions": 2}


def _stub_tasks(monkeypatch):
    """The engine's tasks replaced by counting stand-ins of the same shape (the
    engine's bookkeeping is under test, not the diagnosis)."""
    import inflowsim.campaign.engine as eng
    calls = {"record": [], "condition": []}

    def rec_task(path, settings, info=None):
        calls["record"].append(Path(path).name)
        if Path(path).name == "broken.csv":
            return {"kind": "record", "record": path, **(info or {}), "status": "error",
                    "verdict": "error", "missing_effect": None, "error": "broken"}
        return {"kind": "record", "record": path, **(info or {}), "status": "ok",
                "error": None, "mu": info["plan_mu"], "missing_effect": "glauert",
                "verdict": "explained", "accepted": ["glauert"],
                "ladder_added": ["glauert"], "final_structure": "glauert",
                "candidates": {"glauert": {"accepted": True, "reason": ""}},
                "base_fit": {"structure": "basic", "cost": -1.0, "n_freq": 10,
                             "converged": True, "fit_percent": {"beta0": 90.0},
                             "parameters": {"tau": {"estimate": 1.0 + info["plan_mu"],
                                                    "sigma": 0.1}}}}

    def cond_task(condition, paths, settings):
        calls["condition"].append(condition)
        mu = float(condition[3:])
        return {"kind": "condition", "condition": condition, "records": list(paths),
                "status": "ok", "error": None, "mu": mu,
                "missing_effect": "glauert" if condition == "mu=0.200" else None,
                "trim": {"theta0": 0.1 + mu, "theta1s": -0.2 * mu},
                "verdict": "explained", "base_fit": {"structure": "basic",
                                                          "parameters": {
                    "tau": {"estimate": 1.0 + mu, "sigma": 0.05},
                    "n_beta": {"estimate": 1.0, "sigma": None}}}}
    monkeypatch.setattr(eng, "record_task", rec_task)
    monkeypatch.setattr(eng, "condition_task", cond_task)
    return calls


def test_restart_redoes_only_what_is_missing(plan_dir, tmp_path, monkeypatch):
    calls = _stub_tasks(monkeypatch)
    plan, s, out = read_plan(plan_dir), Settings(pool=POOL, max_steps=1), tmp_path / "o"
    res = run_campaign(plan, out, s, workers=0, progress=False)
    assert len(calls["record"]) == 4 and sorted(calls["condition"]) == ["mu=0.200",
                                                                        "mu=0.300"]
    assert res.computed == {"records": 4, "conditions": 2}
    # the broken record is a row with its error; its condition is fitted without it
    bad = next(r for r in res.records if r["record"].endswith("broken.csv"))
    assert bad["status"] == "error" and bad["error"] == "broken"
    assert len(next(c for c in res.conditions if c["condition"] == "mu=0.300")["records"]) == 1
    # disagreement: mu=0.3's record names glauert, its condition none, and why
    ag = res.agreement
    assert ag["disagreements"] and ag["disagreements"][0]["condition"] == "mu=0.300"
    assert ag["effects"]["glauert"] == {"records": 3, "conditions": 1}
    calls["record"].clear(), calls["condition"].clear()
    again = run_campaign(plan, out, s, workers=0, progress=False)
    assert calls == {"record": [], "condition": []}
    assert again.computed == {"records": 0, "conditions": 0}
    assert [r["missing_effect"] for r in again.records] == \
        [r["missing_effect"] for r in res.records]
    # killed halfway: one record's result never written; its condition is new work
    victim = next(r for r in res.records if r["record"].endswith("mu0.3_theta1s.csv"))
    (out / "results" / "records" / f"{victim['key']}.json").unlink()
    third = run_campaign(plan, out, s, workers=0, progress=False)
    assert calls["record"] == ["mu0.3_theta1s.csv"] and calls["condition"] == []
    assert third.computed == {"records": 1, "conditions": 0}
    # other settings (or another version, or another record file) are other work
    run_campaign(plan, out, Settings(pool=POOL, max_steps=2), workers=0, progress=False)
    assert len(calls["record"]) == 1 + 4
    import pandas as pd
    df = pd.read_parquet(third.files["parquet"])
    assert list(df["kind"]) == ["record"] * 4 + ["condition"] * 2
    assert {"est_tau", "sigma_tau", "error", "verdict"} <= set(df.columns)
    assert "Where records disagree" in Path(third.files["report"]).read_text()
    # the schedule across conditions: written, in the report, read back
    from inflowsim.model.schedule import read_schedule
    sch = read_schedule(third.files["schedule"])
    assert sch.names == ("tau",) and sch.held == (("n_beta", 1.0, None),)
    assert sch.mu_range == (0.2, 0.3) and sch(0.2)["tau"] == pytest.approx(1.25)
    assert "## Schedules" in Path(third.files["report"]).read_text()
    # the conditions' trim: table columns, and a line in mu (two conditions)
    conds = df[df["kind"] == "condition"]
    assert (conds["trim_theta0"] - conds["mu"]).tolist() == pytest.approx([0.1, 0.1])
    assert df[df["kind"] == "record"]["trim_theta0"].isna().all()
    assert sch.trim_columns == ("theta0", "theta1s")
    assert [t.order for t in sch.trim] == [1, 1]
    assert sch.trim_values(0.25)["theta1s"] == pytest.approx(-0.05)
    assert sch.trim_values(0.5) == sch.trim_values(0.3)
    import re
    assert re.search(r"\|\s*theta1s\s*\|\s*1\s*\|", Path(third.files["report"]).read_text())
    page = Path(third.files["html"]).read_text()          # the same report as a page
    assert page.startswith("<!DOCTYPE html>") and "<td>theta1s</td>" in page
    assert '<img src="estimates_vs_mu.png"' in page
    doc = json.loads(Path(third.files["json"]).read_text())
    assert doc["schedule"]["trim"]["theta0"]["order"] == 1
    assert doc["schedule"]["parameters"]["tau"]["order"] == 0   # 2 conditions: a constant
    assert doc["settings"]["schedule"]["variables"] == ["mu"]
    # the schedule's variable is a choice of the run (not of the stored work)
    inv = run_campaign(plan, out, s, workers=0, progress=False,
                       schedule_variables=("1/mu",))
    assert inv.computed == {"records": 0, "conditions": 0}
    doc = json.loads(Path(inv.files["json"]).read_text())
    assert doc["settings"]["schedule"]["variables"] == ["1/mu"]
    with pytest.raises(InputError, match="schedule variables"):
        run_campaign(plan, out, s, workers=0, progress=False, schedule_variables=("log",))


def test_manifests(plan_dir, tmp_path):
    (tmp_path / "plan.csv").write_text(
        "record,condition,manoeuvre,group\n"
        f"{plan_dir / 'mu0.2_theta1s.csv'},slow,doublet,A\n"
        f"{plan_dir / 'mu0.3_theta1s.csv'},fast,,B\n")
    p = read_plan(tmp_path / "plan.csv")
    assert [(e.condition, e.manoeuvre, e.group) for e in p.entries] == [
        ("slow", "doublet", "A"), ("fast", "doublet theta1s", "B")]
    (tmp_path / "plan.toml").write_text(
        '[settings]\nmodel = "glauert"\ncandidates = ["time-delay"]\n'
        f'[[record]]\npath = "{plan_dir / "mu0.2_theta1c.csv"}"\n')
    p = read_plan(tmp_path / "plan.toml")
    assert p.entries[0].condition == "mu=0.200" and p.settings["candidates"] == ["time-delay"]


@pytest.mark.parametrize("setup,words", [
    (lambda d: (d / "nothing").mkdir(), ["no records"]),
    (lambda d: (d / "plan.csv").write_text("path\nx.csv\n"), ["'record' column"]),
    (lambda d: (d / "plan.csv").write_text("record\nmissing.csv\n"), ["not found"]),
    (lambda d: (d / "plan.toml").write_text("[[record]]\nfile = 1\n"), ["no path"]),
])
def test_bad_plans_are_one_line_errors(tmp_path, capsys, setup, words):
    setup(tmp_path)
    target = next(p for p in tmp_path.iterdir())
    code, out, err = run(capsys, "campaign", target, "--out", tmp_path / "o", "--workers",
                         "0")
    assert_user_error(code, out, err, *words)


def test_out_must_be_a_folder(plan_dir, tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("x")
    code, out, err = run(capsys, "campaign", plan_dir, "--out", f, "--workers", "0")
    assert_user_error(code, out, err, "not a folder")
    assert f.read_text() == "x"


def test_a_failing_record_is_a_row_not_the_end(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("# omega: 27\n# mu: 0.3\n# a0: 5.7\n# solidity: 0.09\nt,beta0\n"
                   "0,0\n0.1,0\n0.2,nan\n0.3,0\n0.4,0\n")
    res = record_task(str(bad), Settings(pool=POOL, max_steps=1))
    assert res["status"] == "error" and "NaN" in res["error"]


@pytest.mark.slow
def test_local_dask_cluster_two_processes(plan_dir, tmp_path):
    """Two worker processes (a local cluster): the same answers as in-process,
    and a second run on the cluster does no work."""
    plan = read_plan(plan_dir)
    s = Settings(pool=POOL, max_steps=1)
    ref = run_campaign(plan, tmp_path / "ref", s, workers=0, progress=False)
    res = run_campaign(plan, tmp_path / "dask", s, workers=2, progress=False)
    assert res.computed == {"records": 4, "conditions": 2}
    assert [r["missing_effect"] for r in res.records] == \
        [r["missing_effect"] for r in ref.records]
    assert [r["status"] for r in res.records] == [r["status"] for r in ref.records]
    again = run_campaign(plan, tmp_path / "dask", s, workers=2, progress=False)
    assert again.computed == {"records": 0, "conditions": 0}


def test_virtual_campaign_writes_records_and_plan(tmp_path, capsys):
    from inflowsim.flighttest.campaign import (AMPLITUDE_DEG, campaign_items,
                                               virtual_campaign)
    items = campaign_items()
    # doublets, 3211s and a sweep on each control at each speed
    assert len({i.mu for i in items}) == 6 and len(items) == 6 * 3 * 3
    assert {i.shape for i in items} == {"doublet", "3211", "sweep"}
    assert len({i.seed for i in items}) == len(items)
    plan = virtual_campaign(tmp_path / "s", mus=(0.15,), controls=("theta1c",),
                            shapes=("sweep",), duration=8.0, workers=1)
    from inflowsim.data.record import read_record
    sweep = read_record(read_plan(plan).entries[0].path)
    th = sweep["theta1c"] - sweep["theta1c"][0]
    # a faded log sweep: moves over its whole length, no more than its peak
    peak = np.radians(AMPLITUDE_DEG)
    assert np.max(np.abs(th)) <= peak * (1 + 1e-9)
    assert np.ptp(th[(sweep.t > 3.0) & (sweep.t < 6.0)]) > peak
    plan = virtual_campaign(tmp_path / "c", mus=(0.15,), controls=("theta1s",),
                            shapes=("3211",), duration=6.0, workers=1)
    p = read_plan(plan)
    (e,) = p.entries
    assert (e.condition, e.manoeuvre, e.group, e.mu) == ("mu=0.150", "3211 theta1s",
                                                         "repeat 0", 0.15)
    from inflowsim.data.record import read_record
    rec = read_record(e.path)
    assert rec.meta["manoeuvre"] == "3211 theta1s" and float(rec.meta["mu"]) == 0.15
    assert rec.dt == pytest.approx(1 / 64)
    assert np.ptp(rec["theta1s"]) == pytest.approx(2 * peak, rel=0.05)     # +-A
    # a second generation keeps the record (resumable) and rewrites the plan only
    mtime = Path(e.path).stat().st_mtime_ns
    virtual_campaign(tmp_path / "c", mus=(0.15,), controls=("theta1s",), shapes=("3211",),
                     duration=6.0, workers=1)
    assert Path(e.path).stat().st_mtime_ns == mtime
    assert rec.meta["truth"] == "nonlinear blade-element, 4 blades, speed eq14, body motion"
    # another truth in the same folder is refused, in one line, and nothing is replaced
    code, out, err = run(capsys, "flighttest", "--campaign", tmp_path / "c", "--speeds",
                         "0.15", "--speed", "mu", "--duration", "6", "--workers", "1")
    assert_user_error(code, out, err, "another truth")
    assert Path(e.path).stat().st_mtime_ns == mtime
    # so is a record flown otherwise: one campaign, one amplitude, noise and length
    assert rec.meta["flown"] == f"{AMPLITUDE_DEG:g} deg inputs, flap noise 0.0001 rad, " \
                                "6 s at dt 0.015625 s"
    for other in (["--amplitude-deg", "1"], ["--noise", "2e-4"], ["--duration", "8"]):
        args = ["--duration", "6", *other] if other[0] != "--duration" else other
        code, out, err = run(capsys, "flighttest", "--campaign", tmp_path / "c", "--speeds",
                             "0.15", "--workers", "1", *args)
        assert_user_error(code, out, err, "flown otherwise")
    assert Path(e.path).stat().st_mtime_ns == mtime
    code, out, err = run(capsys, "flighttest", "--campaign", tmp_path / "e", "--blades", "2")
    assert_user_error(code, out, err, "n_blades")
    code, out, err = run(capsys, "flighttest", "--campaign", tmp_path / "d", "--out", "x.csv")
    assert_user_error(code, out, err, "--campaign")


@pytest.mark.slow
def test_a_condition_and_a_record_carry_their_trim(tmp_path):
    """condition_task's ``trim`` is the mean over its records of their find_trim
    totals (records trimmed differently here), record_task's the record's: every
    total an effect linearised about trim reads (TRIM_KEYS)."""
    from inflowsim.campaign.work import condition_task
    from inflowsim.data.record import find_trim, read_record
    from inflowsim.physics.bladeelement import TRIM_KEYS
    paths = []
    for i, (ch, shift) in enumerate((("theta1s", 0.0), ("theta1c", 0.01))):
        r = _rec(0.2, ch, i + 1)
        r = r.with_channels(theta0=r["theta0"] + shift, beta0=r["beta0"] - 0.2 * shift)
        paths.append(str(write_record(r, tmp_path / f"{ch}.csv")))
    s = Settings(pool=POOL, max_steps=0)
    out = condition_task("mu=0.200", paths, s)
    assert out["status"] == "ok" and tuple(out["trim"]) == TRIM_KEYS
    trims = [find_trim(read_record(p)).values for p in paths]
    for c in TRIM_KEYS:
        assert out["trim"][c] == pytest.approx(0.5 * (trims[0][c] + trims[1][c]), abs=1e-15)
    assert out["trim"]["theta0"] == pytest.approx(trims[0]["theta0"] + 0.005)
    one = record_task(paths[1], s)
    assert one["trim"] == {c: trims[1][c] for c in TRIM_KEYS}
    assert json.loads(json.dumps(out))["trim"] == out["trim"]


def test_flighttest_campaign_flies_its_own_amplitude(tmp_path, capsys, monkeypatch):
    """``--campaign`` flies the campaign's amplitude (the truth's linear range at the
    default noise) unless ``--amplitude-deg`` says otherwise; a single record keeps
    its 1 deg."""
    import inflowsim.flighttest.campaign as fc
    seen = []

    def fake(folder, **kw):
        seen.append(kw["amplitude_deg"])
        return Path(folder) / "plan.csv"
    monkeypatch.setattr(fc, "virtual_campaign", fake)
    for extra in ([], ["--amplitude-deg", "1"]):
        code, out, err = run(capsys, "flighttest", "--campaign", tmp_path / "c", *extra)
        assert code == 0, err
    assert seen == [fc.AMPLITUDE_DEG, 1.0] and fc.AMPLITUDE_DEG < 1.0
    code, out, err = run(capsys, "flighttest", "--out", tmp_path / "r.csv", "--start",
                         "0.1", "--duration", "0.5", "--json")
    assert code == 0, err
    (man,) = json.loads(out)["manoeuvres"]
    assert man["amplitude"] == pytest.approx(np.radians(1.0))
