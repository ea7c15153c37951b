"""Do two trees of inflowsim fit the same?  A check for speed work, not a test.

Run the same cases under each tree and compare::

    PYTHONPATH=/tmp/old python bench/check_same_fits.py save /tmp/old.pkl
    PYTHONPATH=$PWD     python bench/check_same_fits.py save /tmp/new.pkl
    python bench/check_same_fits.py compare /tmp/old.pkl /tmp/new.pkl [--rtol 1e-9]

``save`` runs ``identify`` on a few records and structures (continuous and held
records, first- and second-order flapping, output and input delays, a hub-velocity
coupling, ties, two records at once), ``evaluate`` at fixed parameters and, unless
``--quick``, ``diagnose`` of the hidden-glauert record from ``basic`` and from
``glauert`` (``--ladder``: also ``basic`` on the 256 Hz coloured-noise record and
the ladder from ``basic``), and stores every
number and text of the results.  ``compare`` reports, case by case, the largest
relative difference of any number, ``|a - b| / max(|a|, |b|, atol)`` (``atol``
1e-12 by default: numbers at rounding level of zero), and any text, key, iteration
count or shape that differs; the exit status is 1 if anything exceeds ``--rtol``.
"""
from __future__ import annotations

import argparse
import math
import os
import pickle
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def _plain(x):
    """Numbers, texts, lists and dicts only (pickles across trees)."""
    if isinstance(x, dict) or hasattr(x, "items") and hasattr(x, "keys"):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        if x.dtype == object:
            return [_plain(v) for v in x.tolist()]
        return np.array(x)
    if isinstance(x, (np.floating, np.integer, np.bool_, np.complexfloating)):
        return x.item()
    if x is None or isinstance(x, (bool, int, float, complex, str)):
        return x
    return repr(x)


def _fit(res):
    return _plain({"parameters": dict(res.parameters), "sigma": dict(res.sigma),
                   "sigma_colored": dict(res.sigma_colored), "cost": res.cost,
                   "iterations": res.iterations, "converged": res.converged,
                   "starts": list(res.starts), "warnings": list(res.warnings),
                   "S": list(res.S), "correlation": res.correlation, "fit": res.fit,
                   "Y": [d.Y for d in res.data], "nu": [d.nu for d in res.data],
                   "model_a": res.model.a, "model_b": res.model.b})


def cases(quick=False, with_ladder=False):
    from bench_diagnose import TWO_AXES, hidden_glauert
    from inflowsim.flighttest.virtual import Manoeuvre, VirtualTest, virtual_record
    from inflowsim.identify import identify
    from inflowsim.identify.estimator import evaluate
    from inflowsim.model.presets import theory_parameters

    rec = hidden_glauert()
    held = virtual_record(VirtualTest(structure="glauert+time-delay", seed=2, hold="zoh",
                                      manoeuvres=TWO_AXES, dt=0.02))
    hub = virtual_record(VirtualTest(structure="basic+hub-velocity-coupling", seed=3,
                                     manoeuvres=TWO_AXES))
    single = virtual_record(VirtualTest(structure="glauert", seed=4,
                                        manoeuvres=(Manoeuvre(channel="theta1c"),)))
    fits = [("basic, hidden glauert", lambda: identify(rec, "basic")),
            ("glauert, hidden glauert", lambda: identify(rec, "glauert")),
            ("glauert+time-delay, hidden glauert",
             lambda: identify(rec, "glauert+time-delay")),
            ("basic+flap-inertia, hidden glauert",
             lambda: identify(rec, "basic+flap-inertia")),
            ("glauert+time-delay, zoh record", lambda: identify(held, "glauert+time-delay")),
            ("basic+hub-velocity-coupling, hub record",
             lambda: identify(hub, "basic+hub-velocity-coupling")),
            ("basic+hub-velocity-coupling+azimuth-bias+time-delay, hub record",
             lambda: identify(hub, "basic+hub-velocity-coupling+azimuth-bias+time-delay")),
            ("glauert tied tau0=tau_cs, fixed c4, start given, single-axis record",
             lambda: identify(single, "glauert", ties=[("tau0", "tau_cs")],
                              fixed={"c4": None}, start={"tau0": 3.0})),
            ("glauert, two records", lambda: identify([rec, single], "glauert")),
            ("basic+skewed-wake+advance-ratio-perturbation+second-harmonic-flap",
             lambda: identify(rec, "basic+skewed-wake+advance-ratio-perturbation"
                                   "+second-harmonic-flap"))]
    out = {}
    for name, f in fits:
        t = time.process_time()
        out["identify: " + name] = _fit(f())
        print(f"{name}: {time.process_time() - t:.2f} s", file=sys.stderr)
    th = theory_parameters("glauert+time-delay", rec.constants)
    ev = evaluate(rec, "glauert+time-delay", {**th, "delay": 0.03})
    out["evaluate glauert+time-delay at theory"] = _plain(
        {"cost": ev.cost, "residuals": list(ev.residuals), "S": list(ev.S), "nu": list(ev.nu)})
    if not quick:
        from inflowsim.diagnose import diagnose, ladder
        for base in ("basic", "glauert"):
            t = time.process_time()
            out[f"diagnose {base}, hidden glauert"] = _plain(diagnose(rec, base).to_json())
            print(f"diagnose {base}: {time.process_time() - t:.2f} s", file=sys.stderr)
        if with_ladder:
            coloured = hidden_glauert(256.0, colour=2.0)
            out["diagnose basic, 256 Hz, coloured noise"] = _plain(
                diagnose(coloured, "basic").to_json())
            out["ladder basic, hidden glauert"] = _plain(ladder(rec, "basic").to_json())
    return out


