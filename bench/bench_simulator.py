"""Simulator benchmarks (pytest-benchmark); not part of the default test run.

Run::

    python -m pytest bench/bench_simulator.py --benchmark-only -p no:cacheprovider
    python bench/bench_simulator.py          # plain timeit table (the numbers in simulator.md)

Peers are measured side by side in the same run on the SAME discrete system:
``(phi, gam)`` from the simulator (exact ZOH of the glauert preset at the record's
step), ``c`` its output matrix, ``d = 0``.  Goals (issue #2, part 9): ``step`` at
most 3 us a call; replay of a 26.6 s record at 1 kHz at least 5x faster than
``scipy.signal.dlsim`` and 20x faster than ``control.forced_response``.
"""
from __future__ import annotations

import sys
import timeit

import numpy as np
import pytest

from inflowsim.model import build_model
from inflowsim.model.params import PUMA
from inflowsim.model.presets import preset_parameters
from inflowsim.simulate.simulator import Simulator

DT = 1e-3                        # 1 kHz
N_RECORD = 26600                 # 26.6 s at 1 kHz
LENGTHS = (1_000, 10_000, 100_000, 1_000_000)


def glauert_simulator(structure="glauert", dt=DT, **extra):
    p = preset_parameters(structure, PUMA, "paper")
    p.update(extra)
    return Simulator(build_model(structure, p, PUMA), dt)


def doublet_inputs(n, m, dt=DT, seed=0):
    """A theta1s doublet at 2 s plus small random hub motion on every input."""
    rng = np.random.default_rng(seed)
    u = 1e-3 * rng.standard_normal((n, m))
    t = np.arange(n) * dt
    u[:, 2] += np.radians(1.0) * (((t >= 2.0) & (t < 2.4)) * 1.0 - ((t >= 2.4) & (t < 2.8)))
    return u


def peers(sim):
    """``dlsim`` and ``forced_response`` runners on the simulator's own discrete system."""
    import control
    from scipy import signal
    c = sim.model.c
    d = np.zeros((c.shape[0], sim.m))
    sys_scipy = (sim.phi, sim.gam, c, d, sim.dt)
    sys_control = control.ss(sim.phi, sim.gam, c, d, sim.dt)

    def run_dlsim(u):
        return signal.dlsim(sys_scipy, u)[1]

    def run_control(u):
        t = np.arange(len(u)) * sim.dt
        return control.forced_response(sys_control, T=t, U=u.T).outputs.T

    return run_dlsim, run_control


# -- pytest-benchmark ---------------------------------------------------------------
@pytest.mark.benchmark(group="step")
@pytest.mark.parametrize("structure, extra", [("glauert", {}),
                                              ("glauert+time-delay", {"delay": 0.0345})])
def test_step(benchmark, structure, extra):
    sim = glauert_simulator(structure, **extra)
    u = doublet_inputs(1, sim.m)[0]
    benchmark(sim.step, u)
    assert np.all(np.isfinite(sim.state))


@pytest.fixture(scope="module")
def replay_case():
    sim = glauert_simulator()
    u = doublet_inputs(N_RECORD, sim.m)
    run_dlsim, run_control = peers(sim)
    ref = run_dlsim(u)
    # the three runners compute the same thing: checked once, outside the timing
    np.testing.assert_allclose(sim.replay(u), ref, rtol=0, atol=1e-10 * np.abs(ref).max())
    np.testing.assert_allclose(run_control(u), ref, rtol=0, atol=1e-10 * np.abs(ref).max())
    return sim, u, run_dlsim, run_control


@pytest.mark.benchmark(group="replay-26.6s-1kHz")
def test_replay_inflowsim(benchmark, replay_case):
    sim, u, _, _ = replay_case
    benchmark(sim.replay, u)


@pytest.mark.benchmark(group="replay-26.6s-1kHz")
def test_replay_scipy_dlsim(benchmark, replay_case):
    _, u, run_dlsim, _ = replay_case
    benchmark(run_dlsim, u)


@pytest.mark.benchmark(group="replay-26.6s-1kHz")
def test_replay_control_forced_response(benchmark, replay_case):
    _, u, _, run_control = replay_case
    benchmark.pedantic(run_control, args=(u,), rounds=5, iterations=1)


@pytest.mark.benchmark(group="replay-length")
@pytest.mark.parametrize("n", LENGTHS)
def test_replay_length(benchmark, n):
    sim = glauert_simulator()
    u = doublet_inputs(n, sim.m)
    rounds = 3 if n >= 1_000_000 else 10
    benchmark.pedantic(sim.replay, args=(u,), rounds=rounds, iterations=1)


