"""The native FMI 2.0 co-simulation FMU against the Python model (issue #3).

The FMU is built once per session into a temporary folder.  References are the
Python model's SI state space discretised with ``scipy.linalg.expm`` (or the
Simulator itself), never hard-coded numbers.
"""
from __future__ import annotations

import ctypes
import json
import math
import shutil
import subprocess
import zipfile
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import expm

fmpy = pytest.importorskip("fmpy")
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE,  # noqa: E402
                       fmi2CallbackFreeMemoryTYPE, fmi2CallbackFunctions,
                       fmi2CallbackLoggerTYPE)
from fmpy.fmi3 import FMU3Slave  # noqa: E402

from inflowsim.errors import InputError  # noqa: E402
from inflowsim.fmu import VR, apply_parameters, build_fmu, start_values  # noqa: E402
from inflowsim.fmu.generate import GENERATED, TIME_VR, generated_files  # noqa: E402
from inflowsim.fmu.variables import HOVER_HINT  # noqa: E402
from inflowsim.fmu.build import compile_library, source_dir, sources  # noqa: E402
from inflowsim.model import build_model  # noqa: E402
from inflowsim.model.paramfile import read_parameters  # noqa: E402
from inflowsim.model.params import PUMA  # noqa: E402
from inflowsim.model.presets import preset_parameters  # noqa: E402
from inflowsim.data.record import find_trim, model_inputs  # noqa: E402
from inflowsim.simulate.simulator import Simulator  # noqa: E402
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record  # noqa: E402

DT = 0.01
OUTPUTS = ("beta0", "beta1c", "beta1s", "lambda0", "lambda1c", "lambda1s")
LOADS = ("CT", "C_mc", "C_ms", "C_mc_hub", "C_ms_hub")
ALL_INPUTS = ("theta0", "theta1c", "theta1s", "muz", "q", "p", "qdot", "pdot", "mux", "muy")


@pytest.fixture(scope="module")
def fmu_path(tmp_path_factory):
    return build_fmu(tmp_path_factory.mktemp("fmu") / "inflowsim.fmu")


@pytest.fixture(scope="module")
def unzipped(fmu_path, tmp_path_factory):
    return extract(str(fmu_path), str(tmp_path_factory.mktemp("unzipped")))


@pytest.fixture(scope="module")
def guid(fmu_path):
    return read_model_description(str(fmu_path)).guid


@pytest.fixture(scope="module")
def fmu3_path(tmp_path_factory):
    return build_fmu(tmp_path_factory.mktemp("fmu3") / "inflowsim3.fmu", fmi_version=3)


@pytest.fixture(scope="module")
def unzipped3(fmu3_path, tmp_path_factory):
    return extract(str(fmu3_path), str(tmp_path_factory.mktemp("unzipped3")))


@pytest.fixture(scope="module")
def record():
    return virtual_record(VirtualTest(duration=6.0, manoeuvres=(
        Manoeuvre(channel="theta1s", shape="doublet", amplitude=math.radians(1.0),
                  t_start=0.5, width=0.4),
        Manoeuvre(channel="theta1c", shape="doublet", amplitude=math.radians(0.7),
                  t_start=2.5, width=0.3))))


def model_of(structure, **changes):
    p = preset_parameters(structure, PUMA, "paper")
    p.update(changes)
    return build_model(structure, p, PUMA)


def zoh_ref(model, h):
    """[phi gam] of the Python model at step h, straight from scipy's expm."""
    n, m = model.b.shape
    aug = np.zeros((n + m, n + m))
    aug[:n, :n], aug[:n, n:] = model.a, model.b
    e = expm(aug * h)
    return e[:n, :n], e[:n, n:]


#: fmpy's native logger proxy forwards every fmi2 message, whoever's callbacks the FMU
#: was given, to the callback registered last: a Logger must outlive the session or a
#: later message calls freed memory.
_LOGGERS = []


class Logger:
    """fmi2 callbacks that keep the FMU's log messages (formatted by fmpy's proxy)."""

    def __init__(self):
        _LOGGERS.append(self)
        self.messages = []
        lib = ctypes.CDLL(None)
        lib.calloc.restype = ctypes.c_void_p
        self.cb = fmi2CallbackFunctions()
        self._log = fmi2CallbackLoggerTYPE(self._keep)
        self.cb.logger = self._log
        self.cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(("calloc", lib))
        self.cb.freeMemory = fmi2CallbackFreeMemoryTYPE(("free", lib))
        from fmpy.logging import addLoggerProxy
        addLoggerProxy(ctypes.byref(self.cb))

    def _keep(self, env, name, status, category, message):
        self.messages.append((status, message.decode()))

    def text(self):
        return "\n".join(m for _, m in self.messages)


def instantiated_fmu(unzipped, guid, name="a", logger=None):
    """An FMI 2.0 slave instantiated, nothing else (logging to ``logger``)."""
    s = FMU2Slave(guid=guid, unzipDirectory=unzipped, modelIdentifier="inflowsim",
                  instanceName=name)
    s.instantiate(callbacks=logger.cb if logger else None)
    return s


def open_fmu(unzipped, guid, values=None, name="a", logger=None, start=0.0):
    s = instantiated_fmu(unzipped, guid, name, logger)
    s.setupExperiment(startTime=start)
    s.enterInitializationMode()
    if values is not None:
        apply_parameters(s, values)
    s.exitInitializationMode()
    return s


def open_fmu3(unzipped, guid, values=None, name="a", log=None, start=0.0):
    s = FMU3Slave(guid=guid, unzipDirectory=unzipped, modelIdentifier="inflowsim",
                  instanceName=name)
    s.instantiate(logMessage=log)
    s.enterInitializationMode(startTime=start)
    if values is not None:
        apply_parameters(s, values)
    s.exitInitializationMode()
    return s


def set_reals(s, vrs, values):
    """setReal (FMI 2.0) or setFloat64 (FMI 3.0)."""
    (s.setFloat64 if hasattr(s, "setFloat64") else s.setReal)(vrs, list(values))


def get_reals(s, vrs):
    return (s.getFloat64 if hasattr(s, "getFloat64") else s.getReal)(vrs)


def simulate_with_fmpy(fmu_path, values, inputs, u):
    """fmpy.simulate_fmu with the inputs u (columns named inputs) sampled at DT."""
    t = np.arange(len(u)) * DT
    sig = np.zeros(len(u), dtype=[("time", float)] + [(n, float) for n in inputs])
    sig["time"] = t
    for i, n in enumerate(inputs):
        sig[n] = u[:, i]
    res = fmpy.simulate_fmu(str(fmu_path), start_values=values, input=sig,
                            output=list(OUTPUTS), step_size=DT, output_interval=DT,
                            stop_time=t[-1])
    return np.column_stack([res[n] for n in OUTPUTS])


def full_inputs(model, u):
    """The FMU always has the ten inputs; a structure without mux, muy gets zeros."""
    out = np.zeros((len(u), len(ALL_INPUTS)))
    out[:, : u.shape[1]] = u
    return out


def fmu_replay(s, u, h=DT, t0=0.0):
    """Importer convention: inputs at t_k, step, outputs at t_{k+1}; y[0] initial.
    s is an FMI 2.0 or 3.0 slave."""
    ins, outs = [VR[n] for n in ALL_INPUTS], [VR[n] for n in OUTPUTS]
    y = [get_reals(s, outs)]
    for k in range(len(u) - 1):
        set_reals(s, ins, u[k])
        s.doStep(t0 + k * h, h)
        y.append(get_reals(s, outs))
    return np.array(y)


# -- generation, packaging, binary ------------------------------------------------

def test_committed_generated_files_match_the_variable_description():
    src = source_dir()
    for name, text in generated_files().items():
        committed = (src / name).read_text(encoding="utf-8")
        assert committed == text, f"fmu/{name} is stale: run inflowsim.fmu.generate"
    assert set(GENERATED) == set(generated_files())


def test_fmpy_validation_reports_no_problem(fmu_path):
    from fmpy.validation import validate_fmu
    assert validate_fmu(str(fmu_path)) == []


def test_fmu_contents(fmu_path):
    names = set(zipfile.ZipFile(fmu_path).namelist())
    for n in ("modelDescription.xml", "binaries/linux64/inflowsim.so",
              "documentation/index.html", "sources/inflow_model.c", "sources/inflow_fmi2.c",
              "sources/inflow_vars.c", "sources/inflow_vars.h", "sources/fmi2Functions.h",
              "sources/fmi2FunctionTypes.h", "sources/fmi2TypesPlatform.h",
              "sources/LICENSE-FMI.txt"):
        assert n in names


def test_binary_needs_no_python_and_exports_only_fmi(unzipped):
    so = Path(unzipped) / "binaries" / "linux64" / "inflowsim.so"
    dyn = subprocess.run(["readelf", "-d", str(so)], capture_output=True, text=True,
                         check=True).stdout
    needed = [line for line in dyn.splitlines() if "NEEDED" in line]
    assert needed and not any("python" in line.lower() for line in needed)
    syms = subprocess.run(["nm", "-D", "--defined-only", str(so)], capture_output=True,
                          text=True, check=True).stdout.split()
    exported = {s for s in syms if s.startswith(("fmi", "ifs"))}
    for f in ("fmi2Instantiate", "fmi2DoStep", "fmi2GetReal", "fmi2SetReal",
              "fmi2GetFMUstate", "fmi2SerializeFMUstate", "fmi2Reset", "fmi2GetRealStatus"):
        assert f in exported
    assert not any(s.startswith("ifs") for s in exported), "model internals must be hidden"


