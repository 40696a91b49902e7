"""SpRE over streams (:mod:`scenegrep.streams.spre`): how a match is written, the stream searches,
and the warnings for the names a live stream lacks, said once it has ended (in the Python API and
on stderr, ``spre --online`` on standard input and ``--follow``)."""

from __future__ import annotations

import io
import json
from pathlib import Path

import pytest

from scenegrep import readers
from scenegrep.cli.main import main
from scenegrep.readers.strem_json import iter_documents
from scenegrep.spre import Match, SearchOptions, SeenNames, TraceSearch, compile_query, search_stream
from scenegrep.streams.live import open_live
from scenegrep.streams.spre import LiveSearch, MatchFormat, input_searches, match_record

REPO = Path(__file__).resolve().parents[2]
STREAM = REPO / "examples/stream.json"
QUERY = "[[:car:]] | [[:cra:]]"


@pytest.fixture(scope="module")
def document() -> dict:
    return json.loads(STREAM.read_text())


@pytest.fixture(scope="module")
def names(document) -> dict:
    """Classes and channels of the stream, per frame, from the raw document."""
    frames = document["frames"]
    return {
        "classes": [{a["class"] for s in f["samples"] for a in s["annotations"]} for f in frames],
        "channels": sorted({s["channel"] for f in frames for s in f["samples"]}),
    }


def lines(document: dict, frames: slice = slice(None)) -> bytes:
    """The stream's frames as one STREM document per line, as a live writer sends them."""
    return b"".join(
        json.dumps({"version": document["version"], "frames": [f]}).encode() + b"\n" for f in document["frames"][frames]
    )


def class_warning(classes) -> str:
    return f"no trace searched has class 'cra' (classes there: {', '.join(sorted(classes))})"


def test_each_form_of_a_match():
    match = Match(2, 5, 12, 14, 1.2, 1.4, {"p": "7"})
    assert MatchFormat().text(match, "a.json", trace=None) == "a.json:12-14"
    trace = readers.read_trace(STREAM)
    assert MatchFormat().text(match, "a.json", trace=trace) == f"a.json#{trace.name}:12-14"
    assert MatchFormat(strem=True).text(match, "a.json", "a.json") == "a.json:12..15"
    assert MatchFormat(strem=True).text(match, "-") == "12..15"
    record = match_record(match, "-", trace)
    assert record == {
        "source": "-",
        "start_frame": 12,
        "end_frame": 14,
        "start_time": 1.2,
        "end_time": 1.4,
        "trace": trace.name,
        "bound": {"p": "7"},
    }
    assert json.loads(MatchFormat(json=True).text(match, "-", trace=trace)) == record
    plain = match_record(match._replace(bound=None), "-")
    assert "trace" not in plain and "bound" not in plain
    exported = json.loads(MatchFormat(export=True).text(match, "a.json", trace=trace))
    assert [f["index"] for f in exported["frames"]] == trace.frame_index[2:5].tolist()


def test_seen_names_of_chunks_are_those_of_the_whole_trace(names):
    """Gathered chunk by chunk (as a live stream arrives), skipped frames left out, the warnings
    are those of the trace those frames make, read whole."""
    query = compile_query(QUERY)
    trace = readers.read_trace(STREAM)
    for skip, size in [(0, 1), (0, 7), (25, 4), (trace.n_frames - 1, 3)]:
        seen = SeenNames()
        chunks = [trace.slice_frames(k, min(k + size, trace.n_frames)) for k in range(0, trace.n_frames, size)]
        options = SearchOptions(skip=skip, channels=("side",))
        list(search_stream(query, chunks, options, seen))
        whole = TraceSearch(query, trace, options).warnings
        assert seen.warnings(query.tree, query.compat, options.channels) == whole
        assert whole[0] == class_warning(set().union(*names["classes"][skip:]))
        assert (
            whole[1] == f"no trace searched has image channel 'side' (channels there: {', '.join(names['channels'])})"
        )
        assert seen.frames == trace.n_frames - skip


def test_input_searches_name_the_input_in_their_warnings(names):
    (search,) = input_searches(compile_query(QUERY), str(STREAM), SearchOptions(), online=False)
    assert search.prefix == str(STREAM) and search.warnings == [
        f"{STREAM}: {class_warning(set().union(*names['classes']))}"
    ]
    assert [m.first_index for m in search.matches] == [m.first_index for m in search.search.offline()]


def test_a_live_search_warns_once_the_stream_ended(document, names):
    live = open_live(None, iter_documents, stdin=io.BytesIO(lines(document, slice(0, 3))))
    search = LiveSearch(compile_query(QUERY), live, SearchOptions())
    assert search.warnings == []  # nothing read yet
    found = list(search.matches)
    assert len(found) == sum("car" in c for c in names["classes"][:3]) and live.latency.found == bool(found)
    assert search.warnings == [f"<stdin>: {class_warning(set().union(*names['classes'][:3]))}"]
    empty = LiveSearch(compile_query(QUERY), open_live(None, iter_documents, stdin=io.BytesIO(b"")), SearchOptions())
    assert list(empty.matches) == [] and empty.warnings == []


def test_spre_online_on_stdin_warns_at_the_end(document, names, capsys, monkeypatch):
    monkeypatch.setattr("sys.stdin", io.TextIOWrapper(io.BytesIO(lines(document))))
    assert main(["spre", "--online", "[[:cra:]]", "-c", "side"]) == 1
    out, err = capsys.readouterr()
    channels = ", ".join(names["channels"])
    assert out == "" and err.splitlines() == [
        f"scenegrep: warning: <stdin>: {class_warning(set().union(*names['classes']))}",
        f"scenegrep: warning: <stdin>: no trace searched has image channel 'side' (channels there: {channels})",
    ]
    monkeypatch.setattr("sys.stdin", io.TextIOWrapper(io.BytesIO(lines(document))))
    assert main(["spre", "--online", "-q", "[[:cra:]]"]) == 1
    assert capsys.readouterr() == ("", "")


def test_spre_follow_warns_at_the_end_naming_the_file(names, capsys, monkeypatch):
    """``examples/stream.mcap`` holds ``examples/stream.json``'s frames (README)."""
    monkeypatch.chdir(REPO)
    assert main(["spre", "--follow", "examples/stream.mcap", "[[:car:]]", "--latency"]) == 0
    out, err = capsys.readouterr()
    assert out and "warning" not in err  # every name known
    assert main(["spre", "--follow", "examples/stream.mcap", "[[:cra:]]"]) == 1
    expected = f"scenegrep: warning: examples/stream.mcap: {class_warning(set().union(*names['classes']))}\n"
    assert capsys.readouterr() == ("", expected)