# -- plain table -------------------------------------------------------------------
def _best(fn, number, repeat=7):
    return min(timeit.repeat(fn, number=number, repeat=repeat)) / number


def unguarded_step(sim, u, kernel="matmul"):
    """``Simulator.step`` as it was before its input checks (issue #11 item 5), with
    the product it had (``kernel="matmul"``: ``M @ xu``, the 0.1.0 fast path) or the
    one it has now (``"dot"``: ``M.dot(xu)``): the references the guarded step is
    timed against, interleaved in one run."""
    xu = sim._xu
    n = sim.n
    if sim._delay is not None:
        sim._push(xu[:n].copy(), np.asarray(u, dtype=float))
    xu[n:] = u
    out = sim._M @ xu if kernel == "matmul" else sim._M.dot(xu)
    xu[:n] = out[:n]
    sim._k += 1
    y = out[n:-1]
    if sim._delay is not None:
        y = sim._apply_delays(y, sim._k)
    return y


def guard_cost(rounds=7, number=20000):
    """The checked step against the unchecked one with the same product (the checks'
    own cost) and against the 0.1.0 step (``M @ xu``, no checks: what a user's loop
    ran before), alternated round by round so all see the same machine load; prints
    the best of each."""
    sim = glauert_simulator()
    u0 = doublet_inputs(1, sim.m)[0]
    runs = {"checked": lambda: sim.step(u0),
            "unchecked_dot": lambda: unguarded_step(sim, u0, "dot"),
            "v010_matmul": lambda: unguarded_step(sim, u0, "matmul")}
    best = dict.fromkeys(runs, np.inf)
    for _ in range(rounds):
        for name, fn in runs.items():
            best[name] = min(best[name], _best(fn, number, 1))
    g, r, old = best["checked"], best["unchecked_dot"], best["v010_matmul"]
    print(f"step glauert, input checks   {g * 1e9:8.0f} ns/call; without "
          f"{r * 1e9:8.0f} ns/call; checks cost {(g - r) * 1e9:+6.0f} ns "
          f"({(g / r - 1) * 100:+.1f} %); 0.1.0's step (M @ xu, no checks) "
          f"{old * 1e9:8.0f} ns/call: the checked step is {(g / old - 1) * 100:+.1f} %")
    return best


def main():
    import os
    import platform

    import control
    import scipy
    cpu = next((ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo")
                if ln.startswith("model name")), platform.processor())
    print(f"machine: {os.cpu_count()} CPUs, {cpu}; Python {platform.python_version()}, "
          f"numpy {np.__version__}, scipy {scipy.__version__}, control {control.__version__}")
    print(f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', '(unset)')}; "
          f"load average {os.getloadavg()[0]:.2f}")
    print("timings: best of 7 repeats (timeit), per call\n")
    for structure, extra in (("glauert", {}), ("glauert+time-delay", {"delay": 0.0345})):
        sim = glauert_simulator(structure, **extra)
        u0 = doublet_inputs(1, sim.m)[0]
        t = _best(lambda: sim.step(u0), number=20000)
        print(f"step {structure:<20} {t * 1e6:8.2f} us/call")
    guard_cost()
    sim = glauert_simulator()
    u = doublet_inputs(N_RECORD, sim.m)
    run_dlsim, run_control = peers(sim)
    t_ours = _best(lambda: sim.replay(u), number=5)
    t_dlsim = _best(lambda: run_dlsim(u), number=1, repeat=5)
    t_ctrl = _best(lambda: run_control(u), number=1, repeat=5)
    print(f"\nreplay {N_RECORD} samples (26.6 s at 1 kHz), glauert, same discrete system:")
    print(f"  inflowsim Simulator.replay  {t_ours * 1e3:9.3f} ms")
    print(f"  scipy.signal.dlsim          {t_dlsim * 1e3:9.3f} ms   ({t_dlsim / t_ours:6.1f}x "
          "slower)")
    print(f"  control.forced_response     {t_ctrl * 1e3:9.3f} ms   ({t_ctrl / t_ours:6.1f}x "
          "slower)")
    print("\nreplay cost against record length (glauert):")
    for n in LENGTHS:
        un = doublet_inputs(n, sim.m)
        tn = _best(lambda: sim.replay(un), number=1, repeat=3 if n >= 1_000_000 else 7)
        print(f"  N = {n:>9,d}  {tn * 1e3:10.3f} ms  {tn / n * 1e9:8.1f} ns/sample")
    return 0


if __name__ == "__main__":
    sys.exit(main())
