"""Records (record-format.md): round trip, trim, and every listed error.

Each error must be one line naming what is wrong, and the input file must be
left byte-for-byte as it was.
"""
import hashlib

import numpy as np
import pytest

from inflowsim.errors import RecordError, InputError
from inflowsim.record import find_trim, read_record, write_record, perturbations
from inflowsim.virtual import VirtualTest, virtual_record

HEADER = "t,theta0,theta1c,theta1s,muz,p,q,pdot,qdot,mux,muy,beta0,beta1c,beta1s"
META = "# omega: 27.5\n# mu: 0.249\n# a0: 5.73\n# solidity: 0.0917\n"


def rows(n=20, dt=0.01):
    out = []
    for k in range(n):
        out.append(",".join([f"{k * dt:.10f}", "0.17", "0.01", "-0.05", "0", "0", "0", "0", "0",
                             "0.249", "0", "0.06", "0.01", "-0.002"]))
    return out


def text(meta=META, header=HEADER, body=None):
    return meta + header + "\n" + "\n".join(rows() if body is None else body) + "\n"


@pytest.fixture
def write(tmp_path):
    def _w(content, name="rec.csv"):
        p = tmp_path / name
        p.write_bytes(content.encode("utf-8") if isinstance(content, str) else content)
        return p
    return _w


def assert_refused(path, match):
    before = hashlib.sha256(path.read_bytes()).hexdigest()
    with pytest.raises(RecordError, match=match) as e:
        read_record(path)
    assert "\n" not in str(e.value)
    assert hashlib.sha256(path.read_bytes()).hexdigest() == before
    return str(e.value)


def test_round_trip_keeps_ten_significant_digits(tmp_path):
    rec = virtual_record(VirtualTest(duration=2.0))
    p = write_record(rec, tmp_path / "r.csv")
    back = read_record(p)
    assert back.order == rec.order
    for c in rec.order:
        np.testing.assert_allclose(back[c], rec[c], rtol=1e-10, atol=1e-13)
    assert back.meta["aircraft"] == "Puma (virtual)"
    assert back.constants.omega == 27.5


def test_unknown_metadata_and_extra_columns_kept(write):
    p = write(META + "# tailnumber: XW123\n" + HEADER + ",extra\n" +
              "\n".join(r + ",1.5" for r in rows()) + "\n")
    rec = read_record(p)
    assert rec.meta["tailnumber"] == "XW123"
    assert rec["extra"][0] == 1.5


def test_missing_required_metadata(write):
    assert_refused(write(text(meta="# omega: 27.5\n# mu: 0.249\n# a0: 5.73\n")),
                   "missing required metadata '# solidity")


def test_non_numeric_metadata(write):
    assert_refused(write(text(meta=META.replace("27.5", "fast"))), "omega .*not a number")


def test_metadata_out_of_range(write):
    assert_refused(write(text(meta=META.replace("mu: 0.249", "mu: 0.0"))), "mu")


@pytest.mark.parametrize("bad", ["nan", "inf", "-inf"])
def test_nan_or_infinite_value(write, bad):
    body = rows()
    body[7] = body[7].replace("0.01,-0.05", f"{bad},-0.05", 1)
    msg = assert_refused(write(text(body=body)), "column theta1c has a NaN or infinite")
    assert "row 8" in msg


def test_non_monotonic_time(write):
    body = rows()
    body[5], body[6] = body[6], body[5]
    assert_refused(write(text(body=body)), "not strictly increasing")


def test_non_uniform_time(write):
    body = rows()
    body = [b for i, b in enumerate(body) if i != 10]       # a dropped sample
    assert_refused(write(text(body=body)), "not uniformly sampled")


def test_small_jitter_is_tolerated(write):
    body = rows()
    body[4] = body[4].replace("0.0400000000", "0.0400500000", 1)     # 0.5 % of the step
    rec = read_record(write(text(body=body)))
    assert rec.dt == pytest.approx(0.01)


def test_missing_channel_named(write):
    p = write(text(header=HEADER.replace(",mux,muy", ""),
                   body=[",".join(r.split(",")[:9] + r.split(",")[11:]) for r in rows()]))
    rec = read_record(p)
    with pytest.raises(RecordError, match="needs column 'mux'"):
        rec.require(["theta0", "mux"])


def test_non_numeric_cell(write):
    body = rows()
    body[3] = body[3].replace("0.06", "abc")
    assert_refused(write(text(body=body)), "line .*column beta0: 'abc' is not a number")


def test_wrong_number_of_values(write):
    body = rows()
    body[2] = body[2] + ",1"
    assert_refused(write(text(body=body)), "15 values, the header has 14")


def test_no_header_no_data_duplicate_column(write):
    assert_refused(write(META), "no header row")
    assert_refused(write(text(body=[])), "no data rows")
    assert_refused(write(text(header=HEADER.replace("muy", "mux"))), "duplicate column 'mux'")
    assert_refused(write(text(header=HEADER.replace("t,", "time,", 1))), "must start with 't'")


def test_not_utf8_and_missing_file(write, tmp_path):
    assert_refused(write(b"# omega: 27.5\n\xff\xfe"), "not UTF-8")
    with pytest.raises(RecordError, match="no such file"):
        read_record(tmp_path / "nope.csv")


def test_too_short_for_band():
    rec = virtual_record(VirtualTest(duration=2.0))
    with pytest.raises(RecordError, match="too short"):
        rec.check_band((0.2256, 1.58))
    with pytest.raises(RecordError, match="Nyquist"):
        rec.check_band((1.0, 60.0))
    virtual_record().check_band((0.2256, 1.58))


def test_writer_never_overwrites(tmp_path):
    rec = virtual_record(VirtualTest(duration=1.0))
    p = write_record(rec, tmp_path / "r.csv")
    before = p.read_bytes()
    with pytest.raises(InputError, match="exists"):
        write_record(rec, p)
    with pytest.raises(InputError, match="input file"):
        write_record(rec, p, overwrite=True, protect=[p])
    assert p.read_bytes() == before


def test_record_arrays_are_read_only():
    rec = virtual_record(VirtualTest(duration=1.0))
    with pytest.raises(ValueError):
        rec["beta0"][0] = 1.0


def test_trim_is_mean_of_quiet_lead_in():
    rec = virtual_record(VirtualTest(duration=5.0, noise_flap=1e-4, seed=3))
    trim = find_trim(rec)
    assert trim.method == "quiet" and trim.n_samples == 200      # doublet at t = 2 s
    assert trim.values["theta1s"] == pytest.approx(-0.05, abs=1e-12)
    assert trim.values["beta1c"] == pytest.approx(np.mean(rec["beta1c"][:200]))
    assert "before the first control movement" in trim.describe()
    pert = perturbations(rec, trim, ["theta1s"])
    assert np.all(pert[:200] == 0) and pert[200, 0] == pytest.approx(np.radians(1))
