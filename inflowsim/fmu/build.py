"""Compile the C sources with the system compiler and pack the FMU.

The FMU holds ``modelDescription.xml``, the binary (``binaries/linux64/inflowsim.so``
for FMI 2.0, ``binaries/x86_64-linux/inflowsim.so`` for FMI 3.0; no Python inside),
``sources/`` (every C source and the FMI headers) and ``documentation/index.html``.
The variable table and ``modelDescription.xml`` are regenerated from
:mod:`.variables` for every build, so they always agree.  Both FMI versions are
thin layers (``inflow_fmi2.c``, ``inflow_fmi3.c``) over one shim (``inflow_fmi.h``),
the same slave and model.
"""
from __future__ import annotations

import hashlib
import os
import platform
import re
import shutil
import subprocess
import tempfile
import zipfile
from contextlib import contextmanager
from pathlib import Path

try:
    import fcntl
except ImportError:                                # not POSIX: builds never wait
    fcntl = None

from ..fileio import atomic_path, check_output
from ..errors import InputError
from ..progress import bar
from .generate import SOURCES, generated_files, guid, source_dir, time_vr
from .variables import DEFAULT, MODEL_IDENTIFIER, Description, describe

#: Hand-written sources of the model and slave (the generated ``inflow_vars.[ch]``
#: come from Python), then each FMI version's layer and headers.
CORE_SOURCES = ("inflow_numerics.c", "inflow_model.c", "inflow_slave.c")
CORE_HEADERS = ("inflow_numerics.h", "inflow_model.h", "inflow_slave.h", "inflow_fmi.h")
LAYER = {2: ("inflow_fmi2.c", ("fmi2Functions.h", "fmi2FunctionTypes.h",
                               "fmi2TypesPlatform.h")),
         3: ("inflow_fmi3.c", ("fmi3Functions.h", "fmi3FunctionTypes.h",
                               "fmi3PlatformTypes.h"))}
#: The model description of each version among the generated files.
DESCRIPTION = {2: "modelDescription.xml", 3: "modelDescription-fmi3.xml"}
FMI_VERSIONS = (2, 3)
#: -ffp-contract=off: no fused multiply-add the compiler chooses, so every build rounds
#: alike (and the AVX2 and baseline clones of DoStep agree bit for bit); the mu
#: table's Horner rule asks for fused multiply-adds itself (fma, one rounding on every
#: path: the CPU's where it has AVX2 and FMA, else the C library's).
CFLAGS = ("-std=c99", "-O2", "-ffp-contract=off", "-Wall", "-Wextra", "-Werror", "-fPIC",
          "-shared", "-fvisibility=hidden")


#: Cross-compiled binaries an FMU may carry beside the native one: the mingw-w64
#: compiler, the FMI 2.0 and 3.0 folders and the file name.
CROSS = {"win64": ("x86_64-w64-mingw32-gcc", {2: "win64", 3: "x86_64-windows"},
                   f"{MODEL_IDENTIFIER}.dll")}
#: What differs for Windows: no -fPIC or visibility (a DLL exports what is marked
#: __declspec(dllexport)); a static libgcc, so the DLL needs only the C runtime.
CROSS_CFLAGS = ("-std=c99", "-O2", "-ffp-contract=off", "-Wall", "-Wextra", "-Werror",
                "-shared", "-static-libgcc")


def cross_compiler(target: str) -> str | None:
    """The cross compiler for ``target`` (``win64``) if it is installed, else None."""
    if target not in CROSS:
        raise InputError(f"FMU build: unknown platform {target!r} (known: "
                         f"{', '.join(CROSS)})")
    return shutil.which(CROSS[target][0])


def require_cross_compiler(target: str) -> str:
    """The cross compiler for ``target``, or one line saying what to install."""
    cc = cross_compiler(target)
    if cc is None:
        raise InputError(f"FMU build: no {CROSS[target][0]} for the {target} binary "
                         "(install mingw-w64, e.g. Debian's gcc-mingw-w64-x86-64)")
    return cc


def compiler() -> str:
    """The system C compiler: ``$CC``, else ``cc`` or ``gcc`` on the PATH."""
    for cand in (os.environ.get("CC"), "cc", "gcc"):
        if cand and shutil.which(cand):
            return cand
    raise InputError("no C compiler found: install cc or gcc, or set CC")


