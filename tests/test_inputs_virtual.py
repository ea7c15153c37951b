"""Input shapes and the built-in virtual Puma record generator."""
import numpy as np
import pytest

from inflowsim import PUMA, build_model, preset_parameters
from inflowsim.inputs import doublet, input_3211
from inflowsim.record import find_trim, model_inputs
from inflowsim.simulator import Simulator
from inflowsim.virtual import Manoeuvre, VirtualTest, virtual_record


def test_doublet_and_3211_shapes():
    t = np.arange(0, 3, 0.01)
    d = doublet(t, 0.5, 0.4, 2.0)
    assert np.all(d[t < 0.5 - 1e-9] == 0) and np.all(d[(t >= 0.5) & (t < 0.9 - 1e-9)] == 2)
    assert np.all(d[(t >= 0.9 - 1e-9) & (t < 1.3 - 1e-9)] == -2) and np.all(d[t >= 1.3] == 0)
    assert np.sum(d) == pytest.approx(0.0)
    s = input_3211(t, 0.2, 0.3, 1.0)
    assert [np.sum(s == v) for v in (1.0, -1.0)] == [120, 90]    # 3+1 and 2+1 units of 30
    assert s[t.searchsorted(0.2)] == 1 and s[t.searchsorted(1.25)] == -1


def test_virtual_record_is_seeded_and_replays_its_truth():
    test = VirtualTest(duration=6.0, seed=11)
    a, b = virtual_record(test), virtual_record(test)
    np.testing.assert_array_equal(a["beta1c"], b["beta1c"])
    c = virtual_record(VirtualTest(duration=6.0, seed=12))
    assert not np.array_equal(a["beta1c"], c["beta1c"])
    # noise-free: the measured flap is the ZOH replay of the structure's model
    clean = virtual_record(VirtualTest(duration=6.0, noise_flap=0.0))
    m = build_model("glauert", preset_parameters("glauert", PUMA, "paper"), PUMA)
    trim = find_trim(clean)
    y = Simulator(m, clean.dt).replay(model_inputs(clean, m, trim))
    for i, ch in enumerate(("beta0", "beta1c", "beta1s")):
        np.testing.assert_allclose(clean[ch] - trim.values[ch], y[:, i], atol=1e-14)
    resid = a["beta1c"] - clean["beta1c"]
    assert np.std(resid) == pytest.approx(1e-4, rel=0.1)


def test_body_motion_excites_hub_inputs():
    rec = virtual_record(VirtualTest(duration=8.0, noise_flap=0.0,
                                     manoeuvres=(Manoeuvre(channel="theta1c"),)))
    for ch in ("p", "pdot", "muy"):
        assert np.ptp(rec[ch]) > 0
    assert np.ptp(rec["q"]) == 0            # decoupled body model: lateral input only
