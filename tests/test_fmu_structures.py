"""Every structure in the FMU (issue #10 part 2): an FMU generated for any structure the
library builds gives the Simulator's trajectory and loads to 1e-10.

The FMU's C equations are generated from the Python model (``inflowsim.fmu.codegen``):
these tests run each generated FMU against ``inflowsim.Simulator`` on the same
inputs, through fmpy's FMI 2.0 and 3.0 slaves, and check that the generated C code
follows the Python: an effect changed in Python and not regenerated fails here or
in the regeneration test of ``tests/test_fmu.py``.
"""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy import extract  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402
from fmpy.fmi3 import FMU3Slave  # noqa: E402

from inflowsim.errors import InputError  # noqa: E402
from inflowsim.fmu import (apply_parameters, build_fmu, description_for,  # noqa: E402
                           start_values)
from inflowsim.fmu.codegen import traced  # noqa: E402
from inflowsim.model.structure import needs_trim  # noqa: E402
from inflowsim.fmu.generate import guid  # noqa: E402
from inflowsim.model import build_model, descriptor  # noqa: E402
from inflowsim.model.loads import load_matrices  # noqa: E402
from inflowsim.model.params import PUMA, Constants  # noqa: E402
from inflowsim.model.presets import truth_parameters  # noqa: E402
from inflowsim.model.paramfile import read_parameters  # noqa: E402
from inflowsim.data.record import find_trim, model_inputs  # noqa: E402
from inflowsim.simulate.simulator import Simulator  # noqa: E402
from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record  # noqa: E402

DT = 0.01
OUTPUTS = ("beta0", "beta1c", "beta1s", "lambda0", "lambda1c", "lambda1s")
LOADS = ("CT", "C_mc", "C_ms", "C_mc_hub", "C_ms_hub")
ALL_INPUTS = ("theta0", "theta1c", "theta1s", "muz", "q", "p", "qdot", "pdot", "mux", "muy")

#: Each effect the FMU runs, alone and combined; flap-inertia gives nine states.
STRUCTURES = (
    "basic+flap-inertia",
    "glauert+flap-inertia",
    "basic+skewed-wake",
    "glauert+skewed-wake",
    "empirical+time-delay",
    "glauert+delay-beta1s",
    "basic+delay-beta0+delay-beta1c",
    "basic+separate-time-constants+hub-velocity-coupling",
    "glauert+flap-inertia+skewed-wake+time-delay",
    "basic+advance-ratio-perturbation",
    "glauert+advance-ratio-perturbation+flap-inertia",
    "basic+second-harmonic-flap",
    "glauert+advance-ratio-perturbation+flap-inertia+second-harmonic-flap",
    "basic+separate-time-constants+flap-inertia+advance-ratio-perturbation+momentum-speed",
    "basic+azimuth-bias+momentum-speed",
    "basic+wake-distortion",
    "glauert+flap-inertia+wake-distortion+azimuth-bias",
    "basic+wake-distortion+wake-distortion-lag",
    "glauert+flap-inertia+wake-distortion+wake-distortion-lag+time-delay",
    "glauert+servo-actuators",
    "glauert+flap-inertia+azimuth-bias+servo-actuators+time-delay",
    "glauert+lead-lag",
    "basic+flap-inertia+advance-ratio-perturbation+lead-lag+time-delay",
    "basic+peters-he-6",
    "basic+separate-time-constants+peters-he-10",
    "glauert+flap-inertia+azimuth-bias+peters-he-15",
    "glauert+servo-actuators+time-delay+peters-he-15",
    "glauert+lead-lag+servo-actuators+wake-distortion+peters-he-10",
    # two run-time calls, the second's argument (the wake skew) from the first's
    # results (Eq. 14's trim inflow)
    "basic+azimuth-bias+momentum-speed+peters-he-6",
)

#: A trim state (totals) for the effect linearised about it.
TRIM = {"theta0": 0.17, "theta1c": 0.012, "theta1s": -0.05, "beta0": 0.06,
        "beta1c": 0.011, "beta1s": -0.004, "muz": -0.02}