# -- equality with the Python simulator -----------------------------------------

@pytest.mark.parametrize("structure", ["basic", "empirical", "glauert"])
def test_replay_equals_simulator(structure, unzipped, guid, record):
    m = model_of(structure)
    u = model_inputs(record, m, find_trim(record))
    y_py = Simulator(m, DT).replay(u)
    s = open_fmu(unzipped, guid, start_values(m))
    y_fmu = fmu_replay(s, full_inputs(m, u))
    s.freeInstance()
    assert np.abs(y_py).max() > 1e-3               # the doublets move the rotor
    np.testing.assert_allclose(y_fmu, y_py, rtol=0, atol=1e-10)


def test_parameter_file_applies_in_one_call(tmp_path, fmu_path, record):
    """An identify-style file (estimate + sigma) for a non-preset structure."""
    p = preset_parameters("glauert", PUMA, "paper")
    p["tau"] = p.pop("tau0")
    del p["tau_cs"]
    doc = {"structure": "basic+glauert+azimuth-bias", "constants": PUMA.as_dict(),
           "parameters": {k: {"estimate": v, "sigma": 0.01} for k, v in p.items()}}
    f = tmp_path / "fit.json"
    f.write_text(json.dumps(doc))
    ps = read_parameters(f)
    m = ps.model()
    u = model_inputs(record, m, find_trim(record))
    y_py = Simulator(m, DT).replay(u)
    y = simulate_with_fmpy(fmu_path, start_values(ps), m.inputs, u)
    # fmpy records the initial outputs at t0, then the outputs after each step
    assert len(y) == len(u)
    np.testing.assert_allclose(y, y_py, rtol=0, atol=1e-10)


@pytest.mark.parametrize("effect", ["flap-inertia", "skewed-wake"])
def test_unsupported_effect_is_refused(effect):
    from inflowsim.model.presets import truth_parameters
    s = f"basic+{effect}"
    m = build_model(s, truth_parameters(s, PUMA), PUMA)
    with pytest.raises(InputError, match=effect):
        start_values(m)


def test_communication_step_not_a_multiple_of_dt(unzipped, guid, record):
    m = model_of("glauert")
    u = full_inputs(m, model_inputs(record, m, find_trim(record)))
    hs = [0.025, 0.025, 0.003, 0.05, 0.0137, 0.01, 0.025, 0.1] * 3
    s = open_fmu(unzipped, guid, start_values(m))
    ins, outs = [VR[n] for n in ALL_INPUTS], [VR[n] for n in OUTPUTS]
    x = np.zeros(6)
    t = 0.0
    for i, h in enumerate(hs):
        uk = u[50 + 7 * i]
        s.setReal(ins, list(uk))
        s.doStep(t, h)
        phi, gam = zoh_ref(m, h)
        x = phi @ x + gam @ uk
        t += h
        np.testing.assert_allclose(s.getReal(outs), m.c @ x, rtol=0, atol=1e-12)
    assert np.abs(x).max() > 1e-4
    s.freeInstance()


def test_time_is_a_step_counter(unzipped, guid):
    s = open_fmu(unzipped, guid, start=1.0)
    h = 0.1                     # 0.1 is inexact: a running sum drifts, a counter does not
    for k in range(1000):
        s.doStep(1.0 + k * h, h)
    assert s.getRealStatus(2) == 1.0 + 1000 * h     # fmi2LastSuccessfulTime
    s.freeInstance()


def test_interleaved_instances_equal_separate_runs(unzipped, guid, record):
    ma, mb = model_of("glauert"), model_of("empirical")
    ua = full_inputs(ma, model_inputs(record, ma, find_trim(record)))
    ub = full_inputs(mb, model_inputs(record, mb, find_trim(record)))
    sep = []
    for m, u in ((ma, ua), (mb, ub)):
        s = open_fmu(unzipped, guid, start_values(m))
        sep.append(fmu_replay(s, u))
        s.freeInstance()
    a = open_fmu(unzipped, guid, start_values(ma), name="a")
    b = open_fmu(unzipped, guid, start_values(mb), name="b")
    ins, outs = [VR[n] for n in ALL_INPUTS], [VR[n] for n in OUTPUTS]
    ya, yb = [a.getReal(outs)], [b.getReal(outs)]
    for k in range(len(ua) - 1):
        a.setReal(ins, list(ua[k]))
        b.setReal(ins, list(ub[k]))
        a.doStep(k * DT, DT)
        b.doStep(k * DT, DT)
        ya.append(a.getReal(outs))
        yb.append(b.getReal(outs))
    a.freeInstance()
    b.freeInstance()
    assert np.array_equal(np.array(ya), sep[0]) and np.array_equal(np.array(yb), sep[1])
    assert not np.allclose(sep[0], sep[1])


def test_fmu_state_get_set_and_serialize(unzipped, guid, record):
    m = model_of("glauert")
    u = full_inputs(m, model_inputs(record, m, find_trim(record)))
    s = open_fmu(unzipped, guid, start_values(m))
    fmu_replay(s, u[:100])
    saved = s.getFMUstate()
    blob = s.serializeFMUstate(saved)
    tail = fmu_replay(s, u[99:200], t0=0.99)
    s.setFMUstate(saved)
    again = fmu_replay(s, u[99:200], t0=0.99)
    s.setFMUstate(s.deSerializeFMUstate(blob))
    third = fmu_replay(s, u[99:200], t0=0.99)
    s.freeFMUstate(saved)
    s.freeInstance()
    assert np.array_equal(tail, again) and np.array_equal(tail, third)


@pytest.mark.parametrize("flags", [("-DIFS_NO_CLONES",),
                                   ("-DIFS_NO_CLONES", "-DIFS_SCALAR_STEP")],
                         ids=["baseline-only", "plain-c-step"])
def test_every_compiled_step_gives_the_same_numbers(flags, unzipped, guid, record,
                                                     tmp_path):
    """The shipped binary steps with its AVX2 clone where the CPU has AVX2; built
    without clones it steps with the baseline code, and with IFS_SCALAR_STEP with the
    plain-C loop other compilers get.  All must agree bit for bit, on the loop's
    fast path (h = dt), on substeps with a remainder (h = 2.5 dt), with mu
    changing every step (the mu table's evaluation is cloned for AVX2 too; with the
    inputs held, gam u from the table's parts) and with a step changing every frame
    (the Taylor remainder, over the whole remainder and over its difference from the
    cached one)."""
    other = tmp_path / "unzipped"
    shutil.copytree(unzipped, other)
    compile_library(source_dir(), other / "binaries" / "linux64" / "inflowsim.so", flags)
    m = model_of("glauert", azimuth_bias=0.05)
    u = full_inputs(m, model_inputs(record, m, find_trim(record)))[:300]
    runs = []
    for d in (unzipped, str(other)):
        s = open_fmu(d, guid, start_values(m))
        y = fmu_replay(s, u)
        y_long = fmu_replay(s, u[:40], h=2.5 * DT, t0=(len(u) - 1) * DT)
        t0 = (len(u) - 1) * DT + 39 * 2.5 * DT
        y_mu = []
        for k, uk in enumerate(u[:60]):
            set_reals(s, [VR["mu"]], [0.3 + 0.15 * np.sin(0.1 * k)])
            set_reals(s, [VR[n] for n in ALL_INPUTS], list(uk))
            s.doStep(t0 + k * DT, DT)
            y_mu.append(get_reals(s, [VR[n] for n in OUTPUTS]))
        t0 += 60 * DT
        set_reals(s, [VR["mu"]], [0.3])
        for k, uk in enumerate(u[:80]):
            h = ((1 / 60) * (1 + 0.02 * np.sin(1.7 * k)) if k < 60
                 else DT * (1.4 - 0.04 * (k - 60)))
            set_reals(s, [VR[n] for n in ALL_INPUTS], list(uk))
            s.doStep(t0, h)
            t0 += h
            y_mu.append(get_reals(s, [VR[n] for n in OUTPUTS]))
        for k in range(20):                # the inputs held: the step keeps gam u
            s.doStep(t0, DT)
            t0 += DT
            y_mu.append(get_reals(s, [VR[n] for n in OUTPUTS]))
        for k in range(40):                # ... and mu alone: gam u from the table
            set_reals(s, [VR["mu"]], [0.3 + 0.01 * np.sin(0.2 * k)])   # parts' gq
            s.doStep(t0, DT)
            t0 += DT
            y_mu.append(get_reals(s, [VR[n] for n in OUTPUTS]))
        s.freeInstance()
        runs.append(np.vstack([y, y_long, np.array(y_mu)]))
    assert np.abs(runs[0]).max() > 1e-3
    assert np.array_equal(runs[0], runs[1])


