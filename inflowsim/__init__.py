"""inflowsim: rotor flap and dynamic inflow after "Glauert augmentation of rotor
inflow dynamics" (ERF 1989).

Layers, each importing only those above it in this list: ``physics`` (blade-element
flapping and loads), ``model`` (parameters, effects, structures, the equations'
assembly), ``simulate`` (sampled-data relations, the fixed-step simulator, replay),
``data`` (records and trim), ``identify`` (frequency-domain output error),
``diagnose`` (validation, failures, candidate effects, the ladder), ``flighttest``
(virtual records), ``report`` (figures and documents), ``campaign`` (many records
on Dask), ``fmu`` (the co-simulation FMU) and ``commands`` (the ``inflowsim``
command line).  Import paths of 0.1.0
(``inflowsim.record`` ...) still work (:mod:`._legacy`).
"""
from . import _legacy

_legacy.install()
from .errors import InputError, RecordError
from .model.params import PUMA, Constants, SPECS
from .model.structure import PRESETS, Structure
from .model.effects import CATALOGUE
from .model.build import Model, build_model, descriptor
from .model.presets import paper_table, preset_parameters, theory_parameters
from .model.paramfile import ParameterSet, read_parameters

__version__ = "0.1.0"

__all__ = ["InputError", "RecordError", "PUMA", "Constants", "SPECS", "PRESETS",
           "Structure", "CATALOGUE", "Model", "build_model", "descriptor", "paper_table",
           "preset_parameters", "theory_parameters", "ParameterSet", "read_parameters"]
