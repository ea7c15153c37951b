"""inflowsim: rotor flap and dynamic inflow after "Glauert augmentation of rotor
inflow dynamics" (ERF 1989).

Layers, each importing only those above it in this list: ``physics`` (blade-element
flapping and loads), ``model`` (parameters, effects, structures, the equations'
assembly), ``simulate`` (sampled-data relations, the fixed-step simulator, replay),
``data`` (records and trim), ``identify`` (frequency-domain output error),
``diagnose`` (validation, failures, candidate effects, the ladder), ``flighttest``
(virtual records), ``report`` (figures and documents), ``campaign`` (many records
on Dask), ``fmu`` (the co-simulation FMU) and ``commands`` (the ``inflowsim``
command line).
"""

__version__ = "0.1.0"

#: Top-level name -> module that defines it.  Imported on first use (module
#: ``__getattr__``), so ``import inflowsim`` and ``inflowsim --version`` stay cheap
#: (no NumPy until a model is asked for; issue #27).
_EXPORTS = {
    "InputError": "errors", "RecordError": "errors",
    "PUMA": "model.params", "Constants": "model.params", "SPECS": "model.params",
    "PRESETS": "model.structure", "Structure": "model.structure",
    "CATALOGUE": "model.effects",
    "Model": "model.build", "build_model": "model.build", "descriptor": "model.build",
    "paper_table": "model.presets", "preset_parameters": "model.presets",
    "theory_parameters": "model.presets",
    "ParameterSet": "model.paramfile", "read_parameters": "model.paramfile",
}

__all__ = list(_EXPORTS)


def __getattr__(name):
    import importlib
    if name in _EXPORTS:
        value = getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    else:
        # a subpackage or module (``inflowsim.model`` after a bare ``import
        # inflowsim``, as when this file imported them all)
        try:
            value = importlib.import_module(f".{name}", __name__)
        except ModuleNotFoundError as exc:
            if exc.name != f"{__name__}.{name}":
                raise
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
