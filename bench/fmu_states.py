"""FMU step cost against the number of inflow states: 3 (the present model), 6, 10 and
15 (Peters-He, ``peters-he-6/10/15``), and with the servos and the lag mode
(``servo-actuators``, ``lead-lag``, both with ``peters-he-6``), beside each step's
arithmetic floor.

    python bench/fmu_states.py [--base basic] [--steps N] [--rounds R] [--keep DIR]

Builds one FMU per structure (``inflowsim.fmu.build_fmu(model=...)``: ``BASE``,
``BASE+peters-he-6``, ``BASE+peters-he-10``, ``BASE+peters-he-15``; a structure
linearised about the trim, as the Peters-He effects' skewed wake, in forward flight:
the Puma's truth values at its ``mu`` 0.249 and the virtual flight test's trim
there (``flighttest.virtual.PUMA_TRIM``); each build's code generation and compilation timed
in process CPU), compiles
``bench/fmu_driver.c``, ``bench/fp_rate.c`` and, once per ``NX``, ``bench/step_peer.c``
as ``bench/fmu_bench.py`` does, then runs the driver on the libraries in turn,
``--rounds`` times (each run the best of five runs of ``--steps`` steps per case),
keeping each case's best: the libraries interleaved so that a change of machine load
falls on all of them alike.  ``fp_rate`` and the peers are run in every round too
(best kept).  Two floors of a step: the throughput floor, its ``NX (NX + NU)``
multiplies (the matrix-vector product ``x <- [Phi Gamma] [x; u]``) in whole vectors of
four at the measured rate of 4-wide multiplies (no fused multiply-add: every build
rounds alike); and the latency-bound peer, the best plain loop of the same recurrence
with no FMI around it (``step_peer``: every product at every step, the state in
registers or through memory, the faster), and beside it the peer with the inputs held
(``phi x + g``, as the FMU's step with its inputs held, which keeps ``g = gam u``).
Beside them the chain floor: the latency of the recurrence from a state to the one
computed from it, a 16-byte store and the broadcast load of one of its doubles (a step
behind a function call keeps its state in memory), one multiply and
``ceil(log2(NX + 1))`` adds (the least depth of any pairwise sum of ``NX + 1`` terms),
each latency measured by ``fp_rate`` in every round (best kept), per call: halved up to
16 states, where the FMU's step with its inputs held looks ahead (each state computed
from the one two calls before, ``x_(k+1) = phi^2 x_(k-1) + c``: the chain spans two
calls); a step can be no faster than either floor.
Prints a Markdown table.  ``--keep DIR`` keeps the FMUs there (for
``bench/fmu_mu_callgrind.sh``'s instruction counts); ``--beside DIR`` times the FMUs
an earlier run kept in DIR (``s0.fmu`` ... in the same order: another checkout's,
e.g. main's) in the same rounds, interleaved with these, and adds their step to the
table.
"""
from __future__ import annotations

import argparse
import math
import platform
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


#: what is added to ``--base``: the Peters-He orders, then the appended states of the
#: rotor's own physics (3 servos x 2 states; the regressing lag mode's 2 x 3), alone
#: and together with six inflow states (NX 21)
EXTRA = ("peters-he-6", "peters-he-10", "peters-he-15", "servo-actuators", "lead-lag",
         "servo-actuators+lead-lag+peters-he-6")