def constants_for(structure, k=PUMA):
    return k.with_trim(TRIM) if needs_trim([structure]) else k


def parameters(structure) -> dict:
    """Truth values with every effect away from neutral: a bias, fractional delays
    (not whole steps) of different lengths per channel."""
    p = truth_parameters(structure, constants_for(structure))
    p.update({k: v for k, v in {"azimuth_bias": 0.2, "delay": 0.034,
                                "delay_beta0": 0.013, "delay_beta1c": 0.047,
                                "delay_beta1s": 0.021, "k_skew": 0.6,
                                "flap_inertia": 1.0, "K_R": 1.2, "tau_w": 8.0,
                                "k_ph": 1.3}.items() if k in p})
    if "k01" in p:
        p.update(k01=0.05, k02=-0.03, k11=0.4, k12=0.1, k21=-0.2, k22=0.3)
    return p


@pytest.fixture(scope="module")
def record():
    # inputs on pitch and on the hub (the in-plane velocities too: Glauert's and K's
    # columns, and skewed wake's through the loads)
    return virtual_record(VirtualTest(duration=5.0, manoeuvres=(
        Manoeuvre(channel="theta1s", shape="doublet", amplitude=math.radians(1.0),
                  t_start=1.0, width=0.4),
        Manoeuvre(channel="theta1c", shape="doublet", amplitude=math.radians(0.7),
                  t_start=2.2, width=0.3),
        Manoeuvre(channel="theta0", shape="doublet", amplitude=math.radians(0.5),
                  t_start=3.4, width=0.3))))


def inputs_of(model, record):
    u = model_inputs(record, model, find_trim(record))
    t = np.arange(len(u)) * DT
    if model.b.shape[1] == len(ALL_INPUTS):
        # move the in-plane velocities too (the record holds them still)
        u = u.copy()
        u[:, 8] = 0.004 * np.sin(2 * np.pi * 0.7 * t)
        u[:, 9] = -0.003 * np.sin(2 * np.pi * 1.1 * t + 0.4)
    return u


def python_run(model, u):
    """Outputs (initial, then after each step) and the loads with each input held."""
    sim = Simulator(model, DT)
    y, loads = [sim.outputs()], []
    for k in range(len(u) - 1):
        y.append(sim.step(u[k]))
        loads.append(sim.loads())
    return np.array(y), np.array(loads)


def fmu_run(unzipped, d, values, u, version):
    vr = d.vr
    if version == 2:
        s = FMU2Slave(guid=guid(d), unzipDirectory=unzipped, modelIdentifier="inflowsim",
                      instanceName="s")
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        set_r, get_r = s.setReal, s.getReal
    else:
        s = FMU3Slave(guid=guid(d), unzipDirectory=unzipped, modelIdentifier="inflowsim",
                      instanceName="s")
        s.instantiate()
        s.enterInitializationMode(startTime=0.0)
        set_r, get_r = s.setFloat64, s.getFloat64
    apply_parameters(s, values, description=d)
    s.exitInitializationMode()
    ins, outs, lds = ([vr[n] for n in ALL_INPUTS], [vr[n] for n in OUTPUTS],
                      [vr[n] for n in LOADS])
    full = np.zeros((len(u), len(ALL_INPUTS)))
    full[:, : u.shape[1]] = u
    y, loads = [get_r(outs)], []
    for k in range(len(u) - 1):
        set_r(ins, list(full[k]))
        s.doStep(k * DT, DT)
        y.append(get_r(outs))
        loads.append(get_r(lds))
    s.terminate()
    s.freeInstance()
    return np.array(y), np.array(loads)


def built(tmp_path_factory, structure, version=2, model=None):
    folder = tmp_path_factory.mktemp("fmu")
    target = model if model is not None else structure
    path = build_fmu(folder / "s.fmu", fmi_version=version, model=target)
    return extract(str(path), str(folder / "x")), description_for(target)


