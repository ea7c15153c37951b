"""Every command, every kind of hostile input of issue #37 (and more): no traceback,
no exit status other than 0, 2 or 130, no nonsense accepted, no input modified, no
hang.

Each case runs ``inflowsim.cli.main(argv)`` in a forked child of this process (the
imports are warm, a case costs what its command costs), with its own folder, its
own standard output (a file, closed, ``/dev/full`` or a pipe nobody reads) and a
time limit; the parent checks the exit status, the error line, that every file the
case started with is unchanged (content, and kind: a FIFO stays a FIFO), and that a
case meant to be refused was.  The cases are generated from a fixed seed: the same
on every run.

``test_fuzz_sample`` runs a fast sample in the default suite; ``test_fuzz_all`` (slow)
runs ``INFLOWSIM_FUZZ_CASES`` (default 1,200) and writes its counts to
``INFLOWSIM_FUZZ_SUMMARY`` when set.
"""
from __future__ import annotations

import hashlib
import io
import json
import os
import random
import shutil
import signal
import stat
import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

import pytest

CASES = int(os.environ.get("INFLOWSIM_FUZZ_CASES", "1200"))
#: Longest error line accepted (``inflowsim.cli.MAX_LINE`` and the prefix)
MAX_LINE = 1100
TIMEOUT = float(os.environ.get("INFLOWSIM_FUZZ_TIMEOUT", "180"))
WORKERS = int(os.environ.get("INFLOWSIM_FUZZ_WORKERS", "2"))
SEED = 37

GOOD_EFFECT = '''
import numpy as np
from inflowsim.model.effects import Effect, ParameterSpec

def equations(eq, p, k):
    d = np.array(eq.d, dtype=float)
    d[2, 1] -= p["k_fz"]
    return eq.with_(d=d)

EFFECT = Effect(
    name="fuzz-eff", physics="A test coupling of beta1s to beta1c.", paper="test",
    parameters=("k_fz",), theory=lambda k: {"k_fz": 0.0}, equations=equations,
    specs=(ParameterSpec("k_fz", "-", "a test gain", -1.0, 1.0,
                         plausible=(-0.5, 0.5, "a test")),))
'''


@dataclass
class Case:
    """``argv`` run in a fresh copy of the base files, after ``setup`` (name ->
    bytes, or a kind: "fifo", "dir", "sparse:N", "link:TARGET", "hardlink:TARGET",
    "loop"); ``expect`` "refuse" (exit 2), "accept" (exit 0) or "either"."""
    kind: str
    argv: list
    expect: str = "either"
    stdout: str = "file"                 # file, closed, full, broken
    setup: dict = field(default_factory=dict)
    max_line: int | None = None          # longest error line allowed
    forbid: str | None = None            # text the error line must not hold
    heavy: bool = False                  # runs real work (kept out of the sample)


# -- the base files -------------------------------------------------------------------
def make_base(folder: Path) -> Path:
    """The inputs every case starts from: a record, a fit, a schedule, a design, an
    effect, a plan (a folder and a TOML manifest)."""
    from inflowsim.cli import main
    folder.mkdir(parents=True, exist_ok=True)
    quiet = io.StringIO()
    old = sys.stdout, sys.stderr
    sys.stdout = sys.stderr = quiet
    try:
        assert main(["flighttest", "--truth", "linear", "--duration", "12", "--dt", "0.02",
                     "--out", str(folder / "rec.csv")]) == 0
        assert main(["identify", str(folder / "rec.csv"), "-m", "glauert", "--fix", "c2",
                     "--out", str(folder / "P.json")]) == 0
        assert main(["design", "-m", "basic", "--channels", "theta0", "--duration", "9",
                     "--out", str(folder / "design.json")]) == 0
    finally:
        sys.stdout, sys.stderr = old
    sys.path.insert(0, str(Path(__file__).parent))
    from test_schedule import _glauert_schedule
    from inflowsim.model.schedule import write_schedule
    write_schedule(_glauert_schedule()[0], folder / "sched.json")
    (folder / "fx.py").write_text(GOOD_EFFECT)
    plan = folder / "plan"
    plan.mkdir()
    shutil.copy(folder / "rec.csv", plan / "rec.csv")
    (folder / "plan.toml").write_text('[[record]]\npath = "rec.csv"\n')
    shutil.copy(folder / "rec.csv", folder / "rec2.csv")
    text = (folder / "rec.csv").read_text().splitlines()
    h = next(i for i, ln in enumerate(text) if ln.startswith("t,"))
    cols = text[h].split(",")
    j = cols.index("beta1c")
    dead = text[:h + 1] + [",".join(c if k != j else "0.01" for k, c in
                                    enumerate(ln.split(","))) for ln in text[h + 1:]]
    (folder / "dead.csv").write_text("\n".join(dead) + "\n")
    # a control moving from the first sample (a 3 Hz sine on theta1s)
    import math
    k = cols.index("theta1s")
    osc = text[:h + 1]
    for ln in text[h + 1:]:
        c = ln.split(",")
        c[k] = repr(0.01 * math.sin(2 * math.pi * 3 * float(c[0])))
        osc.append(",".join(c))
    (folder / "osc.csv").write_text("\n".join(osc) + "\n")
    return folder


