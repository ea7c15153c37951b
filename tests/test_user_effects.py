"""Effects written outside the package (issue #24, item 2): loaded from a file
(``--effect-file``) or an installed package's ``inflowsim.model.effects`` entry point,
checked, registered beside the catalogue and usable everywhere a catalogue effect
is; a bad effect file is refused with one line naming the file, exit 2."""
import json
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from conftest import assert_user_error, run, virtual
from inflowsim import PUMA, Structure, build_model, theory_parameters
from inflowsim.data.record import write_record
from inflowsim.errors import InputError
from inflowsim.model.effects import CATALOGUE
from inflowsim.model.effects import user as user_module
from inflowsim.model.effects.user import USER_EFFECTS, load_effect_file, unregister
from inflowsim.model.equations import rotation
from inflowsim.model.params import SPECS

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "effects" / \
    "pitch_flap_coupling.py"

GOOD = '''
import numpy as np
from inflowsim.model.effects import Effect, ParameterSpec

def equations(eq, p, k):
    d = np.array(eq.d, dtype=float)
    d[2, 1] -= p["k_{tag}"]
    return eq.with_(d=d)

EFFECT = Effect(
    name="{name}", physics="A test coupling of beta1s to beta1c.", paper="test",
    parameters=("k_{tag}",), theory=lambda k: {{"k_{tag}": 0.0}}, equations=equations,
    specs=(ParameterSpec("k_{tag}", "-", "a test gain", -1.0, 1.0,
                         plausible=(-0.5, 0.5, "a test")),))
'''


def write(tmp_path, text, name="fx.py"):
    p = tmp_path / name
    p.write_text(textwrap.dedent(text))
    return p


@pytest.fixture
def clean():
    """Unregister whatever user effects a test registers."""
    before = set(USER_EFFECTS)
    yield
    for n in set(USER_EFFECTS) - before:
        unregister(n)


def test_a_file_effect_is_registered_and_usable(tmp_path, clean):
    path = write(tmp_path, GOOD.format(name="my-coupling", tag="mc"))
    (eff,) = load_effect_file(path)
    assert CATALOGUE["my-coupling"] is eff and "k_mc" in SPECS
    assert load_effect_file(path) == (eff,)          # idempotent
    s = Structure.parse("basic+my-coupling")
    p = theory_parameters(s, PUMA) | {"k_mc": 0.1}
    m = build_model(s, p, PUMA)
    m0 = build_model("basic", theory_parameters("basic", PUMA), PUMA)
    assert m.A[2, 1] == pytest.approx(m0.A[2, 1] + 0.1)
    # a candidate like any other: offered to the diagnosis
    from inflowsim.diagnose.rule import applicable
    assert "my-coupling" in applicable(Structure.parse("basic"), None)
    unregister("my-coupling")
    assert "my-coupling" not in CATALOGUE and "k_mc" not in SPECS


def test_the_example_effect_is_delta3(clean):
    """``theta - k3 beta``: the flap equation's D gains ``k3 H_theta`` and the
    inflow equation's ``P_beta`` loses ``k3 L G_theta``, in true pitch where the
    structure has an azimuth bias."""
    load_effect_file(EXAMPLE)
    from inflowsim.model.build import equations
    for base in ("basic", "glauert"):
        s = Structure.parse(base)
        p0 = theory_parameters(s, PUMA) | ({"azimuth_bias": 0.2} if "azimuth-bias" in
                                            s.effects else {})
        _, _, eq0, _ = equations(s, p0, PUMA)
        _, _, eq1, _ = equations(s.with_effect("pitch-flap-coupling"), p0 | {"k3": 0.4},
                                 PUMA)
        r = np.eye(3)
        if "azimuth_bias" in p0:
            # the model's pitch columns take recorded pitch, R(dpsi) of the true one
            r[1:3, 1:3] = rotation(0.2)
        # flap: C beta' + D beta = H_u u with u's pitch theta - k3 beta (true pitch)
        np.testing.assert_allclose(eq1.d - eq0.d, 0.4 * eq0.h_u[:, :3] @ r, atol=1e-14)
        np.testing.assert_allclose(eq1.p_beta - eq0.p_beta, -0.4 * eq0.p_u[:, :3] @ r,
                                   atol=1e-14)