def _version(fmi_version) -> int:
    if fmi_version not in FMI_VERSIONS:
        raise InputError(f"FMU build: FMI version {fmi_version!r} is not one of 2, 3")
    return int(fmi_version)


def sources(fmi_version=2) -> tuple:
    """The C sources compiled for ``fmi_version`` (2 or 3), generated table included
    (``generate.SOURCES``: the model description lists the same)."""
    return SOURCES[_version(fmi_version)]


def platform_folder(fmi_version=2) -> str:
    """``binaries/`` folder name: FMI 2.0 ``linux64``, FMI 3.0 ``x86_64-linux``."""
    if platform.system() != "Linux" or platform.machine() not in ("x86_64", "AMD64"):
        raise InputError(f"FMU build: only x86-64 Linux binaries are supported, not "
                         f"{platform.system()} {platform.machine()}")
    return "linux64" if _version(fmi_version) == 2 else "x86_64-linux"


def compile_library(src: Path, out_so: Path, extra_flags=(), fmi_version=2,
                    target=None, say=None) -> Path:
    """Compile the model, the slave and the FMI ``fmi_version`` layer in ``src`` into
    the shared library ``out_so``; for ``target`` (``"win64"``) with its cross
    compiler, into a DLL.

    A binary compiled before from the same files of ``src`` (every source and
    header, byte for byte), the same compiler (its resolved path, size and time) and
    the same flags, for this platform, is copied from the cache
    (:func:`cache_dir`) instead of compiled again; ``say`` is told which.  Else the
    native binary is linked from one object file per source, each reused from the
    cache when compiled before from the same source, the same headers it includes
    (:func:`_included`), compiler and flags (an FMI 3.0 build of a description
    compiles only its layer after the FMI 2.0 one: every other source and header
    is the same), and each compiled with the system headers precompiled once
    (:data:`PCH_HEADER`, gcc; not with ``extra_flags``): the same bytes as one
    ``cc`` over all the sources.  Builds of one binary, object or header wait for
    each other instead of making it twice.
    """
    if target is None:
        cc, flags = compiler(), CFLAGS
    else:
        cc, flags = require_cross_compiler(target), CROSS_CFLAGS
    files = sources(fmi_version)
    cmd = [cc, *flags, *extra_flags, f"-I{src}", "-o", str(out_so),
           *(str(src / f) for f in files), "-lm"]
    cached = _cached_binary(src, cmd, out_so.suffix)
    if _reuse(cached, out_so, say):
        return out_so
    with _locked(cached):
        if _reuse(cached, out_so, say):          # a concurrent build made it meanwhile
            return out_so
        if say:
            say(f"compiling {out_so.name} with {cc} ...")
        if target is None:
            _compile_and_link(cc, list(flags), list(extra_flags), src, files, out_so)
        else:
            _run(cmd)
        if cached is not None:
            _store(out_so, cached)
    return out_so


def _reuse(cached: Path | None, out: Path, say=None) -> bool:
    """Copy the cache file ``cached`` to ``out`` if it is there (True)."""
    if cached is None or not cached.is_file():
        return False
    try:
        shutil.copyfile(cached, out)
        os.utime(cached)                           # recently used: kept by _prune
    except OSError:
        return False                               # a cache that fails is compiled past
    if say:
        say(f"reusing the {out.name} compiled before from the same sources "
            f"({cached.parent})")
    return True


def _run(cmd, check: bool = True) -> subprocess.CompletedProcess:
    """Run the compiler; where ``check``, its first line of complaint is the error."""
    res = subprocess.run(cmd, capture_output=True, text=True)
    if check and res.returncode != 0:
        first = (res.stderr.strip().splitlines() or ["(no message)"])[0]
        raise InputError(f"FMU build: the C compiler failed: {first}")
    return res


