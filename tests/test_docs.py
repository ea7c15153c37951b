"""The documentation in the repository (issue #11 item 8): the README's Python tour runs
as written, its links resolve, and the limits ``docs/`` states are the code's."""
import ast
import re
import shutil
from pathlib import Path

import pytest

from conftest import virtual
from inflowsim.channels import LIMIT
from inflowsim.cli import COMMANDS
from inflowsim.data.record import write_record
from inflowsim.model.params import OMEGA_PLAUSIBLE, OMEGA_RANGE

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")


def python_blocks(text):
    return re.findall(r"```python\n(.*?)```", text, re.S)


def test_readme_links_to_docs_resolve():
    links = re.findall(r"\]\(((?:docs|bench|examples)/[^)#]+)\)", README)
    assert {"docs/model.md", "docs/record-format.md", "docs/interface.md"} <= set(links)
    for link in links:
        assert (ROOT / link).is_file(), link


def test_python_blocks_compile():
    """Every Python block of the README's tour parses and its imports resolve (the
    run itself is the slow test below)."""
    blocks = python_blocks(README)
    assert len(blocks) >= 3
    for i, block in enumerate(blocks):
        compile(block, f"README.md python block {i + 1}", "exec")   # raises if not
        for node in ast.walk(ast.parse(block)):
            if isinstance(node, ast.ImportFrom) and node.module:
                mod = __import__(node.module, fromlist=[a.name for a in node.names])
                for a in node.names:
                    assert hasattr(mod, a.name), (node.module, a.name)


# slow: a ladder and an FMU build as the README writes them (44 s of the default run)
@pytest.mark.slow
def test_python_tour_runs_as_written(tmp_path, monkeypatch):
    blocks = python_blocks(README)
    assert len(blocks) >= 3
    monkeypatch.chdir(tmp_path)
    # a short, coarse record: the tour runs diagnose and a ladder on it as written,
    # and the searches' decisions are tested on their own records (test_diagnose)
    write_record(virtual(structure="glauert+azimuth-bias", duration=12.0, dt=0.02),
                 tmp_path / "flight.csv")
    has_cc = any(shutil.which(c) for c in ("cc", "gcc"))
    scope = {}
    for i, block in enumerate(blocks):
        if "build_fmu" in block and not has_cc:
            pytest.skip("no C compiler: the FMU block cannot build")
        exec(compile(block, f"README.md python block {i + 1}", "exec"), scope)
    # what the tour promises, checked on what it computed
    assert scope["s"].parameters[-1] == "delay"
    assert scope["y"].shape == (600, 6)             # the replayed record, 12 s at 50 Hz
    assert scope["d"].missing_effect is not None
    if has_cc:
        assert len(scope["res"]) == 201 and "beta1s" in scope["res"].dtype.names


def test_interface_lists_every_command():
    text = (ROOT / "docs" / "interface.md").read_text(encoding="utf-8")
    for name in COMMANDS:
        assert f"inflowsim {name}" in text, name


def test_record_format_states_the_codes_limits():
    text = (ROOT / "docs" / "record-format.md").read_text(encoding="utf-8")
    assert f"`omega` outside {OMEGA_RANGE[0]:g}-{OMEGA_RANGE[1]:g} rad/s" in text
    assert f"`omega` outside {OMEGA_PLAUSIBLE[0]:g}-{OMEGA_PLAUSIBLE[1]:g} rad/s" in text
    assert f"exceeds {LIMIT:.0e}".replace("+0", "") in text
    for key in ("# hold:", "# trim_window:"):
        assert key in text


def _anchors(path):
    """The anchors of a Markdown file: ``<a id>``s and GitHub's heading slugs."""
    text = path.read_text(encoding="utf-8")
    ids = set(re.findall(r'<a id="([^"]+)">', text))
    for h in re.findall(r"^#+ (.*)$", text, re.M):
        slug = re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-")
        ids.add(slug)
    return ids


#: Pages whose relative links are checked (issue #40: the studies moved out of the
#: changelog and the results pages into bench/studies/, linked from there).
LINKED_PAGES = ["CHANGELOG.md", "bench/*.md", "bench/studies/*.md"]


def test_links_of_the_changelog_and_the_studies_resolve():
    """Every relative link (inline or a reference definition) names a file that
    exists and, with ``#anchor``, an anchor of that file."""
    bad = []
    for pattern in LINKED_PAGES:
        for page in sorted(ROOT.glob(pattern)):
            text = page.read_text(encoding="utf-8")
            targets = re.findall(r"\]\(([^)\s]+)\)", text) + \
                re.findall(r"^\[[^\]]+\]: (\S+)", text, re.M)
            for t in targets:
                if re.match(r"\w+:", t):                 # http:, mailto: ...
                    continue
                file, _, anchor = t.partition("#")
                target = (page.parent / file).resolve() if file else page
                if not target.is_file():
                    bad.append(f"{page.relative_to(ROOT)}: {t} (no file)")
                elif anchor and anchor not in _anchors(target):
                    bad.append(f"{page.relative_to(ROOT)}: {t} (no anchor)")
    assert not bad, bad


def test_changelog_is_one_short_line_a_change():
    """The changelog says each change in one line (issue #40: it had held 659 lines
    of findings, lines up to 899 characters); the detail is linked."""
    lines = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8").splitlines()
    long = [f"{i + 1}: {len(s)}" for i, s in enumerate(lines) if len(s) > 200]
    assert not long, long
    # a bullet is one line: no continuation lines indented under it
    wrapped = [i + 1 for i, s in enumerate(lines)
               if s.startswith("  ") and not s.lstrip().startswith("|")]
    assert not wrapped, wrapped