def _diff(a, b, path, atol, report):
    """Largest relative difference under ``path``; structural differences reported."""
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            report.append(f"{path}: keys differ {sorted(set(a) ^ set(b))}")
        return max([_diff(a[k], b[k], f"{path}.{k}", atol, report) for k in a if k in b],
                   default=0.0)
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            report.append(f"{path}: lengths {len(a)} and {len(b)}")
            return math.inf
        return max([_diff(x, y, f"{path}[{i}]", atol, report)
                    for i, (x, y) in enumerate(zip(a, b))], default=0.0)
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.asarray(a), np.asarray(b)
        if a.shape != b.shape:
            report.append(f"{path}: shapes {a.shape} and {b.shape}")
            return math.inf
        if a.size == 0:
            return 0.0
        same_nan = np.isnan(a) & np.isnan(b) if a.dtype.kind in "fc" else False
        den = np.maximum(np.maximum(np.abs(a), np.abs(b)), atol)
        with np.errstate(invalid="ignore"):
            r = np.where(same_nan, 0.0, np.abs(a - b) / den)
        return float(np.nanmax(np.where(np.isnan(r), np.inf, r)))
    if isinstance(a, bool) or isinstance(b, bool) or isinstance(a, str) or a is None:
        if a != b:
            report.append(f"{path}: {a!r} != {b!r}")
            return math.inf
        return 0.0
    if isinstance(a, (int, float, complex)) and isinstance(b, (int, float, complex)):
        if isinstance(a, int) and isinstance(b, int):
            if a != b:
                report.append(f"{path}: {a} != {b}")
                return math.inf
            return 0.0
        if (isinstance(a, float) and isinstance(b, float) and math.isnan(a)
                and math.isnan(b)):
            return 0.0
        return abs(a - b) / max(abs(a), abs(b), atol)
    if a != b:
        report.append(f"{path}: {a!r} != {b!r}")
        return math.inf
    return 0.0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    s = sub.add_parser("save")
    s.add_argument("out")
    s.add_argument("--quick", action="store_true", help="no diagnose")
    s.add_argument("--ladder", action="store_true",
                   help="also a 256 Hz coloured-noise diagnose and the ladder from basic")
    c = sub.add_parser("compare")
    c.add_argument("old")
    c.add_argument("new")
    c.add_argument("--rtol", type=float, default=1e-9)
    c.add_argument("--atol", type=float, default=1e-12)
    args = ap.parse_args(argv)
    if args.cmd == "save":
        import inflowsim
        print(f"inflowsim from {inflowsim.__file__}", file=sys.stderr)
        with open(args.out, "wb") as fh:
            pickle.dump(cases(args.quick, args.ladder), fh)
        return 0
    with open(args.old, "rb") as fh:
        old = pickle.load(fh)
    with open(args.new, "rb") as fh:
        new = pickle.load(fh)
    worst, bad = 0.0, False
    for name in old:
        if name not in new:
            print(f"{name}: missing in {args.new}")
            continue
        report = []
        d = _diff(old[name], new[name], "", args.atol, report)
        worst = max(worst, d)
        flag = "OK " if d <= args.rtol and not report else "BAD"
        bad |= flag == "BAD"
        print(f"{flag} {d:9.2e}  {name}")
        for line in report[:10]:
            print(f"      {line}")
    print(f"largest relative difference {worst:.2e} (rtol {args.rtol:g}, "
          f"atol {args.atol:g})")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
