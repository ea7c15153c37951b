"""FMU step cost: the C driver on the native binary, and the cost through fmpy.

    python bench/fmu_bench.py [--steps N] [--model STRUCTURE] [--peers C1,C2] [--rounds R]
    python bench/fmu_bench.py --schedule schedule.json [--steps N] [--rounds R]

Builds the FMU (``inflowsim.fmu.build_fmu``), the same library without the AVX2
clone of ``fmi2DoStep`` (``-DIFS_NO_CLONES``: the baseline x86-64 code every CPU
runs) and the one-state reference (``bench/fmu_onestate.c``) with the same flags,
compiles ``bench/fmu_driver.c``, runs it (best of 5 runs of N steps per case) on
both libraries (and on the FMI 3.0 library, built as ``inflowsim fmu build
--fmi-version 3`` builds it) and times an fmpy ``FMU2Slave`` loop (setReal inputs, doStep,
getReal outputs).  ``--model`` benchmarks an FMU generated for that structure
(``inflowsim fmu build --model``; e.g. ``glauert+flap-inertia``, nine states)
instead of the presets' FMU; its baseline library is compiled from the FMU's own
``sources/`` and the FMI 3.0 rows are left out.  ``bench/fp_rate.c`` measures the
machine's rate of 4-wide multiplies: the step's arithmetic floor is its products in
whole vectors of four at that rate.  Prints a Markdown table; results and method are
kept in ``bench/fmu.md``.

``--schedule FILE`` times only the scheduled FMU (``inflowsim fmu build --schedule``)
against the unscheduled FMU of the same structure: the driver's cases on both
libraries, alternately, ``--rounds`` times each (best per case), and the ratio.
"""
from __future__ import annotations

import argparse
import platform
import subprocess
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=2_000_000)
    ap.add_argument("--fmpy-steps", type=int, default=20_000)
    ap.add_argument("--model", default=None, help="a structure (default: the presets' FMU)")
    ap.add_argument("--peers", default=None,
                    help="commits whose FMU is timed beside (comma-separated; default "
                         "4ddf183,c2cf520 for the presets' FMU, none with --model)")
    ap.add_argument("--rounds", type=int, default=41)
    ap.add_argument("--driver-rounds", type=int, default=3,
                    help="ABBA rounds of the driver (and the fmpy loop)")
    ap.add_argument("--frame-steps", type=int, default=30_000)
    ap.add_argument("--schedule", default=None, metavar="FILE",
                    help="time the FMU of this schedule against the unscheduled one")
    args = ap.parse_args(argv)
    if args.peers is None:
        args.peers = "4ddf183,c2cf520" if args.model is None else ""
    if args.schedule:
        return schedule_main(args)
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    from inflowsim.fmu import VR, build_fmu
    from inflowsim.fmu.build import CFLAGS, compile_library, compiler, source_dir

    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        fmu = build_fmu(tmp / "inflowsim.fmu", model=args.model)
        guid = read_model_description(str(fmu)).guid
        unz = extract(str(fmu), str(tmp / "x"))
        src = source_dir() if args.model is None else Path(unz) / "sources"
        so = Path(unz) / "binaries" / "linux64" / "inflowsim.so"
        cc = compiler()
        inc = f"-I{source_dir()}"
        compile_drivers(cc, inc, tmp)
        baseline = compile_library(src, tmp / "baseline.so", ("-DIFS_NO_CLONES",))
        fmi3 = (compile_library(src, tmp / "fmi3.so", fmi_version=3) if args.model is None
                else None)
        # every driver case of both libraries in every round, the libraries in ABBA
        # order (this, baseline, baseline, this) so a change of the machine's load
        # falls on both; the fmpy loop in the same rounds.  Best per case over the
        # rounds (the one-state reference runs in every driver run: its best and
        # glauert's come from the same runs).
        best, ratios = {}, []
        fmpy_best = float("inf")
        s = FMU2Slave(guid=guid, unzipDirectory=unz, modelIdentifier="inflowsim",
                      instanceName="bench")
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
        ins = [VR[n] for n in ("theta0", "theta1c", "theta1s", "muz", "q", "p", "qdot",
                               "pdot", "mux", "muy")]
        outs = [VR[n] for n in ("beta0", "beta1c", "beta1s", "lambda0", "lambda1c",
                                "lambda1s")]
        u = [1e-3] * 10
        k0 = 0
        libs = ((so, "", [str(fmi3)] if fmi3 else []), (baseline, "baseline_", []))
        for _ in range(args.driver_rounds):
            for lib, tag, extra in (libs[0], libs[1], libs[1], libs[0]):
                out = subprocess.run([str(tmp / "driver"), str(lib), guid,
                                      str(tmp / "onestate.so"), str(args.steps), *extra],
                                     check=True, capture_output=True, text=True)
                run = dict(line.split() for line in out.stdout.splitlines())
                for name, value in run.items():
                    if tag and name.startswith("onestate"):
                        continue
                    best[tag + name] = min(best.get(tag + name, float("inf")), float(value))
                ratios.append((tag, float(run["glauert_dostep"]) / float(run["onestate_dostep"])))
            t0 = time.perf_counter()
            for k in range(k0, k0 + args.fmpy_steps):
                s.setReal(ins, u)
                s.doStep(k * 0.01, 0.01)
                s.getReal(outs)
            fmpy_best = min(fmpy_best, (time.perf_counter() - t0) / args.fmpy_steps)
            k0 += args.fmpy_steps
        s.freeInstance()
        rows = {k: f"{v:.1f}" for k, v in best.items()}

        rows.update(arithmetic_floor(cc, tmp, Path(unz) / "sources"))

        frame_rows = frame_beside_peers(args, tmp, so, baseline, guid, cc, inc,
                                        Path(unz) / "sources")
    best = fmpy_best
    rows["glauert_through_fmpy_set_dostep_get"] = f"{best * 1e9:.0f}"
    flags = Path("/proc/cpuinfo").read_text().split() if Path("/proc/cpuinfo").is_file() else []
    print(f"model: {args.model or 'the presets (structure 2, glauert)'}")
    print(f"machine: {platform.processor() or platform.machine()}, "
          f"{platform.system()} {platform.release()}, python {platform.python_version()}, "
          f"AVX2 {'yes' if 'avx2' in flags else 'no'}")
    print(f"every row: the best of {args.driver_rounds} rounds; in each round the driver "
          "runs the shipped and the baseline library in ABBA order (5 runs of "
          f"{args.steps} steps a case) and fmpy {args.fmpy_steps} steps; the frame table: "
          f"fmu_frame's {args.rounds} rounds, every binary in every round")
    print("| case | ns per step |\n| --- | --- |")
    for k, v in rows.items():
        print(f"| {k} | {v} |")
    print("\n| frame beside peers (one run) | fmi2DoStep best [ns] | median | set 10 + "
          "step + get 6 best [ns] | median |\n| --- | --- | --- | --- | --- |")
    for label, v in frame_rows.items():
        print(f"| {label} | {v['dostep'][0]} | {v['dostep'][1]} | {v['frame'][0]} | "
              f"{v['frame'][1]} |")
    one = float(rows["onestate_dostep"])
    print(f"\nglauert / one-state fmi2DoStep, the best of the same {len(ratios)} driver runs "
          f"(ABBA): {float(rows['glauert_dostep']) / one:.1f}x (shipped binary), "
          f"{float(rows['baseline_glauert_dostep']) / one:.1f}x (baseline code, no AVX2 "
          f"clone); per run, median {sorted(r for _, r in ratios)[len(ratios) // 2]:.1f}x")