# -- the cases ---------------------------------------------------------------------------
VALID = {   # a quick valid run of each command (argv relative to the case folder)
    "model": ["model", "-m", "glauert"],
    "simulate": ["simulate", "rec.csv", "-m", "glauert", "--out", "sim.csv"],
    "validate": ["validate", "rec.csv", "-m", "glauert"],
    "identify": ["identify", "rec.csv", "-m", "basic"],
    "bandstudy": ["bandstudy", "rec.csv", "-m", "basic", "--upper", "1.5", "--lower", "0.3",
                  "0.5"],
    "diagnose": ["diagnose", "rec.csv", "-m", "basic", "--candidates", "time-delay"],
    "ladder": ["ladder", "rec.csv", "-m", "basic", "--candidates", "azimuth-bias",
               "--max-steps", "1"],
    "campaign": ["campaign", "plan", "--out", "cout", "--workers", "0", "--quiet",
                 "--candidates", "time-delay", "--max-steps", "0"],
    "flighttest": ["flighttest", "--truth", "linear", "--duration", "4", "--start", "1",
                   "--out", "ft.csv", "--json"],
    "fmu": ["fmu", "build", "--out", "m.fmu", "-m", "basic"],
    "frf": ["frf", "rec.csv"],
    "design": ["design", "-m", "basic", "--channels", "theta0", "--duration", "9"],
}

#: (command argv prefix, option) pairs naming outputs
OUTPUT_SLOTS = [
    (["simulate", "rec.csv", "-m", "basic"], "--out"),
    (["simulate", "rec.csv", "-m", "basic"], "-o"),
    (["validate", "rec.csv", "-m", "basic"], "--report"),
    (["identify", "rec.csv", "-m", "basic"], "--out"),
    (["identify", "rec.csv", "-m", "basic"], "--report"),
    (["bandstudy", "rec.csv", "-m", "basic"], "--out"),
    (["diagnose", "rec.csv", "-m", "basic"], "--report"),
    (["ladder", "rec.csv"], "--report"),
    (["campaign", "plan", "--workers", "0"], "--out"),
    (["flighttest", "--truth", "linear", "--duration", "4"], "--out"),
    (["flighttest", "--truth", "linear", "--duration", "4", "--out", "x.csv"],
     "--truth-json"),
    (["flighttest"], "--campaign"),
    (["fmu", "build"], "--out"),
    (["frf", "rec.csv"], "--report"),
    (["design", "-m", "basic"], "--out"),
    (["demo"], "--out"),
]

#: (argv with {} for the input, the base file a valid value would be)
INPUT_SLOTS = [
    (["simulate", "{}", "-m", "basic", "--out", "o.csv"], "rec.csv"),
    (["validate", "{}", "-m", "basic"], "rec.csv"),
    (["identify", "{}", "-m", "basic"], "rec.csv"),
    (["bandstudy", "{}", "-m", "basic"], "rec.csv"),
    (["diagnose", "{}", "-m", "basic"], "rec.csv"),
    (["ladder", "{}"], "rec.csv"),
    (["frf", "{}"], "rec.csv"),
    (["frf", "rec.csv", "{}"], "rec.csv"),
    (["model", "-m", "glauert", "-p", "{}"], "P.json"),
    (["validate", "rec.csv", "-m", "glauert", "-p", "{}"], "P.json"),
    (["design", "-m", "glauert", "-p", "{}"], "P.json"),
    (["identify", "rec.csv", "-m", "glauert", "--start", "{}"], "P.json"),
    (["fmu", "build", "--out", "o.fmu", "--schedule", "{}"], "sched.json"),
    (["fmu", "build", "--out", "o.fmu", "--model", "{}"], "P.json"),
    (["flighttest", "--truth", "linear", "--out", "o.csv", "--design", "{}"],
     "design.json"),
    (["model", "-m", "basic", "--effect-file", "{}"], "fx.py"),
    (["campaign", "{}", "--out", "cout", "--workers", "0"], "plan.toml"),
]

BAD_INPUTS = {     # name -> (setup, how the case names it)
    "fifo": ("fifo", "bad"), "dir": ("dir", "bad"), "missing": (None, "bad"),
    "dev-zero": (None, "/dev/zero"), "dev-null": (None, "/dev/null"),
    "dev-stdin": (None, "/dev/stdin"), "empty-name": (None, ""),
    "dangling": ("link:nowhere", "bad"), "loop": ("loop", "bad"),
    "huge": ("sparse:2147483648", "bad"), "empty": (b"", "bad"),
    "binary": (bytes(range(256)) * 8, "bad"), "latin1": ("caf\xe9 \xff".encode("latin-1"),
                                                          "bad"),
    "long-name": (None, "x" * 5000), "newline-name": (None, "a\nb"),
    "fifo-link": ("link:fifo0", "bad"),
}

DEEP = {"list": "[" * 100000 + "]" * 100000,
        "dict": '{"a":' * 50000 + "1" + "}" * 50000,
        "deep40": '{"structure": ' + "[" * 40 + "]" * 40 + "}",
        "params-deep": '{"structure": "glauert", "parameters": {"tau0": '
                       + "[" * 3000 + "]" * 3000 + "}}"}

TOKENS = ["", "nan", "NaN", "inf", "-inf", "1e400", "1e308", "-1e308", "2e6", "abc",
          "0x10", "1,2", " ", "1e-320", "0", "-0", "-1", "1e-9", "60000", "265", "true",
          "\u00e9", "1e7", "0.5", "3", "-3.5", "1e-5"]


def _nonfinite(v: str) -> bool:
    try:
        x = float(v)
    except ValueError:
        return False
    return x != x or x in (float("inf"), float("-inf"))


