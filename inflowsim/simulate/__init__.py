"""Simulation layer: discretisation, the sampled-data relations of each intersample
behaviour, the fixed-step :class:`~inflowsim.simulate.simulator.Simulator` and the
hold-aware record :func:`~inflowsim.simulate.replay.replay`."""
from .replay import replay
from .simulator import Simulator

__all__ = ["Simulator", "replay"]
