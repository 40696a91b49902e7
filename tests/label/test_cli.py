"""``scenegrep label``: labelled Parquet traces, statistics, one-line errors."""

from __future__ import annotations

import json

import numpy as np

from scenegrep.cli.main import main
from scenegrep.readers import read_trace
from scenegrep.writers.trace_json import write_trace_json
from scenegrep.writers.trace_parquet import write_map_parquet, write_trace_parquet
from tests.label.tracks import neighbour_map, trace_of


def files(tmp_path):
    t = np.arange(61) * 0.1
    trace = trace_of(
        ("car", np.full(61, 1.75), 5.0 + 10.0 * t, None), ("pedestrian", np.full(61, -8.0), np.full(61, 5.0), None)
    )
    write_trace_json(trace, tmp_path / "hand.json")
    write_map_parquet(neighbour_map(), tmp_path / "map.parquet")
    return tmp_path


def test_writes_labelled_traces_and_prints_statistics(tmp_path, capsys):
    folder = files(tmp_path)
    code = main(
        ["label", str(folder / "hand.json"), "--map", str(folder / "map.parquet"), "-o", str(folder / "out"), "-q"]
    )
    out = capsys.readouterr().out
    assert code == 0
    labelled = read_trace(folder / "out" / "hand.parquet")
    assert set(labelled.behaviours.sets()) == {frozenset({"FollowLane"}), frozenset({"Stationary"})}
    assert "car: 1 object, 61 obs, 1.00  FollowLane 100.0" in out
    assert labelled.lane_names()[0] == "n1"


def test_json_statistics_and_a_stricter_threshold(tmp_path, capsys):
    folder = files(tmp_path)
    code = main(
        ["label", str(folder / "hand.json"), "-o", str(folder / "out"), "--json", "-q", "--min-confidence", "0.9"]
    )
    stats = json.loads(capsys.readouterr().out)
    assert code == 0 and stats["traces"] == 1
    assert stats["classes"]["pedestrian"]["behaviours"] == {"Stationary": 61}


def test_user_errors_are_one_line_with_exit_2(tmp_path, capsys):
    folder = files(tmp_path)
    (folder / "bad.toml").write_text("[labels]\nmin_confidence = 'high'\n")
    for args in (
        ["label", str(folder / "hand.json"), "-o", str(folder / "out"), "--min-confidence", "2"],
        ["label", str(folder / "hand.json"), "-o", str(folder / "out"), "--config", str(folder / "bad.toml")],
        ["label", str(folder / "missing.json"), "-o", str(folder / "out")],
    ):
        assert main(args) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("scenegrep: error: ") and "Traceback" not in err[0]


def folder_with_a_bad_file(tmp_path):
    """Two good Parquet traces, a truncated one and the map (skipped: not a trace) in one folder."""
    folder = files(tmp_path)
    trace = read_trace(folder / "hand.json")
    (folder / "hand.json").unlink()
    for name in ("a", "b"):
        write_trace_parquet(trace, folder / f"{name}.parquet")
    (folder / "bad.parquet").write_bytes((folder / "a.parquet").read_bytes()[:300])
    return folder


def test_a_bad_file_in_a_folder_is_named_and_the_others_are_labelled(tmp_path, capsys):
    folder = folder_with_a_bad_file(tmp_path / "in")
    out = tmp_path / "out"
    code = main(["label", str(folder), "--map", str(folder / "map.parquet"), "-o", str(out), "--json", "-q"])
    captured = capsys.readouterr()
    assert code == 3 and json.loads(captured.out)["traces"] == 2
    assert len(list(out.glob("*.parquet"))) == 2
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"scenegrep: failed: bad.parquet: {folder / 'bad.parquet'}: ")


def test_a_bad_file_among_several_paths_is_named_and_the_others_are_labelled(tmp_path, capsys):
    folder = folder_with_a_bad_file(tmp_path / "in")
    paths = [str(folder / name) for name in ("a.parquet", "bad.parquet", "b.parquet")]
    code = main(["label", *paths, "--map", str(folder / "map.parquet"), "-o", str(tmp_path / "out"), "-q"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 3 and len(list((tmp_path / "out").glob("*.parquet"))) == 2
    assert len(err) == 1 and err[0].startswith("scenegrep: failed: bad.parquet: ")