def cases_stdout():
    out = []
    for name, argv in VALID.items():
        prints = name != "flighttest" or "--json" in argv
        heavy = name not in ("model",)
        out.append(Case("stdout-closed", argv, "refuse", "closed"))
        out.append(Case("stdout-full", argv, "refuse" if prints else "either", "full",
                        heavy=heavy))
        out.append(Case("stdout-broken", argv, "either", "broken", heavy=heavy))
    for argv in (["--help"], ["--version"], ["model", "--help"], ["design", "--help"]):
        out.append(Case("help-full", argv, "refuse", "full"))
        out.append(Case("help-closed", argv, "refuse", "closed"))
        out.append(Case("help-broken", argv, "either", "broken"))
        out.append(Case("help", argv, "accept"))
    return out


def cases_empty_output():
    return [Case("empty-output", [*argv, opt, ""], "refuse") for argv, opt in OUTPUT_SLOTS]


def cases_output_is_input():
    same = [
        ["identify", "rec.csv", "-m", "basic", "--start", "P.json", "--out", "P.json",
         "--force"],
        ["identify", "rec.csv", "-m", "basic", "--out", "rec.csv", "--force"],
        ["identify", "rec.csv", "rec2.csv", "-m", "basic", "--out", "rec2.csv", "--force"],
        ["simulate", "rec.csv", "-m", "basic", "--out", "rec.csv", "--force"],
        ["simulate", "rec.csv", "-m", "glauert", "-p", "P.json", "--out", "P.json",
         "--force"],
        ["simulate", "rec.csv", "-m", "basic", "--out", "lnk.csv", "--force"],
        ["simulate", "rec.csv", "-m", "basic", "--out", "hard.csv", "--force"],
        ["simulate", "rec.csv", "-m", "basic", "--out", "./sub/../rec.csv", "--force"],
        ["design", "-m", "glauert", "-p", "P.json", "--out", "P.json", "--force"],
        ["fmu", "build", "--model", "P.json", "--out", "P.json", "--force"],
        ["fmu", "build", "--schedule", "sched.json", "--out", "sched.json", "--force"],
        ["flighttest", "--truth", "linear", "--design", "design.json", "--out",
         "design.json", "--force"],
        ["flighttest", "--truth", "linear", "--duration", "4", "--out", "a.csv",
         "--truth-json", "a.csv", "--force"],
        ["frf", "rec.csv", "--report", "rec.csv"],
        ["validate", "rec.csv", "-m", "basic", "--report", "rec.csv"],
        ["model", "-m", "basic", "--effect-file", "fx.py", "-p", "fx.py"],
        ["campaign", "plan.toml", "--out", "plan.toml", "--workers", "0"],
        ["identify", "rec.csv", "-m", "basic", "--out", "o.json", "--report", "o.json"],
    ]
    setup = {"lnk.csv": "link:rec.csv", "hard.csv": "hardlink:rec.csv", "sub": "dir"}
    return [Case("output-is-input", argv, "refuse", setup=setup) for argv in same]


def cases_bad_inputs():
    out = []
    for argv, _ in INPUT_SLOTS:
        for name, (setup, value) in BAD_INPUTS.items():
            files = {}
            if setup is not None:
                files["bad"] = setup
            if name == "fifo-link":
                files["fifo0"] = "fifo"
            a = [value if x == "{}" else x for x in argv]
            out.append(Case(f"input-{name}", a, "refuse", setup=files))
    return out


def cases_deep():
    out = []
    for argv, base in INPUT_SLOTS:
        if not base.endswith((".json", ".toml")):
            continue
        for name, text in DEEP.items():
            if base.endswith(".toml"):
                text = "a = " + "[" * 5000 + "]" * 5000 + "\n"
            out.append(Case(f"deep-{name}", [("deep" + Path(base).suffix) if x == "{}"
                                             else x for x in argv], "refuse",
                            setup={"deep" + Path(base).suffix: text.encode()}))
    return out


def cases_design():
    bad = [["--dt", "0"], ["--dt", "-1"], ["--dt", "1e6"], ["--dt", "1e-9"],
           ["--band", "nan", "2"], ["--band", "0.3", "inf"], ["--band", "0.3", "80"],
           ["--band", "0.3", "1e6"], ["--band", "2", "1"], ["--band", "-1", "1"],
           ["--duration", "1e7"], ["--duration", "0"], ["--duration", "-5"],
           ["--start", "-1"], ["--start", "nan"], ["--limit-deg", "0"],
           ["--limit-deg", "inf"], ["--noise", "0"], ["--noise", "-1"],
           ["--duration", "5000", "--dt", "0.1"]]
    out = [Case("design-nonsense", ["design", "-m", "basic", *b], "refuse",
                forbid="--trim-window") for b in bad]
    return out


def cases_manifest():
    settings = ['band = "wide"', "band = [1]", "band = [nan, 1]", "band = [2, 1]",
                'max_steps = "x"', "max_steps = -1", "max_steps = 1.5", 'alpha = "x"',
                "alpha = 2", "model = 3", 'model = "nonsense"', 'candidates = "time-delay"',
                "candidates = [1]", 'candidates = ["nonsense"]', 'hold = "x"', "hold = 1",
                "band = [true, 2]", "alpha = inf"]
    out = [Case("manifest-setting", ["campaign", "m.toml", "--out", "cout", "--workers", "0"],
                "refuse", setup={"m.toml": f'[[record]]\npath = "rec.csv"\n[settings]\n{s}\n'
                                 .encode()}) for s in settings]
    out.append(Case("campaign-all-failed", ["campaign", "plan", "--out", "cout", "--workers",
                                            "0", "--quiet", "--band", "0.3", "80"],
                    "refuse", heavy=True))
    for text in ("record,condition\n", "nothing\n", "record\n\"unterminated\n",
                 "record\nnone.csv\n", "record\n" + "x" * 200000 + "\n", "\x00\n"):
        out.append(Case("manifest-csv", ["campaign", "m.csv", "--out", "cout", "--workers",
                                         "0"], "refuse", setup={"m.csv": text.encode()}))
    return out


