"""The public API (issue #39): every public module says what it exports (``__all__``,
nothing borrowed such as ``dataclass`` or ``field``), and every callable a package
exports has a numpydoc ``Parameters`` section (a class: ``Parameters`` or
``Attributes``) naming each of its parameters."""
import importlib
import inspect
import pkgutil
import re

import pytest

import inflowsim

#: Not public: the command line (argument parsing and printing, ``HELP``/``run``),
#: the compatibility shim, the FMU's C sources.
SKIP = ("inflowsim.commands", "inflowsim.cli", "inflowsim._legacy", "inflowsim.fmu.csrc")


def _modules():
    out = ["inflowsim"]
    for m in pkgutil.walk_packages(inflowsim.__path__, "inflowsim."):
        if m.name.startswith(SKIP) or any(p.startswith("_") for p in m.name.split(".")[1:]):
            continue
        out.append(m.name)
    return out


MODULES = _modules()
PACKAGES = [n for n in MODULES if hasattr(importlib.import_module(n), "__path__")]


@pytest.mark.parametrize("name", MODULES)
def test_every_public_module_has_all_of_its_own(name):
    mod = importlib.import_module(name)
    assert hasattr(mod, "__all__"), f"{name} has no __all__"
    for n in mod.__all__:
        obj = getattr(mod, n)                      # every name exists
        if inspect.isfunction(obj) or inspect.isclass(obj):
            # its own or the package's, never a borrowed helper (dataclass, field,
            # Path, ...)
            assert getattr(obj, "__module__", "").startswith("inflowsim"), (name, n)


def _section(doc, title):
    m = re.search(rf"^{title}\n-{{{len(title)}}}\n(.*?)(?=^\w[\w ]*\n-{{3,}}\n|\Z)", doc,
                  re.M | re.S)
    return m.group(1) if m else None


def _named(section):
    """Names a numpydoc section documents (``a, b : type`` lines count both)."""
    names = set()
    for line in section.splitlines():
        m = re.match(r"^(\*{0,2}[A-Za-z_][\w]*(?:\s*,\s*\*{0,2}[A-Za-z_]\w*)*)\s*(?::|$)",
                     line)
        if m and not line.startswith(" "):
            names.update(x.strip().lstrip("*") for x in m.group(1).split(","))
    return names


def _public_callables():
    seen = {}
    for name in PACKAGES:
        mod = importlib.import_module(name)
        for n in getattr(mod, "__all__", ()):
            obj = getattr(mod, n)
            if (inspect.isfunction(obj) or inspect.isclass(obj)) and \
                    obj.__module__.startswith("inflowsim"):
                seen.setdefault(f"{obj.__module__}.{obj.__qualname__}", obj)
    return seen


CALLABLES = _public_callables()


def test_there_is_a_public_api():
    assert len(CALLABLES) > 50


@pytest.mark.parametrize("qualname", sorted(CALLABLES))
def test_every_public_callable_documents_its_parameters(qualname):
    obj = CALLABLES[qualname]
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        pytest.skip("no signature")
    params = [p.name for p in sig.parameters.values() if p.name not in ("self", "cls")]
    if not params:
        return
    doc = inspect.getdoc(obj) or ""
    sections = [_section(doc, "Parameters")]
    if inspect.isclass(obj):
        sections.append(_section(doc, "Attributes"))
        sections.append(_section(inspect.getdoc(obj.__init__) or "", "Parameters"))
    sections = [s for s in sections if s is not None]
    assert sections, f"{qualname}: no Parameters section"
    named = set().union(*(_named(s) for s in sections))
    missing = [p for p in params if p not in named]
    assert not missing, f"{qualname}: {missing} not documented"
