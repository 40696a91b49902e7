"""``scenegrep scene``: outputs, options, exit codes, one-line errors."""

from __future__ import annotations

import json
from dataclasses import replace

import pyarrow.parquet as pq
import pytest

from scenegrep.cli.main import main
from scenegrep.writers.trace_json import write_trace_json
from scenegrep.writers.trace_parquet import write_map_parquet
from tests.scene.frames import HEADER, MAP, trace_of

PROGRAM = HEADER + "ego = new Car on road\nother = new Car ahead of ego by Range(4, 10)\n"


@pytest.fixture
def files(tmp_path):
    """A program, a two-frame trace (frame 0 matches: a car 6 m ahead; frame 1 does not), the
    synthetic map as a map that publishes every layer (``map.parquet``: no sidewalks or shoulders)
    and as it is (``unknown.parquet``: its sidewalks and shoulders are unknown)."""
    (tmp_path / "ahead.scenic").write_text(PROGRAM)
    trace = trace_of(
        {"ego": ("Car", 1.75, 20.0, 0.0), "c": ("Car", 1.75, 30.5, 0.0)},
        {"ego": ("Car", 1.75, 20.0, 0.0), "c": ("Car", 5.25, 30.5, 0.0)},
    )
    write_trace_json(trace, tmp_path / "trace.json")
    write_map_parquet(replace(MAP, unknown_layers=frozenset()), tmp_path / "map.parquet")
    write_map_parquet(MAP, tmp_path / "unknown.parquet")
    return tmp_path


def run(args, capsys):
    code = main(["scene", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out.splitlines(), err.splitlines()


def test_text_output_names_correspondence_and_values(files, capsys):
    code, lines, err = run([files / "ahead.scenic", files / "trace.json", "--map", files / "map.parquet"], capsys)
    assert code == 0 and len(lines) == 1
    assert lines[0].startswith(f"{files / 'trace.json'}#hand:0-0  ego=ego  other=c  |  ")
    assert "Range(4, 10)@3:33=6" in lines[0]  # a 6 m gap
    assert err == ["scenegrep: 1 of 1 trace matches, 0 pruned, 0 failed"]


def test_json_output_and_explain(files, capsys):
    out = files / "matches.parquet"
    args = [files / "ahead.scenic", files / "trace.json", "--map", files / "map.parquet", "--json"]
    code, lines, _ = run([*args, "--output", out], capsys)
    (record,) = [json.loads(line) for line in lines]
    assert code == 0 and record["status"] == "match"
    assert (record["start_frame"], record["end_frame"], record["start_time"], record["end_time"]) == (0, 0, 0.0, 0.0)
    assert record["correspondence"] == {"ego": "ego", "other": "c"}
    assert record["values"]["Range(4, 10)@3:33"] == pytest.approx(6.0)
    table = pq.read_table(out).to_pylist()
    assert [(row["start_frame"], json.loads(row["correspondence"])["other"]) for row in table] == [(0, "c")]
    (files / "side.scenic").write_text(HEADER + "ego = new Car on road\nother = new Car left of ego by 3\n")
    code, lines, _ = run([files / "side.scenic", *args[1:], "--explain"], capsys)
    records = [r for r in map(json.loads, lines) if not r.get("nearest_miss")]
    assert code == 1 and [(r["status"], r["start_frame"], r["end_frame"]) for r in records] == [
        ("no match", 0, 0),
        ("no match", 1, 1),
    ]
    assert {r["explanation"] for r in records} == {"no labeled object can be other (Car, line 3): other.x"}
    code, lines, _ = run([*args[:-1], "--explain"], capsys)  # a match, and why the other frame is none
    assert code == 0 and lines[0].startswith(f"{files / 'trace.json'}#hand:0-0  ego=ego  other=c  |  ")
    assert lines[1].startswith(f"{files / 'trace.json'}#hand:1-1  no match: ") and "other.x, other.y" in lines[1]


def test_exit_code_options_and_quiet(files, capsys):
    base = [files / "ahead.scenic", files / "trace.json", "--map", files / "map.parquet"]
    assert run([*base, "--exact", "-q"], capsys)[:2] == (0, [])
    code, lines, _ = run([*base, "--tolerance-position", "4"], capsys)
    assert code == 0 and len(lines) == 2  # frame 1's car is 3.5 m to the side: within 4 m
    (files / "none.scenic").write_text(HEADER + "ego = new Car on road\nother = new Car behind ego by 3\n")
    assert run([files / "none.scenic", files / "trace.json", "--map", files / "map.parquet"], capsys)[0] == 1


@pytest.mark.parametrize(
    ("text", "status", "expected"),
    [
        ("ego = new Car on\n", 2, "scenegrep: error: {p}:2:17: Scenic syntax error"),
        ("import math\nego = new Car\n", 2, "scenegrep: error: {p}:2:1: imports are not supported"),
        (
            "ego = new Car on sidewalk\n",
            2,
            "scenegrep: error: {p}:2:7: the road map 'synthetic' does not publish",
        ),
    ],
)
def test_errors_are_one_line_with_the_place(files, capsys, text, status, expected):
    """Errors in the program stop the command (2), and so does one that the map of the lone trace causes
    (over several traces it fails that trace alone: exit 3)."""
    program = files / "bad.scenic"
    program.write_text(HEADER + text)
    code, _, err = run([program, files / "trace.json", "--map", files / "unknown.parquet"], capsys)
    assert code == status and err[0].startswith(expected.format(p=program))
    assert not any("Traceback" in line for line in err)


def test_missing_inputs(files, capsys):
    code, _, err = run([files / "absent.scenic", files / "trace.json"], capsys)
    assert code == 2 and err == [f"scenegrep: error: {files / 'absent.scenic'}: no such file"]
    code, _, err = run([files / "ahead.scenic", files / "trace.json"], capsys)  # no map anywhere: the trace fails
    assert code == 2 and len(err) == 1 and err[0].startswith("scenegrep: error: ") and "has no road map" in err[0]
    code, _, err = run([files / "ahead.scenic", files / "trace.json", "--tolerance-heading", "-1"], capsys)
    assert code == 2 and "must not be negative" in err[0]