def test_inputs_held_or_set_again_agree_to_rounding(unzipped, guid, record):
    """The step keeps its inputs' part (gam u) while the inputs and the matrices are
    held, and from the third step with them looks ahead (each state from the one two
    steps before, phi^2 and (phi + I) gam u); an input or mu set computes gam u again
    and restarts it, even with the values held (a comparison cost the frame more than
    it saves: bench/fmu_states.md).  So a run that sets the same inputs before every
    step (one step at a time) and one that sets them once (two interleaved recurrences
    of phi^2) agree to rounding, 1e-12 of the peak, through a mu change (the table's
    matrices) and after it."""
    m = model_of("glauert", azimuth_bias=0.05)
    u = full_inputs(m, model_inputs(record, m, find_trim(record)))[:120]
    ins, outs = [VR[n] for n in ALL_INPUTS], [VR[n] for n in OUTPUTS]
    runs = []
    for again in (True, False):
        s = open_fmu(unzipped, guid, start_values(m))
        y = []
        for k in range(len(u)):
            if again or k % 30 == 0:
                set_reals(s, ins, u[30 * (k // 30)])
            if k == 50:
                set_reals(s, [VR["mu"]], [0.31])
            s.doStep(k * DT, DT)
            y.append(get_reals(s, outs))
        s.freeInstance()
        runs.append(np.array(y))
    assert np.abs(runs[0]).max() > 1e-4
    assert np.abs(runs[0] - runs[1]).max() <= 1e-12 * np.abs(runs[0]).max()


# -- one test body against the Python simulator and the FMU ---------------------

class PythonAdapter:
    def __init__(self, model, ctx):
        self.sim = Simulator(model, DT)
        self.model = model
        self.m = model.b.shape[1]

    def step(self, u):
        return self.sim.step(np.asarray(u)[: self.m])

    def set_parameters(self, **kw):
        self.sim.set_model(self.sim.model.with_parameters(**kw))

    def set_mu(self, mu):
        self.sim.set_mu(mu)

    def reset(self):
        """Back to the first model and a zero state, like fmi2Reset + initialization."""
        self.sim.set_model(self.model)
        self.sim.reset()

    def close(self):
        pass


class FmuAdapter:
    opener = staticmethod(open_fmu)

    def __init__(self, model, ctx):
        self.s = self.opener(*ctx, start_values(model))
        self.values = start_values(model)
        self.ctx = ctx
        self.k = 0

    def step(self, u):
        set_reals(self.s, [VR[n] for n in ALL_INPUTS], u)
        self.s.doStep(self.k * DT, DT)
        self.k += 1
        return np.array(get_reals(self.s, [VR[n] for n in OUTPUTS]))

    def set_parameters(self, **kw):
        set_reals(self.s, [VR[n] for n in kw], kw.values())

    def set_mu(self, mu):
        set_reals(self.s, [VR["mu"]], [mu])

    def reset(self):
        self.s.reset()
        self.enter_initialization()
        apply_parameters(self.s, self.values)
        self.s.exitInitializationMode()
        self.k = 0

    def enter_initialization(self):
        self.s.setupExperiment(startTime=0.0)
        self.s.enterInitializationMode()

    def close(self):
        self.s.freeInstance()


class Fmu3Adapter(FmuAdapter):
    """The same FMU through FMI 3.0."""

    opener = staticmethod(open_fmu3)

    def enter_initialization(self):
        self.s.enterInitializationMode(startTime=0.0)


@pytest.mark.parametrize("adapter", [PythonAdapter, FmuAdapter, Fmu3Adapter],
                         ids=["python", "fmi2", "fmi3"])
def test_stepping_contract(adapter, unzipped, unzipped3, guid, record):
    """Steps, a parameter change, a mu change and a reset, each against a reference
    built from the Python model with scipy's expm."""
    m = model_of("glauert")
    u = full_inputs(m, model_inputs(record, m, find_trim(record)))[:240]
    sim = adapter(m, (unzipped3 if adapter is Fmu3Adapter else unzipped, guid))
    ref_model, x, ys, refs = m, np.zeros(6), [], []
    phi0, gam0 = zoh_ref(m, DT)
    x_unchanged = np.zeros(6)
    for k, uk in enumerate(u):
        x_unchanged = phi0 @ x_unchanged + gam0 @ uk
        if k == 80:
            sim.set_parameters(tau_cs=15.0, kc=0.3)
            ref_model = ref_model.with_parameters(tau_cs=15.0, kc=0.3)
        if k == 160:
            sim.set_mu(0.3)
            ref_model = ref_model.with_mu(0.3)
        phi, gam = zoh_ref(ref_model, DT)
        x = phi @ x + gam @ uk
        refs.append(ref_model.c @ x)
        ys.append(sim.step(uk))
    np.testing.assert_allclose(np.array(ys), np.array(refs), rtol=0, atol=1e-10)
    # the changes matter: the unchanged model ends elsewhere
    assert np.abs(refs[-1] - m.c @ x_unchanged).max() > 1e-5
    sim.reset()
    phi, gam = zoh_ref(m, DT)
    x = np.zeros(6)
    for uk in u[:60]:
        x = phi @ x + gam @ uk
        np.testing.assert_allclose(sim.step(uk), m.c @ x, rtol=0, atol=1e-10)
    sim.close()


# -- errors -----------------------------------------------------------------------

def test_bad_parameter_is_refused_with_its_name_and_range(unzipped, guid):
    log = Logger()
    s = open_fmu(unzipped, guid, logger=log)
    with pytest.raises(Exception, match="fmi2SetReal"):
        s.setReal([VR["n_beta"]], [-1.0])
    assert "n_beta" in log.text() and "[1e-06, 10]" in log.text()
    assert s.getReal([VR["n_beta"]])[0] > 0          # not stored
    with pytest.raises(Exception):
        s.setReal([VR["mu"]], [0.05])
    assert "mu" in log.messages[-1][1] and "[0.1, 0.5]" in log.messages[-1][1]
    with pytest.raises(Exception):
        s.setReal([VR["dt"]], [0.02])                 # fixed after initialization
    assert "dt" in log.messages[-1][1]
    with pytest.raises(Exception):
        s.setReal([VR["beta0"]], [0.1])               # an output
    s.doStep(0.0, DT)                                  # the instance still works
    s.freeInstance()


def test_bad_structure_is_refused(unzipped, guid):
    log = Logger()
    s = instantiated_fmu(unzipped, guid, "x", log)
    with pytest.raises(Exception):
        s.setInteger([VR["structure"]], [3])
    assert "structure" in log.text() and "[0, 2]" in log.text()
    s.freeInstance()


@pytest.mark.parametrize("bad", [math.nan, math.inf, -math.inf])
def test_non_finite_input_leaves_the_state(bad, unzipped, guid, record):
    m = model_of("glauert")
    u = full_inputs(m, model_inputs(record, m, find_trim(record)))[:120]
    clean = open_fmu(unzipped, guid, start_values(m))
    y_clean = fmu_replay(clean, u)
    clean.freeInstance()
    log = Logger()
    s = open_fmu(unzipped, guid, start_values(m), logger=log)
    ins, outs = [VR[n] for n in ALL_INPUTS], [VR[n] for n in OUTPUTS]
    y = [s.getReal(outs)]
    for k in range(len(u) - 1):
        if k == 60:
            before = s.getReal(outs)
            with pytest.raises(Exception):
                s.setReal([VR["theta1s"], VR["p"]], [0.5, bad])
            assert s.getReal(outs) == before
            assert "p = " in log.text() and "finite" in log.text()
        s.setReal(ins, list(u[k]))
        s.doStep(k * DT, DT)
        y.append(s.getReal(outs))
    s.freeInstance()
    assert np.array_equal(np.array(y), y_clean)


def test_wrong_guid_is_refused(unzipped, guid):
    log = Logger()
    s = FMU2Slave(guid="{00000000-0000-0000-0000-000000000000}", unzipDirectory=unzipped,
                  modelIdentifier="inflowsim", instanceName="x")
    with pytest.raises(Exception, match="instantiate"):
        s.instantiate(callbacks=log.cb)
    assert "GUID" in log.text()


def test_do_step_before_initialization_is_an_error_not_a_crash(unzipped, guid):
    s = instantiated_fmu(unzipped, guid, "x", Logger())
    with pytest.raises(Exception):
        s.doStep(0.0, DT)
    s.freeInstance()


# -- command line -------------------------------------------------------------------

def test_cli_builds_and_refuses_to_overwrite(tmp_path, capsys):
    from inflowsim.cli import main
    out = tmp_path / "x.fmu"
    assert main(["fmu", "build", "--out", str(out)]) == 0
    assert zipfile.is_zipfile(out)
    before = out.read_bytes()
    assert main(["fmu", "build", "--out", str(out)]) == 2
    assert out.read_bytes() == before
    err = capsys.readouterr().err
    assert "exists" in err and len(err.strip().splitlines()[-1]) > 0
    assert main(["fmu", "build", "--out", str(tmp_path / "x.zip")]) == 2


# -- FMI 3.0: the same slave and model behind the FMI 3.0 functions ------------------

class Log3:
    """An FMI 3.0 logMessage callback that keeps the messages."""

    def __init__(self):
        self.messages = []

    def __call__(self, env, status, category, message):
        self.messages.append((status, message.decode()))

    def text(self):
        return "\n".join(m for _, m in self.messages)


def test_fmi3_validation_reports_no_problem(fmu3_path):
    from fmpy.validation import validate_fmu
    assert validate_fmu(str(fmu3_path)) == []
    md = read_model_description(str(fmu3_path))
    assert md.fmiVersion == "3.0" and md.coSimulation.modelIdentifier == "inflowsim"
    by_name = {v.name: v for v in md.modelVariables}
    assert by_name["time"].causality == "independent"
    for name, vr in VR.items():          # the same value references as FMI 2.0
        assert by_name[name].valueReference == vr
    assert by_name["structure"].type == "Int32" and by_name["theta0"].type == "Float64"


def test_fmi3_contents_and_exports(fmu3_path, unzipped3):
    names = set(zipfile.ZipFile(fmu3_path).namelist())
    for n in ("modelDescription.xml", "binaries/x86_64-linux/inflowsim.so",
              "documentation/index.html", "sources/buildDescription.xml",
              "sources/inflow_fmi3.c", "sources/inflow_slave.c", "sources/inflow_model.c",
              "sources/fmi3Functions.h", "sources/fmi3FunctionTypes.h",
              "sources/fmi3PlatformTypes.h", "sources/LICENSE-FMI.txt"):
        assert n in names
    assert not any("fmi2" in n for n in names)
    so = Path(unzipped3) / "binaries" / "x86_64-linux" / "inflowsim.so"
    syms = set(subprocess.run(["nm", "-D", "--defined-only", str(so)], capture_output=True,
                              text=True, check=True).stdout.split())
    header = (source_dir() / "fmi3Functions.h").read_text()
    declared = {w.rstrip(";") for line in header.splitlines() if "FMI3_Export fmi3" in line
                for w in line.split() if w.startswith("fmi3") and not w.endswith("TYPE")}
    assert len(declared) > 70
    assert declared <= syms, f"not exported: {sorted(declared - syms)}"
    assert not any(x.startswith("ifs") for x in syms)


@pytest.mark.parametrize("structure", ["basic", "empirical", "glauert"])
def test_fmi3_replay_equals_simulator_and_fmi2(structure, unzipped, unzipped3, guid, record):
    m = model_of(structure)
    u = model_inputs(record, m, find_trim(record))
    y_py = Simulator(m, DT).replay(u)
    s3 = open_fmu3(unzipped3, guid, start_values(m))
    y3 = fmu_replay(s3, full_inputs(m, u))
    s3.freeInstance()
    s2 = open_fmu(unzipped, guid, start_values(m))
    y2 = fmu_replay(s2, full_inputs(m, u))
    s2.freeInstance()
    np.testing.assert_allclose(y3, y_py, rtol=0, atol=1e-10)
    assert np.array_equal(y3, y2)          # one slave behind both versions


def test_fmi3_parameter_file_applies_in_one_call(fmu3_path, record):
    m = model_of("empirical", k01=0.2, tau_cs=20.0)
    u = model_inputs(record, m, find_trim(record))
    y_py = Simulator(m, DT).replay(u)
    y = simulate_with_fmpy(fmu3_path, start_values(m), m.inputs, u)
    np.testing.assert_allclose(y, y_py, rtol=0, atol=1e-10)


def test_fmi3_time_substeps_state_and_reset(unzipped3, guid, record):
    m = model_of("glauert", azimuth_bias=0.04)
    u = full_inputs(m, model_inputs(record, m, find_trim(record)))
    s = open_fmu3(unzipped3, guid, start_values(m), start=2.0)
    outs = [VR[n] for n in OUTPUTS]
    x = np.zeros(6)
    t = 2.0
    for i, h in enumerate([0.025, 0.01, 0.0137, 0.1]):
        s.setFloat64([VR[n] for n in ALL_INPUTS], list(u[50 + 9 * i]))
        _, _, _, last = s.doStep(t, h)
        phi, gam = zoh_ref(m, h)
        x = phi @ x + gam @ u[50 + 9 * i]
        t += h
        assert last == s.getFloat64([TIME_VR])[0] == pytest.approx(t, abs=1e-12)
        np.testing.assert_allclose(s.getFloat64(outs), m.c @ x, rtol=0, atol=1e-12)
    state = s.getFMUState()
    blob = s.serializeFMUState(state)
    tail = fmu_replay(s, u[100:160], t0=t)
    s.setFMUState(s.deserializeFMUState(blob))
    again = fmu_replay(s, u[100:160], t0=t)
    assert np.array_equal(tail, again)
    s.freeFMUState(state)
    s.reset()
    s.enterInitializationMode(startTime=0.0)
    s.exitInitializationMode()
    assert s.getFloat64(outs) == [0.0] * 6
    s.freeInstance()


def test_fmi3_errors_name_what_is_wrong(unzipped3, guid, record):
    log = Log3()
    s = open_fmu3(unzipped3, guid, log=log)
    outs = [VR[n] for n in OUTPUTS]
    with pytest.raises(Exception):
        s.setFloat64([VR["n_beta"]], [-1.0])
    assert "n_beta" in log.text() and "[1e-06, 10]" in log.text()
    with pytest.raises(Exception):
        s.setInt32([VR["structure"]], [1])          # fixed after initialization
    assert "structure" in log.text()
    with pytest.raises(Exception):
        s.setFloat64([TIME_VR], [5.0])
    assert "independent" in log.text()
    m = model_of("glauert")
    u = full_inputs(m, model_inputs(record, m, find_trim(record)))
    for k in range(30):
        s.setFloat64([VR[n] for n in ALL_INPUTS], list(u[40 + k]))
        s.doStep(k * DT, DT)
    before = s.getFloat64(outs)
    with pytest.raises(Exception):
        s.setFloat64([VR["theta1s"], VR["p"]], [0.5, math.nan])
    assert "p = nan" in log.text() and "finite" in log.text()
    assert s.getFloat64([VR["theta1s"]])[0] == u[69][2]     # nothing was set
    assert s.getFloat64(outs) == before
    with pytest.raises(Exception):
        s.getFloat64([VR["beta0"], VR["beta1c"]], nValues=1)
    assert "values for 2 value references" in log.text()
    with pytest.raises(Exception):
        s.getBoolean([0])
    s.freeInstance()


def test_fmi3_wrong_token_event_mode_and_early_step_are_refused(unzipped3, guid):
    log = Log3()
    s = FMU3Slave(guid="{00000000-0000-0000-0000-000000000000}", unzipDirectory=unzipped3,
                  modelIdentifier="inflowsim", instanceName="x")
    with pytest.raises(Exception, match="instantiate"):
        s.instantiate(logMessage=log)
    assert "instantiation token" in log.text()
    s = FMU3Slave(guid=guid, unzipDirectory=unzipped3, modelIdentifier="inflowsim",
                  instanceName="y")
    with pytest.raises(Exception, match="instantiate"):
        s.instantiate(logMessage=log, eventModeUsed=True)
    assert "eventModeUsed" in log.text()
    s = FMU3Slave(guid=guid, unzipDirectory=unzipped3, modelIdentifier="inflowsim",
                  instanceName="z")
    s.instantiate(logMessage=log)
    with pytest.raises(Exception):
        s.doStep(0.0, DT)
    assert "not in step mode" in log.text()
    s.freeInstance()


def test_cli_builds_fmi3(tmp_path, capsys):
    from inflowsim.cli import main
    out = tmp_path / "x3.fmu"
    assert main(["fmu", "build", "--out", str(out), "--fmi-version", "3", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["fmi_version"] == "3.0" and read_model_description(str(out)).fmiVersion == "3.0"


# -- hardening (from review): null components, huge steps, bad time, foreign states ------

def _lib(unzipped, folder):
    return ctypes.CDLL(str(Path(unzipped) / "binaries" / folder / "inflowsim.so"))


def test_null_component_is_an_error_never_a_crash(unzipped, unzipped3):
    vr = (ctypes.c_uint * 1)(0)
    buf = (ctypes.c_double * 4)()
    lib2 = _lib(unzipped, "linux64")
    for name, args in (("fmi2GetBoolean", (vr, 1, buf)), ("fmi2SetString", (vr, 1, buf)),
                       ("fmi2CancelStep", ()), ("fmi2GetIntegerStatus", (0, buf)),
                       ("fmi2GetStringStatus", (0, buf)),
                       ("fmi2GetDirectionalDerivative", (vr, 1, vr, 1, buf, buf)),
                       ("fmi2SetRealInputDerivatives", (vr, 1, vr, buf)),
                       ("fmi2GetReal", (vr, 1, buf)), ("fmi2DoStep", (ctypes.c_double(0.0),
                                                                       ctypes.c_double(0.01), 1))):
        assert getattr(lib2, name)(None, *args) == 3, name          # fmi2Error
    lib3 = _lib(unzipped3, "x86_64-linux")
    for name, args in (("fmi3GetBoolean", (vr, 1, buf, 1)), ("fmi3EnterEventMode", ()),
                       ("fmi3GetFloat64", (vr, 1, buf, 1)), ("fmi3SetTime",
                                                             (ctypes.c_double(0.0),))):
        assert getattr(lib3, name)(None, *args) == 3, name          # fmi3Error


def test_huge_or_non_finite_steps_are_refused_and_leave_the_state(unzipped, guid, record):
    m = model_of("glauert")
    u = full_inputs(m, model_inputs(record, m, find_trim(record)))
    log = Logger()
    s = open_fmu(unzipped, guid, start_values(m), logger=log)
    outs = [VR[n] for n in OUTPUTS]
    for k in range(40):
        s.setReal([VR[n] for n in ALL_INPUTS], list(u[40 + k]))
        s.doStep(k * DT, DT)
    before = s.getReal(outs)
    with pytest.raises(Exception):
        s.doStep(40 * DT, 1e12)                 # 1e14 internal steps: refused, not a hang
    assert "more than 1e+09 internal steps" in log.text()
    with pytest.raises(Exception):
        s.doStep(math.nan, DT)
    assert "communication point nan must be finite" in log.text()
    assert s.getReal(outs) == before and s.getRealStatus(2) == pytest.approx(40 * DT)
    s.freeInstance()


def test_time_mismatch_warns_once_with_warning_status(unzipped, guid):
    log = Logger()
    s = open_fmu(unzipped, guid, logger=log)
    lib = s.dll
    comp = s.component
    dostep = lib.fmi2DoStep
    dostep.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
    assert dostep(comp, 0.0, DT, 1) == 0
    assert dostep(comp, 5.0, DT, 1) == 1          # fmi2Warning: the FMU keeps its own time
    assert dostep(comp, 7.0, DT, 1) == 0          # warned once
    assert sum("differs from the FMU's time" in m for _, m in log.messages) == 1
    assert s.getRealStatus(2) == pytest.approx(3 * DT)
    s.freeInstance()


def test_a_state_of_another_model_is_refused(unzipped, guid):
    s = open_fmu(unzipped, guid)
    blob = bytearray(s.serializeFMUstate(s.getFMUstate()))
    i = blob.index(guid.encode())
    blob[i + 1] = ord("0") if blob[i + 1] != ord("0") else ord("1")   # another GUID
    with pytest.raises(Exception):
        s.deSerializeFMUstate(bytes(blob))
    s.freeInstance()


def test_an_importer_builds_the_binary_from_the_listed_sources(fmu_path, guid, record,
                                                               tmp_path):
    """FMI 2.0 ``<SourceFiles>`` (issue #10 part 5): fmpy's ``build_platform_binary``
    compiles the FMU from its sources alone (binaries removed), with its own CMake
    settings, and that binary gives the Simulator's trajectory."""
    if shutil.which("cmake") is None:
        pytest.skip("cmake is not installed: fmpy cannot build from sources")
    from fmpy.build import build_platform_binary
    d = tmp_path / "fromsources"
    with zipfile.ZipFile(fmu_path) as z:
        z.extractall(d)
    shutil.rmtree(d / "binaries")
    md = read_model_description(str(d))
    files = md.buildConfigurations[0].sourceFileSets[0].sourceFiles
    assert files and all((d / "sources" / f).is_file() for f in files)
    (tmp_path / "build").mkdir()
    build_platform_binary(str(d.resolve()), build_dir=str(tmp_path / "build"))
    assert (d / "binaries" / "linux64" / "inflowsim.so").is_file()
    m = model_of("glauert")
    u = model_inputs(record, m, find_trim(record))
    s = open_fmu(str(d), guid, start_values(m))
    y_fmu = fmu_replay(s, full_inputs(m, u))
    s.freeInstance()
    np.testing.assert_allclose(y_fmu, Simulator(m, DT).replay(u), rtol=0, atol=1e-10)


@pytest.mark.parametrize("version", [2, 3])
def test_stop_time_is_enforced(version, unzipped, unzipped3, guid):
    """A step that ends after the experiment's stop time is refused, the state kept;
    steps up to it (within the time tolerance) are taken (issue #10 part 5)."""
    log = Logger()
    stop = 0.05
    if version == 2:
        s = instantiated_fmu(unzipped, guid, "stop", log)
        s.setupExperiment(startTime=0.0, stopTime=stop)
        s.enterInitializationMode()
        s.exitInitializationMode()
        setr, getr = s.setReal, s.getReal
    else:
        s = FMU3Slave(guid=guid, unzipDirectory=unzipped3, modelIdentifier="inflowsim",
                      instanceName="stop")
        s.instantiate()
        s.enterInitializationMode(startTime=0.0, stopTime=stop)
        s.exitInitializationMode()
        setr, getr = s.setFloat64, s.getFloat64
    setr([VR["theta1s"]], [0.01])
    for k in range(5):                       # 5 x 0.01 lands on 0.05 within rounding
        s.doStep(k * DT, DT)
    outs = [VR[n] for n in OUTPUTS]
    before = getr(outs)
    with pytest.raises(Exception):
        s.doStep(5 * DT, DT)
    assert getr(outs) == before
    if version == 2:
        assert "after the experiment's stop time" in log.text()
    s.terminate()
    s.freeInstance()


def test_stop_time_before_start_is_refused(unzipped, guid):
    log = Logger()
    s = instantiated_fmu(unzipped, guid, "stop", log)
    with pytest.raises(Exception):
        s.setupExperiment(startTime=1.0, stopTime=0.5)
    assert "stop time 0.5 must be finite and not before the start time 1" in log.text()
    s.freeInstance()


@pytest.mark.parametrize("bad", [1e7, -1e300, 2e6])
def test_absurd_finite_input_is_refused_and_leaves_the_state(bad, unzipped, guid):
    """Inputs beyond the channel table's limit (1e6 in SI) are refused like a NaN."""
    log = Logger()
    s = open_fmu(unzipped, guid, start_values(model_of("glauert")), logger=log)
    s.setReal([VR["theta1s"]], [0.01])
    s.doStep(0.0, DT)
    outs = [VR[n] for n in OUTPUTS]
    before = s.getReal(outs)
    with pytest.raises(Exception):
        s.setReal([VR["q"]], [bad])
    assert "q = " in log.text() and "outside the allowed range [-1e+06, 1e+06]" in log.text()
    s.doStep(DT, DT)
    after = s.getReal(outs)
    ref = open_fmu(unzipped, guid, start_values(model_of("glauert")))
    ref.setReal([VR["theta1s"]], [0.01])
    ref.doStep(0.0, DT)
    assert ref.getReal(outs) == before
    ref.doStep(DT, DT)
    assert ref.getReal(outs) == after           # the refused value never entered
    s.freeInstance()
    ref.freeInstance()


def test_outputs_follow_a_new_azimuth_bias_at_once(unzipped, guid):
    """Outputs are the state seen through the azimuth bias: setting the bias between
    steps shows in the outputs at once (issue #10 part 5)."""
    m = model_of("glauert")
    s = open_fmu(unzipped, guid, start_values(m))
    s.setReal([VR["theta1s"]], [0.02])
    for k in range(30):
        s.doStep(k * DT, DT)
    outs = [VR[n] for n in OUTPUTS]
    y0 = np.array(s.getReal(outs))
    b0 = m.parameters["azimuth_bias"]
    s.setReal([VR["azimuth_bias"]], [b0 + 0.3])
    y1 = np.array(s.getReal(outs))
    rot = np.array([[math.cos(0.3), -math.sin(0.3)], [math.sin(0.3), math.cos(0.3)]])
    np.testing.assert_allclose(y1[1:3], rot @ y0[1:3], rtol=1e-13, atol=1e-17)
    assert y1[0] == y0[0] and np.array_equal(y1[3:], y0[3:])
    # the loads' true pitch follows the new bias at once too (the state is unchanged)
    from inflowsim.model.loads import load_matrices
    r0 = np.array([[math.cos(b0), math.sin(b0)], [-math.sin(b0), math.cos(b0)]])
    x = np.concatenate([[y0[0]], r0 @ y0[1:3], y0[3:]])
    u = np.zeros(m.b.shape[1])
    u[ALL_INPUTS.index("theta1s")] = 0.02
    new = build_model("glauert", {**m.parameters, "azimuth_bias": b0 + 0.3}, m.constants)
    np.testing.assert_allclose(s.getReal([VR[n] for n in LOADS]), load_matrices(new)(x, u),
                               rtol=1e-12, atol=1e-16)
    s.freeInstance()


@pytest.mark.parametrize("version", [2, 3])
def test_units_have_base_units_and_degrees_to_show(version, fmu_path, fmu3_path):
    """BaseUnit exponents and a deg display unit as an importer reads them (fmpy)."""
    md = read_model_description(str(fmu_path if version == 2 else fmu3_path))
    units = {u.name: u for u in md.unitDefinitions}
    rad = units["rad"]
    assert rad.baseUnit.rad == 1 and rad.baseUnit.s == 0
    deg = {d.name: d for d in rad.displayUnits}["deg"]
    assert float(deg.factor) == pytest.approx(180 / math.pi, rel=1e-15)
    assert units["rad/s2"].baseUnit.s == -2 and units["1/rad"].baseUnit.rad == -1
    theta = next(v for v in md.modelVariables if v.name == "theta1s")
    assert theta.unit == "rad" and theta.displayUnit == "deg"
    assert (float(theta.min), float(theta.max)) == (-1e6, 1e6)


@pytest.mark.parametrize("version", [2, 3])
def test_directional_derivatives_are_exact(version, unzipped, unzipped3, guid, record):
    """Outputs depend on the state only (no direct feedthrough): d y / d u within a
    communication point is exactly zero, which a finite difference confirms; wrong
    kinds of value reference are refused."""
    m = model_of("glauert")
    u = full_inputs(m, model_inputs(record, m, find_trim(record)))
    ins, outs = [VR[n] for n in ALL_INPUTS], [VR[n] for n in OUTPUTS]
    if version == 2:
        s = open_fmu(unzipped, guid, start_values(m))
        setr, getr = s.setReal, s.getReal
    else:
        s = open_fmu3(unzipped3, guid, start_values(m))
        setr, getr = s.setFloat64, s.getFloat64
    for k in range(60):
        setr(ins, list(u[k]))
        s.doStep(k * DT, DT)
    seed = [1.0] * len(ins)
    dy = (s.getDirectionalDerivative(outs, ins, seed) if version == 2 else
          s.getDirectionalDerivative(outs, ins, seed, len(outs)))
    assert list(dy) == [0.0] * len(outs)
    y0 = getr(outs)
    setr(ins, list(u[60] + 1e-3))                 # finite difference at the same point
    assert getr(outs) == y0
    with pytest.raises(Exception):                # an input is not an unknown
        (s.getDirectionalDerivative([VR["theta0"]], ins, seed) if version == 2 else
         s.getDirectionalDerivative([VR["theta0"]], ins, seed, 1))
    s.terminate()
    s.freeInstance()


def test_frame_to_frame_varying_step_is_exact(unzipped, guid, record):
    """h = 1/60 s +- 2 % every frame (issue #10 part 3): each remainder step comes from
    the Taylor series of the exponential (no matrix exponential per frame), and the
    trajectory equals the exact zero-order hold at every frame."""
    m = model_of("glauert")
    u = full_inputs(m, model_inputs(record, m, find_trim(record)))
    rng = np.random.default_rng(7)
    hs = (1 / 60) * (1 + 0.02 * rng.uniform(-1, 1, 300))
    s = open_fmu(unzipped, guid, start_values(m))
    ins, outs = [VR[n] for n in ALL_INPUTS], [VR[n] for n in OUTPUTS]
    x = np.zeros(6)
    t = 0.0
    worst = 0.0
    for i, h in enumerate(hs):
        uk = u[100 + i]
        s.setReal(ins, list(uk))
        s.doStep(t, h)
        phi, gam = zoh_ref(m, h)
        x = phi @ x + gam @ uk
        t += h
        worst = max(worst, np.abs(np.array(s.getReal(outs)) - m.c @ x).max())
    assert np.abs(x).max() > 1e-4
    assert worst < 1e-13 * max(1.0, np.abs(x).max())
    s.freeInstance()



@pytest.mark.parametrize("structure", ["basic", "empirical", "glauert"])
@pytest.mark.parametrize("version", [2, 3])
def test_loads_out_equal_the_python_loads(structure, version, unzipped, unzipped3, guid,
                                         record):
    """The FMU's load outputs (issue #10 part 1) are inflowsim.model.loads on the
    Simulator's state and the inputs held now, at every step, FMI 2.0 and 3.0; and
    their directional derivatives with respect to the inputs are the load matrix."""
    from inflowsim.model.loads import load_matrices
    m = model_of(structure)
    u = full_inputs(m, model_inputs(record, m, find_trim(record)))[:400]
    lm = load_matrices(build_model(structure, dict(m.parameters), m.constants))
    ins = [VR[n] for n in ALL_INPUTS]
    lvr = [VR[n] for n in LOADS]
    if version == 2:
        s = open_fmu(unzipped, guid, start_values(m))
        setr, getr = s.setReal, s.getReal
    else:
        s = open_fmu3(unzipped3, guid, start_values(m))
        setr, getr = s.setFloat64, s.getFloat64
    sim = Simulator(m, DT)
    worst, peak = 0.0, 0.0
    for k in range(len(u) - 1):
        setr(ins, list(u[k]))
        s.doStep(k * DT, DT)
        sim.step(u[k][:sim.m])
        want = lm(sim.state, u[k][:sim.m])
        worst = max(worst, np.abs(np.array(getr(lvr)) - want).max())
        peak = max(peak, np.abs(want).max())
        # direct feedthrough: new inputs show in the loads before the next step
        if k == 200:
            setr(ins, list(u[k + 1]))
            np.testing.assert_allclose(getr(lvr), lm(sim.state, u[k + 1][:sim.m]),
                                       rtol=0, atol=1e-12 * peak)
    assert peak > 1e-5 and worst < 1e-10 * peak
    seed = [1.0] + [0.0] * (len(ins) - 1)
    d = (s.getDirectionalDerivative(lvr, ins, seed) if version == 2 else
         s.getDirectionalDerivative(lvr, ins, seed, len(lvr)))
    np.testing.assert_allclose(d, lm.d[:, 0], rtol=1e-13, atol=1e-18)
    s.terminate()
    s.freeInstance()


@pytest.mark.parametrize("version", [2, 3])
def test_mu_changing_every_step_follows_the_exact_model(version, unzipped, unzipped3,
                                                        guid, record):
    """mu changes every step (issue #10 part 3): the FMU interpolates its tabulated
    discrete matrices (checked against exact builds when tabulated), so the
    trajectory follows the exact zero-order hold of the model at each step's mu; a
    parameter change in between retabulates (no stale table), a state restored
    from before it too."""
    m = model_of("glauert")
    u = full_inputs(m, model_inputs(record, m, find_trim(record)))[:500]
    mus = 0.3 + 0.18 * np.sin(np.arange(len(u)) * 0.05)          # 0.12 .. 0.48
    opener = open_fmu if version == 2 else open_fmu3
    s = opener(unzipped if version == 2 else unzipped3, guid, start_values(m))
    ins, outs = [VR[n] for n in ALL_INPUTS], [VR[n] for n in OUTPUTS]
    ref, x, worst, peak = m, np.zeros(6), 0.0, 0.0
    for k, uk in enumerate(u):
        if k == 250:
            set_reals(s, [VR["tau_cs"]], [15.0])
            ref = ref.with_parameters(tau_cs=15.0)
        set_reals(s, [VR["mu"]], [float(mus[k])])
        set_reals(s, ins, list(uk))
        s.doStep(k * DT, DT)
        mk = ref.with_mu(float(mus[k]))
        phi, gam = zoh_ref(mk, DT)
        x = phi @ x + gam @ uk
        y = np.array(get_reals(s, outs))
        worst = max(worst, np.abs(y - mk.c @ x).max())
        peak = max(peak, np.abs(x).max())
    assert peak > 1e-3 and worst < 1e-10
    s.freeInstance()


def test_a_new_mu_alone_takes_effect_at_once(unzipped, guid):
    """A set of mu alone between steps takes the table's matrices at once (issue #38:
    the step after it is the fixed-mu step), as the Simulator's set_mu: the loads
    read before the next step are those of the new mu, and the steps equal the
    Simulator's, mu changing every step."""
    from inflowsim.model.loads import load_matrices
    m = model_of("glauert")
    s = open_fmu(unzipped, guid, start_values(m))
    sim = Simulator(m, DT)
    ins, outs, lvr = ([VR[n] for n in ALL_INPUTS], [VR[n] for n in OUTPUTS],
                      [VR[n] for n in LOADS])
    u = np.zeros(len(ALL_INPUTS))
    worst_y = worst_l = peak = peak_l = 0.0
    for k in range(40):
        mu = 0.3 + 0.1 * math.sin(0.2 * k)
        u[ALL_INPUTS.index("theta1s")] = 0.02 * math.cos(0.3 * k)
        s.setReal([VR["mu"]], [mu])
        sim.set_mu(mu)
        s.setReal(ins, list(u))
        if k >= 2:     # the table built (the FMU's first change, the Simulator's second)
            want = load_matrices(m.with_mu(mu))(sim.state, u[:sim.m])
            worst_l = max(worst_l, np.abs(np.array(s.getReal(lvr)) - want).max())
            peak_l = max(peak_l, np.abs(want).max())
        s.doStep(k * DT, DT)
        sim.step(u[:sim.m])
        worst_y = max(worst_y, np.abs(np.array(s.getReal(outs)) - sim.outputs()).max())
        peak = max(peak, np.abs(sim.outputs()).max())
    s.freeInstance()
    assert peak > 1e-4 and worst_y < 1e-10 * peak and worst_l < 1e-10 * peak_l


def test_a_new_mu_with_the_inputs_held_steps_with_its_own_gam(unzipped, guid):
    """The inputs set once, then mu alone every step: the step's kept inputs' part
    ``gam u`` (held inputs, issue #35) belongs to the old mu's ``gam``, so a mu the
    table applies at its set must drop it (the FMU equals the Simulator)."""
    m = model_of("glauert")
    s = open_fmu(unzipped, guid, start_values(m))
    sim = Simulator(m, DT)
    ins, outs = [VR[n] for n in ALL_INPUTS], [VR[n] for n in OUTPUTS]
    u = np.zeros(len(ALL_INPUTS))
    u[ALL_INPUTS.index("theta1s")] = 0.02
    u[ALL_INPUTS.index("theta0")] = 0.01
    s.setReal(ins, list(u))
    worst = peak = 0.0
    for k in range(40):
        mu = 0.3 + 0.1 * math.sin(0.2 * k)
        s.setReal([VR["mu"]], [mu])
        sim.set_mu(mu)
        s.doStep(k * DT, DT)
        sim.step(u[:sim.m])
        worst = max(worst, np.abs(np.array(s.getReal(outs)) - sim.outputs()).max())
        peak = max(peak, np.abs(sim.outputs()).max())
    s.freeInstance()
    assert peak > 1e-4 and worst < 1e-10 * peak


@pytest.mark.parametrize("version", [2, 3])
def test_mu_alone_across_the_tables_parts_with_the_inputs_held(version, unzipped, unzipped3,
                                                                guid):
    """The inputs set once, then mu alone every step across some sixty of the
    table's parts, back and forth (the step's ``gam u`` from the part's power
    coefficients of it, made again at each new part; ``gam`` itself evaluated only
    when read: issue #38), with new inputs in between, set before and after mu, and
    held again: the FMU equals the Simulator to 1e-10 throughout."""
    m = model_of("glauert")
    s = (open_fmu(unzipped, guid, start_values(m)) if version == 2
         else open_fmu3(unzipped3, guid, start_values(m)))
    sim = Simulator(m, DT)
    ins, outs = [VR[n] for n in ALL_INPUTS], [VR[n] for n in OUTPUTS]
    u = np.zeros(len(ALL_INPUTS))
    worst = peak = 0.0
    for k in range(300):
        # (51 and 157: after mu, where mu turns, so that mu stays in one part)
        new = k in (0, 51, 90, 157) or 230 <= k < 240
        if new:
            u[ALL_INPUTS.index("theta1s")] = 0.02 * math.cos(0.05 * k)
            u[ALL_INPUTS.index("theta0")] = 0.01 + 0.005 * math.sin(0.07 * k)
            u[ALL_INPUTS.index("q")] = 0.01 * math.sin(0.03 * k)
        if new and k % 2 == 0:
            set_reals(s, ins, u)
        mu = 0.3 + 0.03 * math.sin(0.03 * k)          # parts of 0.0009 here
        set_reals(s, [VR["mu"]], [mu])
        sim.set_mu(mu)
        if new and k % 2 == 1:                        # the inputs after mu
            set_reals(s, ins, u)
        s.doStep(k * DT, DT)
        sim.step(u[:sim.m])
        worst = max(worst, np.abs(np.array(get_reals(s, outs)) - sim.outputs()).max())
        peak = max(peak, np.abs(sim.outputs()).max())
    s.freeInstance()
    assert peak > 1e-3 and worst < 1e-10 * peak


def test_what_reads_gam_after_mu_changes_with_the_inputs_held(unzipped, guid):
    """After mu alone changes with the inputs held (the step's g from the table part's
    coefficients of gam u, gam itself left until read): the loads and their
    directional derivatives are those of the new mu, a step of two internal steps
    (the general step, whose steps read gam) and new inputs step as the Simulator,
    from a saved state restored too (the state holds the whole [phi gam])."""
    from inflowsim.model.loads import load_matrices
    m = model_of("glauert")
    s = open_fmu(unzipped, guid, start_values(m))
    sim = Simulator(m, DT)
    ins, outs, lvr = ([VR[n] for n in ALL_INPUTS], [VR[n] for n in OUTPUTS],
                      [VR[n] for n in LOADS])
    u = np.zeros(len(ALL_INPUTS))
    u[ALL_INPUTS.index("theta1s")] = 0.02
    u[ALL_INPUTS.index("theta0")] = 0.01
    s.setReal(ins, list(u))
    t, peak, worst = 0.0, 0.0, 0.0

    def mu_alone(n, k0):
        nonlocal t, worst, peak
        for k in range(k0, k0 + n):
            mu = 0.3 + 0.02 * math.sin(0.1 * k)
            s.setReal([VR["mu"]], [mu])
            sim.set_mu(mu)
            s.doStep(t, DT)
            t += DT
            sim.step(u[:sim.m])
            worst = max(worst, np.abs(np.array(s.getReal(outs)) - sim.outputs()).max())
            peak = max(peak, np.abs(sim.outputs()).max())
        return mu

    mu = mu_alone(12, 0)
    lm = load_matrices(m.with_mu(mu))
    want = lm(sim.state, u[:sim.m])
    assert np.abs(np.array(s.getReal(lvr)) - want).max() <= 1e-10 * np.abs(want).max()
    seed = np.linspace(0.5, 1.5, len(ins))
    want = lm(np.zeros(sim.n), seed[:sim.m])          # the loads are linear in u
    got = np.array(s.getDirectionalDerivative(lvr, ins, list(seed)))
    assert np.abs(got - want).max() <= 1e-10 * np.abs(want).max()
    mu_alone(6, 12)
    s.doStep(t, 2 * DT)                                # two internal steps at once
    t += 2 * DT
    for _ in range(2):
        sim.step(u[:sim.m])
    worst = max(worst, np.abs(np.array(s.getReal(outs)) - sim.outputs()).max())
    mu_alone(6, 18)
    saved = s.getFMUstate()
    x_saved = sim.state.copy()
    v = u.copy()
    v[ALL_INPUTS.index("theta1c")] = 0.015
    runs = []
    for run in range(2):
        s.setReal(ins, list(v))
        y = []
        for k in range(5):
            s.doStep(t + k * DT, DT)
            sim.step(v[:sim.m])
            y.append(s.getReal(outs))
            worst = max(worst, np.abs(np.array(y[-1]) - sim.outputs()).max())
        runs.append(np.array(y))
        s.setFMUstate(saved)
        sim.reset(x_saved)
    s.freeFMUstate(saved)
    s.freeInstance()
    assert np.array_equal(runs[0], runs[1])
    assert peak > 1e-4 and worst < 1e-10 * peak


def test_the_look_ahead_with_the_inputs_held_follows_the_simulator(unzipped, guid):
    """With the inputs and the matrices held the step looks ahead (from the third
    step on, x_(k+1) = phi^2 x_(k-1) + (phi + I) gam u, the state of two steps
    before): over long holds, after new inputs, a step of two internal steps and a mu
    change (each restarting it), it follows the Simulator's one-step recurrence to
    1e-10; a state saved in the middle of it steps on, restored, to the same numbers
    bit for bit."""
    m = model_of("glauert", azimuth_bias=0.05)
    s = open_fmu(unzipped, guid, start_values(m))
    sim = Simulator(m, DT)
    ins, outs = [VR[n] for n in ALL_INPUTS], [VR[n] for n in OUTPUTS]
    u = np.zeros(len(ALL_INPUTS))
    u[ALL_INPUTS.index("theta0")] = 0.01
    u[ALL_INPUTS.index("theta1s")] = 0.02
    t, peak, worst = 0.0, 0.0, 0.0

    def hold(n):
        nonlocal t, worst, peak
        y = []
        for _ in range(n):
            s.doStep(t, DT)
            t += DT
            sim.step(u[:sim.m])
            y.append(s.getReal(outs))
            worst = max(worst, np.abs(np.array(y[-1]) - sim.outputs()).max())
            peak = max(peak, np.abs(sim.outputs()).max())
        return np.array(y)

    s.setReal(ins, list(u))
    hold(400)
    u[ALL_INPUTS.index("theta1c")] = -0.015
    s.setReal(ins, list(u))
    hold(3)
    s.doStep(t, 2 * DT)
    t += 2 * DT
    for _ in range(2):
        sim.step(u[:sim.m])
    hold(50)
    s.setReal([VR["mu"]], [0.31])
    sim.set_mu(0.31)
    hold(200)
    saved = s.getFMUstate()
    t_saved, x_saved = t, sim.state.copy()
    runs = []
    for _ in range(2):
        runs.append(hold(60))
        s.setFMUstate(saved)
        t = t_saved
        sim.reset(x_saved)
    s.freeFMUstate(saved)
    s.freeInstance()
    assert np.array_equal(runs[0], runs[1])
    assert peak > 1e-4 and worst < 1e-10 * peak


@pytest.mark.parametrize("mu", [0.0, 0.05, 0.3])
@pytest.mark.parametrize("structure", ["basic", "glauert"])
def test_mass_flow_speed_from_hover_equals_the_simulator(structure, mu, unzipped, guid,
                                                         record):
    """inflow_speed 1 (issue #10 part 4 in the FMU): from hover, the FMU gives the
    Simulator's trajectory for the mass-flow model, and refuses mu < 0.1 with the
    paper's V ~ mu, naming the remedy."""
    from inflowsim.model.params import Constants
    from inflowsim.model.presets import theory_parameters
    k = Constants(mu=mu, a0=5.73, solidity=0.0917, omega=27.5, radius=7.5, ct=0.0064,
                  inflow_speed="mass-flow").check()
    m = build_model(structure, theory_parameters(structure, k), k)
    u = model_inputs(record, m, find_trim(record))
    y_py = Simulator(m, DT).replay(u)
    vals = start_values(m)
    assert vals["inflow_speed"] == 1 and vals["ct"] == 0.0064
    s = open_fmu(unzipped, guid, vals)
    y_fmu = fmu_replay(s, full_inputs(m, u))
    s.freeInstance()
    assert np.abs(y_py).max() > 1e-3
    np.testing.assert_allclose(y_fmu, y_py, rtol=0, atol=1e-10)
    if mu < 0.1:
        log = Logger()
        vals["inflow_speed"] = 0
        s = instantiated_fmu(unzipped, guid, "vmu", log)
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        with pytest.raises(Exception):
            apply_parameters(s, vals)
        assert f"with inflow_speed 0: {HOVER_HINT}" in log.text()
        s.freeInstance()


STATIC_DRIVER = r"""
#include <stdio.h>
#include <stdlib.h>
#include "fmi2FunctionTypes.h"
#include "inflow_vars.h"
#define DECLARE(P) \
    extern fmi2InstantiateTYPE P##fmi2Instantiate; \
    extern fmi2SetupExperimentTYPE P##fmi2SetupExperiment; \
    extern fmi2EnterInitializationModeTYPE P##fmi2EnterInitializationMode; \
    extern fmi2ExitInitializationModeTYPE P##fmi2ExitInitializationMode; \
    extern fmi2SetRealTYPE P##fmi2SetReal; \
    extern fmi2GetRealTYPE P##fmi2GetReal; \
    extern fmi2DoStepTYPE P##fmi2DoStep; \
    extern fmi2FreeInstanceTYPE P##fmi2FreeInstance;
DECLARE(main_rotor_)
DECLARE(tail_rotor_)
static void logger(fmi2ComponentEnvironment e, fmi2String n, fmi2Status s, fmi2String c,
                   fmi2String m, ...) { (void)e; (void)n; (void)s; (void)c; (void)m; }
#define RUN(P, OUT) do { \
    fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL}; \
    fmi2ValueReference in = IFS_VR_theta1s, out = IFS_VR_beta1s; \
    double u = 0.01; int k; \
    fmi2Component c = P##fmi2Instantiate("x", fmi2CoSimulation, IFS_GUID, "", &cb, \
                                         fmi2False, fmi2False); \
    if (!c || P##fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0) || \
        P##fmi2EnterInitializationMode(c) || P##fmi2ExitInitializationMode(c)) return 1; \
    P##fmi2SetReal(c, &in, 1, &u); \
    for (k = 0; k < 50; k++) if (P##fmi2DoStep(c, k * 0.01, 0.01, fmi2True)) return 1; \
    P##fmi2GetReal(c, &out, 1, &OUT); \
    P##fmi2FreeInstance(c); } while (0)
int main(void) {
    double a = 0.0, b = 0.0;
    RUN(main_rotor_, a);
    RUN(tail_rotor_, b);
    printf("%.17g %.17g\n", a, b);
    return 0;
}
"""


def test_two_fmus_link_statically_with_function_prefixes(tmp_path, unzipped, guid):
    """FMI2_FUNCTION_PREFIX (issue #10 part 5): the sources compile with a prefix, every
    global name then carries it (no clash between two inflowsim FMUs), and two copies
    with different prefixes link into one program that runs both; the numbers equal
    the shared library's."""
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    src = source_dir()
    objs = []
    for prefix in ("main_rotor_", "tail_rotor_"):
        for f in sources(2):
            o = tmp_path / f"{prefix}{f}.o"
            subprocess.run([cc, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror",
                            "-ffp-contract=off", f"-DFMI2_FUNCTION_PREFIX={prefix}",
                            f"-I{src}", "-c", str(src / f), "-o", str(o)], check=True)
            objs.append(o)
            names = subprocess.run(["nm", "-g", "--defined-only", str(o)],
                                   capture_output=True, text=True, check=True).stdout
            for line in names.splitlines():
                sym = line.split()[-1]
                assert sym.startswith(prefix), (f, sym)
    drv = tmp_path / "driver.c"
    drv.write_text(STATIC_DRIVER)
    exe = tmp_path / "twofmus"
    subprocess.run([cc, "-std=c99", "-O2", f"-I{src}", "-o", str(exe), str(drv),
                    *map(str, objs), "-lm"], check=True)
    a, b = map(float, subprocess.run([str(exe)], capture_output=True, text=True,
                                     check=True).stdout.split())
    s = open_fmu(unzipped, guid)
    s.setReal([VR["theta1s"]], [0.01])
    for k in range(50):
        s.doStep(k * 0.01, 0.01)
    want = s.getReal([VR["beta1s"]])[0]
    s.freeInstance()
    assert a == b == want and abs(want) > 1e-5


def test_every_refused_range_is_declared(fmu_path, unzipped, guid):
    """Every parameter and input the FMU range-checks declares the range it checks, an
    open lower bound at 0 as :data:`~inflowsim.fmu.variables.POSITIVE_MIN` (issue #39;
    it was the least double above 0): the declared minimum is accepted and the next
    double below refused."""
    md = read_model_description(str(fmu_path))
    by_name = {v.name: v for v in md.modelVariables}
    from inflowsim.fmu.variables import VARIABLES
    bounded = [v for v in VARIABLES if v.causality in ("parameter", "input")
               and v.type == "Real" and math.isfinite(v.lower)]
    assert len(bounded) > 15
    for var in bounded:
        assert by_name[var.name].min is not None, var.name
    log = Logger()
    # in initialization mode only the declared range applies (in step mode a value is
    # also built into the model at once, and n_beta = 5e-324 makes E singular)
    s = instantiated_fmu(unzipped, guid, "range", log)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    from inflowsim.fmu.variables import POSITIVE_MIN
    low = float(by_name["n_beta"].min)
    assert low == POSITIVE_MIN             # a documented minimum, not 5e-324 (issue #39)
    s.setReal([VR["n_beta"]], [low])                   # accepted
    with pytest.raises(Exception):
        s.setReal([VR["n_beta"]], [math.nextafter(low, 0.0)])   # refused
    with pytest.raises(Exception):
        s.setReal([VR["n_beta"]], [0.0])              # refused
    s.freeInstance()


@pytest.mark.parametrize("delay", [0.0345, 0.05, 0.004])
@pytest.mark.parametrize("version", [2, 3])
def test_time_delay_in_the_fmu_equals_the_simulator(delay, version, unzipped, unzipped3,
                                                    guid, record):
    """The time-delay effect in the FMU (issue #10 part 2, one effect): a fit with an
    output lag gives the Simulator's trajectory (exact fractional delays), whole and
    fractional steps alike; a lead and a step that is not a multiple of dt are refused."""
    p = preset_parameters("glauert", PUMA, "paper")
    p["delay"] = delay
    m = build_model("glauert+time-delay", p, PUMA)
    u = model_inputs(record, m, find_trim(record))
    y_py = Simulator(m, DT).replay(u)
    vals = start_values(m)
    assert vals["delay"] == delay
    s = (open_fmu(unzipped, guid, vals) if version == 2 else
         open_fmu3(unzipped3, guid, vals))
    y_fmu = fmu_replay(s, full_inputs(m, u))
    s.freeInstance()
    undelayed = Simulator(build_model("glauert", preset_parameters("glauert", PUMA,
                                                                   "paper"), PUMA),
                          DT).replay(u)
    assert np.abs(y_py - undelayed).max() > 1e-4           # the delay shows
    np.testing.assert_allclose(y_fmu, y_py, rtol=0, atol=1e-10)
    if version == 2:
        log = Logger()
        s = open_fmu(unzipped, guid, vals, logger=log)
        with pytest.raises(Exception):
            s.doStep(0.0, 0.015)
        assert "must be a whole number of internal steps" in log.text()
        s.freeInstance()
        p["delay"] = -0.01
        with pytest.raises(InputError, match="lead"):
            start_values(build_model("glauert+time-delay", p, PUMA))


def _pe_exports(dll):
    """Names a Windows DLL exports (mingw-w64's objdump) and the DLLs it imports."""
    text = subprocess.run(["x86_64-w64-mingw32-objdump", "-p", str(dll)],
                          capture_output=True, text=True, check=True).stdout
    table = text.split("[Ordinal/Name Pointer] Table", 1)[1].split("\n\n", 1)[0]
    names = {ln.split()[-1] for ln in table.splitlines() if ln.strip().startswith("[")}
    imports = {ln.split(":", 1)[1].strip() for ln in text.splitlines()
               if ln.strip().startswith("DLL Name:")}
    return names, imports, text


@pytest.mark.parametrize("version", [2, 3])
def test_win64_binary_cross_compiled(version, tmp_path):
    """``--platform win64`` (issue #10 part 5): with mingw-w64 installed, the FMU also
    carries a Windows x86-64 DLL exporting exactly the FMI functions the Linux binary
    exports, needing only the C runtime.  (Nothing here runs Windows code.)"""
    from inflowsim.fmu.build import cross_compiler
    if cross_compiler("win64") is None:
        pytest.skip("mingw-w64 (x86_64-w64-mingw32-gcc) is not installed")
    fmu = build_fmu(tmp_path / "w.fmu", fmi_version=version, platforms=("win64",))
    d = tmp_path / "u"
    with zipfile.ZipFile(fmu) as z:
        z.extractall(d)
    win = "win64" if version == 2 else "x86_64-windows"
    lin = "linux64" if version == 2 else "x86_64-linux"
    dll = d / "binaries" / win / "inflowsim.dll"
    assert dll.read_bytes()[:2] == b"MZ"
    names, imports, text = _pe_exports(dll)
    assert "file format pei-x86-64" in text
    so = subprocess.run(["nm", "-D", "--defined-only", str(d / "binaries" / lin /
                                                            "inflowsim.so")],
                        capture_output=True, text=True, check=True).stdout
    so_names = {ln.split()[-1] for ln in so.splitlines()} - {"fmi2DoStep.resolver",
                                                             "fmi3DoStep.resolver"}
    assert names == so_names and len(names) > 30
    assert {i.lower() for i in imports} <= {"kernel32.dll", "msvcrt.dll"}
    from fmpy.validation import validate_fmu
    assert validate_fmu(str(fmu)) == []


def test_win64_without_its_compiler_is_one_clear_error(tmp_path, monkeypatch, capsys):
    import inflowsim.fmu.build as b
    real = shutil.which
    monkeypatch.setattr(b.shutil, "which", lambda name: None if "mingw" in name
                        else real(name))
    from inflowsim.cli import main
    code = main(["fmu", "build", "--platform", "win64", "--out", str(tmp_path / "x.fmu")])
    err = capsys.readouterr().err
    assert code == 2 and "x86_64-w64-mingw32-gcc" in err and "mingw-w64" in err
    assert not (tmp_path / "x.fmu").exists()


def test_a_parameter_the_model_cannot_take_is_refused_at_once(unzipped, guid, record):
    """In step mode a new parameter is built into the model when set: one the model
    refuses (E singular) is refused there, naming why, and changes nothing."""
    log = Logger()
    m = model_of("glauert")
    s = open_fmu(unzipped, guid, start_values(m), logger=log)
    s.setReal([VR["theta1s"]], [0.01])
    for k in range(20):
        s.doStep(k * DT, DT)
    outs = [VR[n] for n in OUTPUTS + LOADS]
    before = s.getReal(outs)
    from inflowsim.fmu.variables import POSITIVE_MIN
    with pytest.raises(Exception):
        # below the declared minimum (issue #39: a documented minimum, so E cannot
        # be made singular through n_beta any more, as 5e-324 did)
        s.setReal([VR["n_beta"]], [math.nextafter(POSITIVE_MIN, 0.0)])
    assert "outside the allowed range" in log.text()
    assert s.getReal([VR["n_beta"]])[0] == m.parameters["n_beta"]
    assert s.getReal(outs) == before
    s.doStep(20 * DT, DT)                              # and it goes on
    s.freeInstance()
