"""The scheduled FMU (issue #26 item 3): ``inflowsim fmu build --schedule FILE``
gives the scheduled Simulator's trajectory to 1e-10 through fmpy, libcosim
(``libcosimpy``) and ecos (``ecospy``), and flies the mu sweep of
``examples/simulator_loop.c``."""
import contextlib
import io
import json
import shutil
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest

from inflowsim.cli import main
from inflowsim.model.build import build_model
from inflowsim.model.params import PUMA
from inflowsim.model.schedule import write_schedule
from inflowsim.simulate.simulator import Simulator
from test_schedule import TRIM_STRUCTURE, _glauert_schedule, _trim_schedule

ROOT = Path(__file__).resolve().parents[1]
INPUTS = ("theta0", "theta1c", "theta1s", "muz", "q", "p", "qdot", "pdot", "mux", "muy")
OUTPUTS = ("beta0", "beta1c", "beta1s", "lambda0", "lambda1c", "lambda1s")
N = 300
#: down from the start through the schedule's lower end (0.12) to the table's, then
#: up through its upper end (0.30) to 0.45: both held ends and both knots
MUS = np.concatenate([np.linspace(0.249, 0.101, 100), np.linspace(0.101, 0.45, 200)])


def build_scheduled(sch, folder) -> dict:
    """``sch`` written to ``folder/schedule.json`` and built by ``inflowsim fmu build
    --schedule`` into ``folder/s.fmu``: the command's ``--json`` document."""
    path = write_schedule(sch, Path(folder) / "schedule.json")
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["fmu", "build", "--schedule", str(path), "--out",
                     str(Path(folder) / "s.fmu"), "--json"])
    assert code == 0
    return json.loads(buf.getvalue())


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The schedule file, the FMU built from it by the command, its description."""
    d = tmp_path_factory.mktemp("sched")
    sch, p0 = _glauert_schedule()
    doc = build_scheduled(sch, d)
    assert doc["scheduled"] == list(sch.names)
    from inflowsim.fmu import description_for
    return sch, p0, Path(doc["fmu"]), description_for(sch), doc["guid"]


@pytest.fixture(scope="module")
def reference(built):
    """The scheduled Simulator's outputs along MUS (seeded inputs) and the inputs."""
    sch, p0, *_ = built
    u = 1e-2 * np.random.default_rng(1).standard_normal((N, 10))
    sim = Simulator(build_model("glauert", p0, PUMA), 0.01, schedule=sch)
    y = []
    for k in range(N):
        sim.set_mu(MUS[k])
        y.append(sim.step(u[k]))
    return u, np.array(y)


def test_fmpy(built, reference):
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave
    from fmpy.fmi1 import FMICallException
    sch, _, fmu, d, guid = built
    u, ref = reference
    vr = d.vr
    s = FMU2Slave(guid=guid, unzipDirectory=extract(str(fmu)), modelIdentifier="inflowsim",
                  instanceName="s")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    y = []
    for k in range(N):
        s.setReal([vr["mu"]], [float(MUS[k])])
        s.setReal([vr[n] for n in INPUTS], list(map(float, u[k])))
        s.doStep(k * 0.01, 0.01)
        y.append(s.getReal([vr[n] for n in OUTPUTS]))
    assert np.abs(np.array(y) - ref).max() < 1e-10 * np.abs(ref).max()
    # a scheduled parameter reads its value at the last step's mu, and is not set
    assert s.getReal([vr["tau0"]])[0] == sch(0.45)["tau0"]
    with pytest.raises(FMICallException):
        s.setReal([vr["tau0"]], [2.0])
    s.terminate()
    s.freeInstance()
    # the model description declares them local, calculated, without a start value
    from fmpy.validation import validate_fmu
    assert validate_fmu(str(fmu)) == []
    with zipfile.ZipFile(fmu) as z:
        xml = z.read("modelDescription.xml").decode()
    line = next(ln for ln in xml.splitlines() if 'name="tau0"' in ln)
    assert 'causality="local"' in line and 'initial="calculated"' in line


def test_libcosim(built, reference):
    pytest.importorskip("libcosimpy", reason="libcosimpy not installed "
                        "(pip install inflowsim[importers])")
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave
    _, _, fmu, d, _ = built
    u, ref = reference
    log_output_level(CosimLogLevel.ERROR)
    ex = CosimExecution.from_step_size(step_size=10_000_000)          # 0.01 s in ns
    i = ex.add_local_slave(CosimLocalSlave(fmu_path=str(fmu), instance_name="rotor"))
    man = CosimManipulator.create_override()
    obs = CosimObserver.create_last_value()
    ex.add_manipulator(man)
    ex.add_observer(obs)
    ins = [d.vr["mu"]] + [d.vr[n] for n in INPUTS]
    y = []
    for k in range(N):              # an override is applied before the next step
        man.slave_real_values(i, ins, [float(MUS[k])] + list(map(float, u[k])))
        assert ex.step()
        y.append(obs.last_real_values(i, [d.vr[n] for n in OUTPUTS]))
    assert np.abs(np.array(y) - ref).max() < 1e-10 * np.abs(ref).max()