#: By default five structures that hold every effect at least once, nine states and
#: the output delays (momentum-speed: by default in the hover test); every structure
#: is slow.
FMI2_DEFAULT = ("glauert+flap-inertia+skewed-wake+time-delay",
                "basic+delay-beta0+delay-beta1c", "glauert+delay-beta1s",
                "basic+separate-time-constants+hub-velocity-coupling",
                "glauert+flap-inertia+azimuth-bias+servo-actuators+time-delay",
                "basic+peters-he-6")


@pytest.mark.parametrize("structure", [
    s if s in FMI2_DEFAULT else pytest.param(s, marks=pytest.mark.slow) for s in STRUCTURES])
def test_generated_fmu_equals_the_simulator(structure, record, tmp_path_factory):
    p = parameters(structure)
    m = build_model(structure, p, constants_for(structure))
    u = inputs_of(m, record)
    y_py, l_py = python_run(m, u)
    unzipped, d = built(tmp_path_factory, structure, model=m)
    assert d.structures == (m.structure.name,)
    y_fmu, l_fmu = fmu_run(unzipped, d, {"structure": 0}, u, 2)
    assert np.abs(y_py).max() > 1e-3                     # the inputs move the rotor
    np.testing.assert_allclose(y_fmu, y_py, rtol=0, atol=1e-10)
    np.testing.assert_allclose(l_fmu, l_py, rtol=0, atol=1e-10)


#: FMI 3.0 shares the generated model with FMI 2.0: by default nine states, output
#: delays and the servos, three of FMI2_DEFAULT (the same C but the layer: a cold
#: binary cache compiles only inflow_fmi3.c for them); every structure is slow.
FMI3_DEFAULT = ("glauert+flap-inertia+skewed-wake+time-delay", "glauert+delay-beta1s",
                "glauert+flap-inertia+azimuth-bias+servo-actuators+time-delay")


@pytest.mark.parametrize("structure", [
    s if s in FMI3_DEFAULT else pytest.param(s, marks=pytest.mark.slow) for s in STRUCTURES])
def test_generated_fmi3_fmu_equals_the_simulator(structure, record, tmp_path_factory):
    p = parameters(structure)
    m = build_model(structure, p, constants_for(structure))
    u = inputs_of(m, record)
    y_py, l_py = python_run(m, u)
    unzipped, d = built(tmp_path_factory, structure, version=3, model=m)
    y_fmu, l_fmu = fmu_run(unzipped, d, {"structure": 0}, u, 3)
    assert np.abs(y_py).max() > 1e-3
    np.testing.assert_allclose(y_fmu, y_py, rtol=0, atol=1e-10)
    np.testing.assert_allclose(l_fmu, l_py, rtol=0, atol=1e-10)


#: advance-ratio-perturbation (about the trim) with the skewed wake: the new trim's and
#: the hover's tests share one FMU of it.
ARP_SKEW = "basic+advance-ratio-perturbation+skewed-wake"

#: The nine-state structure the tests below share one FMU of (its start values those
#: of :func:`nine_state_model`): one compile for all of them with a cold binary cache.
NINE = "glauert+flap-inertia+skewed-wake"


def nine_state_model():
    return build_model(NINE, parameters(NINE), constants_for(NINE))


def test_parameters_stay_tunable_in_a_generated_fmu(record, tmp_path_factory):
    """A generated FMU takes any values of its structure's parameters (they are
    variables of the C, not numbers baked in): set others than the start values."""
    structure = NINE
    unzipped, d = built(tmp_path_factory, structure, model=nine_state_model())
    p = parameters(structure)
    p.update(k_skew=0.3, flap_inertia=0.8, n_beta=p["n_beta"] * 1.1, c2=0.2)
    m = build_model(structure, p, PUMA.with_mu(0.3))
    u = inputs_of(m, record)
    y_py, l_py = python_run(m, u)
    values = {"structure": 0, "mu": 0.3, **p}
    y_fmu, l_fmu = fmu_run(unzipped, d, values, u, 2)
    np.testing.assert_allclose(y_fmu, y_py, rtol=0, atol=1e-10)
    np.testing.assert_allclose(l_fmu, l_py, rtol=0, atol=1e-10)


