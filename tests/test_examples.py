"""The scripts in examples/ run as a user runs them and write what they promise."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run(script, *args):
    return subprocess.run([sys.executable, str(EXAMPLES / script), *map(str, args)],
                          capture_output=True, text=True, timeout=300)


def test_puma_presets_prints_every_preset():
    res = run("puma_presets.py")
    assert res.returncode == 0, res.stderr
    for name in ("basic", "empirical", "glauert"):
        assert f"| {name} | paper |" in res.stdout and f"| {name} | theory |" in res.stdout


def test_validate_doublet_writes_its_report(tmp_path):
    res = run("validate_doublet.py", tmp_path / "out")
    assert res.returncode == 0, res.stderr
    for f in ("index.html", "time.png", "frequency.png", "errors.png"):
        assert (tmp_path / "out" / f).stat().st_size > 0


@pytest.mark.parametrize("version", ["2", pytest.param("3", marks=pytest.mark.slow)])
def test_fmu_cosim_matches_the_simulator(version, tmp_path):
    pytest.importorskip("fmpy")
    res = run("fmu_cosim.py", tmp_path / "out", version)
    assert res.returncode == 0, res.stderr
    line = next(x for x in res.stdout.splitlines() if x.startswith("max |FMU - Simulator|"))
    assert float(line.split(":")[1].split()[0]) < 1e-10
    assert (tmp_path / "out" / "fmu_cosim.png").stat().st_size > 0


def test_simulator_loop_flies_from_hover_to_forward_flight(tmp_path):
    """The airframe example (issue #10 part 6, Python): the autopilot takes it from
    hover to about 50 m/s on the rotor's loads, holding height and wings level."""
    res = run("simulator_loop.py", tmp_path / "out")
    assert res.returncode == 0, res.stderr
    line = next(x for x in res.stdout.splitlines() if x.startswith("final airspeed"))
    speed = float(line.split()[2])
    mu = float(line.split("(mu ")[1].split(")")[0])
    assert speed > 45.0 and mu == pytest.approx(speed / (27.5 * 7.5), abs=1e-3)
    line = next(x for x in res.stdout.splitlines() if x.startswith("largest height"))
    assert float(line.split()[3]) < 5.0
    assert (tmp_path / "out" / "simulator_loop.png").stat().st_size > 0


def test_c_simulator_loop_flies_on_the_fmu(tmp_path):
    """The C program (issue #10 part 6) flies the airframe on the FMU's loads from hover
    to about 50 m/s, holding height and wings level; plotted by its Python driver."""
    import shutil as _sh
    if not any(_sh.which(c) for c in ("cc", "gcc")):
        pytest.skip("no C compiler: the FMU and the C program cannot be built")
    res = run("simulator_loop_fmu.py", tmp_path / "out")
    assert res.returncode == 0, res.stderr
    line = next(x for x in res.stdout.splitlines() if x.startswith("final airspeed"))
    assert float(line.split()[2]) > 45.0
    line = next(x for x in res.stdout.splitlines() if x.startswith("largest height"))
    assert float(line.split()[3]) < 10.0
    assert float(line.split()[7]) < 5.0           # roll [deg]
    assert (tmp_path / "out" / "simulator_loop_fmu.png").stat().st_size > 0
