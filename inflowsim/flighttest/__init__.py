"""Virtual flight tests: records from a truth that is not fitted.

:mod:`.virtual` (a linear structure, integrated by an adaptive ODE solver),
:mod:`.nonlinear` (the individual-blade rotor of :mod:`.bladesim`), the body
motion of :mod:`.body`.  ``inflowsim.flighttest`` was a module before the package
was split into layers; its public names are kept here.
"""
__all__ = ["FlightTest", "FlightTestResult", "flighttest", "nonlinear_flighttest",
           "linear_flighttest", "blade_response", "continuous_hub", "TRIM_CONTROLS",
           "INFLOW_COLUMNS"]


def __getattr__(name):
    """The public names of :mod:`.nonlinear`, imported on first use: a command that
    only asks :mod:`.advice` for the standard manoeuvres loads no blade simulation."""
    if name in __all__:
        from . import nonlinear
        return getattr(nonlinear, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
