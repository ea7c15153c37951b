"""The package's architecture (issue #12): layers, one source of each fact, thin
commands, and the import paths users had before the layers."""
import ast
import importlib
from pathlib import Path

import pytest

import inflowsim
from inflowsim import _legacy

PKG = Path(inflowsim.__file__).parent
#: Each layer may import itself and the layers before it (and the foundation).
LAYERS = ["physics", "model", "simulate", "data", "identify", "diagnose", "flighttest",
          "report", "campaign", "fmu", "commands"]
FOUNDATION = {"errors", "fileio", "channels", "defaults", "frozen", "progress", "_legacy",
              "__init__"}


def _layer(module):
    head = module.split(".")[0]
    return head


def _imports(path):
    """Absolute names under ``inflowsim`` imported by a module file."""
    rel = path.relative_to(PKG).with_suffix("")
    parts = list(rel.parts)
    pkg = parts[:-1] if parts[-1] != "__init__" else parts[:-1]
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = pkg[: len(pkg) - (node.level - 1)] if node.level > 1 else pkg
            name = ".".join(base + ([node.module] if node.module else []))
            if node.module is None:
                out.update(f"{name}.{a.name}".strip(".") for a in node.names)
            else:
                out.add(name)
        elif isinstance(node, ast.ImportFrom) and (node.module or "").startswith("inflowsim."):
            out.add(node.module[len("inflowsim."):])
    return out


def test_layers_import_only_downward():
    bad = []
    for path in PKG.rglob("*.py"):
        if "csrc" in path.parts:
            continue
        own = _layer(".".join(path.relative_to(PKG).with_suffix("").parts))
        if own in FOUNDATION or own == "cli":
            continue
        for name in _imports(path):
            other = _layer(name)
            if other in FOUNDATION or other == own or other not in LAYERS:
                continue
            if LAYERS.index(other) > LAYERS.index(own):
                bad.append(f"{path.relative_to(PKG)} imports {name}")
    assert not bad, bad


def test_commands_are_thin():
    """Command modules parse arguments and print: no command imports another, and
    what they define is HELP, add_arguments, run and private helpers."""
    for path in (PKG / "commands").glob("*.py"):
        if path.name in ("__init__.py", "_common.py", "_checks.py"):
            continue
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.level == 1:
                assert node.module in ("_common", "_checks"), (path.name, node.module)
        public = [n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))
                  and not n.name.startswith("_")]
        assert set(public) <= {"add_arguments", "run", "format_model"}, (path.name, public)


def test_no_global_matplotlib_backend_switch():
    """Figures are drawn on their own canvas: no code calls matplotlib.use or
    imports pyplot (process-wide state)."""
    for path in PKG.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
                assert node.func.attr != "use" or not (
                    isinstance(node.func.value, ast.Name)
                    and node.func.value.id == "matplotlib"), path
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                names = [a.name for a in node.names] + [getattr(node, "module", "") or ""]
                assert not any("pyplot" in n for n in names), path


@pytest.mark.parametrize("old", sorted(_legacy.ALIASES))
def test_old_import_paths_still_work_and_warn(old):
    import sys
    sys.modules.pop(f"inflowsim.{old}", None)        # import it afresh
    new = _legacy.target(f"inflowsim.{old}")
    with pytest.warns(DeprecationWarning, match=new.replace(".", r"\.")):
        a = importlib.import_module(f"inflowsim.{old}")
    b = importlib.import_module(new)
    assert a is b and a.__spec__.name == b.__name__


def test_nothing_of_the_package_uses_an_old_path():
    """New code, docs and tests use the layered paths (issue #28 item 6)."""
    import re
    old = "|".join(re.escape(k) for k in sorted(_legacy.ALIASES, key=len, reverse=True))
    pat = re.compile(r"\binflowsim\.(" + old + r")\b(?=[\s.,;:)`'\"\]]|$)"
                     r"|from inflowsim import [\w, ]*\b(" + old + r")\b")
    root = Path(__file__).resolve().parents[1]
    files = [root / "README.md", *root.glob("docs/*.md"), *root.glob("examples/**/*.py"),
             *root.glob("bench/*.py"), *root.glob("tests/*.py"),
             *root.glob("inflowsim/**/*.py")]
    bad = [f"{p.relative_to(root)}:{i + 1}" for p in files
           if p.name not in ("_legacy.py", "test_layout.py")
           for i, line in enumerate(p.read_text(encoding="utf-8").splitlines())
           if pat.search(line)]
    assert not bad, bad


def test_documented_imports():
    """The README's tour and every path in its prose."""
    from inflowsim.diagnose import diagnose, ladder  # noqa: F401
    from inflowsim.model.effects.skewed_wake import theory_skew  # noqa: F401
    from inflowsim.fmu import build_fmu, start_values  # noqa: F401
    from inflowsim.identify import identify  # noqa: F401
    from inflowsim.model import Model, build_model  # noqa: F401
    from inflowsim.model.paramfile import read_parameters  # noqa: F401
    from inflowsim.model.presets import truth_parameters  # noqa: F401
    from inflowsim.data.record import find_trim, model_inputs, read_record  # noqa: F401
    from inflowsim.simulate.simulator import Simulator
    from inflowsim.simulate.simulator import Simulator as S2
    assert Simulator is S2


def test_one_table_of_channels():
    """Record, model, simulator, FMU and plots read the channel facts from
    inflowsim.channels: one order of the inputs everywhere."""
    from inflowsim import channels
    from inflowsim.data import record
    from inflowsim.fmu import variables  # noqa: F401
    from inflowsim.flighttest.body import HUB
    from inflowsim.fmu.variables import VARIABLES
    equations = importlib.import_module("inflowsim.model.equations")
    from inflowsim.model.structure import Structure
    assert record.INPUT_COLUMNS == equations.INPUTS == channels.INPUTS
    assert record.FLAP_COLUMNS == channels.FLAP and channels.CONTROLS + HUB == channels.INPUTS
    assert Structure.parse("glauert").inputs == channels.INPUTS
    assert Structure.parse("basic").inputs == channels.INPUTS[: channels.N_BASE_INPUTS]
    fmu_inputs = [v.name for v in VARIABLES if v.causality == "input" and v.name != "mu"]
    assert tuple(fmu_inputs) == channels.INPUTS
    units = {v.name: v.unit for v in VARIABLES}
    assert units["qdot"] == "rad/s2" and units["theta0"] == "rad"
    assert list(channels.input_scale(10.0)) == [1, 1, 1, 1, 0.1, 0.1, 0.01, 0.01, 1, 1]


def test_one_band():
    """Identification, validation and diagnosis share the default band and its
    snapping: the same bins."""
    from inflowsim.commands._common import DEFAULT_BAND as cli_band
    from inflowsim.diagnose import validation
    from inflowsim.diagnose.failures import DEFAULT_BAND as fail_band
    from inflowsim.identify.transform import DEFAULT_BAND, snap_band
    assert cli_band is fail_band is DEFAULT_BAND is validation.PAPER_BAND_HZ
    from inflowsim.flighttest.virtual import VirtualTest, virtual_record
    rec = virtual_record(VirtualTest(duration=26.6))
    k, _ = snap_band(len(rec), rec.dt, DEFAULT_BAND)
    assert list(validation.dft_bins(rec)) == list(k) == list(range(6, 43))
