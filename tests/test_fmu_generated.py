"""What the FMU's C is generated from: the loads' rows and the speed through the disc
are the Python functions run on symbols (inflowsim.fmu.codegen), equal to the
Python model's numbers; the mu table's and the Taylor rule's constants come from
inflowsim.simulate.mutable; and the C table gives the same matrices as the
Simulator's."""
import ctypes
import subprocess

import numpy as np
import pytest
import sympy as sp

from inflowsim.channels import INPUTS
from inflowsim.fmu import codegen, pyc
from inflowsim.fmu.build import CFLAGS, compiler, source_dir
from inflowsim.fmu.generate import vars_header
from inflowsim.model.build import build_model
from inflowsim.model.loads import load_matrices, load_rows
from inflowsim.model.params import PUMA, Constants
from inflowsim.model.presets import truth_parameters
from inflowsim.physics import loads as ld
from inflowsim.simulate import mutable
from inflowsim.simulate.simulator import Simulator

TRIM = {"theta0": 0.17, "theta1c": 0.012, "theta1s": -0.05, "beta0": 0.06,
        "beta1c": 0.011, "beta1s": -0.004, "muz": -0.02}


def _numbers(structure, mu=0.27):
    k = PUMA.with_mu(mu)
    if "advance-ratio-perturbation" in structure:
        k = k.with_trim(TRIM)
    p = truth_parameters(structure, k)
    p.update({n: v for n, v in {"azimuth_bias": 0.2, "k_skew": 0.6,
                                "flap_inertia": 1.0}.items() if n in p})
    return build_model(structure, p, k)


@pytest.mark.parametrize("structure", ["basic", "glauert", "glauert+flap-inertia",
                                       "basic+second-harmonic-flap+azimuth-bias",
                                       "glauert+skewed-wake"])
def test_generated_loads_are_the_python_loads(structure):
    """The expressions printed into inflow_equations.c's loads_<i>, evaluated at the
    model's numbers, equal inflowsim.model.loads.load_matrices."""
    m = _numbers(structure)
    s = codegen.supported(structure)
    p, k = codegen._symbols(s)
    _, _, _, _, meas = codegen.traced(structure)
    n, nu = m.a.shape[0], len(INPUTS)
    a = np.array([[sp.Symbol(f"a[{i * n + j}]") for j in range(n)] for i in range(n)])
    b = np.array([[sp.Symbol(f"b[{i * nu + j}]") for j in range(nu)] for i in range(n)])
    c_sym, d_sym = load_rows(a, b, s.effects, p, k, meas.azimuth_bias, s.states, INPUTS)
    b10 = np.zeros((n, nu))
    b10[:, [INPUTS.index(c) for c in m.inputs]] = m.b
    values = {a[i, j]: m.a[i, j] for i in range(n) for j in range(n)}
    values |= {b[i, j]: b10[i, j] for i in range(n) for j in range(nu)}
    values |= {sp.Symbol(q): v for q, v in m.parameters.items()}
    values |= {sp.Symbol("mu"): m.constants.mu, sp.Symbol("omega"): m.constants.omega,
               sp.Symbol("a0"): m.constants.a0, sp.Symbol("solidity"): m.constants.solidity}
    values |= {sp.Symbol(f"trim_{c}"): v for c, v in TRIM.items()}
    ev = np.vectorize(lambda x: float(sp.sympify(x).xreplace(values)))
    want = load_matrices(m)
    np.testing.assert_allclose(ev(c_sym), want.c, rtol=1e-13, atol=1e-15)
    cols = [INPUTS.index(c) for c in m.inputs]
    np.testing.assert_allclose(ev(d_sym)[:, cols], want.d, rtol=1e-13, atol=1e-15)


def test_generated_flow_speed_is_the_python_one():
    # not typed as C in the model's equations: the physics' own function, translated
    assert "double ifs_flow_speed(" not in codegen.equations_c(["glauert"])
    assert "double ifs_flow_speed(int inflow_speed, double mu, double ct)" in \
        pyc.algorithms_c()
    for m_, c_ in ((0.0, 0.008), (0.05, 0.008), (0.3, 0.0065)):
        assert ld.flow_speed(1, m_, c_) == ld.mass_flow_parameter(m_, c_)
        assert ld.flow_speed(0, m_, c_) == m_
    assert Constants(mu=0.0, a0=5.73, solidity=0.0917, omega=27.5, ct=0.008,
                     inflow_speed="mass-flow").flow_speed == pytest.approx(
        2 * np.sqrt(0.004), rel=1e-14)


