"""Compile the C sources with the system compiler and pack the FMU.

The FMU holds ``modelDescription.xml``, ``binaries/linux64/inflowsim.so`` (no
Python inside), ``sources/`` (every C source and the FMI headers) and
``documentation/index.html``.  The variable table and ``modelDescription.xml``
are regenerated from :mod:`.variables` for every build, so they always agree.
"""
from __future__ import annotations

import html
import os
import platform
import shutil
import subprocess
import tempfile
import zipfile
from pathlib import Path

from ..fileio import atomic_path
from ..errors import InputError
from .generate import generated_files, guid
from .variables import MODEL_IDENTIFIER, VARIABLES

#: Hand-written sources (the generated ``inflow_vars.[ch]`` come from Python).
C_SOURCES = ("inflow_model.c", "inflow_slave.c", "inflow_fmi2.c")
HEADERS = ("inflow_model.h", "inflow_slave.h", "fmi2Functions.h", "fmi2FunctionTypes.h",
           "fmi2TypesPlatform.h")
CFLAGS = ("-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", "-fPIC", "-shared",
          "-fvisibility=hidden")


def source_dir() -> Path:
    """The folder holding the C sources: ``inflowsim/fmu/csrc``, a link to the
    repository's ``fmu/`` that setuptools follows, so an installed package ships
    the sources as package data."""
    here = Path(__file__).resolve().parent
    for cand in (here / "csrc", here.parents[1] / "fmu"):
        if (cand / "inflow_model.c").is_file():
            return cand
    raise InputError(f"FMU build: the C sources are missing from {here / 'csrc'}")


def compiler() -> str:
    """The system C compiler: ``$CC``, else ``cc`` or ``gcc`` on the PATH."""
    for cand in (os.environ.get("CC"), "cc", "gcc"):
        if cand and shutil.which(cand):
            return cand
    raise InputError("no C compiler found: install cc or gcc, or set CC")


def platform_folder() -> str:
    if platform.system() != "Linux" or platform.machine() not in ("x86_64", "AMD64"):
        raise InputError(f"FMU build: only linux64 binaries are supported, not "
                         f"{platform.system()} {platform.machine()}")
    return "linux64"


def compile_library(src: Path, out_so: Path, extra_flags=()) -> Path:
    """Compile the model and FMI sources in ``src`` into the shared library ``out_so``."""
    cmd = [compiler(), *CFLAGS, *extra_flags, f"-I{src}", "-o", str(out_so),
           *(str(src / f) for f in C_SOURCES + ("inflow_vars.c",)), "-lm"]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if res.returncode != 0:
        first = (res.stderr.strip().splitlines() or ["(no message)"])[0]
        raise InputError(f"FMU build: the C compiler failed: {first}")
    return out_so


def _stage_sources(dest: Path) -> None:
    src = source_dir()
    missing = [f for f in C_SOURCES + HEADERS if not (src / f).is_file()]
    if missing:
        raise InputError(f"FMU build: {missing[0]} is missing from {src}")
    dest.mkdir(parents=True)
    for f in C_SOURCES + HEADERS + ("LICENSE-FMI.txt",):
        if (src / f).is_file():
            shutil.copyfile(src / f, dest / f)
    for name, text in generated_files().items():
        if name.endswith((".c", ".h")):
            (dest / name).write_text(text, encoding="utf-8")
    (dest / "buildDescription.xml").write_text(_build_description(), encoding="utf-8")


def _build_description() -> str:
    files = "\n".join(f'      <SourceFile name="{f}"/>'
                      for f in C_SOURCES + ("inflow_vars.c",))
    return ('<?xml version="1.0" encoding="UTF-8"?>\n'
            '<fmiBuildDescription fmiVersion="3.0">\n'
            f'  <BuildConfiguration modelIdentifier="{MODEL_IDENTIFIER}">\n'
            '    <SourceFileSet language="C99">\n'
            f"{files}\n"
            "    </SourceFileSet>\n"
            '    <Library name="m"/>\n'
            "  </BuildConfiguration>\n"
            "</fmiBuildDescription>\n")