def test_cli_commands_take_effect_files(tmp_path, capsys, clean):
    code, out, err = run(capsys, "model", "--model", "basic+pitch-flap-coupling",
                         "--effect-file", EXAMPLE, "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert "k3" in json.dumps(doc)
    rec = virtual(structure="basic", noise_flap=1e-4, duration=26.6, hold="zoh",
                  dt=1 / 64)
    path = write_record(rec, tmp_path / "r.csv")
    code, out, err = run(capsys, "simulate", path, "--model", "basic+pitch-flap-coupling",
                         "--effect-file", EXAMPLE, "--out", tmp_path / "sim.csv")
    assert code == 0, err
    code, out, err = run(capsys, "identify", path, "--model", "basic+pitch-flap-coupling",
                         "--effect-file", EXAMPLE, "--json")
    assert code == 0, err
    fit = json.loads(out)
    k3 = fit["parameters"]["k3"]
    # the truth has no coupling: k3 within 3 sigma of zero
    assert abs(k3["estimate"]) < 3 * k3["sigma"], k3
    code, out, err = run(capsys, "validate", path, "--model", "basic+pitch-flap-coupling",
                         "--effect-file", EXAMPLE, "--json")
    assert code == 0, err
    # without the file the effect is unknown: one line, exit 2
    unregister("pitch-flap-coupling")
    assert_user_error(*run(capsys, "model", "--model", "basic+pitch-flap-coupling"),
                      "unknown effect", "pitch-flap-coupling")


BAD = {
    "syntax": ("def f(:\n", "syntax error at line 1"),
    "no-effect": ("X = 1\n", "defines no EFFECT"),
    "import-error": ("import no_such_module_xyz\n", "importing it raised"),
    "not-an-effect": ("EFFECT = 3\n", "must be an inflowsim.model.effects.Effect"),
    "missing-field": (GOOD.format(name="x-eff", tag="x").replace(' paper="test",', ''),
                      "missing 1 required"),
    "empty-physics": (GOOD.format(name="x-eff", tag="x").replace(
        'physics="A test coupling of beta1s to beta1c."', 'physics=""'), "'physics'"),
    "catalogue-clash": (GOOD.format(name="glauert", tag="g"), "clashes with the catalogue"),
    "preset-clash": (GOOD.format(name="basic", tag="b"), "clashes"),
    "bad-name": (GOOD.format(name="My Effect", tag="m"), "lower-case words"),
    "parameter-clash": (GOOD.format(name="x-eff", tag="x").replace('"k_x"', '"tau"')
                        .replace("k_x", "tau"), "clashes with a parameter"),
    "no-spec": (GOOD.format(name="x-eff", tag="x").replace(
        'specs=(ParameterSpec("k_x", "-", "a test gain", -1.0, 1.0,\n'
        '                         plausible=(-0.5, 0.5, "a test")),))', "specs=())"),
        "has no ParameterSpec"),
    "no-plausible": (GOOD.format(name="x-eff", tag="x").replace(
        ',\n                         plausible=(-0.5, 0.5, "a test")', ""),
        "plausible range"),
    "wrong-shape": (GOOD.format(name="x-eff", tag="x").replace(
        "return eq.with_(d=d)", "return eq.with_(d=np.zeros((2, 2)))"),
        "block d has shape (2, 2), must be (3, 3)"),
    "not-equations": (GOOD.format(name="x-eff", tag="x").replace(
        "return eq.with_(d=d)", "return d"), "must return an Equations"),
    "raises": (GOOD.format(name="x-eff", tag="x").replace(
        'd[2, 1] -= p["k_x"]', 'd[2, 1] -= p["nope"]'), "raised KeyError"),
    "theory-range": (GOOD.format(name="x-eff", tag="x").replace(
        '{"k_x": 0.0}', '{"k_x": 5.0}'), "theory value"),
    "neutral-changes": (GOOD.format(name="x-eff", tag="x").replace(
        'd[2, 1] -= p["k_x"]', 'd[2, 1] -= p["k_x"] + 0.1'),
        "its neutral values change the model"),
    "bad-flap-map": (GOOD.format(name="x-eff", tag="x") + textwrap.dedent('''
        EFFECT = Effect(name="x-eff", physics="A test.", paper="test",
            parameters=("k_x",), theory=lambda k: {"k_x": 0.0},
            measurement=lambda m, p, k: m.with_(flap_map=np.zeros((2, 6))),
            specs=(ParameterSpec("k_x", "-", "a gain", -1, 1, plausible=(-1, 1, "t")),))
        '''), "flap_map must be a finite 3x6 array"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_a_bad_effect_file_is_refused_in_one_line(case, tmp_path, capsys, clean):
    text, words = BAD[case]
    path = write(tmp_path, text, f"bad_{case.replace('-', '_')}.py")
    before = dict(CATALOGUE)
    specs = dict(SPECS)
    assert_user_error(*run(capsys, "model", "--model", "basic", "--effect-file", path),
                      str(path), words)
    assert CATALOGUE == before and SPECS == specs      # nothing half-registered


def test_a_missing_effect_file_is_refused(tmp_path, capsys):
    assert_user_error(*run(capsys, "identify", tmp_path / "r.csv", "--model", "basic",
                           "--effect-file", tmp_path / "none.py"),
                      "none.py", "no such effect file")


def test_every_command_that_takes_a_model_takes_effect_files(capsys):
    from inflowsim.cli import build_parser
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command").choices
    for name in ("identify", "diagnose", "ladder", "validate", "simulate", "model"):
        assert any("--effect-file" in a.option_strings for a in sub[name]._actions), name
    fmu = next(a for a in sub["fmu"]._actions if a.dest == "action").choices["build"]
    assert any("--effect-file" in a.option_strings for a in fmu._actions)


def test_an_installed_package_s_effect_is_found_by_entry_point(tmp_path, monkeypatch,
                                                                clean):
    pkg = tmp_path / "site"
    pkg.mkdir()
    (pkg / "my_fx.py").write_text(textwrap.dedent(GOOD.format(name="installed-fx",
                                                              tag="ifx")))
    dist = pkg / "my_fx-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: my-fx\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[inflowsim.model.effects]\ninstalled-fx = my_fx\n")
    monkeypatch.syspath_prepend(str(pkg))
    monkeypatch.setattr(user_module, "_installed_loaded", False)
    # a structure naming it finds it without any file
    s = Structure.parse("basic+installed-fx")
    assert s.effects == ("installed-fx",)
    assert USER_EFFECTS["installed-fx"].startswith("entry point installed-fx")
    monkeypatch.delitem(sys.modules, "my_fx", raising=False)


def test_a_bad_installed_effect_is_refused_naming_the_entry_point(tmp_path, monkeypatch,
                                                                   clean):
    pkg = tmp_path / "site"
    pkg.mkdir()
    (pkg / "bad_fx.py").write_text("X = 1\n")
    dist = pkg / "bad_fx-0.1.dist-info"
    dist.mkdir()
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: bad-fx\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[inflowsim.model.effects]\nbad = bad_fx\n")
    monkeypatch.syspath_prepend(str(pkg))
    monkeypatch.setattr(user_module, "_installed_loaded", False)
    with pytest.raises(InputError, match="entry point bad .*defines no EFFECT"):
        user_module.load_installed()
    monkeypatch.delitem(sys.modules, "bad_fx", raising=False)
