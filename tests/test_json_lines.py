"""``--json`` is JSON Lines with numbers at the data's precision, from one writer
(:mod:`scenegrep.json_lines`), in every command; ``source`` is a real path."""

import io
import json
import math
import sys
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from scenegrep import json_lines
from scenegrep.cli.main import main

REPO = Path(__file__).resolve().parents[1]
SAMPLE = REPO / "examples" / "sample"
BG1 = "examples/sample/bg1_following_traffic-000.parquet"
FIG1 = "examples/sample/fig1_lane_change-000.parquet"


def decimals(key):
    return 9 if key == "time" or key.endswith(("_time", "_s")) else 6


def reference(x: float, places: int) -> float:
    """Rounding to ``places`` decimals, by decimal text (a brute-force reference)."""
    return float(f"{x:.{places}f}") + 0.0


@given(
    st.floats(allow_nan=False, allow_infinity=False, min_value=-1e9, max_value=1e9),
    st.sampled_from(["start_time", "time", "duration_s", "x", "rate_hz", "balanced_accuracy"]),
)
def test_a_float_is_written_rounded_by_its_key(x, key):
    (written,) = json.loads(json_lines.line({key: x})).values()
    assert written == reference(x, decimals(key))
    assert json_lines.line({key: x}) == json.dumps({key: reference(x, decimals(key))})


def test_noise_is_gone_lists_inherit_their_key_and_the_rest_is_kept():
    record = {"end_time": 0.1 + 0.2, "values": {"p": [0.1 + 0.2, -1e-9]}, "n": 3, "ok": True, "none": None}
    text = json_lines.line(record)
    assert "\n" not in text and "0000" not in text
    assert json.loads(text) == {"end_time": 0.3, "values": {"p": [0.3, 0.0]}, "n": 3, "ok": True, "none": None}
    assert json_lines.line({"x": math.nan}) == '{"x": NaN}'


def rounded_everywhere(value, key=""):
    """Whether every float in a decoded record is at the rule's precision."""
    if isinstance(value, float):
        return not math.isfinite(value) or value == reference(value, decimals(key))
    if isinstance(value, dict):
        return all(rounded_everywhere(v, str(k)) for k, v in value.items())
    if isinstance(value, list):
        return all(rounded_everywhere(v, key) for v in value)
    return True


def records(argv, capsys, codes=(0,)):
    """The command's stdout, each line checked to be one JSON object at the data's precision."""
    code = main(argv)
    out = capsys.readouterr().out
    assert code in codes, out
    lines = out.splitlines()
    assert lines, argv
    decoded = [json.loads(line) for line in lines]
    assert all(isinstance(r, dict) for r in decoded) and all(rounded_everywhere(r) for r in decoded)
    return decoded


@pytest.fixture(autouse=True)
def at_repo(monkeypatch):
    monkeypatch.chdir(REPO)


def test_spre_over_a_stream_names_its_source_as_given_and_writes_times_at_1_ns(capsys):
    rows = records(["spre", "--online", "--json", "[[:car:]]{2,}", BG1], capsys)
    assert {r["source"] for r in rows} == {BG1} and {r["trace"] for r in rows} == {"bg1_following_traffic-000"}
    assert [r["end_time"] for r in rows[:3]] == [0.1, 0.2, 0.3]  # 0.30000000000000004 before


def test_spre_on_standard_input_names_it_dash(capsys, monkeypatch, conformance_dir):
    text = (conformance_dir / "strem/data/noncontig.json").read_text()
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(text.encode())))
    rows = records(["spre", "--json", "[[:car:]]{2}", "-"], capsys)
    assert {r["source"] for r in rows} == {"-"}


def test_query_tables_name_an_existing_absolute_source(capsys):
    for argv in (
        ["spre", "--json", "[[:car:]]{2,}", BG1],
        ["scene", "examples/scenes/fig3_car_ahead.scenic", FIG1, "--json", "--tolerance-position", "0.5"],  # misses
        ["scenario", "examples/queries/fig1_lane_change.scenic", FIG1, "--window", "3s", "--json"],
    ):
        rows = records(argv, capsys, codes=(0, 1))
        assert all(Path(r["source"]).is_absolute() and Path(r["source"]).is_file() for r in rows), argv
        assert {r["status"] for r in rows if "status" in r} == {"match" if argv[0] != "scene" else "no match"}
        assert argv[0] != "scene" or rows[-1]["nearest_miss"]  # a miss's source was the trace's name


def test_info_label_and_a_rate_with_noise(capsys, tmp_path):
    (summary,) = records(["info", "--json", BG1], capsys)
    assert summary["path"] == BG1 and summary["traces"][0]["rate_hz"] == 10.0  # 10.000000000000036 before
    (statistics,) = records(["label", BG1, "-o", str(tmp_path), "--json", "-q"], capsys)
    assert statistics["traces"] == 1
