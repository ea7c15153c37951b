"""Results that travel (issue #26): records, models, fits, diagnoses, ladders and
validations pickle and come back equal in content and still read-only; a real
process pool returns them; records round-trip through JSON exactly and the
result documents through JSON text."""
import copy
import json
import pickle
from concurrent.futures import ProcessPoolExecutor
from dataclasses import fields, is_dataclass
from collections.abc import Mapping

import numpy as np
import pytest

from conftest import virtual
from inflowsim.data.record import Record, find_trim
from inflowsim.diagnose import diagnose, ladder
from inflowsim.diagnose.validation import validate
from inflowsim.fileio import json_text
from inflowsim.frozen import FrozenDict
from inflowsim.identify import identify
from inflowsim.model.build import build_model

POOL = ["time-delay"]


def same(a, b, path="x"):
    """Equal in content: the same types, fields, mappings, arrays (NaN equal to NaN)."""
    assert type(a) is type(b), f"{path}: {type(a).__name__} != {type(b).__name__}"
    if isinstance(a, np.ndarray):
        assert a.shape == b.shape and a.dtype == b.dtype, path
        assert np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"), path
    elif is_dataclass(a):
        for f in fields(a):
            same(getattr(a, f.name), getattr(b, f.name), f"{path}.{f.name}")
    elif isinstance(a, Mapping):
        assert list(a) == list(b), path
        for k in a:
            same(a[k], b[k], f"{path}[{k!r}]")
    elif isinstance(a, (tuple, list)):
        assert len(a) == len(b), path
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{path}[{i}]")
    elif isinstance(a, float) and np.isnan(a):
        assert np.isnan(b), path
    else:
        assert a == b, path


def assert_read_only(rec: Record):
    with pytest.raises(ValueError):
        rec.t[0] = 1.0
    with pytest.raises(ValueError):
        rec.channels["beta0"][0] = 1.0
    with pytest.raises(TypeError):
        rec.channels["beta0"] = rec.t
    with pytest.raises(TypeError):
        rec.meta["mu"] = "0.2"
    with pytest.raises(AttributeError):
        rec.source = "elsewhere"


@pytest.fixture(scope="module")
def rec():
    return virtual(structure="glauert", dt=1 / 64, seed=3)


@pytest.fixture(scope="module")
def diag(rec):
    return diagnose(rec, "glauert", pool=POOL)


def test_frozen_dict_refuses_mutation_and_pickles():
    d = FrozenDict(a=1.0, b=np.arange(3.0))
    with pytest.raises(TypeError):
        d["a"] = 2.0
    with pytest.raises(TypeError):
        del d["a"]
    with pytest.raises(AttributeError):
        d._d = {}
    back = pickle.loads(pickle.dumps(d))
    same(d, back)
    assert d == {"a": 1.0, "b": d["b"]} and d.copy() == dict(d)
    assert (d | {"c": 2}) == {**dict(d), "c": 2}
    same(copy.deepcopy(d), d)


def test_record_pickles_and_stays_read_only(rec):
    back = pickle.loads(pickle.dumps(rec))
    same(rec, back)
    assert_read_only(back)
    assert_read_only(copy.copy(rec))
    trim = find_trim(rec)
    tback = pickle.loads(pickle.dumps(trim))
    same(trim, tback)
    with pytest.raises(TypeError):
        tback.values["beta0"] = 0.0


def test_record_round_trips_through_json(rec):
    doc = json.loads(json_text(rec.to_json()))
    back = Record.from_json(doc)
    same(rec, back)                      # every float exact through JSON text
    assert_read_only(back)


def test_model_pickles_read_only(rec):
    m = build_model("glauert+flap-inertia", _params(rec), rec.constants)
    back = pickle.loads(pickle.dumps(m))
    same(m, back)
    with pytest.raises(ValueError):
        back.a[0, 0] = 1.0
    with pytest.raises(TypeError):
        back.parameters["tau0"] = 1.0


def _params(rec):
    from inflowsim.model.presets import preset_parameters
    from inflowsim.model.structure import Structure
    s = Structure.parse("glauert+flap-inertia")
    p = dict(preset_parameters("glauert", rec.constants, "paper"))
    p.setdefault("flap_inertia", 1.0)
    return {n: p.get(n, 1.0) for n in s.parameters}


def test_fit_diagnosis_ladder_validation_pickle(rec, diag):
    fit = diag.fit
    lad = ladder(rec, "glauert", pool=POOL, max_steps=1)
    val = validate(rec, fit.model)
    for obj in (fit, diag, lad, val):
        back = pickle.loads(pickle.dumps(obj))
        same(obj, back)
        # the JSON document is plain and the same from the copy
        text = json_text(obj.to_json())
        assert json_text(back.to_json()) == text
        assert json_text(json.loads(text)) == text
    assert diag.candidates and lad.rungs[0].diagnosis.candidates
    with pytest.raises(AttributeError):
        pickle.loads(pickle.dumps(diag)).missing_effect = "glauert"
    with pytest.raises(TypeError):
        pickle.loads(pickle.dumps(fit)).model.parameters["tau0"] = 1.0


def _identify_in_worker(record):
    return record, identify(record, "glauert")


def test_process_pool_returns_records_and_fits(rec):
    local = identify(rec, "glauert")
    with ProcessPoolExecutor(max_workers=1) as ex:
        back_rec, fit = ex.submit(_identify_in_worker, rec).result(timeout=120)
    same(rec, back_rec)
    assert_read_only(back_rec)
    assert json_text(fit.to_json()) == json_text(local.to_json())
