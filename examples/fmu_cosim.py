"""Co-simulate the native FMU with fmpy on a virtual doublet record.

    python examples/fmu_cosim.py [OUT_DIR [FMI_VERSION]]

Builds the FMU (FMI 2.0, or 3.0 with FMI_VERSION 3), replays the record's inputs (perturbations about the trim found in
the quiet lead-in) through it with fmpy, and plots the FMU's flap against the Python
Simulator and the measurements (``OUT_DIR/fmu_cosim.png``, default
``inflowsim-fmu-cosim`` in the system's temporary folder).
"""
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import fmpy  # noqa: E402

from inflowsim.fmu import build_fmu, start_values  # noqa: E402
from inflowsim.model import build_model  # noqa: E402
from inflowsim.model.presets import preset_parameters  # noqa: E402
from inflowsim.data.record import find_trim, model_inputs  # noqa: E402
from inflowsim.simulate.simulator import Simulator  # noqa: E402
from inflowsim.flighttest.virtual import VirtualTest, virtual_record  # noqa: E402

FLAP = ("beta0", "beta1c", "beta1s")


def main(out_dir=None, fmi_version="2"):
    # default: a temporary folder, never the repository (issue #39)
    out = Path(out_dir or Path(tempfile.gettempdir()) / "inflowsim-fmu-cosim")
    out.mkdir(parents=True, exist_ok=True)
    rec = virtual_record(VirtualTest(structure="glauert", seed=0))
    k = rec.constants
    model = build_model("glauert", preset_parameters("glauert", k, "paper"), k)
    trim = find_trim(rec)
    u = model_inputs(rec, model, trim)
    y_py = Simulator(model, rec.dt).replay(u)

    with tempfile.TemporaryDirectory() as tmp:
        fmu = build_fmu(Path(tmp) / "inflowsim.fmu", fmi_version=int(fmi_version))
        sig = np.zeros(len(u), dtype=[("time", float), ("mu", float)]
                       + [(n, float) for n in model.inputs])
        sig["time"] = rec.t - rec.t[0]
        sig["mu"] = k.mu                 # a total (the flight condition), not a perturbation
        for i, n in enumerate(model.inputs):
            sig[n] = u[:, i]
        res = fmpy.simulate_fmu(str(fmu), start_values=start_values(model), input=sig,
                                output=list(FLAP), step_size=rec.dt,
                                output_interval=rec.dt, stop_time=sig["time"][-1])
    y_fmu = np.column_stack([res[n] for n in FLAP])
    print(f"max |FMU - Simulator| over the flap: {np.abs(y_fmu - y_py[:, :3]).max():.2e} rad")

    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(8, 7))
    for i, (ax, n) in enumerate(zip(axes, FLAP)):
        meas = np.degrees(rec[n] - trim.values[n])
        ax.plot(rec.t, meas, color="0.7", lw=1, label="measured (perturbation)")
        ax.plot(rec.t, np.degrees(y_py[:, i]), lw=2, label="Python Simulator")
        ax.plot(rec.t, np.degrees(y_fmu[:, i]), "--", lw=1.2, label="FMU via fmpy")
        ax.set_ylabel(f"{n} [deg]")
    axes[0].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time [s]")
    fig.suptitle(f"inflowsim FMU (FMI {fmi_version}.0) co-simulation: glauert, Table 3, "
                 "theta1s doublet")
    fig.tight_layout()
    png = out / "fmu_cosim.png"
    fig.savefig(png, dpi=100)
    print(f"wrote {png}")


if __name__ == "__main__":
    main(*sys.argv[1:3])