def _compile_and_link(cc: str, flags: list, extra: list, src: Path, files,
                      out: Path) -> None:
    """``cc flags extra -c`` each of ``files`` in ``src`` (or reuse its object from
    the cache), then link them in that order into ``out``: the bytes one ``cc`` over
    all the sources gives.  Objects that do not link (a corrupt cache entry) are
    compiled again; a precompiled header gcc refuses is thrown away."""
    with tempfile.TemporaryDirectory(prefix="inflowsim-obj-") as tmp:
        work = Path(tmp)
        # the header made and used with the same flags, gcc's safe choice (the
        # variants' -D flags mostly leave out immintrin.h: no faster with it)
        pch = _pch(cc, flags, work) if PCH_HEADER and not extra else None
        for fresh in (False, True):
            objs = [_object(cc, [*flags, *extra], src, f, work, pch, fresh) for f in files]
            if pch is not None and any(refused for _, refused in objs):
                if pch.parent != work:
                    shutil.rmtree(pch.parent, ignore_errors=True)
                pch = None
            # the second link, of fresh objects, fails as the compiler says
            if _run([cc, *flags, *extra, "-o", str(out), *(str(o) for o, _ in objs),
                     "-lm"], check=fresh).returncode == 0:
                return


def _object(cc: str, flags: list, src: Path, name: str, work: Path, pch: Path | None,
            fresh: bool = False) -> tuple:
    """The object file of ``src/name``, in ``work``: from the cache (unless
    ``fresh``), else compiled (with the precompiled header ``pch`` if given, without
    it if that fails) and stored; and whether ``pch`` failed where the source
    compiled without it."""
    out = work / (Path(name).stem + ".o")
    cached = _cached_object(cc, flags, src, name)
    if not fresh and _reuse(cached, out):
        return out, False
    with _locked(cached):
        if not fresh and _reuse(cached, out):
            return out, False
        cmd = [cc, *flags, f"-I{src}", "-c", "-o", str(out), str(src / name)]
        refused = pch is not None and subprocess.run(
            cmd[:-1] + ["-include", str(pch), cmd[-1]], capture_output=True).returncode != 0
        if pch is None or refused:
            _run(cmd)
        if cached is not None:
            _store(out, cached, OBJECT_CACHE_SIZE)
    return out, refused


#: Binaries the cache keeps (the most recently used).
CACHE_SIZE = 64
#: Object files the cache keeps (in ``objects/``: eight a binary).
OBJECT_CACHE_SIZE = 8 * CACHE_SIZE
#: Precompiled system headers the cache keeps (in ``pch/``: one a compiler and its
#: flags; some 25 MB each).
PCH_CACHE_SIZE = 2
#: The system headers the FMU's sources include, precompiled once per compiler and
#: flags and given to each source's compile (``-include``): parsing them (mostly
#: ``immintrin.h``) is most of the time of a source's compile at -O2.  Declarations
#: only, so each object is the same bytes as without (tests/test_fmu_cache.py checks);
#: gcc only (another compiler stops at the ``#error`` and compiles without), and gcc
#: uses it only where the flags and macros agree with those it was made with.
PCH_HEADER = """\
/* inflowsim: the FMU sources' system headers, precompiled (inflowsim/fmu/build.py) */
#if defined(__clang__) || !defined(__GNUC__)
#error "a precompiled header for gcc only"
#endif
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#if defined(__x86_64__)
#include <immintrin.h>
#endif
"""
_PCH_NAME = "inflowsim_system.h"


def cache_dir() -> Path | None:
    """Where compiled FMU binaries are kept: ``$INFLOWSIM_CACHE_DIR`` (empty: no
    cache), else ``$XDG_CACHE_HOME/inflowsim/fmu``, else ``~/.cache/inflowsim/fmu``."""
    env = os.environ.get("INFLOWSIM_CACHE_DIR")
    if env is not None:
        return Path(env) if env else None
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "inflowsim" / "fmu"


def _compiler_id(exe: str) -> bytes | None:
    """The compiler's resolved path, size and modification time (None: not found)."""
    exe = shutil.which(exe) or exe
    try:
        st = os.stat(exe)
    except OSError:
        return None
    return f"{os.path.realpath(exe)}\0{st.st_size}\0{st.st_mtime_ns}\0".encode()


def _hash(tag: str, cc: str):
    """A SHA-256 begun with ``tag``, the platform and the compiler ``cc`` (None if
    the compiler is not found)."""
    ident = _compiler_id(cc)
    if ident is None:
        return None
    h = hashlib.sha256(tag.encode() + b"\0")
    for part in (platform.system(), platform.machine()):
        h.update(part.encode() + b"\0")
    h.update(ident)
    return h


