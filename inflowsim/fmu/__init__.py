"""The native FMI 2.0 co-simulation FMU (no Python inside).

- :func:`build_fmu` compiles ``fmu/*.c`` with the system C compiler and packs the FMU:
  by default the three presets, or any structure or identified parameter file
  (``model=``), its C equations generated from the Python model (:mod:`.codegen`).
- :func:`start_values` turns a model or an ``identify`` parameter file into the FMU's
  values in one call (``fmpy.simulate_fmu(fmu, start_values=start_values(ps))``);
  :func:`apply_parameters` sets them on an fmpy ``FMU2Slave``.
- :mod:`.variables` is the one description of the FMU's variables
  (:func:`describe` for other structures); :mod:`.generate` writes
  ``modelDescription.xml``, the C table and (through :mod:`.codegen`) the C
  equations from it.

Inputs and outputs are perturbations about trim in SI units, the convention of
:class:`inflowsim.simulate.simulator.Simulator`; ``mu`` is the total trim advance ratio.
"""
from .build import build_fmu, description_for
from .values import apply_parameters, start_values, structure_code
from .variables import MODEL_IDENTIFIER, STRUCTURES, VARIABLES, VR, Description, describe

__all__ = ["build_fmu", "description_for", "start_values", "apply_parameters",
           "structure_code", "describe", "Description", "VARIABLES", "VR", "STRUCTURES",
           "MODEL_IDENTIFIER"]
