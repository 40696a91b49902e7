"""``show --trace`` accepts every name the command line prints for a trace (view.trace_names)."""

from __future__ import annotations

import contextlib
import io
import json

import pytest

from scenegrep.cli.main import main
from scenegrep.errors import UserError
from scenegrep.view.trace_names import LISTED, TraceChoice, choose_trace
from tests.conftest import REPO

SAMPLE = REPO / "examples" / "sample"


def rows(*traces: tuple[str, str, str]) -> list[dict]:
    return [{"trace_id": t, "name": n, "source": s} for t, n, s in traces]


TABLE = rows(
    ("a-1111", "a", "/data/a.parquet"),
    ("b-2222", "b", "/data/many.tfrecord"),
    ("c-3333", "c", "/data/many.tfrecord"),
)


@pytest.mark.parametrize(
    "given, expected",
    [
        ("a-1111", TraceChoice("a-1111")),
        ("a", TraceChoice("a-1111")),
        ("/data/a.parquet", TraceChoice("a-1111")),
        ("/data/../data/a.parquet", TraceChoice("a-1111")),
        ("/data/many.tfrecord#c", TraceChoice("c-3333")),
        ("b:3-17", TraceChoice("b-2222", (3, 17))),
        ("/data/many.tfrecord#b:0-9", TraceChoice("b-2222", (0, 9))),
        ("c-3333:5-5", TraceChoice("c-3333", (5, 5))),
    ],
)
def test_every_printed_name_means_its_trace(given, expected):
    assert choose_trace(TABLE, given) == expected


def test_a_hash_in_a_path_or_a_name_is_told_by_the_trace_name():
    table = rows(("n-1", "x#y", "/d#1/f.json"), ("n-2", "y", "/d#1/g.json"))
    assert choose_trace(table, "/d#1/f.json#x#y:2-4") == TraceChoice("n-1", (2, 4))
    assert choose_trace(table, "/d#1/./f.json#x#y") == TraceChoice("n-1")
    assert choose_trace(table, "/d#1/f.json#x#y") == TraceChoice("n-1")
    assert choose_trace(table, "/d#1/../d#1/g.json#y:0-0") == TraceChoice("n-2", (0, 0))
    with pytest.raises(UserError):
        choose_trace(table, "/d#1/f.json#y")


def test_a_relative_path_names_the_source(tmp_path, monkeypatch):
    (tmp_path / "t.parquet").write_bytes(b"")
    monkeypatch.chdir(tmp_path)
    table = rows(("t-1", "t", str(tmp_path / "t.parquet")))
    assert choose_trace(table, "t.parquet") == TraceChoice("t-1")
    assert choose_trace(table, "./t.parquet:1-2") == TraceChoice("t-1", (1, 2))


def test_a_name_with_a_colon_is_a_name_before_a_window():
    table = rows(("x:1-2-9", "x:1-2", ""), ("x-8", "x", ""))
    assert choose_trace(table, "x:1-2") == TraceChoice("x:1-2-9")
    assert choose_trace(table, "x:1-2:4-6") == TraceChoice("x:1-2-9", (4, 6))


@pytest.mark.parametrize(
    "given, message",
    [
        ("/data/many.tfrecord", "2 traces have that name; give one's trace_id: b-2222 (/data/many.tfrecord), c-3333"),
        ("d", "no such trace; traces: a (a-1111), b (b-2222), c (c-3333)"),
        ("d:1-2", "no such trace; traces: a (a-1111)"),
        ("/data/many.tfrecord#z", "no such trace"),
    ],
)
def test_unknown_or_ambiguous_names_list_the_valid_ones(given, message):
    with pytest.raises(UserError) as error:
        choose_trace(TABLE, given)
    assert error.value.one_line().startswith(f"--trace {given}: ")
    assert message in error.value.one_line()


def test_many_traces_list_the_nearest_names():
    table = rows(*((f"scene-{k:04d}-abc", f"scene-{k:04d}", "") for k in range(LISTED + 5)))
    with pytest.raises(UserError) as error:
        choose_trace(table, "scene-0O12")
    assert "nearest of its 15 traces: scene-0012" in error.value.one_line()
    with pytest.raises(UserError) as error:
        choose_trace(table, "zzz")
    assert "none of its 15 traces has a near name" in error.value.one_line()


@pytest.fixture(scope="module")
def printed(tmp_path_factory):
    """A scenario query over three sample traces: its results file, its text lines and JSON rows."""
    folder = tmp_path_factory.mktemp("trace-names")
    traces = [str(SAMPLE / f"fig1_lane_change-00{k}.parquet") for k in range(3)]
    program = str(REPO / "examples" / "queries" / "fig1_lane_change.scenic")
    results = folder / "results.parquet"
    with pytest.MonkeyPatch.context() as patch, _captured() as out:
        patch.chdir(folder)
        assert main(["scenario", program, *traces, "--window", "3s", "-o", str(results)]) == 0
    lines = out.getvalue().splitlines()
    with _captured() as out:
        assert main(["scenario", program, *traces, "--window", "3s", "--json"]) == 0
    return results, lines, [json.loads(line) for line in out.getvalue().splitlines()]


def _captured():
    return contextlib.redirect_stdout(io.StringIO())


def test_show_draws_the_trace_of_a_printed_match_line(printed, tmp_path, capsys):
    results, lines, _ = printed
    place = lines[1].split()[0]  # SOURCE#NAME:START-END, as printed
    assert main(["show", str(results), "--trace", place, "-o", str(tmp_path / "m.png")]) == 0
    name = place.rsplit(":", 1)[0].rsplit("#", 1)[1]
    assert capsys.readouterr().err.startswith(f"scenegrep: match 0 of {name} drawn in ")


def test_the_json_rows_names_mean_their_trace(printed, tmp_path, capsys):
    """Every name a JSON row gives means its trace in the results file; ``show`` draws one."""
    from scenegrep.dataset.results import Results

    results, _, json_rows = printed
    table = Results.read(results).table.to_pylist()
    for row in json_rows:
        for field in ("trace_id", "name", "source"):
            assert choose_trace(table, row[field]) == TraceChoice(row["trace_id"])
    row = json_rows[2]
    assert main(["show", str(results), "--trace", row["source"], "-o", str(tmp_path / "t.png")]) == 0
    assert f"match 0 of {row['name']} drawn" in capsys.readouterr().err


def test_show_unknown_trace_lists_the_choices(printed, tmp_path, capsys):
    results, _, json_rows = printed
    assert main(["show", str(results), "--trace", "fig1", "-o", str(tmp_path / "t.png")]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("scenegrep: error: --trace fig1: the results have no such trace; traces: ")
    assert all(f"{row['name']} ({row['trace_id']})" in line for row in json_rows)