def _cached_binary(src: Path, cmd, suffix: str) -> Path | None:
    """The cache file of this compilation: named by a SHA-256 of the platform, the
    compiler (resolved path, size, modification time), the command with ``src``
    written as a placeholder, and every file under ``src`` (name and bytes)."""
    folder = cache_dir()
    h = None if folder is None else _hash("inflowsim fmu binary 1", cmd[0])
    if h is None:
        return None
    root, out = str(src), cmd[cmd.index("-o") + 1]
    for arg in cmd[1:]:
        arg = "<out>" if arg == out else arg.replace(root, "<src>")
        h.update(arg.encode() + b"\0")
    for f in sorted(p for p in src.rglob("*") if p.is_file()):
        h.update(f.relative_to(src).as_posix().encode() + b"\0")
        h.update(f.read_bytes())
        h.update(b"\0")
    return folder / f"{h.hexdigest()}{suffix}"


_INCLUDE = re.compile(r"^[ \t]*#[ \t]*include\b[ \t]*(.*)$", re.M)


def _included(src: Path, name: str) -> list | None:
    """``name`` and the files of ``src`` it includes, directly or through them
    (``#include "f"`` or ``<f>`` found in ``src``; every such line, whatever ``#if``
    or comment it stands in), sorted; None when an include is not a plain name (a
    macro): then every file of ``src`` counts."""
    seen, todo = {name}, [name]
    while todo:
        text = (src / todo.pop()).read_text(encoding="utf-8", errors="replace")
        for m in _INCLUDE.finditer(text):
            arg = m.group(1).strip()
            close = {'"': '"', "<": ">"}.get(arg[:1])
            if close is None or close not in arg[1:]:
                return None
            inc = arg[1:arg.index(close, 1)]
            if inc not in seen and (src / inc).is_file():
                seen.add(inc)
                todo.append(inc)
    return sorted(seen)


def _cached_object(cc: str, flags, src: Path, name: str) -> Path | None:
    """The cache file of ``src/name``'s object: named by a SHA-256 of the platform,
    the compiler, the flags and the names and bytes of the source and of every file
    of ``src`` it includes (:func:`_included`; all files of ``src`` if that cannot
    tell)."""
    folder = cache_dir()
    h = None if folder is None else _hash("inflowsim fmu object 1", cc)
    if h is None:
        return None
    for arg in (*flags, "-I<src>", "-c", name):
        h.update(arg.replace(str(src), "<src>").encode() + b"\0")
    deps = _included(src, name)
    if deps is None:
        deps = sorted(p.relative_to(src).as_posix() for p in src.rglob("*") if p.is_file())
    for f in deps:
        h.update(f.encode() + b"\0")
        h.update((src / f).read_bytes())
        h.update(b"\0")
    return folder / "objects" / f"{h.hexdigest()}.o"


#: The cache folder of each compiler's precompiled header this process found (or
#: None: it cannot be made), by compiler, flags and cache: the system headers are
#: preprocessed for its key once a process.
_PCH_SEEN: dict = {}


def _pch(cc: str, flags: list, work: Path) -> Path | None:
    """:data:`PCH_HEADER` precompiled by ``cc`` with ``flags`` (``-include`` the path
    returned; its ``.gch`` lies beside): from the cache if made before by the same
    compiler, flags and system headers (the header preprocessed, byte for byte),
    else made (in ``work`` if there is no cache).  None where it cannot be made
    (another compiler than gcc)."""
    hdr = work / _PCH_NAME
    hdr.write_text(PCH_HEADER, encoding="utf-8")
    folder = cache_dir()
    seen = (_compiler_id(cc), cc, tuple(flags), str(folder), PCH_HEADER)
    final = _PCH_SEEN.get(seen, False)
    if final is False:
        res = subprocess.run([cc, *flags, "-E", str(hdr)], capture_output=True)
        if res.returncode != 0:                    # not gcc
            _PCH_SEEN[seen] = None
            return None
        h = None if folder is None else _hash("inflowsim fmu pch 1", cc)
        if h is None:                              # no cache: made for this build
            return hdr if _make_pch(cc, flags, hdr) else None
        for arg in flags:
            h.update(arg.encode() + b"\0")
        h.update(res.stdout.replace(str(work).encode(), b"<work>"))
        final = _PCH_SEEN[seen] = folder / "pch" / h.hexdigest()
    if final is None:
        return None
    if (final / (_PCH_NAME + ".gch")).is_file():
        _touch(final)
        return final / _PCH_NAME
    with _locked(final):
        if (final / (_PCH_NAME + ".gch")).is_file():
            return final / _PCH_NAME
        if not _make_pch(cc, flags, hdr):
            return None
        part = None
        try:                  # a complete folder renamed into place, as _store does
            final.parent.mkdir(parents=True, exist_ok=True)
            part = Path(tempfile.mkdtemp(prefix=".part-", dir=final.parent))
            for f in (hdr, hdr.with_name(_PCH_NAME + ".gch")):
                shutil.copyfile(f, part / f.name)
            os.replace(part, final)
        except OSError:       # no cache (or another build's already there): work's
            if part is not None:
                shutil.rmtree(part, ignore_errors=True)
            return hdr
        _prune(final.parent, PCH_CACHE_SIZE, dirs=True)
    return final / _PCH_NAME