def cases_effects():
    texts = {"e.txt": GOOD_EFFECT, "e": GOOD_EFFECT, "e.py.bak": GOOD_EFFECT,
             "exit0.py": "import sys\nsys.exit(0)\n", "exit3.py": "import sys\nsys.exit(3)\n",
             "exitstr.py": "raise SystemExit('bye')\n", "syntax.py": "def (:\n",
             "none.py": "X = 1\n", "three.py": "EFFECT = 3\n",
             "raises.py": "raise RuntimeError('at import')\n",
             "imports.py": "import no_such_module_xyz\n", "deep.py": "x = " + "(" * 5000
             + ")" * 5000 + "\n", "big.py": "# x\n" * 400000}
    out = []
    for name, text in texts.items():
        for argv in (["model", "-m", "basic"], ["validate", "rec.csv", "-m", "basic"],
                     ["fmu", "build", "--out", "o.fmu"]):
            out.append(Case("effect-file", [*argv, "--effect-file", name], "refuse",
                            setup={name: text.encode()}))
    return out


def _schedule_mutations(base: dict, rng: random.Random):
    """The schedule nonsense of the issue, then random ones."""
    def param(doc, name="tau0"):
        return doc["parameters"][name]
    fixed = [
        lambda d: param(d)["coefficients"].__setitem__(0, "1.0"),
        lambda d: param(d)["coefficients"].__setitem__(0, 1e308),
        lambda d: param(d)["coefficients"].__setitem__(0, -50.0),
        lambda d: d.__setitem__("mu_range", [0.12, 5]),
        lambda d: param(d).__setitem__("center", float("nan")),
        lambda d: param(d).__setitem__("scale", 0),
        lambda d: d.__setitem__("held", {"tau0": {"estimate": 1.0, "sigma": 0.1}}),
        lambda d: d.__setitem__("mu_range", [0.3, 0.12]),
        lambda d: d.__setitem__("structure", "basic"),
        lambda d: param(d).__setitem__("coefficients", []),
        lambda d: param(d, "c1").__setitem__("coefficients", [1e200, 1e200, 1e200]),
    ]
    out = []
    for f in fixed:
        d = json.loads(json.dumps(base))
        f(d)
        out.append((d, "refuse"))
    values = [None, True, "x", 1e308, -1e308, 0, -1, [], {}, [1, 2], "nan", 1e-300]
    for _ in range(40):
        d = json.loads(json.dumps(base))
        node = d
        key = None
        for _ in range(3):
            if not isinstance(node, dict) or not node:
                break
            key = rng.choice(sorted(node))
            if isinstance(node[key], dict) and rng.random() < 0.6:
                node = node[key]
                continue
            break
        if key is None or not isinstance(node, dict):
            continue
        if rng.random() < 0.3:
            node.pop(key, None)
        else:
            node[key] = rng.choice(values)
        out.append((d, "either"))
    return out


def cases_schedule(base_dir: Path, rng):
    base = json.loads((base_dir / "sched.json").read_text())
    out = []
    for doc, expect in _schedule_mutations(base, rng):
        text = json.dumps(doc).encode()            # NaN as NaN: the reader's to refuse
        out.append(Case("schedule", ["fmu", "build", "--schedule", "s.json", "--out",
                                     "o.fmu"], expect, setup={"s.json": text},
                        heavy=expect != "refuse"))
    return out


def cases_flighttest():
    base = ["flighttest", "--truth", "linear", "--duration", "4", "--out", "o.csv"]
    bad = [["--amplitude-deg", "0"], ["--amplitude-deg", "-1"], ["--amplitude-deg", "90"],
           ["--start", "100"], ["--start", "-1"], ["--delay", "-0.1"], ["--delay", "1e9"],
           ["--azimuth-bias", "10"], ["--noise", "-1"], ["--dt", "0"], ["--seed", "-1"],
           ["--seed", "99999999999"], ["--width", "0"], ["--rise", "-1"],
           ["--noise-color-hz", "1e6"], ["--input", "sweep", "--sweep-range", "1", "0.5"],
           ["--input", "multisine", "--fade", "1e9"], ["--duration", "1e9"],
           ["--set", "tau0="], ["--set", "tau0=nan"]]
    out = [Case("flighttest-nonsense", [*base, *b], "refuse") for b in bad]
    nl = ["flighttest", "--duration", "4", "--out", "o.csv"]
    for b in (["--blades", "1000"], ["--blades", "2"], ["--blades", "-4"],
              ["--speed", "mu", "--truth", "linear"]):
        out.append(Case("flighttest-nonsense", [*nl, *b], "refuse"))
    camp = ["flighttest", "--campaign", "fc", "--speeds", "0.1", "--workers", "1"]
    out.append(Case("campaign-other-truth", camp, "refuse",
                    setup={"fc": "dir", "fc/mu0.100_theta0_doublet_r0.csv": "copy:rec.csv"}))
    for b in (["--repeats", "0"], ["--speeds", "5"], ["--speeds", "nan"],
              ["--workers", "0"], ["--out", "x.csv"]):
        out.append(Case("flighttest-campaign-nonsense", [*camp, *b], "refuse"))
    return out


