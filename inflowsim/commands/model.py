"""``inflowsim model``: show a structure, its parameters and its matrices.

The matrices are the azimuth-time descriptor ``E x' = A x + B u`` of Eq. (8)
(``model.md`` order of states and inputs); eigenvalues are those of the SI state
space [1/s].  With ``--json`` the parameters take the parameter-file form
(``{"estimate", "sigma"}`` plus unit and range), so the document is itself a
valid ``--params`` file.
"""
from __future__ import annotations

from ._checks import finite_float
from ._common import add_model_arguments, load_model, print_json

HELP = "show a structure: states, inputs, parameters, E, A, B and eigenvalues"


def add_arguments(p):
    add_model_arguments(p)
    p.add_argument("--mu", type=finite_float, metavar="X",
                   help="advance ratio of the flight condition (default the parameter "
                        "file's, else the Puma's 0.249)")
    p.add_argument("--json", action="store_true", help="one JSON document on stdout")


def run(args) -> int:
    from ..model.describe import describe_model
    from ..model.paramfile import read_parameters
    from ..model.params import PUMA
    from ..model.presets import TABLE_OF_PRESET, paper_table
    k, sigma = PUMA, {}
    if args.params:
        ps = read_parameters(args.params)
        k = ps.constants or PUMA
        sigma = ps.sigma
    if args.mu is not None:
        k = k.with_mu(args.mu)
    k.check()
    model = load_model(args, k)
    if not args.params:
        table = TABLE_OF_PRESET.get(model.structure.name)
        if table:
            sigma = paper_table(table)[2]
    doc = describe_model(model, sigma)
    if args.json:
        print_json(doc)
        return 0
    print(format_model(doc, model))
    return 0


def _matrix(name, m, rows, cols):
    import numpy as np
    w = max(len(c) for c in cols) + 1
    w = max(w, 11)
    head = " " * 14 + "".join(f"{c:>{w}}" for c in cols)
    lines = [f"{name}:", head]
    for r, row in zip(rows, np.asarray(m) + 0.0):  # no "-0"
        lines.append(f"  {r:<12}" + "".join(f"{v:>{w}.5g}" for v in row))
    return "\n".join(lines)


def format_model(doc, model) -> str:
    """Human-readable text of :func:`describe_model`."""
    from ..model.describe import eigen_table
    out = [f"structure: {doc['structure']}  (effects: "
           f"{', '.join(doc['effects']) or 'none'})",
           "constants: " + ", ".join(f"{k} = {v:g}" for k, v in doc["constants"].items()
                                     if isinstance(v, (int, float))),
           "states:    " + " ".join(doc["states"]),
           "inputs:    " + " ".join(doc["inputs"]) + "   (azimuth units; record columns: "
           + " ".join(doc["record_inputs"]) + ")",
           "", "parameters:"]
    for n, d in doc["parameters"].items():
        sig = f" (1-sigma {d['sigma']:.4g})" if "sigma" in d else ""
        out.append(f"  {n:<14}{d['estimate']:>11.5g}{sig:<22} [{d['unit']}] "
                   f"range {d['range']}: {d['description']}")
    if any(model.delays):
        out.append("delays [s]: " + ", ".join(f"{c} {v:g}" for c, v in
                                             doc["delays_s"].items() if v))
    out += ["", _matrix("E", model.E, doc["states"], doc["states"]),
            "", _matrix("A", model.A, doc["states"], doc["states"]),
            "", _matrix("B", model.B, doc["states"], doc["inputs"]),
            "", "eigenvalues of the SI state space:",
            f"  {'re [1/s]':>11}{'im [1/s]':>11}{'wn [rad/s]':>12}{'f [Hz]':>9}"
            f"{'damping':>9}"]
    for e in eigen_table(model):
        out.append(f"  {e['re']:>11.4g}{e['im']:>11.4g}{e['wn_rad_s']:>12.4g}"
                   f"{e['f_hz']:>9.4g}{e['damping']:>9.3f}")
    return "\n".join(out)