def _make_pch(cc: str, flags: list, hdr: Path) -> bool:
    """Precompile ``hdr`` into ``hdr.gch`` beside it."""
    return subprocess.run([cc, *flags, "-x", "c-header", "-o",
                           str(hdr.with_name(hdr.name + ".gch")), str(hdr)],
                          capture_output=True).returncode == 0


def _touch(path: Path) -> None:
    try:
        os.utime(path)
    except OSError:
        pass


@contextmanager
def _locked(path: Path | None):
    """Hold an exclusive lock beside ``path`` (a cache file about to be made): a
    concurrent build of the same file waits, then finds it made.  Only saves work:
    without locks (no ``fcntl``, a folder that cannot take them) each build makes
    its own copy, the same bytes."""
    fd = None
    if path is not None and fcntl is not None:
        lock = path.parent / f".lock-{path.name}"
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
            fcntl.flock(fd, fcntl.LOCK_EX)
        except OSError:
            if fd is not None:
                os.close(fd)
            fd = None
    try:
        yield
    finally:
        if fd is not None:
            try:
                os.unlink(lock)                    # made or failed: none to wait for
            except OSError:
                pass
            os.close(fd)


def _store(binary: Path, cached: Path, keep: int = CACHE_SIZE) -> None:
    """Put a fresh binary into the cache: written beside under a name of its own,
    then renamed into place (atomic: a concurrent build reads the old file, the new
    one or none, never a part; two builds of one key write the same bytes)."""
    try:
        cached.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=".part-", dir=cached.parent)
        try:
            with os.fdopen(fd, "wb") as fh, open(binary, "rb") as src:
                shutil.copyfileobj(src, fh)
            os.replace(tmp, cached)
        except BaseException:
            try:
                os.unlink(tmp)
            except OSError:
                pass
            raise
        _prune(cached.parent, keep)
    except OSError:
        pass                                       # no cache: the build stands


def _prune(folder: Path, keep: int = CACHE_SIZE, dirs: bool = False) -> None:
    """Keep the ``keep`` most recently used files (``dirs``: folders) of ``folder``."""
    try:
        items = [p for p in folder.iterdir() if not p.name.startswith(".")
                 and (p.is_dir() if dirs else p.is_file())]
        items.sort(key=lambda p: p.stat().st_mtime)
    except OSError:
        return
    for p in items[:-keep] if len(items) > keep else ():
        if dirs:
            shutil.rmtree(p, ignore_errors=True)
            continue
        try:
            p.unlink()
        except OSError:
            pass


def description_for(model=None) -> Description:
    """The FMU description for ``model``: None (the presets), a structure text or
    :class:`~inflowsim.model.structure.Structure`, a :class:`Description`, a
    :class:`~inflowsim.model.Model` or identified parameter set (its structure, its
    parameters and constants as start values), or a
    :class:`~inflowsim.model.schedule.Schedule` (its structure, its scheduled
    parameters computed from ``mu`` at every step, its held ones start values).

    Parameters
    ----------
    model : None, str, Structure, Description, Model, ParameterSet or Schedule
        What the FMU runs (see above).
    """
    from ..model.structure import Structure
    from .codegen import supported
    from .values import refuse_leads
    if model is None:
        return DEFAULT
    if isinstance(model, Description):
        return model
    if isinstance(model, (str, Structure)):
        return describe((supported(model).name,))
    from ..model.schedule import Schedule
    if isinstance(model, Schedule):
        s = supported(model.structure)
        held = {n: v for n, v, _ in model.held}
        refuse_leads(held)
        return describe((s.name,), start=held, constants=model.constants, schedule=model)
    try:
        structure, params = model.structure, dict(model.parameters)
    except AttributeError:
        raise InputError("an FMU is built for a structure, a Model or a parameter file "
                         f"(inflowsim.model.paramfile.read_parameters), not {type(model).__name__}"
                         ) from None
    s = supported(structure)
    refuse_leads(params)
    return describe((s.name,), start=params, constants=getattr(model, "constants", None))


