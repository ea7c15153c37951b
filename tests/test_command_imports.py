"""A command that draws nothing imports no plotting library (issue #38 item 2).

Each command runs in a fresh interpreter, as the installed script runs it, and its
``sys.modules`` is read at the end: matplotlib must not be there (it cost
``identify --json`` half of its CPU time, through ``report.fit``).  The transform
of a continuous record must not import SciPy's special functions either (the
Bernoulli numbers of Gregory's weights are a table, checked here against the
exact rationals).
A test of imports, not of time.
"""
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import virtual

ROOT = Path(__file__).resolve().parents[1]

_PROBE = """
import json, sys
from inflowsim.cli import main
try:
    code = main(sys.argv[1:])
except SystemExit as exc:
    code = exc.code
sys.stderr.write("\\n" + json.dumps({"code": code, "modules": sorted(
    m for m in sys.modules if m.split(".")[0] == "matplotlib"
    or m in ("scipy.special", "scipy.stats"))}))
"""


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    from inflowsim.data.record import write_record
    d = tmp_path_factory.mktemp("imports")
    write_record(virtual(structure="glauert", duration=12.0), d / "rec.csv")
    return d


def _modules(folder, *argv):
    res = subprocess.run([sys.executable, "-c", _PROBE, *argv], capture_output=True,
                         text=True, cwd=folder, timeout=120,
                         env={**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"})
    doc = json.loads(res.stderr.strip().splitlines()[-1])
    assert doc["code"] == 0, res.stderr
    return doc["modules"]


#: Commands that draw nothing (no --report, no plot file asked for).
QUIET = [("model", "--model", "glauert", "--json"),
         ("simulate", "--model", "basic", "rec.csv", "--out", "sim.csv", "--force"),
         ("identify", "rec.csv", "--model", "basic", "--json"),
         ("validate", "rec.csv", "--model", "basic", "--json"),
         ("frf", "rec.csv", "--json"),
         ("diagnose", "rec.csv", "--model", "basic", "--candidates", "glauert", "--json"),
         ("flighttest", "--truth", "linear", "--duration", "6", "--out", "ft.csv",
          "--force")]


@pytest.mark.parametrize("argv", QUIET, ids=[a[0] for a in QUIET])
def test_a_command_that_draws_nothing_imports_no_plotting(folder, argv):
    mods = _modules(folder, *argv)
    assert not [m for m in mods if m.startswith("matplotlib")]
    # nor scipy.stats (0.6 s of a command's start; :mod:`inflowsim.diagnose.tails`)
    assert "scipy.stats" not in mods
    # (identify now marks a fit conditional through the diagnosis's residual
    # analyses, which use scipy.special's digamma: the transform alone must not)
    if argv[0] in ("simulate", "frf", "model"):
        assert "scipy.special" not in mods


def test_the_probe_sees_a_plotting_command(folder):
    """The same probe finds matplotlib where a command draws (it can fail)."""
    mods = _modules(folder, "identify", "rec.csv", "--model", "basic", "--report", "rep",
                    "--force")
    assert "matplotlib" in mods


def test_bernoulli_numbers_are_exact():
    from fractions import Fraction
    from inflowsim.simulate.sampled import bernoulli, gregory_weights
    exact = [1, Fraction(-1, 2), Fraction(1, 6), 0, Fraction(-1, 30), 0, Fraction(1, 42),
             0, Fraction(-1, 30), 0, Fraction(5, 66)]
    assert bernoulli(10) == [float(x) for x in exact]
    # the table Gregory's weights use (scipy's floats, kept bit for bit) is within
    # 2e-12 of them
    from inflowsim.simulate.sampled import _GREGORY_B
    assert np.allclose(_GREGORY_B, bernoulli(7), rtol=2e-12, atol=0)
    c = gregory_weights(1000)
    # exact for polynomials of degree < 6: int_0^1 t^5 dt = 1/6
    t = np.linspace(0.0, 1.0, 1000)
    assert abs(float(c @ t ** 5) * (t[1] - t[0]) - 1 / 6) < 1e-14