def _ecospy():
    try:
        import ecospy
    except ImportError:
        pytest.skip("ecospy not installed (pip install inflowsim[importers])")
    except OSError as exc:          # its binary needs the system's oneTBB (libtbb12)
        pytest.skip(f"ecospy cannot load its library: {exc}")
    return ecospy


def test_ecos(built, reference):
    ecospy = _ecospy()
    _, _, fmu, _, _ = built
    u, ref = reference
    ecospy.EcosLib.set_log_level("warn")
    st = ecospy.EcosSimulationStructure()
    st.add_model("rotor", str(fmu))
    sim = ecospy.EcosSimulation(structure=st, step_size=0.01)
    sim.init()
    y = []
    try:
        for k in range(N):
            sim.set_real("rotor::mu", float(MUS[k]))
            for n, v in zip(INPUTS, u[k]):
                sim.set_real(f"rotor::{n}", float(v))
            sim.step()
            y.append([sim.get_real(f"rotor::{n}") for n in OUTPUTS])
    finally:
        sim.terminate()
        sim.free()
    assert np.abs(np.array(y) - ref).max() < 1e-10 * np.abs(ref).max()


def test_the_scheduled_fmu_flies_the_simulator_loop_sweep(built, tmp_path):
    """examples/simulator_loop.c (unchanged) flies the scheduled FMU from hover to
    forward flight (its value references from the FMU's own generated header); then its
    mu sweep, with the pilot's cyclic and collective it recorded, drives the FMU
    through fmpy and the scheduled Simulator alike (mass-flow speed, frames of
    1/60 s): the same trajectory to 1e-10."""
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave
    sch, p0, fmu, d, guid = built
    unz = Path(extract(str(fmu), str(tmp_path / "x")))
    exe = tmp_path / "loop"
    subprocess.run([cc, "-std=c99", "-O2", "-I", str(unz / "sources"), "-o", str(exe),
                    str(ROOT / "examples" / "simulator_loop.c"), "-ldl", "-lm"], check=True)
    out = subprocess.run([str(exe), str(unz / "binaries" / "linux64" / "inflowsim.so"),
                          guid, str(tmp_path / "loop.csv")], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "frames: 2700" in out.stdout
    rows = np.genfromtxt(tmp_path / "loop.csv", delimiter=",", names=True)
    mus = rows["mu"]
    assert len(mus) == 2700 and np.all(np.isfinite(rows["thrust"]))
    assert mus[0] == 0.0 and mus.max() > 0.24         # hover to forward flight
    frame = 1 / 60
    ct = 5805.0 * 9.81 / (1.225 * np.pi * 7.5 ** 2 * (27.5 * 7.5) ** 2)
    u = np.zeros((len(mus), 10))
    u[:, :3] = np.column_stack([rows["theta0"], rows["theta1c"], rows["theta1s"]])
    k = PUMA.with_mu(0.249)
    from dataclasses import replace
    k = replace(k, inflow_speed="mass-flow", ct=ct)
    sim = Simulator(build_model("glauert", p0, k), frame, schedule=sch)
    vr = d.vr
    s = FMU2Slave(guid=guid, unzipDirectory=str(unz), modelIdentifier="inflowsim",
                  instanceName="sweep")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.setInteger([vr["inflow_speed"]], [1])
    s.setReal([vr["ct"], vr["dt"], vr["mu"]], [ct, frame, 0.0])
    s.exitInitializationMode()
    sim.set_mu(0.0)
    worst = scale = 0.0
    for j in range(len(mus)):
        s.setReal([vr["mu"]] + [vr[n] for n in INPUTS], [float(mus[j])] + list(u[j]))
        s.doStep(j * frame, frame)
        yf = np.array(s.getReal([vr[n] for n in OUTPUTS]))
        sim.set_mu(float(mus[j]))
        ys = sim.step(u[j])
        worst, scale = max(worst, np.abs(yf - ys).max()), max(scale, np.abs(ys).max())
    s.terminate()
    s.freeInstance()
    assert scale > 1e-3 and worst < 1e-10 * scale
    # the sweep went through the schedule: its parameters at hover and at the end
    assert sim.model.parameters["tau0"] == sch(float(mus[-1]))["tau0"]
    assert sch(0.0)["tau0"] != sch(float(mus[-1]))["tau0"]


def test_bad_schedule_options_are_one_line_errors(tmp_path, capsys):
    from conftest import assert_user_error, run
    bad = tmp_path / "bad.json"
    bad.write_text('{"schedule": 1, "structure": "glauert", "mu_range": [0.1, 0.3], '
                   '"parameters": {"tau": {}}}')
    code, out, err = run(capsys, "fmu", "build", "--schedule", bad, "--out",
                         tmp_path / "x.fmu")
    assert_user_error(code, out, err, "bad.json")
    sch, _ = _glauert_schedule()
    good = write_schedule(sch, tmp_path / "s.json")
    code, out, err = run(capsys, "fmu", "build", "--schedule", good, "--model", "basic",
                         "--out", tmp_path / "x.fmu")
    assert_user_error(code, out, err, "--schedule")
    assert not (tmp_path / "x.fmu").exists()


# -- the trim follows mu ---------------------------------------------------------

def test_a_scheduled_trim_is_computed_from_mu_in_the_c():
    """A schedule with a trim, of a structure linearised about trim: the FMU's
    trim_<column> are local variables (read-only, calculated) after the scheduled
    parameters, computed in ifs_schedule_apply beside them, left out of the start
    values; another trim is another model (GUID).  A structure not linearised about
    trim has no trim variables: its C is that of the schedule without trim."""
    from dataclasses import replace
    from inflowsim.fmu import description_for, start_values
    from inflowsim.fmu.codegen import TRIM_PARAMETERS
    from inflowsim.fmu.generate import guid, schedule_c
    sch, p0 = _trim_schedule()
    d = description_for(sch)
    trims = tuple(TRIM_PARAMETERS)
    assert d.scheduled == sch.names + trims
    for n in trims:
        v = d.variables[d.vr[n]]
        assert (v.causality, v.variability, v.initial) == ("local", "continuous",
                                                            "calculated")
    # the start value (the C table's, before the first step) is the trim at the start
    # mu (the schedule's rotor's: its range's middle)
    assert d.variables[d.vr["trim_theta0"]].start == sch.trim_values(
        sch.constants.mu)["theta0"]
    c = schedule_c(d)
    for n in trims:
        assert sum(line.startswith(f"    v->{n} = ") for line in c) == 1
    vals = start_values(build_model(TRIM_STRUCTURE, p0, PUMA.with_trim(
        sch.trim_values(0.2))), description=d)
    assert not set(trims) & set(vals) and "mu" in vals
    bare = description_for(replace(sch, trim=()))
    assert not set(trims) & set(bare.scheduled) and guid(bare) != guid(d)
    assert bare.variables[bare.vr["trim_theta0"]].causality == "parameter"
    glauert, _ = _glauert_schedule()
    with_trim = replace(glauert, trim=sch.trim)
    assert description_for(with_trim).scheduled == glauert.names
    assert schedule_c(description_for(with_trim)) == schedule_c(description_for(glauert))


@pytest.mark.slow
def test_the_scheduled_trim_fmu_steps_as_the_simulator(tmp_path):
    """``inflowsim fmu build --schedule`` of a schedule with a trim (flap inertia,
    the direct in-plane forcing linearised about the trim): through fmpy, along the
    module's mu sweep (down through the schedule's lower end 0.12 to the table's,
    up through its upper end 0.30 to 0.45), the Simulator of the schedule's
    trajectory to 1e-10; the trim read from the FMU is the schedule's at the last
    step's mu, and is not set."""
    from fmpy import extract
    from fmpy.fmi2 import FMU2Slave
    from fmpy.fmi1 import FMICallException
    from inflowsim.fmu import description_for
    sch, p0 = _trim_schedule()
    doc = build_scheduled(sch, tmp_path)
    assert "trim_theta0" in doc["scheduled"]
    d = description_for(sch)
    u = 1e-2 * np.random.default_rng(2).standard_normal((N, 10))
    sim = Simulator(sch.model(PUMA), 0.01, schedule=sch)      # its trim at PUMA.mu
    vr = d.vr
    s = FMU2Slave(guid=doc["guid"], unzipDirectory=extract(doc["fmu"]),
                  modelIdentifier="inflowsim", instanceName="s")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    y, ref = [], []
    for k in range(N):
        s.setReal([vr["mu"]], [float(MUS[k])])
        s.setReal([vr[n] for n in INPUTS], list(map(float, u[k])))
        s.doStep(k * 0.01, 0.01)
        y.append(s.getReal([vr[n] for n in OUTPUTS]))
        sim.set_mu(MUS[k])
        ref.append(sim.step(u[k]))
    ref = np.array(ref)
    assert np.abs(ref).max() > 1e-3
    assert np.abs(np.array(y) - ref).max() < 1e-10 * np.abs(ref).max()
    got = s.getReal([vr[f"trim_{c}"] for c in sch.trim_columns])
    assert got == list(sch.trim_values(0.45).values())
    assert sch.trim_values(0.45) == sch.trim_values(0.30) != sch.trim_values(0.12)
    with pytest.raises(FMICallException):
        s.setReal([vr["trim_theta0"]], [0.1])
    s.terminate()
    s.freeInstance()
