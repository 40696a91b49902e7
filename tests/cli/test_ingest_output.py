"""``scenegrep ingest -o DATASET``: a name that cannot be a dataset directory is a one-line error
(exit 2) before anything is read or made, not a traceback nor a dataset in the working directory."""

from __future__ import annotations

from pathlib import Path

import pytest

from scenegrep.cli.main import main

REPO = Path(__file__).resolve().parents[2]
TRACE = str(REPO / "examples/sample/s3_pass_pedestrian-000.parquet")


@pytest.mark.parametrize(
    "into, message",
    [
        ("", "-o: give the dataset directory"),
        ("  ", "-o: give the dataset directory"),
        ("{tmp}/file", "-o {tmp}/file: not a directory; a dataset is a directory"),
        ("{tmp}/file/ds", "-o {tmp}/file/ds: not a directory ({tmp}/file is a file); a dataset is a directory"),
        ("{tmp}/" + "d" * 300, "-o {tmp}/" + "d" * 300 + ": File name too long"),
    ],
)
def test_one_line_errors(tmp_path, monkeypatch, capsys, into, message):
    (tmp_path / "file").write_text("not a dataset")
    monkeypatch.chdir(tmp_path)
    assert main(["ingest", TRACE, "-q", "-o", into.format(tmp=tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message.format(tmp=tmp_path) in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]
    assert (tmp_path / "file").read_text() == "not a dataset"