def test_the_c_table_constants_are_the_pythons():
    text = vars_header()
    for line in mutable.c_defines():
        assert line in text
    assert f"#define IFS_MU_TOL {mutable.TOLERANCE!r}" in text
    c = "".join((source_dir() / f).read_text() for f in ("inflow_numerics.c",
                                                        "inflow_algorithms.c"))
    for name in ("IFS_MU_LO", "IFS_MU_SEG", "IFS_MU_DEG", "IFS_MU_TOL", "IFS_TAYLOR_TOL",
                 "IFS_KMAX"):
        assert name in c
    assert "1e-11" not in c and "1e-17" not in c        # no constant of its own


HARNESS = r"""
#include <string.h>
#include "inflow_slave.h"
/* the C table's [phi gam] at mu, by columns, unpadded (IFS_NX x IFS_NA) */
int table_at(double dt, int inflow_speed, double ct, const double *mus, int nmu,
             double *out)
{
    static IfsMuTable t;
    static IfsSlave s;
    static IfsModel m;
    char msg[256];
    int k, i, j;
    ifs_slave_init(&s);                  /* the start values: the presets, glauert */
    s.v.dt = dt;
    s.v.inflow_speed = inflow_speed;
    s.v.ct = ct;
    if (ifs_mu_table_build(&t, &s.v) != 1) return -1;
    memset(&m, 0, sizeof m);
    if (ifs_build(&m, &s.v, msg, sizeof msg) != 0) return -2;
    for (k = 0; k < nmu; k++) {
        s.v.mu = mus[k];
        ifs_mu_table_apply(&t, &s.v, &m);
        for (j = 0; j < IFS_NA; j++)      /* m.pg: the step's order (IFS_PG_AT) */
            for (i = 0; i < IFS_NX; i++)
                out[(size_t)k * IFS_NX * IFS_NA + j * IFS_NX + i] = m.pg[IFS_PG_AT(i, j)];
    }
    return 0;
}
"""


@pytest.fixture(scope="module")
def table_lib(tmp_path_factory):
    """The presets' model and slave with :data:`HARNESS`, compiled once (ct is an
    argument)."""
    tmp_path = tmp_path_factory.mktemp("table")
    src = source_dir()
    h = tmp_path / "harness.c"
    h.write_text(HARNESS)
    so = tmp_path / "h.so"
    files = [src / f for f in ("inflow_numerics.c", "inflow_model.c", "inflow_slave.c",
                               "inflow_vars.c", "inflow_equations.c", "inflow_algorithms.c")]
    flags = [f for f in CFLAGS if f != "-fvisibility=hidden"]
    subprocess.run([compiler(), *flags, f"-I{src}", "-o", str(so), str(h),
                    *map(str, files), "-lm"], check=True)
    return ctypes.CDLL(str(so))


@pytest.mark.parametrize("ct", [None, 0.008])
def test_the_c_table_and_the_simulators_agree(table_lib, ct):
    """The presets' FMU (glauert at its start values, the Puma; with ct the mass-flow
    speed) tabulates [phi gam] in C; the Simulator in Python from the same
    description: both within 1e-12 of each other (and of expm, tested in
    test_simulator_fast)."""
    lib = table_lib
    dt = 0.01
    mus = np.array([0.1, 0.17, 0.249, 0.3333, 0.41, 0.5])
    out = np.zeros((len(mus), 16 * 6))
    dp = ctypes.POINTER(ctypes.c_double)
    rc = lib.table_at(ctypes.c_double(dt), int(ct is not None), ctypes.c_double(ct or 0.0),
                      mus.ctypes.data_as(dp), len(mus), out.ctypes.data_as(dp))
    assert rc == 0
    from dataclasses import replace
    from inflowsim.model.presets import preset_parameters
    k = PUMA if ct is None else replace(PUMA, ct=ct, inflow_speed="mass-flow")
    m0 = build_model("glauert", preset_parameters("glauert", k, "paper"), k)
    sim = Simulator(m0, dt)
    sim.set_mu(0.3)
    sim.set_mu(0.31)
    assert sim._mu_table
    for k, mu in enumerate(mus):
        sim.set_mu(mu)
        pg = np.hstack([sim.phi, sim.gam])
        c_pg = out[k].reshape(16, 6).T
        assert np.max(np.abs(c_pg - pg)) <= 1e-12 * np.max(np.abs(pg)), mu


def test_the_outputs_rotation_follows_the_parameters_of_the_measurement():
    """IFS_SCHEDULED_BIAS (a schedule's parameter turns the outputs) from the effects'
    measurement run on symbols, not from a parameter's name."""
    assert codegen.bias_parameters(["basic", "glauert"]) == {"azimuth_bias"}
    assert codegen.bias_parameters(["basic+flap-inertia"]) == frozenset()
