"""Build the FMU, compile the C simulator loop on it, fly it and plot the flight
(issue #10 part 6): ``examples/simulator_loop.c`` flies a rigid airframe on the FMU's
rotor loads from hover to forward flight, with no Python in the loop.

    python examples/simulator_loop_fmu.py [OUTDIR]

Needs a C compiler (``cc``/``gcc`` or ``$CC``).  Writes ``OUTDIR/inflowsim.fmu``, the
program, ``OUTDIR/simulator_loop_fmu.csv`` and ``OUTDIR/simulator_loop_fmu.png``
(default ``inflowsim-simulator-loop-fmu`` in the system's temporary folder).
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import numpy as np

from inflowsim.fmu import build_fmu
from inflowsim.report.plots import new_figure, save_png

HERE = Path(__file__).resolve().parent


def main(argv):
    # default: a temporary folder, never the repository (issue #39)
    out = Path(argv[1] if len(argv) > 1
               else Path(tempfile.gettempdir()) / "inflowsim-simulator-loop-fmu")
    out.mkdir(parents=True, exist_ok=True)
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not cc:
        print("no C compiler (cc, gcc or $CC): cannot build the FMU", file=sys.stderr)
        return 2
    # the rotor of simulator_loop.py (its parameters and constants become the FMU's
    # start values), so the two loops fly the same model
    sys.path.insert(0, str(HERE))
    from simulator_loop import rotor_model
    fmu = build_fmu(out / "inflowsim.fmu", overwrite=True, model=rotor_model())
    unz = out / "unzipped"
    with zipfile.ZipFile(fmu) as z:
        z.extractall(unz)
    exe = out / "simulator_loop"
    # the FMU's own headers: its value references, as an importer generates them
    # from its modelDescription.xml
    subprocess.run([cc, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror",
                    f"-I{unz / 'sources'}", "-o", str(exe),
                    str(HERE / "simulator_loop.c"), "-ldl", "-lm"], check=True)
    guid = ElementTree.parse(unz / "modelDescription.xml").getroot().get("guid")
    csv = out / "simulator_loop_fmu.csv"
    res = subprocess.run([str(exe), str(unz / "binaries" / "linux64" / "inflowsim.so"),
                          guid, str(csv)], capture_output=True, text=True, check=True)
    print(res.stdout, end="")
    log = np.genfromtxt(csv, delimiter=",", names=True)
    fig, ax = new_figure(4, 1, size=(8.0, 10.0))
    t = log["t"]
    ax[0, 0].plot(t, log["airspeed"], label="airspeed [m/s]")
    ax[0, 0].plot(t, 100 * log["mu"], label="mu x 100")
    ax[0, 0].plot(t, log["height"], label="height change [m]")
    for n in ("pitch", "roll", "theta0", "theta1c", "theta1s"):
        ax[1, 0].plot(t, np.degrees(log[n]), "--" if n.startswith("theta") else "-",
                      label=n)
    ax[0, 0].set_ylabel("speed [m/s], height [m]")
    ax[1, 0].set_ylabel("attitude, control [deg]")
    ax[2, 0].plot(t, log["thrust"] / 1e3, color="k", label="thrust")
    ax[2, 0].set_ylabel("thrust [kN]")
    ax[3, 0].plot(t, log["pitch_moment"] / 1e3, label="pitch moment")
    ax[3, 0].plot(t, log["roll_moment"] / 1e3, label="roll moment")
    ax[3, 0].set_ylabel("hub moment [kN m]")
    ax[3, 0].set_xlabel("time [s]")
    for a in ax[:, 0]:
        a.grid(True, alpha=0.3)
        a.legend(fontsize="small", loc="best")
    fig.suptitle("Hover to forward flight in C on the FMU's rotor loads")
    print(f"plot: {save_png(fig, out / 'simulator_loop_fmu.png')}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
