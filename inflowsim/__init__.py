"""inflowsim: rotor flap and dynamic inflow after "Glauert augmentation of rotor
inflow dynamics" (ERF 1989)."""
from .errors import InputError, RecordError
from .params import PUMA, Constants, SPECS
from .structure import PRESETS, Structure
from .effects import CATALOGUE
from .model import Model, build_model, descriptor
from .presets import paper_table, preset_parameters, theory_parameters
from .paramfile import ParameterSet, read_parameters

__version__ = "0.1.0"

__all__ = ["InputError", "RecordError", "PUMA", "Constants", "SPECS", "PRESETS",
           "Structure", "CATALOGUE", "Model", "build_model", "descriptor", "paper_table",
           "preset_parameters", "theory_parameters", "ParameterSet", "read_parameters"]
