"""Imports made inside functions (kept lazy for start-up time) resolve: a name moved
or removed elsewhere must fail here, not in a user's command (the campaign command
once imported a level constant from a module that no longer had it)."""
import ast
import importlib
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "inflowsim"


def _lazy_imports():
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        mod = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts)
        if mod.endswith(".__init__"):
            mod = mod[: -len(".__init__")]
        tree = ast.parse(path.read_text())
        for fn in ast.walk(tree):
            if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            for node in ast.walk(fn):
                if isinstance(node, ast.ImportFrom):
                    out.append((mod, path.name.endswith("__init__.py"), node))
    return out


def _resolve(mod, is_package, node):
    if node.level:
        base = mod.split(".")
        base = base if is_package else base[:-1]
        base = base[: len(base) - (node.level - 1)]
        name = ".".join(base + ([node.module] if node.module else []))
    else:
        name = node.module
    return name


LAZY = [(m, p, n) for m, p, n in _lazy_imports()
        if (n.level or (n.module or "").startswith("inflowsim"))]


def test_there_are_lazy_imports_to_check():
    assert len(LAZY) > 50


@pytest.mark.parametrize("mod, is_package, node", LAZY,
                         ids=[f"{m}:{n.lineno}" for m, _, n in LAZY])
def test_a_lazy_import_resolves(mod, is_package, node):
    target = _resolve(mod, is_package, node)
    module = importlib.import_module(target)
    for alias in node.names:
        if alias.name == "*":
            continue
        if hasattr(module, alias.name):
            continue
        importlib.import_module(f"{target}.{alias.name}")    # a submodule
