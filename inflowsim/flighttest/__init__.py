"""Virtual flight tests: records from a truth that is not fitted.

:mod:`.virtual` (a linear structure, integrated by an adaptive ODE solver),
:mod:`.nonlinear` (the individual-blade rotor of :mod:`.bladesim`), the body
motion of :mod:`.body`.  ``inflowsim.flighttest`` was a module before the package
was split into layers; its public names are kept here.
"""
from .nonlinear import (INFLOW_COLUMNS, TRIM_CONTROLS, FlightTest, FlightTestResult,
                        blade_response, continuous_hub, flighttest, linear_flighttest,
                        nonlinear_flighttest)

__all__ = ["FlightTest", "FlightTestResult", "flighttest", "nonlinear_flighttest",
           "linear_flighttest", "blade_response", "continuous_hub", "TRIM_CONTROLS",
           "INFLOW_COLUMNS"]
