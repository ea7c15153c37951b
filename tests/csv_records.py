"""The sensor noise and the CSV writing that the tests' independent record
generators share (``test_independent_records``, ``servo_records``,
``test_lead_lag_records``, ``extra_term_truths``, ``test_wake_distortion``).

Written here, not by the library's ``write_record``: a record no code under test
made must not pass through its writer either.
"""
import numpy as np
from scipy import signal

from inflowsim.data.record import read_record


def flap_noise(seed, n, rate, colour_hz=None, sigma=1e-4):
    """``(n, 3)`` flap noise [rad]: white of standard deviation ``sigma``, or the same
    draw through a second-order Butterworth low-pass at ``colour_hz`` [Hz], scaled
    back to ``sigma`` per channel; ``rate`` the sample rate [Hz]."""
    e = np.random.default_rng(seed).normal(size=(n, 3))
    if colour_hz:
        b, a = signal.butter(2, colour_hz / (rate / 2))
        e = signal.lfilter(b, a, e, axis=0)
        e /= e.std(axis=0)
    return sigma * e


def write_csv(path, constants, cols, hub=False, mu=None):
    """Write ``cols`` (``{column: array}``, ``t`` first) as a record with the
    ``constants``' header (``# hub:`` too when ``hub``; ``mu`` overrides the
    header's advance ratio) and read it back."""
    mu = constants.mu if mu is None else mu
    lines = [f"# omega: {constants.omega}", f"# mu: {mu}", f"# a0: {constants.a0}",
             f"# solidity: {constants.solidity}"]
    if hub:
        lines.append(f"# hub: {constants.hub}")
    lines.append(",".join(cols))
    n = len(cols["t"])
    lines += [",".join(f"{cols[c][i]:.12g}" for c in cols) for i in range(n)]
    path.write_text("\n".join(lines) + "\n")
    return read_record(path)
