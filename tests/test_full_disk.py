"""A full disk is reported in one line naming where the write went, exit 2 (issue #28
item 5): the standard output redirected to a full disk (``> /dev/full``), whose OS
error carries no file name, and the FMU build folder in the temporary folder.
(A file written through :func:`inflowsim.fileio.atomic_path` is tested in
test_edges.)"""
import errno
import os
import sys

import pytest

from conftest import assert_user_error, run


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_stdout_on_a_full_disk_is_named(capsys, monkeypatch):
    with open("/dev/full", "w") as full:
        monkeypatch.setattr(sys, "stdout", full)
        code, out, err = run(capsys, "model", "-m", "glauert", "--json")
    assert_user_error(code, out, err, "standard output", "No space left on device")
    if os.path.exists("/proc/self/fd"):
        assert "(/dev/full)" in err


def test_stdout_is_restored_after_the_command(capsys):
    before = sys.stdout
    code, out, _ = run(capsys, "model", "-m", "basic")
    assert code == 0 and "basic" in out and sys.stdout is before


def test_fmu_build_folder_on_a_full_disk_is_named(capsys, monkeypatch, tmp_path):
    import inflowsim.fmu.build as build

    def full(*a, **k):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    monkeypatch.setattr(build.shutil, "copyfile", full)
    out = tmp_path / "m.fmu"
    code, stdout, err = run(capsys, "fmu", "build", "-m", "basic", "--out", out)
    # the progress line "building ..." comes first; the error is one line
    *_, last = err.strip().splitlines()
    assert code == 2 and stdout == "" and "Traceback" not in err
    assert last.startswith("inflowsim fmu: error: ")
    for word in ("the build folder of", str(out), "No space left on device"):
        assert word in last
    assert not out.exists()