def forward_flight(structure):
    """``structure`` as the FMU gets it: a name, or, linearised about the trim, a
    model at the Puma's ``mu`` with the virtual flight test's trim there."""
    from inflowsim.model.structure import needs_trim
    if not needs_trim([structure]):
        return structure
    from inflowsim import build_model
    from inflowsim.flighttest.virtual import PUMA_TRIM
    from inflowsim.model.params import PUMA
    from inflowsim.model.presets import truth_parameters
    k = PUMA.with_trim(dict(PUMA_TRIM, mux=PUMA.mu))
    return build_model(structure, truth_parameters(structure, k), k)


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--base", default="basic", help="structure the inflow states are added to")
    ap.add_argument("--steps", type=int, default=1_000_000)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--keep", type=Path, help="folder to keep the FMUs in")
    ap.add_argument("--beside", type=Path,
                    help="folder of FMUs kept by another checkout's run, timed beside")
    args = ap.parse_args(argv)
    from fmpy import extract, read_model_description
    from inflowsim.fmu import build_fmu
    from inflowsim.fmu.build import compiler, source_dir
    from fmu_bench import compile_drivers

    structures = [args.base] + [f"{args.base}+{e}" for e in EXTRA]
    # inflow states: Peters-He's order where the structure has one, else the three
    inflow = {st: max([3] + [int(e.rsplit('-', 1)[1]) for e in st.split('+')
                            if e.startswith('peters-he-')]) for st in structures}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        libs = {}
        built = {}
        for i, st in enumerate(structures):
            folder = args.keep if args.keep is not None else tmp
            folder.mkdir(parents=True, exist_ok=True)
            cpu = time.process_time(), _children_cpu()
            fmu = build_fmu(folder / f"s{i}.fmu", model=forward_flight(st), overwrite=True)
            built[st] = (time.process_time() - cpu[0], _children_cpu() - cpu[1])
            unz = Path(extract(str(fmu), str(tmp / f"x{i}")))
            text = (unz / "sources" / "inflow_vars.h").read_text()
            nx = int(re.search(r"#define IFS_NX (\d+)", text).group(1))
            nu = int(re.search(r"#define IFS_N_INPUTS (\d+)", text).group(1))
            libs[st] = (unz / "binaries" / "linux64" / "inflowsim.so",
                        read_model_description(str(fmu)).guid, nx, nu)
        other = {}
        if args.beside is not None:
            for i, st in enumerate(structures):
                fmu = args.beside / f"s{i}.fmu"
                unz = Path(extract(str(fmu), str(tmp / f"b{i}")))
                other[st] = (unz / "binaries" / "linux64" / "inflowsim.so",
                             read_model_description(str(fmu)).guid)
        cc = compiler()
        compile_drivers(cc, f"-I{source_dir()}", tmp)
        for nx in sorted({nx for _, _, nx, _ in libs.values()}):
            subprocess.run([cc, "-std=c99", "-O2", "-ffp-contract=off", "-Wall", "-Wextra",
                            "-Werror", f"-DNX={nx}", "-o", str(tmp / f"peer{nx}"),
                            str(HERE / "step_peer.c")], check=True)
        rate_exe = tmp / "fp_rate"
        subprocess.run([cc, "-std=c99", "-O2", "-ffp-contract=off", "-Wall", "-Wextra",
                        "-Werror", "-o", str(rate_exe), str(HERE / "fp_rate.c")], check=True)
        best: dict = {}
        mul_rate = 0.0
        lat: dict = {}
        for _ in range(args.rounds):
            out = subprocess.run([str(rate_exe)], check=True, capture_output=True,
                                 text=True).stdout
            rates = {k: float(v) for k, v in (line.split() for line in out.splitlines())}
            mul_rate = max(mul_rate, rates["mul_per_ns"])
            for k in ("mul_lat_ns", "add_lat_ns", "store_load_ns"):
                lat[k] = min(lat.get(k, math.inf), rates[k])
            for nx in sorted({nx for _, _, nx, _ in libs.values()}):
                out = subprocess.run([str(tmp / f"peer{nx}"), str(args.steps)], check=True,
                                     capture_output=True, text=True).stdout
                for line in out.splitlines():
                    name, value = line.split()
                    best[(nx, name)] = min(best.get((nx, name), math.inf), float(value))
            runs = [(st, "", so, guid) for st, (so, guid, _, _) in libs.items()]
            runs += [(st, "beside ", so, guid) for st, (so, guid) in other.items()]
            for st, tag, so, guid in runs:
                out = subprocess.run([str(tmp / "driver"), str(so), guid,
                                      str(tmp / "onestate.so"), str(args.steps)],
                                     check=True, capture_output=True, text=True).stdout
                for line in out.splitlines():
                    name, value = line.split()
                    if name in ("glauert_dostep", "glauert_set_dostep_get"):
                        key = (st, tag + name)
                        best[key] = min(best.get(key, math.inf), float(value))
    flags = Path("/proc/cpuinfo").read_text().split() if Path("/proc/cpuinfo").is_file() else []
    print(f"machine: {platform.processor() or platform.machine()}, {platform.system()} "
          f"{platform.release()}, AVX2 {'yes' if 'avx2' in flags else 'no'}; "
          f"4-wide multiplies {mul_rate:.2f} per ns (best of {args.rounds} rounds)")
    print(f"steps {args.steps} per run, best of 5 runs x {args.rounds} rounds, libraries "
          "interleaved")
    print(f"latencies [ns]: 4-wide multiply {lat['mul_lat_ns']:.3f}, add "
          f"{lat['add_lat_ns']:.3f}, 16-byte store then broadcast load "
          f"{lat['store_load_ns']:.3f} (best of {args.rounds} rounds)")
    beside = (" beside [ns] | beside / floor | beside set + step + get [ns] |" if other else "")
    print("| structure | inflow states | NX | generation + compiler CPU [s] | "
          "fmi2DoStep [ns] | set + step + get [ns] | floor [ns] | step / floor | "
          "chain floor [ns] | step / chain floor | peer [ns] | step / peer | peer, inputs held [ns] | step / peer held | "
          "step / 3-state step |" + beside)
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
          " --- | --- |" +
          (" --- | --- | --- |" if other else ""))
    first = best[(structures[0], "glauert_dostep")]
    for st, (_, _, nx, nu) in libs.items():
        step = best[(st, "glauert_dostep")]
        floor = math.ceil(nx * (nx + nu) / 4) / mul_rate
        # the chain from a state to the one computed from it: the store and load
        # through memory, one multiply, a tree of NX + 1 terms (any pairwise order:
        # depth at least ceil(log2(NX + 1)))
        chain = (lat["store_load_ns"] + lat["mul_lat_ns"] +
                 math.ceil(math.log2(nx + 1)) * lat["add_lat_ns"])
        # ... spanning two calls where the step looks ahead (the column step)
        chain /= 2 if nx <= 16 else 1
        peer = min(best[(nx, "peer_reg_ns")], best[(nx, "peer_mem_ns")])
        held = best[(nx, "peer_held_ns")]
        gen, comp = built[st]
        print(f"| {st} | {inflow[st]} | {nx} | {gen:.1f} + {comp:.1f} | {step:.1f} | "
              f"{best[(st, 'glauert_set_dostep_get')]:.1f} | {floor:.1f} | "
              f"{step / floor:.2f} | {chain:.1f} | {step / chain:.2f} | {peer:.1f} | {step / peer:.2f} | {held:.1f} | "
              f"{step / held:.2f} | {step / first:.2f} |" +
              (f" {best[(st, 'beside glauert_dostep')]:.1f} | "
               f"{best[(st, 'beside glauert_dostep')] / floor:.2f} | "
               f"{best[(st, 'beside glauert_set_dostep_get')]:.1f} |" if other else ""))


if __name__ == "__main__":
    main()