def compile_drivers(cc, inc, tmp):
    """The one-state reference library and the C driver, into ``tmp``."""
    from inflowsim.fmu.build import CFLAGS
    subprocess.run([cc, *CFLAGS, inc, "-o", str(tmp / "onestate.so"),
                    str(HERE / "fmu_onestate.c"), "-lm"], check=True)
    subprocess.run([cc, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", inc, "-o",
                    str(tmp / "driver"), str(HERE / "fmu_driver.c"), "-ldl"], check=True)


def arithmetic_floor(cc, tmp, fmu_sources) -> dict:
    """The machine's rate of 4-wide multiplies and adds (``bench/fp_rate.c``) and the
    step's floor: its ``NX (NX + NU)`` products in whole vectors of four, at that
    rate of multiplies [ns] (no fused multiply-add: every build rounds alike)."""
    import math
    import re
    exe = tmp / "fp_rate"
    subprocess.run([cc, "-std=c99", "-O2", "-ffp-contract=off", "-Wall", "-Wextra",
                    "-Werror", "-o", str(exe), str(HERE / "fp_rate.c")], check=True)
    out = subprocess.run([str(exe)], check=True, capture_output=True, text=True).stdout
    rates = {k: float(v) for k, v in (line.split() for line in out.splitlines())}
    text = (fmu_sources / "inflow_vars.h").read_text()
    nx = int(re.search(r"#define IFS_NX (\d+)", text).group(1))
    nu = int(re.search(r"#define IFS_N_INPUTS (\d+)", text).group(1))
    muls = math.ceil(nx * (nx + nu) / 4)
    return {"vector_mul_per_ns": f"{rates['mul_per_ns']:.2f}",
            "vector_add_per_ns": f"{rates['add_per_ns']:.2f}",
            f"step_floor_{muls}_vector_muls": f"{muls / rates['mul_per_ns']:.1f}"}


