"""``scenegrep label``: labelled Parquet traces, statistics, one-line errors."""

from __future__ import annotations

import json

import numpy as np

from scenegrep.cli.main import main
from scenegrep.readers import read_trace
from scenegrep.writers.trace_json import write_trace_json
from scenegrep.writers.trace_parquet import write_map_parquet
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
    assert "car: 1 objects, 61 obs, 1.00  FollowLane 100.0" in out
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
