"""Shared test helpers: the virtual records most tests use, built once a session.

``virtual(**settings)`` returns a :func:`inflowsim.virtual.virtual_record` for the
given :class:`~inflowsim.virtual.VirtualTest` settings, cached (records are
immutable); ``TWO_AXES`` is a longitudinal then a lateral cyclic doublet.  Test
modules import the helpers they need from here (``from conftest import ...``);
pytest puts this folder on the path.
"""
from functools import lru_cache

import pytest

from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record

TWO_AXES = (Manoeuvre(), Manoeuvre(channel="theta1c", t_start=12.0))


@lru_cache(maxsize=None)
def _virtual(items):
    return virtual_record(VirtualTest(**dict(items)))


def virtual(**settings):
    """A cached virtual record (settings must be hashable: tuples, not lists)."""
    return _virtual(tuple(sorted(settings.items())))


@pytest.fixture(scope="session")
def noise_free_glauert():
    """The default virtual Puma record, glauert truth, no noise, continuous time."""
    return virtual(structure="glauert", noise_flap=0.0)
