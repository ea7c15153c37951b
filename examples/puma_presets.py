"""Eigenvalues of the Puma presets (paper Tables 1-3 and theory values).

Run: python examples/puma_presets.py
"""
import numpy as np

import inflowsim as ifs


def main():
    print("| preset | values | eigenvalues [1/s] | slowest time constant [s] |")
    print("| --- | --- | --- | --- |")
    for preset in ("basic", "empirical", "glauert"):
        for source in ("paper", "theory"):
            m = ifs.build_model(preset, ifs.preset_parameters(preset, ifs.PUMA, source), ifs.PUMA)
            ev = m.eigenvalues()
            txt = ", ".join(f"{e.real:.2f}{e.imag:+.2f}j" if abs(e.imag) > 1e-9
                            else f"{e.real:.2f}" for e in ev if e.imag >= -1e-9)
            print(f"| {preset} | {source} | {txt} | {-1 / np.max(ev.real):.3f} |")


if __name__ == "__main__":
    main()