def cases_small():
    return [
        Case("fix-empty-value", ["identify", "rec.csv", "-m", "basic", "--fix", "tau0="],
             "refuse"),
        Case("fix-nan", ["identify", "rec.csv", "-m", "basic", "--fix", "tau0=nan"],
             "refuse"),
        Case("moves-from-start", ["validate", "osc.csv", "-m", "basic"], "refuse",
             forbid="constant"),
        Case("also-unknown", ["diagnose", "rec.csv", "-m", "basic", "--also", "nonsense"],
             "refuse", max_line=200),
        Case("candidates-unknown", ["ladder", "rec.csv", "--candidates", "nonsense"],
             "refuse", max_line=200),
        Case("model-unknown-effect", ["model", "-m", "basic+nonsense"], "refuse",
             max_line=200),
        Case("no-command", [], "refuse", max_line=120),
        Case("frf-dead-output", ["frf", "dead.csv"], "refuse"),
        Case("unknown-command", ["nonsense"], "refuse"),
        Case("fmu-no-action", ["fmu"], "refuse"),
        Case("long-model", ["model", "-m", "glauert+" + "x" * 100000], "refuse"),
        Case("empty-model", ["model", "-m", ""], "refuse"),
        Case("interrupt-free", ["model", "-m", "basic", "--mu", "nan"], "refuse"),
        Case("mu-range", ["model", "-m", "basic", "--mu", "5"], "refuse"),
        Case("demo-seed", ["demo", "--seed", "-1", "--out", "d"], "refuse"),
        Case("frf-overlap", ["frf", "rec.csv", "--overlap", "1"], "refuse"),
        Case("frf-windows", ["frf", "rec.csv", "--windows", "0"], "refuse"),
        Case("frf-channel", ["frf", "rec.csv", "--outputs", "nonsense"], "refuse"),
        Case("bandstudy-lower", ["bandstudy", "rec.csv", "-m", "basic", "--lower", "-1"],
             "refuse"),
        Case("trim-window", ["validate", "rec.csv", "-m", "basic", "--trim-window", "5",
                             "1"], "refuse"),
        Case("out-missing-folder", ["simulate", "rec.csv", "-m", "basic", "--out",
                                    "no/such/o.csv"], "refuse"),
        Case("out-is-folder", ["simulate", "rec.csv", "-m", "basic", "--out", "plan"],
             "refuse"),
        Case("out-fifo", ["simulate", "rec.csv", "-m", "basic", "--out", "f", "--force"],
             "refuse", setup={"f": "fifo"}),
        Case("out-dev", ["simulate", "rec.csv", "-m", "basic", "--out", "/dev/full",
                         "--force"], "refuse"),
    ]


def _mutate_record(text: str, rng: random.Random) -> str:
    lines = text.splitlines()
    for _ in range(rng.randint(1, 3)):
        h = next((i for i, ln in enumerate(lines) if ln.startswith("t,")), None)
        if h is None or len(lines) <= h + 2:
            break
        how = rng.choice(["cell", "meta", "drop", "dup", "swap", "column", "truncate",
                          "header", "nudge"])
        if how == "cell":
            r = rng.randint(h + 1, len(lines) - 1)
            c = lines[r].split(",")
            c[rng.randrange(len(c))] = rng.choice(TOKENS)
            lines[r] = ",".join(c)
        elif how == "meta" and h > 0:
            i = rng.randrange(h)
            lines[i] = lines[i].split(":")[0] + ": " + rng.choice(TOKENS)
        elif how == "drop":
            del lines[rng.randrange(len(lines))]
        elif how == "dup":
            i = rng.randrange(len(lines))
            lines.insert(i, lines[i])
        elif how == "swap":
            i = rng.randint(h + 1, len(lines) - 2)
            lines[i], lines[i + 1] = lines[i + 1], lines[i]
        elif how == "column":
            j = rng.randrange(len(lines[h].split(",")))
            lines[h:] = [",".join(c for k, c in enumerate(ln.split(",")) if k != j)
                         for ln in lines[h:]]
        elif how == "truncate":
            t = "\n".join(lines)
            lines = t[:rng.randrange(len(t))].splitlines()
        elif how == "header":
            c = lines[h].split(",")
            c[rng.randrange(len(c))] = rng.choice(["", "t", "beta0", "x y", "theta0"])
            lines[h] = ",".join(c)
        elif how == "nudge":
            r = rng.randint(h + 1, len(lines) - 1)
            c = lines[r].split(",")
            k = rng.randrange(1, len(c))
            try:
                c[k] = repr(float(c[k]) + rng.uniform(-1e-3, 1e-3))
            except ValueError:
                pass
            lines[r] = ",".join(c)
    return "\n".join(lines) + "\n"


def _mutate_json(doc, rng: random.Random):
    doc = json.loads(json.dumps(doc))
    values = [None, True, "x", 1e308, -1.0, 0, [], {}, [1], "nan", 1e-300, 10 ** 30]
    for _ in range(rng.randint(1, 3)):
        node, key = doc, None
        while isinstance(node, dict) and node:
            key = rng.choice(sorted(node))
            if isinstance(node[key], dict) and node[key] and rng.random() < 0.5:
                node = node[key]
                continue
            break
        if key is None or not isinstance(node, dict):
            break
        how = rng.random()
        if how < 0.3 and isinstance(node[key], (int, float)) and \
                not isinstance(node[key], bool):
            node[key] = node[key] * rng.uniform(0.5, 1.5)
        elif how < 0.5:
            node.pop(key)
        else:
            node[key] = rng.choice(values)
    return doc