def documentation_html() -> str:
    """``documentation/index.html``: conventions and the variable table."""
    rows = "\n".join(
        f"<tr><td><code>{html.escape(v.name)}</code></td><td>{i}</td><td>{v.type}</td>"
        f"<td>{v.causality}</td><td>{v.variability}</td>"
        f"<td>{'' if v.start is None else v.start}</td><td>{html.escape(v.unit)}</td>"
        f"<td>{html.escape(v.description)}</td></tr>" for i, v in enumerate(VARIABLES))
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>inflowsim FMU</title></head><body>
<h1>inflowsim: rotor flap and Glauert-augmented dynamic inflow (FMI 2.0 co-simulation)</h1>
<p>First-order multiblade flapping with dynamic inflow, after "Glauert augmentation of
rotor inflow dynamics" (ERF 1989): basic momentum model (Eq. 1-4), empirical model
(Eq. 13) and Glauert-augmented model (Eq. 19-20) with azimuth bias, selected by the
integer parameter <code>structure</code> (0 basic, 1 empirical, 2 glauert).
GUID {guid()}.</p>
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
&Omega;), as in the paper.</li>
<li><code>fmi2DoStep(t, h)</code> holds the inputs over [t, t+h) and leaves the outputs at
t+h: internal exact zero-order-hold steps of <code>dt</code> plus one exact remainder
step, so any communication step is exact.  Time is counted in steps, never summed.</li>
<li>Tunable parameters and constants may change between steps (the matrices are
rebuilt); <code>dt</code> and <code>structure</code> are fixed after initialization.</li>
<li>A value out of range or not finite is refused with <code>fmi2Error</code> and a
logged message naming it; the state and the stored value are untouched.</li>
<li>Apply an identified parameter file in one call:
<code>fmpy.simulate_fmu(fmu, start_values=inflowsim.fmu.start_values(read_parameters(path)))</code>.</li>
</ul>
<h2>Building from <code>sources/</code></h2>
<p><code>cc -std=c99 -O2 -fPIC -shared -fvisibility=hidden -o inflowsim.so
inflow_model.c inflow_fmi2.c inflow_vars.c -lm</code>.
On glibc x86-64, <code>fmi2DoStep</code> is compiled twice (AVX2 and baseline) and the
loader picks one; both give the same numbers bit for bit.
<code>-DIFS_NO_CLONES</code> builds the baseline only; <code>-DIFS_SCALAR_STEP</code>
uses the plain-C step (what compilers without GNU vector types get), again with the
same numbers.</p>
<h2>Variables</h2>
<table border="1" cellpadding="3">
<tr><th>name</th><th>value reference</th><th>type</th><th>causality</th>
<th>variability</th><th>start</th><th>unit</th><th>description</th></tr>
{rows}
</table>
<p>The FMI 2.0 headers in <code>sources/</code> are under the 2-clause BSD licence
(<code>sources/LICENSE-FMI.txt</code>).</p>
</body></html>
"""


def build_fmu(out_path="inflowsim.fmu", overwrite: bool = False, protect=()) -> Path:
    """Build the co-simulation FMU with the system C compiler.

    Parameters
    ----------
    out_path : str or Path
        The ``.fmu`` file to write.
    overwrite : bool
        Replace an existing file (default: refuse).
    protect : iterable of paths
        Files never to write over.

    Returns
    -------
    Path
        ``out_path``.
    """
    out = Path(out_path)
    if out.suffix != ".fmu":
        raise InputError(f"{out}: an FMU file name must end in .fmu")
    for q in protect:
        if out.exists() and Path(q).exists() and os.path.samefile(out, q):
            raise InputError(f"{out}: refusing to write over the input file {q}")
    if out.exists() and not overwrite:
        raise InputError(f"{out}: exists; choose another name or pass --force")
    parent = out.parent if str(out.parent) else Path(".")
    if not parent.is_dir():
        raise InputError(f"{out}: folder {parent} does not exist")
    plat = platform_folder()
    with tempfile.TemporaryDirectory(prefix="inflowsim-fmu-") as tmp:
        root = Path(tmp) / "fmu"
        _stage_sources(root / "sources")
        (root / "binaries" / plat).mkdir(parents=True)
        compile_library(root / "sources", root / "binaries" / plat / f"{MODEL_IDENTIFIER}.so")
        (root / "documentation").mkdir()
        (root / "documentation" / "index.html").write_text(documentation_html(),
                                                           encoding="utf-8")
        (root / "modelDescription.xml").write_text(generated_files()["modelDescription.xml"],
                                                   encoding="utf-8")
        with atomic_path(out) as part:
            with zipfile.ZipFile(part, "w", zipfile.ZIP_DEFLATED) as z:
                for p in sorted(root.rglob("*")):
                    if p.is_file():
                        z.write(p, p.relative_to(root).as_posix())
    return out
