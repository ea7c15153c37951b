"""Other importers: modelica's fmusim (Reference-FMUs) runs FMI 2.0 and 3.0 FMUs of
the presets and of every generated structure (every effect the FMU takes) and gives
the Simulator's trajectory and loads to 1e-10 (issue #10, "Done when").

fmusim is not on PyPI or in Debian, and today's fmusim (Rust) needs crates.io, so the
test runs where one is installed: ``INFLOWSIM_FMUSIM=/path/to/fmusim`` or ``fmusim`` on
the PATH (the C fmusim's command line; ``tools/fmusim/build.sh`` builds it from a
Reference-FMUs checkout).  Elsewhere it is skipped with that reason; fmpy runs the same
FMUs in ``tests/test_fmu_structures.py`` everywhere.
"""
from __future__ import annotations

import os
import shutil
import subprocess

import numpy as np
import pytest

pytest.importorskip("fmpy")
from test_fmu_structures import STRUCTURES as FMPY_STRUCTURES  # noqa: E402
from test_fmu_structures import (ALL_INPUTS, LOADS, OUTPUTS, constants_for,  # noqa: E402
                                 inputs_of, parameters, python_run, record)

from inflowsim.fmu import build_fmu  # noqa: E402
from inflowsim.model import build_model  # noqa: E402

FMUSIM = os.environ.get("INFLOWSIM_FMUSIM") or shutil.which("fmusim")
pytestmark = pytest.mark.skipif(
    not FMUSIM, reason="no fmusim: set INFLOWSIM_FMUSIM or put fmusim on the PATH "
    "(tools/fmusim/build.sh builds it)")
DT = 0.01
__all__ = ["record"]          # the record fixture, shared with test_fmu_structures

#: the presets and every generated structure of the fmpy tests
STRUCTURES = ("basic", "empirical", "glauert") + FMPY_STRUCTURES


def fmusim_run(fmu, u, tmp_path):
    """Outputs and loads of fmusim stepping the FMU at dt with the inputs u (one row
    per step, held: fmusim reads each row at its own communication point)."""
    full = np.zeros((len(u), len(ALL_INPUTS)))
    full[:, : u.shape[1]] = u
    csv_in, csv_out = tmp_path / "in.csv", tmp_path / "out.csv"
    rows = ["time," + ",".join(ALL_INPUTS)]
    rows += [f"{k * DT:.2f}," + ",".join(repr(float(v)) for v in full[k])
             for k in range(len(u))]
    csv_in.write_text("\n".join(rows) + "\n")
    stop = (len(u) - 1) * DT
    cmd = [FMUSIM, "--interface-type", "cs", "--input-file", str(csv_in),
           "--output-file", str(csv_out), "--output-interval", str(DT),
           "--stop-time", f"{stop:.2f}"]
    for name in OUTPUTS + LOADS:
        cmd += ["--output-variable", name]
    done = subprocess.run(cmd + [str(fmu)], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    with open(csv_out) as f:
        header = [h.strip('"') for h in f.readline().strip().split(",")]
    data = np.loadtxt(csv_out, delimiter=",", skiprows=1, ndmin=2)
    col = {h: data[:, i] for i, h in enumerate(header)}
    np.testing.assert_allclose(col["time"], np.arange(len(u)) * DT, atol=1e-9)
    return (np.column_stack([col[n] for n in OUTPUTS]),
            np.column_stack([col[n] for n in LOADS]))


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("structure", STRUCTURES)
def test_fmusim_runs_every_structure_equal_to_the_simulator(structure, version, record,
                                                            tmp_path):
    m = build_model(structure, parameters(structure), constants_for(structure))
    u = inputs_of(m, record)
    y_py, l_py = python_run(m, u)
    fmu = build_fmu(tmp_path / "s.fmu", fmi_version=version, model=m)
    y, loads = fmusim_run(fmu, u, tmp_path)
    assert np.abs(y_py).max() > 1e-3
    np.testing.assert_allclose(y, y_py, rtol=0, atol=1e-10)
    # the loads fmusim records at t_k + dt are those with u_k held (the Simulator's)
    np.testing.assert_allclose(loads[1:], l_py, rtol=0, atol=1e-10)
