"""``fmu build`` reuses a binary compiled before from the same sources (issue #38):
a second build of an unchanged structure does not run the compiler and packs the
same bytes; any change to a source, a header, the flags or the compiler is a new
binary.  Below the binaries, each source's object file is cached too (keyed by the
source, the headers it includes, the flags and the compiler), compiled with the
system headers precompiled: another FMI version of a structure compiles only its
layer, and the objects link to the bytes one ``cc`` over all sources gives."""
import shutil
import subprocess
import zipfile
from types import SimpleNamespace

import pytest

from inflowsim.fmu import build

pytest.importorskip("ctypes")
if build.shutil.which("cc") is None and build.shutil.which("gcc") is None:
    pytest.skip("no C compiler", allow_module_level=True)


def _binary(fmu, folder="linux64"):
    with zipfile.ZipFile(fmu) as z:
        return z.read(f"binaries/{folder}/inflowsim.so")


def _spy(monkeypatch):
    """The compiler commands build runs from now on (each a list)."""
    calls = []
    real = build.subprocess.run

    def spy(cmd, *args, **kwargs):
        calls.append(cmd)
        return real(cmd, *args, **kwargs)

    monkeypatch.setattr(build, "subprocess", SimpleNamespace(run=spy))
    return calls


def _compiled(calls):
    """The sources compiled (``-c``), by file name."""
    return sorted(c[-1].rsplit("/", 1)[-1] for c in calls if "-c" in c)


def test_a_second_build_of_the_same_structure_does_not_compile(tmp_path, monkeypatch):
    monkeypatch.setenv("INFLOWSIM_CACHE_DIR", str(tmp_path / "cache"))
    calls = _spy(monkeypatch)
    said = []
    first = build.build_fmu(tmp_path / "a.fmu", model="glauert", say=said.append)
    assert _compiled(calls) == sorted(build.sources(2))
    assert any(m.startswith("compiling") for m in said)
    calls.clear()
    said.clear()
    second = build.build_fmu(tmp_path / "b.fmu", model="glauert", say=said.append)
    assert calls == []                           # no compiler this time
    assert any(m.startswith("reusing") for m in said)
    assert _binary(first) == _binary(second)
    assert len([p for p in (tmp_path / "cache").iterdir() if p.is_file()]) == 1
    # FMI 3.0 of the same structure: only its layer is compiled, then linked
    third = build.build_fmu(tmp_path / "c.fmu", model="glauert", fmi_version=3)
    assert _compiled(calls) == ["inflow_fmi3.c"]
    assert _binary(third, "x86_64-linux") != _binary(first)
    calls.clear()
    _objects_link_to_the_bytes_of_one_compile(tmp_path, calls)


def _objects_link_to_the_bytes_of_one_compile(tmp_path, calls):
    """Objects compiled one by one with the precompiled system headers, from the
    cache or not, and linked, are the bytes of one ``cc`` over the same sources
    (two of them here: a shared library may leave names undefined; every source:
    test_one_compile_and_the_objects_give_the_same_binary, slow); a corrupt cached
    object or precompiled header is compiled past."""
    src = tmp_path / "src"
    shutil.copytree(build.source_dir(), src)
    files = ["inflow_numerics.c", "inflow_vars.c"]
    cc = build.compiler()
    one = tmp_path / "one.so"
    build.subprocess.run([cc, *build.CFLAGS, f"-I{src}", "-o", str(one),
                          *(str(src / f) for f in files), "-lm"], check=True)
    calls.clear()
    pch = tmp_path / "cache" / "pch"

    def split(k):
        out = tmp_path / f"split{k}.so"
        build._compile_and_link(cc, list(build.CFLAGS), [], src, files, out)
        assert out.read_bytes() == one.read_bytes(), k
        compiled = _compiled(calls)
        assert all("-include" in c for c in calls if "-c" in c) == (k < 3), k
        calls.clear()
        return sorted(set(compiled))

    assert len(list(pch.glob("*/*.gch"))) == 1       # made by the builds above
    assert split(0) == sorted(files)                 # with the header precompiled
    assert split(1) == []                            # from the cache
    # garbage in the cached objects, the precompiled header cut short: compiled past
    for o in (tmp_path / "cache" / "objects").iterdir():
        o.write_bytes(b"not an object")
    gch = next(pch.glob("*/*.gch"))
    gch.write_bytes(gch.read_bytes()[:100000])
    assert split(3) == sorted(files)                 # compiled without it, dropped
    assert list(pch.glob("*/*.gch")) == []


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