@contextmanager
def _naming_os_errors(name):
    """An OS error without a file name (a write to a full disk) names ``name``: the
    build folder lies in the system's temporary folder, maybe on another disk than
    the FMU."""
    try:
        yield
    except OSError as exc:
        if exc.filename is None and exc.errno is not None:
            raise type(exc)(exc.errno, exc.strerror or os.strerror(exc.errno),
                            name) from exc
        raise


def _stage_sources(dest: Path, fmi_version: int, d: Description = DEFAULT) -> dict:
    """Copy the hand-written sources and write the generated ones into ``dest``;
    returns the generated files (:func:`generated_files`, made once per build)."""
    src = source_dir()
    layer, headers = LAYER[fmi_version]
    hand = CORE_SOURCES + (layer,) + CORE_HEADERS + headers
    missing = [f for f in hand if not (src / f).is_file()]
    if missing:
        raise InputError(f"FMU build: {missing[0]} is missing from {src}")
    dest.mkdir(parents=True)
    for f in hand + ("LICENSE-FMI.txt",):
        if (src / f).is_file():
            shutil.copyfile(src / f, dest / f)
    files = generated_files(d)
    for name, text in files.items():
        if name.endswith((".c", ".h")):
            (dest / name).write_text(text, encoding="utf-8")
    # the FMI 3.0 build description; FMPy also reads it to compile an FMI 2.0 FMU
    (dest / "buildDescription.xml").write_text(_build_description(fmi_version),
                                               encoding="utf-8")
    return files


def _build_description(fmi_version: int) -> str:
    files = "\n".join(f'      <SourceFile name="{f}"/>' for f in sources(fmi_version))
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            '<fmiBuildDescription fmiVersion="3.0">\n'
            f'  <BuildConfiguration modelIdentifier="{MODEL_IDENTIFIER}">\n'
            '    <SourceFileSet language="C99" compilerOptions="-ffp-contract=off">\n'
            f"{files}\n"
            "    </SourceFileSet>\n"
            '    <Library name="m"/>\n'
            "  </BuildConfiguration>\n"
            "</fmiBuildDescription>\n")