RECORD_COMMANDS = {
    "validate": lambda f: ["validate", f, "-m", "glauert", "--json"],
    "identify": lambda f: ["identify", f, "-m", "basic", "--json"],
    "simulate": lambda f: ["simulate", f, "-m", "glauert", "--out", "s.csv"],
    "frf": lambda f: ["frf", f, "--json"],
    "diagnose": lambda f: ["diagnose", f, "-m", "basic", "--candidates", "time-delay"],
    "bandstudy": lambda f: ["bandstudy", f, "-m", "basic", "--upper", "1.5", "--lower",
                            "0.4"],
}

PARAM_COMMANDS = {
    "model": lambda f: ["model", "-m", "glauert", "-p", f, "--json"],
    "validate": lambda f: ["validate", "rec.csv", "-m", "glauert", "-p", f],
    "simulate": lambda f: ["simulate", "rec.csv", "-m", "glauert", "-p", f, "--out",
                           "s.csv"],
    "design": lambda f: ["design", "-m", "glauert", "-p", f, "--channels", "theta0",
                         "--duration", "9"],
    "identify": lambda f: ["identify", "rec.csv", "-m", "glauert", "--start", f, "--fix",
                           "c2"],
    "fmu": lambda f: ["fmu", "build", "--model", f, "--out", "o.fmu"],
}

#: number options of each command (for random values); quick argv prefixes
OPTIONS = {
    "model": (["model", "-m", "glauert"], ["--mu"]),
    "validate": (["validate", "rec.csv", "-m", "basic"], ["--band", "--trim-window"]),
    "identify": (["identify", "rec.csv", "-m", "basic"], ["--band", "--trim-window"]),
    "frf": (["frf", "rec.csv"], ["--band", "--windows", "--overlap", "--trim-window"]),
    "design": (["design", "-m", "basic", "--channels", "theta0", "--duration", "9"],
               ["--dt", "--band", "--start", "--limit-deg", "--noise", "--duration"]),
    "flighttest": (["flighttest", "--truth", "linear", "--duration", "4", "--out", "o.csv"],
                   ["--dt", "--duration", "--start", "--amplitude-deg", "--width", "--rise",
                    "--noise", "--seed", "--delay", "--azimuth-bias", "--noise-color-hz"]),
    "simulate": (["simulate", "rec.csv", "-m", "basic", "--out", "o.csv"], ["--dt"]),
    "diagnose": (["diagnose", "rec.csv", "-m", "basic", "--candidates", "time-delay"],
                 ["--alpha", "--band"]),
    "bandstudy": (["bandstudy", "rec.csv", "-m", "basic"], ["--upper", "--lower"]),
    "campaign": (["campaign", "plan", "--out", "cout", "--workers", "0", "--quiet",
                  "--candidates", "time-delay", "--max-steps", "0"],
                 ["--alpha", "--band", "--max-steps", "--schedule-order", "--workers"]),
    "demo": (["demo", "--out", "d"], ["--seed"]),
}
PAIRS = {"--band", "--trim-window"}


def cases_random(base_dir: Path, rng: random.Random, n: int):
    rec = (base_dir / "rec.csv").read_text()
    params = json.loads((base_dir / "P.json").read_text())
    out = []
    while len(out) < n:
        what = rng.random()
        if what < 0.35:
            name = rng.choice(sorted(RECORD_COMMANDS))
            out.append(Case(f"record-{name}", RECORD_COMMANDS[name]("m.csv"), "either",
                            setup={"m.csv": _mutate_record(rec, rng).encode()}, heavy=True))
        elif what < 0.6:
            name = rng.choice(sorted(PARAM_COMMANDS))
            doc = _mutate_json(params, rng)
            out.append(Case(f"params-{name}", PARAM_COMMANDS[name]("m.json"), "either",
                            setup={"m.json": json.dumps(doc).encode()}, heavy=True))
        else:
            name = rng.choice(sorted(OPTIONS))
            argv, opts = OPTIONS[name]
            opt = rng.choice(opts)
            vals = [rng.choice(TOKENS) for _ in range(2 if opt in PAIRS else 1)]
            expect = "refuse" if any(_nonfinite(v) or v.strip() in ("", "abc", "true",
                                                                     "1,2", "\u00e9")
                                     for v in vals) else "either"
            if name == "demo" and expect == "either":
                continue                  # a valid seed runs the whole demo
            if name == "campaign" and opt == "--workers" and expect == "either":
                continue                  # a cluster per case: too slow here
            out.append(Case(f"option-{name}", [*argv, opt, *vals], expect, heavy=True))
    return out


#: Kinds left out (comma-separated), e.g. ``input-dev-zero`` when fuzzing an old
#: version that would read /dev/zero until memory runs out.
SKIP = tuple(k for k in os.environ.get("INFLOWSIM_FUZZ_SKIP", "").split(",") if k)


def generate(base_dir: Path, n: int) -> list:
    rng = random.Random(SEED)
    fixed = (cases_stdout() + cases_empty_output() + cases_output_is_input()
             + cases_bad_inputs() + cases_deep() + cases_design() + cases_manifest()
             + cases_effects() + cases_schedule(base_dir, rng) + cases_flighttest()
             + cases_small())
    out = fixed + cases_random(base_dir, rng, max(0, n - len(fixed)))
    return [c for c in out if c.kind not in SKIP]