#: The FMU's generated C (inflowsim.fmu.generate.GENERATED): a ``--model`` peer is
#: the peer commit's hand-written C compiled with this FMU's generated files.
GENERATED_C = ("inflow_vars.h", "inflow_vars.c", "inflow_equations.c")


def schedule_main(args):
    """The scheduled FMU against the unscheduled one of the same structure."""
    from fmpy import extract, read_model_description
    from inflowsim.fmu import build_fmu
    from inflowsim.fmu.build import CFLAGS, compiler, source_dir
    from inflowsim.model.schedule import read_schedule
    sch = read_schedule(args.schedule)
    steps = args.steps if args.steps != 2_000_000 else 300_000
    rounds = args.rounds if args.rounds != 41 else 3
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        libs = {}
        for tag, model in (("unscheduled", sch.structure), ("scheduled", sch)):
            fmu = build_fmu(tmp / f"{tag}.fmu", model=model)
            unz = extract(str(fmu), str(tmp / tag))
            libs[tag] = (Path(unz) / "binaries" / "linux64" / "inflowsim.so",
                         read_model_description(str(fmu)).guid)
        cc = compiler()
        inc = f"-I{source_dir()}"
        compile_drivers(cc, inc, tmp)
        best: dict = {}
        for _ in range(rounds):
            for tag, (so, guid) in libs.items():
                out = subprocess.run([str(tmp / "driver"), str(so), guid,
                                      str(tmp / "onestate.so"), str(steps)], check=True,
                                     capture_output=True, text=True).stdout
                for line in out.splitlines():
                    name, value = line.split()
                    key = (name, tag)
                    best[key] = min(best.get(key, float("inf")), float(value))
    print(f"schedule: {args.schedule} ({sch.structure}, {len(sch.parameters)} parameters "
          f"following mu {sch.mu_range[0]:g}-{sch.mu_range[1]:g}, orders "
          f"{', '.join(f'{p.name} {p.order}' for p in sch.parameters)})")
    print(f"steps {steps} (mu every step: {steps // 100 + 1}), best of 5 runs x {rounds} "
          "rounds, the two libraries alternating")
    print("| case | unscheduled [ns] | scheduled [ns] | ratio |\n| --- | --- | --- | --- |")
    for name in dict.fromkeys(n for n, _ in best):
        if name.startswith("onestate"):
            continue
        a, b = best[(name, "unscheduled")], best[(name, "scheduled")]
        print(f"| {name} | {a:.1f} | {b:.1f} | {b / a:.2f} |")


def frame_beside_peers(args, tmp, so, baseline, guid, cc, inc, fmu_sources) -> dict:
    """``{label: {"dostep": (best, median), "frame": (best, median)}}`` [ns] from one
    run of ``fmu_frame`` over this FMU, its baseline build and each peer commit's
    (the presets' FMU of that commit; with ``--model``, that commit's hand-written C
    with this FMU's generated files, if they still build together)."""
    import shutil
    from inflowsim.fmu.build import CFLAGS
    exe = tmp / "frame"
    subprocess.run([cc, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", inc, "-o",
                    str(exe), str(HERE / "fmu_frame.c"), "-ldl"], check=True)
    libs = [("this", so, guid), ("this_baseline", baseline, guid)]
    for commit in filter(None, args.peers.split(",")):
        d = tmp / f"peer_{commit}"
        d.mkdir()
        tar = subprocess.run(["git", "-C", str(HERE.parent), "archive", commit, "fmu"],
                             check=True, capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", str(d)], input=tar, check=True)
        src = d / "fmu"
        pguid = guid
        if args.model is None:
            text = (src / "modelDescription.xml").read_text()
            pguid = text.split('guid="', 1)[1].split('"', 1)[0]
        else:
            for f in GENERATED_C:
                shutil.copyfile(fmu_sources / f, src / f)
        peer = tmp / f"peer_{commit}.so"
        cfiles = sorted(str(f) for f in src.glob("inflow_*.c") if "fmi3" not in f.name)
        res = subprocess.run([cc, *CFLAGS, f"-I{src}", "-o", str(peer), *cfiles, "-lm"],
                             capture_output=True, text=True)
        if res.returncode != 0:
            print(f"peer {commit}: its C does not build with this FMU's generated files; "
                  "left out")
            continue
        libs.append((commit, peer, pguid))
    cmd = [str(exe), str(args.frame_steps), str(args.rounds)]
    for label, lib, g in libs:
        cmd += [label, str(lib), g]
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    rows = {}
    for line in out.splitlines():
        label, kind, best, med = line.split()
        rows.setdefault(label, {})[kind] = (best, med)
    return rows


if __name__ == "__main__":
    main()
