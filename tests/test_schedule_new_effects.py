"""Schedules with the effects of issue #35 (item 2): a campaign's schedule of a
structure holding ``servo-actuators``, ``lead-lag``, ``peters-he-6`` and
``wake-distortion`` (every parameter following ``mu``, the trim too, since
``lead-lag`` is linearised about it) flies the Simulator at every ``mu`` as the
model rebuilt there, and builds into a scheduled FMU that flies it to 1e-10."""
import numpy as np
import pytest

from inflowsim.model.params import PUMA
from test_schedule import TRIM_MUS, _trim_rows

STRUCTURE = "glauert+servo-actuators+lead-lag+peters-he-6+wake-distortion"
NEW = ("servo_tau", "servo_zeta", "nu_zeta", "zeta_lag", "k_flap_lag", "k_ph", "K_R")


def _schedule():
    from inflowsim.campaign.schedule import campaign_schedule
    rows, p0 = _trim_rows(TRIM_MUS, structure=STRUCTURE)
    for row in rows:              # K_R's theory is 0 at the Puma's skew: give it a value
        m = row["mu"]
        row["base_fit"]["parameters"]["K_R"] = {"estimate": 0.8 - 1.5 * (m - 0.2),
                                                "sigma": 0.01}
    sch, note = campaign_schedule(rows)
    assert note == ""
    return sch, p0


def test_a_schedule_of_the_new_effects_flies_the_simulator_at_every_mu():
    """Every parameter of the structure is scheduled (the new effects' with a trend),
    the trim too; each step of the scheduled Simulator through and beyond the range
    equals the exact zero-order hold of the model rebuilt at that mu with the
    scheduled parameters and trim (the table, not rebuilds), to 1e-11 of the state."""
    from inflowsim.model.build import build_model
    from inflowsim.simulate.discrete import discretize
    from inflowsim.simulate.simulator import Simulator
    sch, p0 = _schedule()
    assert set(NEW) <= set(sch.names) and set(sch.names) == set(p0) | {"K_R"}
    assert all(sch[n].order >= 1 for n in ("servo_tau", "nu_zeta", "k_ph", "K_R"))
    assert sch.trim_columns and sch.mu_range == (TRIM_MUS[0], TRIM_MUS[-1])
    m0 = sch.model(PUMA, 0.2)
    assert m0.structure.name == build_model(STRUCTURE, sch(0.2), m0.constants).structure.name
    sim = Simulator(m0, 0.01, schedule=sch)
    rng = np.random.default_rng(0)
    x = np.zeros(m0.a.shape[0])
    worst = 0.0
    for mu in np.linspace(0.101, 0.42, 60):
        u = 1e-3 * rng.standard_normal(10)
        sim.set_mu(mu)
        y = sim.step(u)
        m = sch.model(PUMA, mu)
        phi, gam = discretize(m.a, m.b, 0.01)
        x = phi @ x + gam @ u
        worst = max(worst, np.abs(m.c @ x - y).max() / np.abs(x).max())
    assert sim._mu_table and sim._mu_table.ok
    assert worst < 1e-11
    # the new effects' values follow mu: at the range's ends they differ
    lo, hi = sch(TRIM_MUS[0]), sch(TRIM_MUS[-1])
    assert all(lo[n] != hi[n] for n in ("servo_tau", "nu_zeta", "k_ph", "K_R"))


@pytest.mark.slow
def test_the_scheduled_fmu_of_the_new_effects_is_the_scheduled_simulator(tmp_path):
    """``inflowsim fmu build --schedule`` of that schedule: FMI 2 through fmpy along
    a mu sweep through both held ends equals the scheduled Simulator to 1e-10."""
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave
    from inflowsim.fmu import description_for
    from inflowsim.simulate.simulator import Simulator
    from test_fmu_schedule import INPUTS, MUS, N, OUTPUTS, build_scheduled
    sch, _ = _schedule()
    doc = build_scheduled(sch, tmp_path)
    assert set(NEW) <= set(doc["scheduled"])
    d = description_for(sch)
    u = 1e-2 * np.random.default_rng(1).standard_normal((N, 10))
    sim = Simulator(sch.model(PUMA, MUS[0]), 0.01, schedule=sch)
    s = FMU2Slave(guid=doc["guid"], unzipDirectory=extract(doc["fmu"]),
                  modelIdentifier="inflowsim", instanceName="s")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    ref, got = [], []
    for k in range(N):
        sim.set_mu(MUS[k])
        ref.append(sim.step(u[k]))
        s.setReal([d.vr["mu"]], [float(MUS[k])])
        s.setReal([d.vr[n] for n in INPUTS], list(map(float, u[k])))
        s.doStep(k * 0.01, 0.01)
        got.append(s.getReal([d.vr[n] for n in OUTPUTS]))
    s.terminate()
    s.freeInstance()
    ref = np.array(ref)
    assert np.abs(np.array(got) - ref).max() < 1e-10 * np.abs(ref).max()
    assert s is not None and d.vr["nu_zeta"] and d.vr["servo_tau"]
