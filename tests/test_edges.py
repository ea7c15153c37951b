"""Clean edges (issue #28 items 1-4) and a start that imports only what it needs
(issue #27 item 2)."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import assert_user_error, run, virtual
from inflowsim.cli import COMMANDS

ROOT = Path(__file__).resolve().parents[1]


# -- start-up: what --version and --help import ---------------------------------------
#: Modules the help and the version must not import (seconds of start-up between them).
HEAVY = ("numpy", "scipy", "scipy.stats", "matplotlib", "inflowsim.diagnose",
         "inflowsim.report", "inflowsim.identify", "inflowsim.model")

_PROBE = """
import json, sys
from inflowsim.cli import main
heavy = {heavy!r}
seen = {{}}
for argv in {argvs!r}:
    try:
        main(argv)
    except SystemExit:
        pass
    seen[" ".join(argv)] = [m for m in heavy if m in sys.modules]
sys.stderr.write(json.dumps(seen))
"""


def test_help_and_version_import_no_computing_module():
    """``inflowsim --version``, ``--help`` and each command's ``--help``, in one fresh
    interpreter (one after the other: a module one of them imports stays in
    ``sys.modules`` and is charged to it)."""
    argvs = [["--version"], ["--help"]] + [[c, "--help"] for c in COMMANDS]
    argvs.append(["fmu", "build", "--help"])
    code = _PROBE.format(heavy=HEAVY, argvs=argvs)
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, env={**__import__("os").environ,
                                        "PYTHONPATH": str(ROOT)}, timeout=60)
    assert res.returncode == 0, res.stderr
    seen = json.loads(res.stderr.strip().splitlines()[-1])
    assert set(seen) == {" ".join(a) for a in argvs}
    assert {a: m for a, m in seen.items() if m} == {}


def test_top_level_names_resolve_on_use():
    import inflowsim as ifs
    assert ifs.Structure.parse("glauert").name == "glauert"
    assert ifs.build_model("basic", ifs.preset_parameters("basic", ifs.PUMA, "paper"),
                           ifs.PUMA).structure.name == "basic"
    assert set(ifs.__all__) <= set(dir(ifs))
    with pytest.raises(AttributeError):
        ifs.no_such_name
