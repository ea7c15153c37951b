"""The command's BLAS threads (issue #38, bench/startup.md): one unless the
environment says otherwise, set before NumPy is imported; a process that imported
NumPy first is left alone."""
import os
import subprocess
import sys

import pytest

from inflowsim.cli import BLAS_THREADS

PROBE = ("import os, sys{pre}; from inflowsim.cli import main\n"
         "try:\n    main(['--version'])\nexcept SystemExit:\n    pass\n"
         "print({names!r} and [os.environ.get(n) for n in {names!r}])")


def _threads(pre="", **env):
    base = {k: v for k, v in os.environ.items() if k not in BLAS_THREADS}
    out = subprocess.run([sys.executable, "-c", PROBE.format(pre=pre, names=list(BLAS_THREADS))],
                         env=base | env, capture_output=True, text=True, check=True).stdout
    return eval(out.strip().splitlines()[-1])


@pytest.mark.parametrize("case, pre, env, want", [
    ("unset", "", {}, ["1", "1", "1"]),
    ("the user's", "", {"OPENBLAS_NUM_THREADS": "2"}, ["2", "1", "1"]),
    ("numpy first", "; import numpy", {}, [None, None, None]),
])
def test_one_blas_thread_unless_said_otherwise(case, pre, env, want):
    assert _threads(pre, **env) == want, case


ALLOC_PROBE = ("import sys{pre}; import inflowsim.cli as cli\n"
               "try:\n    cli.main(['--version'])\nexcept SystemExit:\n    pass\n"
               "print(cli._ALLOCATOR_SET)")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's mallopt")
@pytest.mark.parametrize("case, pre, env, tuned", [
    ("a program", "", {}, True),
    ("the user's tunables", "", {"MALLOC_TRIM_THRESHOLD_": "1000000"}, False),
])
def test_the_allocator_keeps_long_arrays_unless_said_otherwise(case, pre, env, tuned):
    from inflowsim.cli import ALLOCATOR
    base = {k: v for k, v in os.environ.items() if not k.startswith("MALLOC_")}
    out = subprocess.run([sys.executable, "-c", ALLOC_PROBE.format(pre=pre)],
                         env=base | env, capture_output=True, text=True, check=True).stdout
    got = eval(out.strip().splitlines()[-1])
    assert got == ({n: v for n, (_, v) in ALLOCATOR.items()} if tuned else None), case
