"""The package's architecture (issue #12): layers, no import circle (issue #40), one
source of each fact, thin commands."""
import ast
import importlib
from pathlib import Path

import pytest

import inflowsim

PKG = Path(inflowsim.__file__).parent
#: Each layer may import itself and the layers before it (and the foundation).
LAYERS = ["physics", "model", "simulate", "data", "identify", "diagnose", "flighttest",
          "report", "campaign", "fmu", "commands"]
FOUNDATION = {"errors", "fileio", "channels", "defaults", "frozen", "progress", "__init__"}


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


def _module_names():
    """Absolute name of every module of the package -> its file."""
    out = {}
    for path in PKG.rglob("*.py"):
        if "csrc" in path.parts:
            continue
        parts = ["inflowsim", *path.relative_to(PKG).with_suffix("").parts]
        out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


def import_graph(everywhere: bool = False):
    """Module -> the package's modules it imports: the imports at module level (in
    ``if``/``try`` blocks too), or, with ``everywhere``, also those inside functions.
    Relative imports are resolved; ``from a import b`` is an import of ``a.b`` when
    that is a module, else of ``a`` (the package's ``__init__``)."""
    modules = _module_names()
    graph = {}
    for name, path in modules.items():
        pkg = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        tree = ast.parse(path.read_text())
        if everywhere:
            nodes = list(ast.walk(tree))
        else:
            nodes, todo = [], list(tree.body)
            while todo:                      # module level, through if/try blocks
                node = todo.pop()
                nodes.append(node)
                if isinstance(node, (ast.If, ast.Try)):
                    todo += node.body + node.orelse + getattr(node, "finalbody", [])
                    todo += [n for h in getattr(node, "handlers", []) for n in h.body]
        deps = set()
        for node in nodes:
            if isinstance(node, ast.Import):
                deps.update(a.name for a in node.names)
            elif isinstance(node, ast.ImportFrom):
                base = (".".join(pkg[: len(pkg) - node.level + 1] + [node.module or ""])
                        .strip(".") if node.level else node.module or "")
                for a in node.names:
                    deps.add(f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base)
        graph[name] = {d for d in deps if d in modules and d != name}
    return graph


def import_circles(graph):
    """The graph's circles: each strongly connected set of two or more modules
    (Tarjan's algorithm), sorted, as lists of names."""
    index, low, stack, on, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            part = []
            while True:
                w = stack.pop()
                on.discard(w)
                part.append(w)
                if w == v:
                    break
            if len(part) > 1:
                found.append(sorted(part))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(found)


def test_import_circles_are_found():
    """The search finds a circle (two modules and three) and nothing else."""
    g = {"a": {"b"}, "b": {"a", "c"}, "c": set(), "d": {"e"}, "e": {"f"}, "f": {"d"},
         "g": {"c"}}
    assert import_circles(g) == [["a", "b"], ["d", "e", "f"]]
    assert import_circles({"a": {"b"}, "b": {"c"}, "c": set()}) == []


def test_no_import_circle():
    """No module of the package imports, at module level, a module that imports it
    back, directly or around a longer circle (issue #40)."""
    circles = import_circles(import_graph())
    assert not circles, "import circles: " + "; ".join(" <-> ".join(c) for c in circles)


def test_no_import_circle_through_functions():
    """Counting the imports inside functions too, there is no circle (issue #40):
    ``advance_ratio_perturbation`` <-> ``momentum_speed``, ``report.plots`` <->
    ``report.frf_plots`` and the effect registry's are gone.  The catalogue
    (``model.effects``) imports no structure, preset or equations' assembly; the user
    effects (``model.effects.user``), which need them to check an effect, sit above
    them and plug their loader into the catalogue (``LOADERS``)."""
    circles = import_circles(import_graph(everywhere=True))
    assert circles == [], "import circles: " + "; ".join(" <-> ".join(c) for c in circles)


def test_the_registry_loads_installed_effects_and_moved_names_resolve():
    """An installed effect is looked up when a structure names one (the loader the
    user-effect module plugs in), and the names ``model.effects`` exported before
    they moved resolve to their new homes (``MOVED``, the one table)."""
    from inflowsim.model import effects, structure
    from inflowsim.model.effects import user
    assert user.load_installed in effects.LOADERS
    for name, module in effects.MOVED.items():
        assert getattr(effects, name) is getattr(importlib.import_module(module), name)
    assert effects.needs_trim is structure.needs_trim
    with pytest.raises(AttributeError):
        effects.no_such_name


def test_no_private_import_across_packages():
    """A module imports no private name (``_x``) from another package of the layers
    (issue #40): a helper one package uses from another has a public name in its
    home module."""
    bad = []
    for path in PKG.rglob("*.py"):
        if "csrc" in path.parts:
            continue
        parts = path.relative_to(PKG).with_suffix("").parts
        pkg = parts[:-1]
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.ImportFrom):
                continue
            if node.level:
                base = list(pkg[: len(pkg) - node.level + 1]) + (
                    node.module.split(".") if node.module else [])
            elif (node.module or "").startswith("inflowsim."):
                base = node.module.split(".")[1:]
            else:
                continue
            for a in node.names:
                if a.name.startswith("_") and not a.name.startswith("__") and \
                        base[:1] != list(parts[:1]):
                    bad.append(f"{path.relative_to(PKG)} imports {a.name} from "
                               f"{'.'.join(base)}")
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
