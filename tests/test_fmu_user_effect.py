"""A user effect in the FMU (issue #24): the generator traces an effect loaded from a
file into the generated C like a catalogue effect, so ``fmu build --model
basic+pitch-flap-coupling --effect-file FILE`` gives the Simulator's trajectory to
1e-10 and passes fmpy's validation; an effect the C cannot hold (a recorded-flap
output map) is refused in one line."""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy import extract  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from conftest import assert_user_error, run  # noqa: E402
from inflowsim.fmu import description_for  # noqa: E402
from inflowsim.model import build_model  # noqa: E402
from inflowsim.model.effects.user import USER_EFFECTS, load_effect_file, unregister  # noqa: E402
from inflowsim.model.params import PUMA  # noqa: E402
from inflowsim.model.presets import truth_parameters  # noqa: E402
from test_fmu_structures import fmu_run, inputs_of, python_run, record  # noqa: E402,F401

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "effects" / \
    "pitch_flap_coupling.py"


@pytest.fixture
def example():
    before = set(USER_EFFECTS)
    load_effect_file(EXAMPLE)
    yield EXAMPLE
    for n in set(USER_EFFECTS) - before:
        unregister(n)


@pytest.mark.parametrize("structure", [
    "basic+pitch-flap-coupling",
    # another structure to compile (a few seconds of CPU with a cold binary cache)
    pytest.param("glauert+pitch-flap-coupling", marks=pytest.mark.slow)])
def test_a_user_effect_in_the_fmu_equals_the_simulator(structure, example, record,
                                                       tmp_path, capsys):
    p = truth_parameters(structure, PUMA) | {"k3": 0.35}
    if "azimuth_bias" in p:
        p["azimuth_bias"] = 0.2              # the coupling acts on the true pitch
    m = build_model(structure, p, PUMA)
    # through the command, as a user builds it (the structure; values set below)
    code, out, err = run(capsys, "fmu", "build", "--model", structure, "--effect-file",
                         example, "--out", tmp_path / "u.fmu")
    assert code == 0, err
    assert validate_fmu(str(tmp_path / "u.fmu")) == []
    unzipped = extract(str(tmp_path / "u.fmu"), str(tmp_path / "x"))
    d = description_for(structure)
    assert "k3" in d.vr
    u = inputs_of(m, record)
    y_py, l_py = python_run(m, u)
    y_fmu, l_fmu = fmu_run(unzipped, d, {"structure": 0, **p}, u, 2)
    assert np.abs(y_py).max() > 1e-3
    np.testing.assert_allclose(y_fmu, y_py, rtol=0, atol=1e-10)
    np.testing.assert_allclose(l_fmu, l_py, rtol=0, atol=1e-10)
    # the coupling is felt: without it the trajectory differs
    y0, _ = python_run(build_model(structure, p | {"k3": 0.0}, PUMA), u)
    assert np.abs(y0 - y_py).max() > 1e-4


def test_an_output_map_effect_is_refused_by_the_fmu(tmp_path, capsys):
    path = tmp_path / "gain.py"
    path.write_text(textwrap.dedent('''
        import numpy as np
        from inflowsim.model.effects import Effect, ParameterSpec

        def measurement(m, p, k):
            fm = np.zeros((3, 6), dtype=object)
            fm[0, 0] = p["g_test"]
            return m.with_(flap_map=fm)

        EFFECT = Effect(name="sensor-gain-test", physics="A coning sensor gain error.",
                        paper="test", parameters=("g_test",),
                        theory=lambda k: {"g_test": 0.0}, measurement=measurement,
                        specs=(ParameterSpec("g_test", "-", "gain error", -1, 1,
                                             plausible=(-0.1, 0.1, "a sensor")),))
        '''))
    try:
        assert_user_error(*run(capsys, "fmu", "build", "--model", "basic+sensor-gain-test",
                               "--effect-file", path, "--out", tmp_path / "g.fmu"),
                          "the FMU does not run", "flap_map")
        assert not (tmp_path / "g.fmu").exists()
    finally:
        if "sensor-gain-test" in USER_EFFECTS:
            unregister("sensor-gain-test")
