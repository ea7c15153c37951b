"""Shared test helpers: the virtual records most tests use, built once a session.

``virtual(**settings)`` returns a :func:`inflowsim.flighttest.virtual.virtual_record` for the
given :class:`~inflowsim.flighttest.virtual.VirtualTest` settings, cached (records are
immutable); ``TWO_AXES`` is a longitudinal then a lateral cyclic doublet.  Test
modules import the helpers they need from here (``from conftest import ...``);
pytest puts this folder on the path.
"""
import os
from functools import lru_cache

# two test workers share two cores (pytest-xdist, -n auto): BLAS threads beyond one a
# worker only spin against each other (set before NumPy is imported; a value the
# caller set is kept)
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import pytest

from inflowsim.cli import main
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


def run(capsys, *argv):
    """Run the ``inflowsim`` command in-process: ``(exit code, stdout, stderr)``."""
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def assert_user_error(code, out, err, *words):
    """Exit 2, nothing on stdout, one line on stderr holding every one of ``words``."""
    assert code == 2, err
    assert out == ""
    assert len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in err
    for w in words:
        assert w in err, err
