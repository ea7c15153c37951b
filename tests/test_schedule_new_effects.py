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
    from inflowsim.simulate.simulator import Simulator
    from test_schedule import worst_against_rebuilds
    sch, p0 = _schedule()
    assert set(NEW) <= set(sch.names) and set(sch.names) == set(p0) | {"K_R"}
    assert all(sch[n].order >= 1 for n in ("servo_tau", "nu_zeta", "k_ph", "K_R"))
    assert sch.trim_columns and sch.mu_range == (TRIM_MUS[0], TRIM_MUS[-1])
    m0 = sch.model(PUMA, 0.2)
    assert m0.structure.name == build_model(STRUCTURE, sch(0.2),
                                            m0.constants).structure.name
    sim = Simulator(m0, 0.01, schedule=sch)
    worst = worst_against_rebuilds(sim, sch, np.linspace(0.101, 0.42, 30))
    assert sim._mu_table and sim._mu_table.ok
    assert worst < 1e-11
    # the new effects' values follow mu: at the range's ends they differ
    lo, hi = sch(TRIM_MUS[0]), sch(TRIM_MUS[-1])
    assert all(lo[n] != hi[n] for n in ("servo_tau", "nu_zeta", "k_ph", "K_R"))


@pytest.fixture(scope="module")
def scheduled_fmu(tmp_path_factory):
    """The schedule built by ``inflowsim fmu build --schedule``: ``(schedule, the
    command's --json document, the FMU's description)``."""
    from inflowsim.fmu import description_for
    from test_fmu_schedule import build_scheduled
    sch, _ = _schedule()
    doc = build_scheduled(sch, tmp_path_factory.mktemp("sched_new"))
    assert set(NEW) <= set(doc["scheduled"])
    return sch, doc, description_for(sch)


def _fly(scheduled_fmu, mus):
    """The FMU (FMI 2, fmpy) and the scheduled Simulator along ``mus`` with seeded
    inputs: the largest output difference over the largest output."""
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave
    from inflowsim.simulate.simulator import Simulator
    from test_fmu_schedule import INPUTS, OUTPUTS
    sch, doc, d = scheduled_fmu
    u = 1e-2 * np.random.default_rng(1).standard_normal((len(mus), 10))
    sim = Simulator(sch.model(PUMA, mus[0]), 0.01, schedule=sch)
    s = FMU2Slave(guid=doc["guid"], unzipDirectory=extract(doc["fmu"]),
                  modelIdentifier="inflowsim", instanceName="s")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    ref, got = [], []
    for k, mu in enumerate(mus):
        sim.set_mu(mu)
        ref.append(sim.step(u[k]))
        s.setReal([d.vr["mu"]], [float(mu)])
        s.setReal([d.vr[n] for n in INPUTS], list(map(float, u[k])))
        s.doStep(k * 0.01, 0.01)
        got.append(s.getReal([d.vr[n] for n in OUTPUTS]))
    s.terminate()
    s.freeInstance()
    ref = np.array(ref)
    return np.abs(np.array(got) - ref).max() / np.abs(ref).max()


@pytest.mark.slow
def test_the_scheduled_fmu_of_the_new_effects_is_the_scheduled_simulator(scheduled_fmu):
    """``inflowsim fmu build --schedule`` of that schedule: FMI 2 through fmpy, mu
    changed at every step down through the lower held end and up through the upper
    (test_fmu_schedule's sweep without its repeated turning point), equals the
    scheduled Simulator to 1e-10 (measured 3e-15)."""
    from test_fmu_schedule import MUS
    mus = np.concatenate([MUS[:100], MUS[101:]])
    assert np.all(np.diff(mus) != 0)
    assert _fly(scheduled_fmu, mus) < 1e-10


@pytest.mark.slow
def test_the_scheduled_fmu_of_the_new_effects_holds_a_constant_mu(scheduled_fmu):
    """The same FMU flown at a mu held for a while, as a loop that sets mu every step
    does in steady flight: test_fmu_schedule's sweep (its turning point sets 0.101
    twice), and a constant 0.2.  The step after a new mu is the general one, a held
    mu's the fast one (AVX2: the four-wide step, whose outputs of eight states or
    more rotate by the model's ``rot``): the scheduled azimuth bias must reach both
    (it reached ``cos_bias`` only: 1e-3 to 5e-3 of the output; measured 4e-14 now)."""
    from test_fmu_schedule import MUS
    assert _fly(scheduled_fmu, MUS) < 1e-10
    assert _fly(scheduled_fmu, np.full(100, 0.2)) < 1e-10