def test_a_new_trim_is_a_parameter_change(record, tmp_path_factory):
    """advance-ratio-perturbation is linearised about the trim: the generated FMU
    takes the trim totals as tunable parameters trim_theta0 ... trim_muz (its trim
    inflow solved in the generated C), so one FMU serves any trim (the one the hover
    test below sets its values in)."""
    structure = ARP_SKEW
    unzipped, d = built(tmp_path_factory, structure)          # start trim: zeros
    trim = {"theta0": 0.2, "theta1c": -0.01, "theta1s": -0.07, "beta0": 0.07,
            "beta1c": 0.02, "beta1s": 0.003, "muz": -0.03}
    k = PUMA.with_trim(trim).with_mu(0.4)
    p = parameters(structure)
    m = build_model(structure, p, k)
    u = inputs_of(m, record)
    y_py, l_py = python_run(m, u)
    values = {"structure": 0, "mu": 0.4, **p, **{f"trim_{c}": x for c, x in trim.items()}}
    y_fmu, l_fmu = fmu_run(unzipped, d, values, u, 2)
    np.testing.assert_allclose(y_fmu, y_py, rtol=0, atol=1e-10)
    np.testing.assert_allclose(l_fmu, l_py, rtol=0, atol=1e-10)


def test_mass_flow_speed_in_a_generated_fmu(record, tmp_path_factory):
    """Hover to top speed for a generated structure too: the mass-flow speed (set in
    the shared nine-state FMU, as its mu and ct)."""
    structure = NINE
    k = Constants(mu=0.15, a0=PUMA.a0, solidity=PUMA.solidity, omega=PUMA.omega,
                  inflow_speed="mass-flow", ct=0.0064)
    p = parameters(structure)
    m = build_model(structure, p, k)
    u = inputs_of(m, record)
    y_py, l_py = python_run(m, u)
    unzipped, d = built(tmp_path_factory, structure, model=nine_state_model())
    y_fmu, l_fmu = fmu_run(unzipped, d, {"structure": 0, "mu": 0.15, "inflow_speed": 1,
                                         "ct": 0.0064}, u, 2)
    np.testing.assert_allclose(y_fmu, y_py, rtol=0, atol=1e-10)