# -- running a case ---------------------------------------------------------------------
def _prepare(case: Case, base: Path, folder: Path) -> dict:
    """The case's folder: the base files, then its setup; returns the snapshot of
    every file in it (path -> (kind, sha256))."""
    shutil.copytree(base, folder, symlinks=True)
    for name, what in case.setup.items():
        p = folder / name
        if p.is_symlink() or p.is_file():
            p.unlink()
        elif p.is_dir():
            shutil.rmtree(p)
        if isinstance(what, bytes):
            p.write_bytes(what)
        elif what == "fifo":
            os.mkfifo(p)
        elif what == "dir":
            p.mkdir()
        elif what == "loop":
            os.symlink(p.name, p)
        elif what.startswith("sparse:"):
            with open(p, "wb") as f:
                f.truncate(int(what.split(":")[1]))
        elif what.startswith("link:"):
            os.symlink(what.split(":", 1)[1], p)
        elif what.startswith("hardlink:"):
            os.link(folder / what.split(":", 1)[1], p)
        elif what.startswith("copy:"):
            shutil.copy(folder / what.split(":", 1)[1], p)
    return snapshot(folder)


def snapshot(folder: Path) -> dict:
    out = {}
    for root, dirs, files in os.walk(folder):
        for n in dirs + files:
            p = Path(root) / n
            st = os.lstat(p)
            if stat.S_ISREG(st.st_mode):
                if st.st_size > 64 << 20:            # the sparse file: size and mtime
                    out[str(p)] = ("big", st.st_size, st.st_mtime_ns)
                else:
                    out[str(p)] = ("file", hashlib.sha256(p.read_bytes()).hexdigest())
            elif stat.S_ISLNK(st.st_mode):
                out[str(p)] = ("link", os.readlink(p))
            elif stat.S_ISFIFO(st.st_mode):
                out[str(p)] = ("fifo",)
            elif stat.S_ISDIR(st.st_mode):
                out[str(p)] = ("dir",)
    return out