def test_an_objects_key_follows_its_source_and_the_headers_it_includes(tmp_path,
                                                                        monkeypatch):
    monkeypatch.setenv("INFLOWSIM_CACHE_DIR", str(tmp_path / "cache"))
    cc, flags = build.compiler(), list(build.CFLAGS)
    src, other = tmp_path / "src", tmp_path / "other"
    shutil.copytree(build.source_dir(), src)
    shutil.copytree(src, other)
    # what inflow_model.c includes, through its headers; not the FMI layers'
    assert build._included(src, "inflow_model.c") == [
        "inflow_model.c", "inflow_model.h", "inflow_names.h", "inflow_numerics.h",
        "inflow_vars.h"]
    assert "fmi2Functions.h" in build._included(src, "inflow_fmi2.c")
    keys = {f: build._cached_object(cc, flags, src, f) for f in build.sources(2)}
    assert len(set(keys.values())) == len(keys)
    # the same files elsewhere: the same objects
    assert {f: build._cached_object(cc, flags, other, f) for f in keys} == keys
    # a file none includes (the other layer's header) changes none
    h = other / "fmi3Functions.h"
    h.write_bytes(h.read_bytes() + b"\n")
    assert {f: build._cached_object(cc, flags, other, f) for f in keys} == keys
    # a header: every object that includes it, through others too, and no other
    h = other / "inflow_slave.h"
    h.write_bytes(h.read_bytes() + b"\n")
    moved = {f for f in keys if build._cached_object(cc, flags, other, f) != keys[f]}
    assert moved == {"inflow_slave.c", "inflow_fmi2.c"}
    # a source: its own object
    s = other / "inflow_equations.c"
    s.write_bytes(s.read_bytes() + b"\n")
    assert build._cached_object(cc, flags, other, "inflow_equations.c") != \
        keys["inflow_equations.c"]
    # a flag, a macro: every object
    for extra in (["-O3"], ["-DIFS_NO_CLONES"]):
        assert build._cached_object(cc, flags + extra, src, "inflow_vars.c") != \
            keys["inflow_vars.c"]
    # an include that is not a plain name: every file of the folder counts
    s = other / "inflow_vars.c"
    s.write_text(s.read_text() + "\n#define HDR <float.h>\n#include HDR\n")
    assert build._included(other, "inflow_vars.c") is None
    before = build._cached_object(cc, flags, other, "inflow_vars.c")
    h = other / "fmi3Functions.h"
    h.write_bytes(h.read_bytes() + b"\n")
    assert build._cached_object(cc, flags, other, "inflow_vars.c") != before
    monkeypatch.setenv("INFLOWSIM_CACHE_DIR", "")
    assert build._cached_object(cc, flags, src, "inflow_vars.c") is None


def test_a_link_that_fails_with_fresh_objects_is_one_line(tmp_path, monkeypatch):
    """Objects that do not link are compiled again and linked once more (a corrupt
    cache entry); a link that fails with fresh objects too is the compiler's first
    line of complaint, an :class:`InputError`."""
    from inflowsim.errors import InputError
    monkeypatch.setenv("INFLOWSIM_CACHE_DIR", str(tmp_path / "cache"))
    (tmp_path / "one.c").write_text("int inflowsim_one(void) { return 1; }\n")
    calls = _spy(monkeypatch)
    with pytest.raises(InputError, match="^FMU build: the C compiler failed: .*"
                       "no_such_library_here"):
        build._compile_and_link(build.compiler(), list(build.CFLAGS),
                                ["-lno_such_library_here"], tmp_path, ["one.c"],
                                tmp_path / "one.so")
    links = [c for c in calls if "-c" not in c]
    assert len(links) == 2 and _compiled(calls) == ["one.c", "one.c"]


@pytest.mark.slow
@pytest.mark.parametrize("flags", [(), ("-DIFS_NO_CLONES",)], ids=["default", "no-clones"])
def test_one_compile_and_the_objects_give_the_same_binary(flags, tmp_path, monkeypatch):
    """Every source of the presets' FMU (and the nine-state one) compiled to cached
    objects with the precompiled system headers (by default) and linked, twice (the
    second time all from the cache): the bytes of one ``cc`` over them all."""
    from inflowsim.fmu.build import _stage_sources, description_for
    monkeypatch.setenv("INFLOWSIM_CACHE_DIR", str(tmp_path / "cache"))
    cc = build.compiler()
    for i, model in enumerate((None, "glauert+flap-inertia")):
        src = tmp_path / f"src{i}"
        _stage_sources(src, 2, description_for(model))
        one = tmp_path / f"one{i}.so"
        subprocess.run([cc, *build.CFLAGS, *flags, f"-I{src}", "-o", str(one),
                        *(str(src / f) for f in build.sources(2)), "-lm"], check=True)
        for k in range(2):
            out = tmp_path / f"split{i}{k}.so"
            build._compile_and_link(cc, list(build.CFLAGS), list(flags), src,
                                    build.sources(2), out)
            assert out.read_bytes() == one.read_bytes(), (model, k)
