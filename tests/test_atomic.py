"""Atomic outputs: complete or absent, with a new file's usual permissions; a failure to write (disk
full, unwritable place, full standard output) is a one-line error, exit 2."""

from __future__ import annotations

import errno
import os
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from scenegrep.cli.main import main
from scenegrep.writers.atomic import atomic_path
from tests.conftest import REPO

SAMPLE = REPO / "examples/sample/s3_pass_pedestrian-000.parquet"


def test_the_file_appears_whole_with_the_umask_permissions(tmp_path):
    old = os.umask(0o022)
    try:
        with atomic_path(tmp_path / "out.txt") as tmp:
            tmp.write_text("done")
            assert not (tmp_path / "out.txt").exists()
    finally:
        os.umask(old)
    assert (tmp_path / "out.txt").read_text() == "done"
    assert stat.S_IMODE((tmp_path / "out.txt").stat().st_mode) == 0o644


def test_a_failure_leaves_nothing(tmp_path):
    with pytest.raises(RuntimeError), atomic_path(tmp_path / "out.txt") as tmp:
        tmp.write_text("half")
        raise RuntimeError("stop")
    assert list(tmp_path.iterdir()) == []


def _disk_full(*args, **kwargs):
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))


def test_a_full_disk_is_one_line_exit_2_and_no_file(tmp_path, monkeypatch, capsys):
    """A write failing with ENOSPC (here: Parquet's writer) leaves no output, not even a partial
    temporary file, and is a one-line user error."""
    import pyarrow.parquet as pq

    monkeypatch.setattr(pq, "write_table", _disk_full)
    out = tmp_path / "out" / "matches.parquet"
    program = REPO / "examples/scenes/fig3_car_ahead.scenic"
    assert main(["scene", str(program), str(SAMPLE), "--output", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert err == f"scenegrep: error: {out}: cannot write: No space left on device\n"
    assert list(out.parent.iterdir()) == []


def test_a_read_only_place_is_one_line_exit_2(capsys):
    """sysfs takes no new files, even from root."""
    out = Path("/sys/scenegrep-test/t.html")
    assert main(["show", str(SAMPLE), "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"scenegrep: error: {out}: cannot write: ") and err.count("\n") == 1
    assert not out.parent.exists()


def test_an_output_under_a_file_is_one_line_exit_2(tmp_path, capsys):
    """A folder that cannot be made (a file is in the way) is the same kind of error; this
    also runs as root, where permissions do not stop a write."""
    (tmp_path / "file").write_text("")
    out = tmp_path / "file" / "t.html"
    assert main(["show", str(SAMPLE), "-o", str(out), "-q"]) == 2
    assert capsys.readouterr().err == f"scenegrep: error: {out}: cannot write: File exists ({out.parent})\n"


def test_a_full_standard_output_is_one_line_exit_2():
    """/dev/full: every write fails with ENOSPC."""
    with open("/dev/full", "w") as full:
        done = subprocess.run(
            [sys.executable, "-m", "scenegrep", "info", "--no-map", str(SAMPLE)],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            env=dict(os.environ, PYTHONPATH=str(REPO / "src")),
            timeout=120,
        )
    assert done.returncode == 2
    assert done.stderr == "scenegrep: error: <stdout>: cannot write: No space left on device\n"