def _child(case: Case, folder: Path, out_path: Path, err_path: Path):
    """In the forked child: standard streams as the case says, run main, exit with
    its status as the console script would."""
    from inflowsim.cli import main
    code = 1
    try:
        os.chdir(folder)
        fd_in = os.open(os.devnull, os.O_RDONLY)
        os.dup2(fd_in, 0)
        fd_err = os.open(err_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
        os.dup2(fd_err, 2)
        if case.stdout == "file":
            fd = os.open(out_path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
            os.dup2(fd, 1)
        elif case.stdout == "full":
            fd = os.open("/dev/full", os.O_WRONLY)
            os.dup2(fd, 1)
        elif case.stdout == "broken":
            r, w = os.pipe()
            os.close(r)
            os.dup2(w, 1)
        elif case.stdout == "closed":
            os.close(1)
        sys.stdin = None
        sys.stderr = io.TextIOWrapper(io.FileIO(2, "w", closefd=False), encoding="utf-8",
                                      errors="backslashreplace", line_buffering=True)
        sys.stdout = None if case.stdout == "closed" else io.TextIOWrapper(
            io.FileIO(1, "w", closefd=False), encoding="utf-8")
        signal.signal(signal.SIGPIPE, signal.SIG_IGN)        # as Python sets it
        signal.signal(signal.SIGINT, signal.default_int_handler)
        try:
            code = main(list(case.argv))
        except SystemExit as exc:        # escaping main: what the console script does
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None
                                                               else 1)
            if not isinstance(exc.code, (int, type(None))):
                sys.stderr.write(f"{exc.code}\n")
        except BaseException:
            traceback.print_exc()
            code = 1
        # the interpreter's last flush
        for s in (sys.stdout, sys.stderr):
            try:
                if s is not None:
                    s.flush()
            except BaseException:
                try:
                    os.write(2, b"Exception ignored on flushing at exit\n")
                except OSError:
                    pass
                code = 120
    except BaseException:
        try:
            os.write(2, traceback.format_exc().encode())
        except OSError:
            pass
        code = 1
    finally:
        os._exit(code if isinstance(code, int) and 0 <= code < 256 else 1)


@dataclass
class Outcome:
    case: Case
    code: int | None              # None: killed after the time limit
    err: str
    seconds: float
    problems: list


def run_cases(cases, base: Path, work: Path, timeout=TIMEOUT, workers=WORKERS):
    """Every case in a forked child, ``workers`` at a time; their outcomes."""
    todo = list(enumerate(cases))
    running = {}
    outcomes = [None] * len(cases)
    while todo or running:
        while todo and len(running) < workers:
            i, case = todo.pop(0)
            folder = work / f"c{i:05d}"
            before = _prepare(case, base, folder)
            out_path, err_path = work / f"c{i:05d}.out", work / f"c{i:05d}.err"
            sys.stdout.flush()
            sys.stderr.flush()
            pid = os.fork()
            if pid == 0:
                _child(case, folder, out_path, err_path)
            running[pid] = (i, case, folder, before, err_path, time.monotonic())
        time.sleep(0.01)
        for pid, (i, case, folder, before, err_path, t0) in list(running.items()):
            done, status = os.waitpid(pid, os.WNOHANG)
            elapsed = time.monotonic() - t0
            if not done and elapsed < timeout:
                continue
            if not done:
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
                code = None
            else:
                code = os.waitstatus_to_exitcode(status)
            del running[pid]
            err = err_path.read_text(errors="replace") if err_path.exists() else ""
            outcomes[i] = Outcome(case, code, err, elapsed,
                                  judge(case, code, err, before, snapshot(folder)))
            shutil.rmtree(folder, ignore_errors=True)
    return outcomes


def judge(case: Case, code, err: str, before: dict, after: dict) -> list:
    """What is wrong with an outcome (empty: nothing)."""
    bad = []
    if code is None:
        return [f"hang (killed after {TIMEOUT:g} s)"]
    if "Traceback" in err or "Exception ignored" in err:
        bad.append("traceback")
    if code not in (0, 2, 130):
        bad.append(f"exit {code}")
    if case.expect == "refuse" and code == 0:
        bad.append("nonsense accepted")
    if case.expect == "accept" and code != 0:
        bad.append(f"refused a valid run (exit {code})")
    lines = [ln for ln in err.splitlines() if ln.strip()]
    if code == 2:
        errors = [ln for ln in lines if ": error: " in ln]
        if len(errors) != 1 or not lines or ": error: " not in lines[-1] or \
                not lines[-1].startswith("inflowsim"):
            bad.append("not one error line")
        elif len(errors[0]) > (case.max_line or MAX_LINE):
            bad.append(f"error line of {len(errors[0])} characters")
        elif case.forbid and case.forbid in errors[0]:
            bad.append(f"error line says {case.forbid!r}")
    changed = [p for p, v in before.items() if after.get(p) != v]
    if changed:
        bad.append(f"inputs modified: {', '.join(Path(p).name for p in changed[:3])}")
    return bad


def summary(outcomes) -> dict:
    kinds = {}
    for o in outcomes:
        kinds.setdefault(o.case.kind.split("-")[0], 0)
        kinds[o.case.kind.split("-")[0]] += 1
    problems = [o for o in outcomes if o.problems]
    return {
        "cases": len(outcomes),
        "exit": {str(c): sum(1 for o in outcomes if o.code == c)
                 for c in sorted({o.code for o in outcomes if o.code is not None})},
        "tracebacks": sum("traceback" in o.problems for o in outcomes),
        "other_exits": sum(any(p.startswith("exit") for p in o.problems) for o in outcomes),
        "nonsense_accepted": sum("nonsense accepted" in o.problems for o in outcomes),
        "inputs_modified": sum(any(p.startswith("inputs modified") for p in o.problems)
                               for o in outcomes),
        "hangs": sum(o.code is None for o in outcomes),
        "refused_valid": sum(any(p.startswith("refused a valid") for p in o.problems)
                             for o in outcomes),
        "bad_error_lines": sum(any(p.startswith(("not one error", "error line"))
                                   for p in o.problems) for o in outcomes),
        "expected_refusals": sum(o.case.expect == "refuse" for o in outcomes),
        "longest_s": round(max((o.seconds for o in outcomes), default=0.0), 1),
        "by_kind": kinds,
        "problems": [{"kind": o.case.kind, "argv": [a[:80] for a in o.case.argv],
                      "stdout": o.case.stdout, "code": o.code, "problems": o.problems,
                      "err": o.err[-400:]} for o in problems[:40]],
    }


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    import inflowsim.identify, inflowsim.diagnose.search, inflowsim.report.ladder  # noqa
    import inflowsim.campaign.engine, inflowsim.flighttest.design  # noqa: warm imports
    return make_base(tmp_path_factory.mktemp("fuzzbase") / "base")


def _check(outcomes):
    s = summary(outcomes)
    report = os.environ.get("INFLOWSIM_FUZZ_SUMMARY")
    if report:
        Path(report).write_text(json.dumps(s, indent=1))
    assert not s["problems"], json.dumps(s["problems"], indent=1)
    return s


def test_fuzz_sample(base, tmp_path):
    """A fast sample of the kinds (refusals and the stdout cases of ``model``): under
    20 s."""
    cases = [c for c in generate(base, 0) if not c.heavy]
    rng = random.Random(SEED)
    picked = {}
    for c in cases:                       # one of each kind first, then random ones
        picked.setdefault(c.kind, c)
    sample = list(picked.values())
    rng.shuffle(sample)
    sample = sample[:30]
    s = _check(run_cases(sample, base, tmp_path, timeout=60))
    assert s["cases"] == len(sample) and s["expected_refusals"] > 10


@pytest.mark.slow
def test_fuzz_all(base, tmp_path):
    """``INFLOWSIM_FUZZ_CASES`` cases (default 1,200) over every command and kind."""
    cases = generate(base, CASES)
    assert len(cases) >= 1000 or CASES < 1000
    s = _check(run_cases(cases, base, tmp_path))
    print(json.dumps({k: v for k, v in s.items() if k != "problems"}))


def _real(argv, stdout, preexec=None):
    """``python -m inflowsim.cli argv`` as a real process (the interpreter's own
    start and exit: how it sets up a closed descriptor, its last flush)."""
    import subprocess
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    p = subprocess.Popen([sys.executable, "-m", "inflowsim.cli", *argv], stdout=stdout,
                         stderr=subprocess.PIPE, stdin=subprocess.DEVNULL, env=env,
                         preexec_fn=preexec)
    if stdout == subprocess.PIPE:
        p.stdout.close()                 # the reader is gone before the first write
    err = p.stderr.read().decode()
    return p.wait(timeout=60), err


@pytest.mark.parametrize("how", ["closed", "help-full", "broken"])
def test_real_standard_output(how):
    """What the forked cases emulate, in real processes: ``>&-``, ``> /dev/full``
    (``--help`` and ``--version`` too) and a pipe whose reader left."""
    import subprocess
    argv = {"help-full": ["--help"], "closed": ["--version"]}.get(how,
                                                                  ["model", "-m", "basic"])
    if how == "closed":
        code, err = _real(argv, None, preexec=lambda: os.close(1))
    elif how == "broken":
        code, err = _real(argv, subprocess.PIPE)
    else:
        with open("/dev/full", "w") as full:
            code, err = _real(argv, full)
    lines = err.strip().splitlines()
    assert "Traceback" not in err and "Exception ignored" not in err, err
    if how == "broken":
        assert code == 0 and err == "", err
    else:
        assert code == 2 and len(lines) == 1 and lines[0].startswith("inflowsim"), err