#: ``documentation/index.html`` (a Jinja2 template; every text escaped).
DOCUMENTATION = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>inflowsim FMU</title></head><body>
<h1>inflowsim: rotor flap and Glauert-augmented dynamic inflow (FMI {{ v }}.0 co-simulation)</h1>
<p>First-order multiblade flapping with dynamic inflow, after "Glauert augmentation of
rotor inflow dynamics" (ERF 1989): basic momentum model (Eq. 1-4), empirical model
(Eq. 13) and Glauert-augmented model (Eq. 19-20), and the effects the diagnosis adds.
This FMU runs {% for n in structures %}{{ loop.index0 }} <code>{{ n }}</code>{{ ", " if not loop.last }}{% endfor %}, selected by the integer parameter <code>structure</code>;
its C equations are generated from inflowsim's Python model
(<code>inflow_equations.c</code>).
{{ "GUID" if v == 2 else "Instantiation token" }} {{ guid }}.</p>
<h2>Conventions</h2>
<ul>
<li><b>Inputs and outputs are perturbations about trim</b>, in SI units (rad, rad/s,
rad/s&sup2;; <code>muz, mux, muy</code> over &Omega;R), exactly as the Python
<code>inflowsim.Simulator</code>: subtract the trim (the record's quiet lead-in) from
measured totals before setting inputs, add it back to outputs.
The recorded flap outputs include the azimuth bias rotation.</li>
<li><code>mu</code> is the <b>total</b> trim advance ratio (the flight condition,
0.1 to 0.5); changing it between steps rebuilds the discrete matrices, as
<code>Simulator.set_mu</code>.</li>
<li>Time constants <code>tau, tau0, tau_cs</code> are in azimuth units (seconds times
&Omega;, dimensionless: unit <code>1</code>), as in the paper.  Dimensionless
quantities declare the unit <code>1</code>; a parameter that must be positive has
the minimum {{ positive_min }}.</li>
<li><code>{{ fmi }}DoStep(t, h)</code> holds the inputs over [t, t+h) and leaves the outputs at
t+h: internal exact zero-order-hold steps of <code>dt</code> plus one exact remainder
step, so any communication step is exact.  Time is counted in steps, never summed.</li>
<li>Tunable parameters and constants may change between steps (the matrices are
rebuilt); <code>dt</code> and <code>structure</code> are fixed after initialization.</li>
{% if schedule %}<li><b>Scheduled parameters</b> {% for n in schedule.names %}<code>{{ n }}</code>{{ ", " if not loop.last }}{% endfor %} follow <code>mu</code>: each a polynomial in mu fitted across a campaign's flight conditions (inflowsim fmu build --schedule{% if schedule.trim %}; the trim totals <code>trim_*</code> from the conditions' measured trims{% endif %}), held at its end values outside mu {{ schedule.lo }} to {{ schedule.hi }}; they are local variables (read-only), computed at every step's mu, the matrices tabulated with them.</li>
{% endif %}<li>A value out of range or not finite is refused with <code>{{ fmi }}Error</code> and a
logged message naming it; the state and the stored value are untouched.</li>
<li>Apply an identified parameter file in one call:
<code>fmpy.simulate_fmu(fmu, start_values=inflowsim.fmu.start_values(read_parameters(path)))</code>.</li>
</ul>
<h2>Building from <code>sources/</code></h2>
<p><code>cc -std=c99 -O2 -ffp-contract=off -fPIC -shared -fvisibility=hidden -o
inflowsim.so {{ files }} -lm</code>.  Without <code>-ffp-contract=off</code> a compiler may fuse
multiply-adds and the results differ from inflowsim's at the level of rounding.
On glibc x86-64, <code>{{ fmi }}DoStep</code> is compiled twice (AVX2 and baseline) and the
loader picks one; both give the same numbers bit for bit.  A change of <code>mu</code>
evaluates its table with fused multiply-adds (<code>fma</code>): the CPU's four at a
time where it has AVX2 and FMA, else the C library's, with the same numbers.
<code>-DIFS_NO_CLONES</code> builds the baseline only; <code>-DIFS_SCALAR_STEP</code>
uses the plain-C step (what compilers without GNU vector types get), again with the
same numbers.</p>
<h2>Variables</h2>
<table border="1" cellpadding="3">
<tr><th>name</th><th>value reference</th><th>type</th><th>causality</th>
<th>variability</th><th>start</th><th>unit</th><th>description</th></tr>
{% for r in rows %}<tr><td><code>{{ r.name }}</code></td><td>{{ r.vr }}</td><td>{{ r.type }}</td><td>{{ r.causality }}</td><td>{{ r.variability }}</td><td>{{ r.start }}</td><td>{{ r.unit }}</td><td>{{ r.description }}</td></tr>
{% endfor %}</table>
<p>The FMI {{ v }}.0 headers in <code>sources/</code> are under the 2-clause BSD licence
(<code>sources/LICENSE-FMI.txt</code>).</p>
</body></html>
"""


def documentation_html(fmi_version=2, d: Description = DEFAULT) -> str:
    """``documentation/index.html``: conventions and the variable table
    (:data:`DOCUMENTATION`, rendered by Jinja2).

    Parameters
    ----------
    fmi_version : {2, 3}
        The FMI version documented.
    d : Description
        The FMU's variables and structures.
    """
    from jinja2 import Environment

    from .generate import xml_unit
    from .variables import POSITIVE_MIN
    v_ = _version(fmi_version)
    types = {"Real": "Float64", "Integer": "Int32"} if v_ == 3 else {}
    rows = [] if v_ == 2 else [
        {"name": "time", "vr": time_vr(d), "type": "Float64", "causality": "independent",
         "variability": "continuous", "start": "", "unit": "s",
         "description": "simulation time (read-only)"}]
    rows += [{"name": v.name, "vr": i, "type": types.get(v.type, v.type),
              "causality": v.causality, "variability": v.variability,
              "start": "" if v.start is None else v.start,
              "unit": xml_unit(v.unit) if v.type == "Real" else v.unit,
              "description": v.description} for i, v in enumerate(d.variables)]
    schedule = None
    if d.schedule is not None:
        lo, hi = d.schedule.mu_range
        schedule = {"names": d.scheduled, "lo": f"{lo:g}", "hi": f"{hi:g}",
                    "trim": any(n.startswith("trim_") for n in d.scheduled)}
    env = Environment(autoescape=True, keep_trailing_newline=True)
    return env.from_string(DOCUMENTATION).render(
        v=v_, fmi=f"fmi{v_}", structures=d.structures, guid=guid(d), rows=rows,
        files=" ".join(sources(v_)), schedule=schedule, positive_min=f"{POSITIVE_MIN:g}")


def build_fmu(out_path="inflowsim.fmu", overwrite: bool = False, protect=(),
              fmi_version=2, platforms=(), say=None, model=None) -> Path:
    """Build the co-simulation FMU with the system C compiler.

    Parameters
    ----------
    out_path : str or Path
        The ``.fmu`` file to write.
    overwrite : bool
        Replace an existing file (default: refuse).
    protect : iterable of paths
        Files never to write over.
    fmi_version : {2, 3}
        FMI 2.0 (default) or FMI 3.0 co-simulation; the same model and variables.
    platforms : iterable of str
        Cross-compiled binaries to add beside the native one: ``"win64"`` (with
        mingw-w64's ``x86_64-w64-mingw32-gcc``).
    say : callable, optional
        Progress (:func:`inflowsim.progress.bar`): told each step (generating the C
        equations, compiling, packing) once the output and the compilers are
        checked.
    model : optional
        What the FMU runs (:func:`description_for`): default the three presets
        (integer ``structure`` 0 basic, 1 empirical, 2 glauert); a structure text
        such as ``"glauert+flap-inertia"``; or a Model or an identified parameter
        file, whose parameters and constants become the start values; or a
        :class:`~inflowsim.model.schedule.Schedule`, whose parameters follow ``mu``
        at every step.  Its C equations are generated from the Python model
        (:mod:`.codegen`).

    Returns
    -------
    Path
        ``out_path``.
    """
    out = Path(out_path)
    if out.suffix != ".fmu":
        raise InputError(f"{out}: an FMU file name must end in .fmu")
    check_output(out, overwrite, protect)
    d = description_for(model)
    version = _version(fmi_version)
    plat = platform_folder(version)
    for target in platforms:                  # refuse before compiling anything
        require_cross_compiler(target)
    steps = 3 + len(platforms)
    with bar(say, steps, f"fmu build {out}", "step") as b, \
            tempfile.TemporaryDirectory(prefix="inflowsim-fmu-") as tmp, \
            _naming_os_errors(f"{tmp} (the build folder of {out})"):
        root = Path(tmp) / "fmu"
        b.set_postfix_str("generating the C equations of " + ", ".join(d.structures))
        files = _stage_sources(root / "sources", version, d)
        b.update()
        (root / "binaries" / plat).mkdir(parents=True)
        b.set_postfix_str(f"compiling {plat} with {compiler()}")
        compile_library(root / "sources", root / "binaries" / plat / f"{MODEL_IDENTIFIER}.so",
                        fmi_version=version, say=say)
        b.update()
        for target in platforms:
            cc, folders, name = CROSS[target]
            b.set_postfix_str(f"compiling {target} with {cc}")
            (root / "binaries" / folders[version]).mkdir(parents=True, exist_ok=True)
            compile_library(root / "sources", root / "binaries" / folders[version] / name,
                            fmi_version=version, target=target, say=say)
            b.update()
        b.set_postfix_str("packing")
        (root / "documentation").mkdir()
        (root / "documentation" / "index.html").write_text(documentation_html(version, d),
                                                           encoding="utf-8")
        (root / "modelDescription.xml").write_text(files[DESCRIPTION[version]],
                                                   encoding="utf-8")
        with atomic_path(out) as part:
            with zipfile.ZipFile(part, "w", zipfile.ZIP_DEFLATED) as z:
                for p in sorted(root.rglob("*")):
                    if p.is_file():
                        z.write(p, p.relative_to(root).as_posix())
        b.update()
    return out


__all__ = ["CORE_SOURCES", "CORE_HEADERS", "LAYER", "DESCRIPTION", "FMI_VERSIONS",
           "CFLAGS", "source_dir", "CROSS", "CROSS_CFLAGS", "cross_compiler",
           "require_cross_compiler", "compiler", "sources", "platform_folder",
           "compile_library", "description_for", "DOCUMENTATION", "documentation_html",
           "build_fmu"]
