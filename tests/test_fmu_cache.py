"""``fmu build`` reuses a binary compiled before from the same sources (issue #38):
a second build of an unchanged structure does not run the compiler and packs the
same bytes; any change to a source, a header, the flags or the compiler is a new
binary."""
import shutil
import zipfile
from types import SimpleNamespace

import pytest

from inflowsim.fmu import build

pytest.importorskip("ctypes")
if build.shutil.which("cc") is None and build.shutil.which("gcc") is None:
    pytest.skip("no C compiler", allow_module_level=True)


def _binary(fmu):
    with zipfile.ZipFile(fmu) as z:
        return z.read("binaries/linux64/inflowsim.so")


def test_a_second_build_of_the_same_structure_does_not_compile(tmp_path, monkeypatch):
    monkeypatch.setenv("INFLOWSIM_CACHE_DIR", str(tmp_path / "cache"))
    calls = []
    real = build.subprocess.run

    def spy(cmd, *args, **kwargs):
        calls.append(cmd)
        return real(cmd, *args, **kwargs)

    monkeypatch.setattr(build, "subprocess", SimpleNamespace(run=spy))
    said = []
    first = build.build_fmu(tmp_path / "a.fmu", model="glauert", say=said.append)
    assert len(calls) == 1 and any(m.startswith("compiling") for m in said)
    said.clear()
    second = build.build_fmu(tmp_path / "b.fmu", model="glauert", say=said.append)
    assert len(calls) == 1                       # no compiler this time
    assert any(m.startswith("reusing") for m in said)
    assert _binary(first) == _binary(second)
    assert len(list((tmp_path / "cache").iterdir())) == 1


def test_the_cache_key_follows_every_source_and_flag(tmp_path, monkeypatch):
    monkeypatch.setenv("INFLOWSIM_CACHE_DIR", str(tmp_path / "cache"))
    src = tmp_path / "src"
    shutil.copytree(build.source_dir(), src)
    cmd = [build.compiler(), *build.CFLAGS, f"-I{src}", "-o", str(tmp_path / "x.so"),
           *(str(src / f) for f in build.sources(2)), "-lm"]
    key = build._cached_binary(src, cmd, ".so")
    # the same files elsewhere and another output name: the same binary
    other = tmp_path / "other"
    shutil.copytree(src, other)
    cmd_o = [c.replace(str(src), str(other)) for c in cmd]
    cmd_o[cmd_o.index("-o") + 1] = str(tmp_path / "y.so")
    assert build._cached_binary(other, cmd_o, ".so") == key
    # one byte of a header, one flag: another
    h = other / "inflow_model.h"
    h.write_bytes(h.read_bytes() + b"\n")
    assert build._cached_binary(other, cmd_o, ".so") != key
    assert build._cached_binary(src, cmd[:1] + ["-O3"] + cmd[1:], ".so") != key
    monkeypatch.setenv("INFLOWSIM_CACHE_DIR", "")
    assert build._cached_binary(src, cmd, ".so") is None
