"""Atomic outputs: complete or absent, with a new file's usual permissions."""

from __future__ import annotations

import os
import stat

import pytest

from scenegrep.writers.atomic import atomic_path


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