def test_an_identified_parameter_file_builds_and_runs(record, tmp_path, capsys):
    """``inflowsim fmu build --model FIT.json``: the file identify and the ladder write
    (estimate and sigma per parameter) becomes the FMU's start values; fmpy's
    simulate_fmu with no start values then gives the Simulator's outputs."""
    from inflowsim.cli import main
    structure = NINE          # the values of nine_state_model: its FMU, from the cache
    p = parameters(structure)
    doc = {"structure": structure, "constants": constants_for(structure).as_dict(),
           "parameters": {n: {"estimate": v, "sigma": 0.01} for n, v in p.items()}}
    fit = tmp_path / "fit.json"
    fit.write_text(json.dumps(doc))
    before = fit.read_bytes()
    out = tmp_path / "fit.fmu"
    assert main(["fmu", "build", "--model", str(fit), "--out", str(out), "--json"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["structures"] == [structure]
    assert fit.read_bytes() == before
    m = read_parameters(fit).model()
    u = inputs_of(m, record)
    y_py, _ = python_run(m, u)
    t = np.arange(len(u)) * DT
    sig = np.zeros(len(u), dtype=[("time", float)] + [(n, float) for n in m.inputs])
    sig["time"] = t
    for i, n in enumerate(m.inputs):
        sig[n] = u[:, i]
    res = fmpy.simulate_fmu(str(out), input=sig, output=list(OUTPUTS), step_size=DT,
                            output_interval=DT, stop_time=t[-1])
    y = np.column_stack([res[n] for n in OUTPUTS])
    np.testing.assert_allclose(y, y_py, rtol=0, atol=1e-10)
    from fmpy.validation import validate_fmu
    assert validate_fmu(str(out)) == []


def test_generated_equations_are_the_python_descriptor():
    """The symbols the C is printed from, evaluated, are build_model's E, A, B: the
    tracing itself is checked apart from the compiler (every catalogue effect the
    FMU runs, on a structure with all of them that can combine)."""
    structure = "glauert+flap-inertia+skewed-wake+delay-beta1c+advance-ratio-perturbation"
    p = parameters(structure)
    k = constants_for(structure).with_mu(0.33)
    e, a, b = descriptor(structure, p, k)
    s, es, as_, bs, meas = traced(structure)
    values = {**p, "mu": k.mu, "a0": k.a0, "solidity": k.solidity, "V": k.flow_speed,
              **{f"trim_{c}": x for c, x in TRIM.items()}}
    import sympy
    subs = {sympy.Symbol(n): v for n, v in values.items()}
    for sym, num in ((es, e), (as_, a), (bs, b[:, : bs.shape[1]])):
        got = np.array([[float(sympy.sympify(x).xreplace(subs)) for x in row]
                        for row in sym])
        np.testing.assert_allclose(got, num if num.shape == got.shape else
                                   np.pad(num, ((0, 0), (0, got.shape[1] - num.shape[1]))),
                                   rtol=1e-13, atol=1e-13)
    assert str(meas.delays[1]) == "delay_beta1c"


def test_a_run_time_coupling_is_traced_as_a_call():
    """momentum-speed's coupling is computed at run time (a disc quadrature at the
    trim inflow of Eq. 14): traced, its terms are symbols of one call whose
    arguments are the trim turned by the azimuth bias; with the call's results put
    in, the symbols are build_model's E, A, B (the generated C's own numbers are
    checked against the Simulator above)."""
    import sympy
    from inflowsim.fmu.codegen import _trace
    from inflowsim.model.effects.momentum_speed import coupling
    structure = "basic+separate-time-constants+azimuth-bias+momentum-speed"
    p = dict(parameters(structure), k_V=0.8)
    k = constants_for(structure).with_mu(0.27)
    e, a, b = descriptor(structure, p, k)
    _, es, as_, bs, _, calls = _trace(structure)
    assert [c[0] for c in calls] == ["momentum-speed"]
    values = {**p, "mu": k.mu, "a0": k.a0, "solidity": k.solidity, "V": k.flow_speed,
              **{f"trim_{c}": x for c, x in TRIM.items()}}
    subs = {sympy.Symbol(n): v for n, v in values.items()}
    args = [float(x.xreplace(subs)) for x in calls[0][1]]
    assert args[:3] == [k.mu, k.a0s, k.flow_speed] and args[-1] == TRIM["muz"]
    ca, cb = coupling(k, p["azimuth_bias"])
    subs.update({sympy.Symbol(f"numeric_0_0[{i}]"): x for i, x in enumerate(ca.ravel())})
    subs.update({sympy.Symbol(f"numeric_0_1[{i}]"): x for i, x in enumerate(cb.ravel())})
    for sym, num in ((es, e), (as_, a), (bs, b[:, : bs.shape[1]])):
        got = np.array([[float(sympy.sympify(x).xreplace(subs)) for x in row]
                        for row in sym])
        np.testing.assert_allclose(got, num, rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("structure, match", [
    ("basic+delay-theta1s", "causal step"),
    ("glauert+delay-mux", "causal step"),
])
def test_what_the_fmu_cannot_run_is_refused_with_one_line(structure, match, tmp_path):
    with pytest.raises(InputError, match=match):
        build_fmu(tmp_path / "x.fmu", model=structure)
    assert not (tmp_path / "x.fmu").exists()


def test_a_lead_in_a_parameter_file_is_refused(tmp_path):
    p = parameters("basic+delay-beta0")
    p["delay_beta0"] = -0.02
    m = build_model("basic+delay-beta0", p, PUMA)
    with pytest.raises(InputError, match="lead"):
        build_fmu(tmp_path / "x.fmu", model=m)


def test_loads_use_the_structure_generated_load_matrices():
    """load_matrices (Python) of a nine-state model: the FMU's loads read the flap
    rate from the state, the Python from the dynamics; both are checked equal above.
    Here: the loads of the nine-state model equal the first-order model's when the
    flap inertia is negligible (a finite-difference-free cross-check)."""
    p = parameters("basic+flap-inertia")
    p1 = dict(p)
    p1["flap_inertia"] = 1e-6
    m9 = build_model("basic+flap-inertia", p1, PUMA)
    m6 = build_model("basic", {n: v for n, v in p.items() if n != "flap_inertia"}, PUMA)
    l9, l6 = load_matrices(m9), load_matrices(m6)
    x6 = np.array([0.01, -0.02, 0.015, 0.003, -0.002, 0.001])
    u = np.array([0.01, 0.02, -0.01, 0.001, 0.02, -0.01, 0.0, 0.0])
    # on the slow manifold the flap rates are the first-order model's
    x9 = m9.end_state(x6, u)
    np.testing.assert_allclose(l9.c @ x9 + l9.d @ u, l6.c @ x6 + l6.d @ u, rtol=1e-4,
                               atol=1e-9)


@pytest.mark.parametrize("structure", [
    NINE,
    pytest.param("glauert+peters-he-6", marks=pytest.mark.slow),
    pytest.param("basic+separate-time-constants+peters-he-10", marks=pytest.mark.slow),
    pytest.param("glauert+flap-inertia+azimuth-bias+peters-he-15", marks=pytest.mark.slow)])
def test_mu_every_step_and_a_varying_step_in_a_nine_state_fmu(structure, record,
                                                              tmp_path_factory):
    """The real-time paths (issue #10 part 3) for a generated structure with other
    state counts: mu changing every step (the tabulated matrices) and a
    communication step changing every frame (the Taylor remainder) follow the
    exact zero-order hold of the nine-state model (scipy's expm at each step's mu
    and length).  Slow: the Peters-He structures at their trim (6, 10, 15 inflow
    states), whose skewed wake's ``L(X)^-1`` the FMU solves at each of the table's
    builds (``X`` moves with ``mu``)."""
    from scipy.linalg import expm
    p = parameters(structure)
    m = build_model(structure, p, constants_for(structure))
    unzipped, d = built(tmp_path_factory, structure, model=m)
    u = inputs_of(m, record)[:400]
    full = np.zeros((len(u), len(ALL_INPUTS)))
    full[:, : u.shape[1]] = u
    mus = 0.3 + 0.18 * np.sin(np.arange(len(u)) * 0.05)
    rng = np.random.default_rng(3)
    hs = DT * (1 + 0.4 * rng.uniform(-1, 1, len(u)))       # 0.6 dt .. 1.4 dt
    s = FMU2Slave(guid=guid(d), unzipDirectory=unzipped, modelIdentifier="inflowsim",
                  instanceName="s")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    ins, outs = [d.vr[n] for n in ALL_INPUTS], [d.vr[n] for n in OUTPUTS]
    x, t, worst, peak = np.zeros(m.a.shape[0]), 0.0, 0.0, 0.0
    n = m.a.shape[0]
    for k in range(len(u)):
        mu_k, h = float(mus[k]), (DT if k < 200 else float(hs[k]))
        mk = m.with_mu(mu_k)
        s.setReal([d.vr["mu"]], [mu_k])
        s.setReal(ins, list(full[k]))
        s.doStep(t, h)
        t += h
        aug = np.zeros((n + full.shape[1], n + full.shape[1]))
        aug[:n, :n], aug[:n, n:n + m.b.shape[1]] = mk.a, mk.b
        e = expm(aug * h)
        x = e[:n, :n] @ x + e[:n, n:] @ full[k]
        y = np.array(s.getReal(outs))
        worst = max(worst, np.abs(y - mk.c @ x).max())
        peak = max(peak, np.abs(x[:6]).max())
    s.terminate()
    s.freeInstance()
    assert peak > 1e-3 and worst < 1e-10, worst


def realtime_run(unzipped, d, u):
    """Outputs of an FMU run through the real-time paths: fixed mu and h = dt, mu
    changing every step, then a step changing every frame (1/60 s +- 2 %, then
    wider) at a fixed mu."""
    s = FMU2Slave(guid=guid(d), unzipDirectory=unzipped, modelIdentifier="inflowsim",
                  instanceName="s")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    ins, outs = [d.vr[n] for n in ALL_INPUTS], [d.vr[n] for n in OUTPUTS]
    full = np.zeros((len(u), len(ALL_INPUTS)))
    full[:, : u.shape[1]] = u
    y, t = [], 0.0
    for k in range(len(u)):
        if 100 <= k < 200:
            s.setReal([d.vr["mu"]], [0.3 + 0.15 * np.sin(0.1 * k)])
        h = DT
        if k >= 200:
            h = (1 / 60) * (1 + 0.02 * np.sin(1.7 * k)) if k < 300 else DT * (1.4 - 0.003 * k)
        s.setReal(ins, list(full[k]))
        s.doStep(t, h)
        t += h
        y.append(s.getReal(outs))
    s.terminate()
    s.freeInstance()
    return np.array(y)


def test_nine_state_step_rounds_alike_vector_and_scalar(record, tmp_path_factory):
    """The nine-state kernels (the step, the mu table's evaluation, the Taylor
    remainder) in GNU vectors and in plain C (-DIFS_SCALAR_STEP, what compilers
    without vector types get) add in the same order: the same numbers bit for bit,
    at fixed mu, with mu changing every step and with a step changing every
    frame."""
    import shutil
    from pathlib import Path
    from inflowsim.fmu.build import compile_library
    structure = NINE
    m = nine_state_model()
    unzipped, d = built(tmp_path_factory, structure, model=m)
    u = inputs_of(m, record)
    y_v, l_v = fmu_run(unzipped, d, {"structure": 0}, u, 2)
    r_v = realtime_run(unzipped, d, u[:400])
    assert np.abs(y_v).max() > 1e-3
    assert np.abs(r_v[200:]).max() > 1e-3
    # plain C, and the baseline code's pairs of rows (the shipped binary steps four
    # rows at a time where the CPU has AVX2)
    for flag in ("-DIFS_SCALAR_STEP", "-DIFS_NO_CLONES"):
        other = tmp_path_factory.mktemp("other") / "x"
        shutil.copytree(unzipped, other)
        so = Path(other) / "binaries" / "linux64" / "inflowsim.so"
        compile_library(Path(other) / "sources", so, (flag,))
        y_s, l_s = fmu_run(str(other), d, {"structure": 0}, u, 2)
        assert np.array_equal(y_v, y_s) and np.array_equal(l_v, l_s), flag
        assert np.array_equal(r_v, realtime_run(str(other), d, u[:400])), flag


@pytest.mark.parametrize("structure", [ARP_SKEW,
                                       "basic+separate-time-constants+momentum-speed"])
def test_the_trim_effects_reach_hover_with_the_mass_flow_speed(structure, record,
                                                               tmp_path_factory):
    """advance-ratio-perturbation, skewed-wake and momentum-speed use the base
    model's speed through the disc (in their gain and their trim inflow): with the
    mass-flow speed they run from hover, where they used to stop (Python: mu below
    0.1 refused; skew gain divided by zero), and the FMU steps as the Simulator does
    at mu 0 and 0.05 (the sweep of examples/simulator_loop.c starts in hover)."""
    from dataclasses import replace
    p = parameters(structure)
    ct = 0.006
    unzipped = d = None
    for mu in (0.0, 0.05):
        k = replace(constants_for(structure, PUMA.with_mu(mu)), inflow_speed="mass-flow",
                    ct=ct)
        m = build_model(structure, p, k)
        assert m.is_stable()
        u = inputs_of(m, record)
        y_py, _ = python_run(m, u)
        if unzipped is None:   # one FMU: the parameters, trim, mu, speed, ct its variables
            unzipped, d = built(tmp_path_factory, structure)
        values = start_values(m, description=d)
        assert values["inflow_speed"] == 1 and values["ct"] == ct and values["mu"] == mu
        y_fmu, _ = fmu_run(unzipped, d, {**values, "structure": 0}, u, 2)
        assert np.abs(y_py).max() > 1e-3
        np.testing.assert_allclose(y_fmu, y_py, rtol=0, atol=1e-10)
