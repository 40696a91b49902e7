"""``--follow`` and MCAP on standard input (issue 18, item 3): matches printed as their frames are written.

Acceptance: another process (tests/live_writer.py) writes an MCAP file message by message, each record
in two writes, while ``scenegrep ... --follow`` reads it; every match line must reach this test within
100 ms of the last byte of its window's last frame (both times on the system's monotonic clock). The
follower polls every 10 ms (``POLL_SECONDS``), so 10 ms of the budget go to polling at worst; the rest
is decoding, the query and the pipe.
"""

from __future__ import annotations

import base64
import io
import json
import signal
import struct
import subprocess
import sys
import threading
import time
from pathlib import Path
from types import SimpleNamespace

import pytest
from mcap.writer import CompressionType, Writer

from scenegrep import readers
from scenegrep.streams.latency import Latency
from scenegrep.cli.main import main
from scenegrep.readers.mcap_documents import STREM_SCHEMA, TRACE_SCHEMA
from scenegrep.readers.mcap_follow import MAGIC, RawMessage, follow_mcap
from scenegrep.writers.trace_json import trace_document, write_trace_json
from scenegrep.writers.trace_parquet import write_map_parquet

from .live_writer import has_open
from scenegrep.writers.ros_bag import TRACKED_TOPIC, write_detections2d, write_tracked
from .scenario.worked_example import worked_map, worked_trace

FIG1 = "examples/queries/fig1_lane_change.scenic"
WRITER = Path(__file__).with_name("live_writer.py")
BUDGET = 0.1
AV2 = "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede"


def strem_frame(index: int, kind: str) -> dict:
    """A STREM frame with one ``kind`` box on channel ``cam``."""
    box = {"type": "@stremf/bbox/aabb", "region": {"center": {"x": 5, "y": 5}, "dimensions": {"w": 2, "h": 2}}}
    sample = {
        "type": "@stremf/sample/detection",
        "channel": "cam",
        "image": {"path": f"{index}.png", "dimensions": {"width": 10, "height": 10}},
        "annotations": [{"class": kind, "score": 1.0, "bbox": box}],
    }
    return {"index": index, "samples": [sample]}


KINDS = ["car", "car", "pedestrian", "bus", "car", "pedestrian", "car", "car", "pedestrian"]
"""Frames of the SpRE stream: ``[[:car:]][[:pedestrian:]]`` ends at each pedestrian after a car."""


def documents(topic: str, schema: str, bodies: list[dict]) -> list[RawMessage]:
    """JSON document messages, one per 100 ms of log time."""
    return [RawMessage(topic, schema, "", b"", "json", k * 10**8, json.dumps(b).encode()) for k, b in enumerate(bodies)]


def strem_messages() -> list[RawMessage]:
    bodies = [{"version": "0.2.0", "frames": [strem_frame(k, kind)]} for k, kind in enumerate(KINDS)]
    return documents("/detections", STREM_SCHEMA, bodies)


def trace_messages() -> list[RawMessage]:
    trace = worked_trace()
    return documents(
        "/trace", TRACE_SCHEMA, [trace_document(trace.slice_frames(k, k + 1)) for k in range(trace.n_frames)]
    )


def mcap_file(messages: list[RawMessage], finish: bool = True, noise: bool = False, chunks: bool = True) -> bytes:
    """An MCAP file of the messages in lz4 chunks of a few messages (or unchunked)."""
    output = io.BytesIO()
    writer = Writer(output, chunk_size=2000, compression=CompressionType.LZ4, use_chunking=chunks)
    writer.start("", "test")
    channels: dict[str, int] = {}
    if noise:
        channels["/noise"] = writer.register_channel("/noise", "cdr", 0)
    for message in messages:
        if message.topic not in channels:
            schema = writer.register_schema(message.schema_name, message.schema_encoding, message.schema_data)
            channels[message.topic] = writer.register_channel(message.topic, message.message_encoding, schema)
        time = message.log_time
        writer.add_message(channels[message.topic], log_time=time, data=message.data, publish_time=time)
        if noise:
            writer.add_message(channels["/noise"], log_time=time, data=b"\x00", publish_time=time)
    writer.finish() if finish else writer.flush()
    return output.getvalue()


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("live")
    write_map_parquet(worked_map(), folder / "map.parquet")
    write_trace_json(worked_trace(), folder / "table2.json")
    return folder


def follow(folder: Path, name: str, messages: list[RawMessage], command: list[str], pause: float) -> SimpleNamespace:
    """Run the writer and ``scenegrep COMMAND --follow`` on ``folder/name``: the writer's time of each
    message, each output line with its arrival time, and scenegrep's exit code and stderr."""
    plan = folder / f"{name}.json"
    entries = [
        message._asdict() | {"schema_data": _base64(message.schema_data), "data": _base64(message.data)}
        for message in messages
    ]
    plan.write_text(json.dumps({"pause": pause, "messages": entries}))
    target = folder / f"{name}.mcap"
    writer = subprocess.Popen(
        [sys.executable, str(WRITER), str(target), str(plan)], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    assert writer.stdout.readline().strip() == "ready"
    command = [sys.executable, "-m", "scenegrep", *command, "--follow", str(target), "--latency", "--idle-timeout", "5"]
    scenegrep = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    lines: list[tuple[str, float]] = []

    def read() -> None:
        for line in scenegrep.stdout:
            lines.append((line.rstrip("\n"), time.monotonic()))

    reader = threading.Thread(target=read)
    reader.start()
    assert has_open(scenegrep.pid, target, 30), "scenegrep never opened the followed file"
    writer.stdin.write("go\n")
    writer.stdin.flush()
    written = [float(line.split()[1]) for line in writer.stdout if line.strip() != "done"]
    assert writer.wait(10) == 0
    code = scenegrep.wait(10)
    reader.join()
    return SimpleNamespace(written=written, lines=lines, code=code, err=scenegrep.stderr.read())


def _base64(data: bytes) -> str:
    return base64.b64encode(data).decode()


def assert_in_time(run: SimpleNamespace, last_frame) -> None:
    """Every line arrived after, and within the budget of, the writing of its last frame's message."""
    assert run.lines
    for line, arrival in run.lines:
        written = run.written[last_frame(line)]
        assert written < arrival < written + BUDGET, (line, arrival - written)


@pytest.mark.slow
def test_scenario_follow_prints_each_window_within_100ms_of_its_last_frame(files, capsys):
    main(["scenario", FIG1, str(files / "table2.json"), "--window", "3", "--map", str(files / "map.parquet"), "--all"])
    offline = capsys.readouterr().out.splitlines()
    args = ["scenario", FIG1, "--window", "3", "--map", str(files / "map.parquet"), "--all"]
    run = follow(files, "scenario", trace_messages(), args, pause=0.15)
    assert run.code == 0, run.err
    live = [line for line, _ in run.lines]
    source = str(files / "table2.json")  # each line's SOURCE#: the followed file's, as given
    assert [line.replace(source, str(files / "scenario.mcap"), 1) for line in offline] == live and len(offline) == 3
    assert_in_time(run, lambda line: int(line.split()[0].rsplit("-", 1)[1]))
    assert "scenegrep: latency: 5 frames, median " in run.err and "; 3 matches, median " in run.err


def test_spre_follow_prints_each_match_within_100ms_of_its_last_frame(files):
    run = follow(files, "spre", strem_messages(), ["spre", "[[:car:]][[:pedestrian:]]"], pause=0.1)
    path = str(files / "spre.mcap")
    ends = [k for k, kind in enumerate(KINDS) if kind == "pedestrian" and KINDS[k - 1] == "car"]
    assert run.code == 0, run.err
    assert [line for line, _ in run.lines] == [f"{path}:{k - 1}-{k}" for k in ends]
    assert_in_time(run, lambda line: int(line.rsplit("-", 1)[1]))
    assert f"latency: {len(KINDS)} frames" in run.err and f"; {len(ends)} matches" in run.err


@pytest.fixture(scope="module")
def ros_run(real_data, files) -> SimpleNamespace:
    """TrackedObjects + /tf of 20 frames of an AV2 log written live (scenegrep.writers.ros_bag)
    while ``spre --space topdown --online '[[:pedestrian:]]' --follow`` reads them: the run, the
    frames with a pedestrian (from the raw states) and each frame's last message."""
    trace = readers.read_trace(real_data / AV2).slice_frames(0, 20)
    write_tracked(trace, files / "av2_whole.mcap")
    messages = list(follow_mcap(files / "av2_whole.mcap"))
    command = ["spre", "--space", "topdown", "--online", "[[:pedestrian:]]"]
    run = follow(files, "av2", messages, command, pause=0.04)
    pedestrian = trace.objects.kinds()[trace.states.object] == "pedestrian"
    run.frames = sorted(set(trace.states.frame[pedestrian].tolist()))
    by_topic: dict[str, list[int]] = {}
    for position, message in enumerate(messages):
        by_topic.setdefault(message.topic, []).append(position)
    run.last = [max(positions) for positions in zip(by_topic["/tf"], by_topic[TRACKED_TOPIC])]
    run.n_frames = trace.n_frames
    return run


@pytest.mark.slow
@pytest.mark.real_data
def test_spre_follow_on_a_ros_bag_prints_each_frame_with_a_pedestrian(ros_run, files):
    assert ros_run.code == 0, ros_run.err
    assert [line for line, _ in ros_run.lines] == [f"{files / 'av2.mcap'}:{k}-{k}" for k in ros_run.frames]
    assert ros_run.frames and f"latency: {ros_run.n_frames} frames" in ros_run.err
    for line, arrival in ros_run.lines:  # never before its frame's last message was written
        assert arrival > ros_run.written[ros_run.last[int(line.rsplit("-", 1)[1])]]


@pytest.mark.slow
@pytest.mark.real_data
def test_spre_follow_on_a_ros_bag_prints_each_frame_within_100ms(ros_run):
    assert_in_time(ros_run, lambda line: ros_run.last[int(line.rsplit("-", 1)[1])])


def test_sigterm_ends_following_cleanly(files):
    """A writer that never finishes: SIGTERM stops the follower, which keeps its matches and exit code."""
    target = files / "unfinished.mcap"
    target.write_bytes(mcap_file(strem_messages(), finish=False))
    command = [sys.executable, "-m", "scenegrep", "spre", "[[:car:]][[:pedestrian:]]", "--follow", str(target)]
    process = subprocess.Popen([*command, "--latency"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = process.stdout.readline()
    assert first.strip() == f"{target}:1-2"
    time.sleep(0.1)
    process.send_signal(signal.SIGTERM)
    out, err = process.communicate(timeout=10)
    assert process.returncode == 0 and "Traceback" not in err
    assert err.startswith("scenegrep: latency: ")


def stdin_run(monkeypatch, capsys, data: bytes, args: list[str]) -> tuple[int, list[str], str]:
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(data)))
    code = main(args)
    out, err = capsys.readouterr()
    return code, out.splitlines(), err


def test_mcap_on_standard_input_with_other_topics_noted(monkeypatch, capsys, files):
    data = mcap_file(strem_messages(), noise=True)
    code, lines, err = stdin_run(monkeypatch, capsys, data, ["spre", "--online", "[[:car:]][[:pedestrian:]]"])
    assert (code, lines) == (0, ["-:1-2", "-:4-5", "-:7-8"])
    assert err.count("note: skipped topics of unsupported types: /noise") == 1 and "latency" not in err
    data = mcap_file(trace_messages())
    args = ["scenario", FIG1, "--online", "--window", "3", "--map", str(files / "map.parquet")]
    code, lines, _ = stdin_run(monkeypatch, capsys, data, args)
    assert code == 0 and [line.split()[0] for line in lines] == ["-#table2:0-2", "-#table2:1-3", "-#table2:2-4"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["spre", "x", "--idle-timeout", "2"], "--idle-timeout S needs --follow FILE"),
        (["spre", "x", "--follow", "F", "--idle-timeout", "nan"], "nan is not a positive number of seconds"),
        (["spre", "x", "--follow", "F", "--idle-timeout", "0"], "0.0 is not a positive number of seconds"),
        (["spre", "x", "other.json", "--follow", "F"], "give no other FILE"),
        (["scenario", FIG1, "other.json", "--window", "3", "--follow", "F"], "give no DATA"),
        (["spre", "[[:car:]]", "--follow", "{missing}"], "missing.mcap: cannot read: No such file"),
        (["spre", "[[:car:]]", "--follow", "{table2}"], "table2.json: not an MCAP stream"),
        (["scenario", FIG1, "--window", "3", "--follow", "{table2}"], "table2.json: not an MCAP stream"),
    ],
)
def test_bad_live_options_and_inputs_are_one_line_errors(files, capsys, args, message):
    paths = {"missing": files / "missing.mcap", "table2": files / "table2.json"}
    code = main([arg.format(**paths) for arg in args])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("scenegrep: error: ") and err.count("\n") == 1 and message in err


def test_a_bad_document_in_a_message_names_its_topic_and_log_time(monkeypatch, capsys):
    bad = RawMessage("/detections", STREM_SCHEMA, "", b"", "json", 3 * 10**8, b'{"version": "0.2.0", "frames": [{')
    messages = strem_messages()[:3] + [bad]
    code, lines, err = stdin_run(monkeypatch, capsys, mcap_file(messages), ["spre", "--online", "[[:car:]]"])
    assert code == 2 and lines == ["-:0-0", "-:1-1"] and err.startswith("scenegrep: error: /detections @ 300000000 ns")


def test_latency_line_gives_median_and_p99_in_milliseconds():
    latency = Latency(time.perf_counter, keep=True)
    latency.frames.extend([0.004, 0.001, 0.003, 0.002])
    latency.matches.append(0.0025)
    assert latency.line() == ("latency: 4 frames, median 2.50 ms, p99 3.97 ms; 1 match, median 2.50 ms, p99 2.50 ms")
    assert Latency(time.perf_counter, keep=False).line() == "latency: 0 frames; 0 matches"


@pytest.mark.parametrize("pattern", ["[[:car:]]+", "[[:car:]][[:pedestrian:]]", "[[:pedestrian:]]"])
def test_detection2d_messages_on_stdin_give_the_stream_answers(conformance_dir, tmp_path, monkeypatch, capsys, pattern):
    """A STREM stream written as vision_msgs/Detection2DArray (scenegrep.writers.ros_bag), piped in:
    the matches ``spre --online`` finds on the STREM file itself."""
    stream = conformance_dir / "strem/data/seq_a.json"
    write_detections2d(readers.read_trace(stream), tmp_path / "boxes.mcap")
    main(["spre", "--online", pattern, str(stream)])
    expected = ["-:" + line.rsplit(":", 1)[1] for line in capsys.readouterr().out.splitlines()]
    code, lines, _ = stdin_run(
        monkeypatch, capsys, (tmp_path / "boxes.mcap").read_bytes(), ["spre", "--online", pattern]
    )
    assert lines == expected and code == (0 if expected else 1)


def test_a_second_camera_arriving_after_the_frame_topic_is_dropped_with_a_note(
    conformance_dir, tmp_path, monkeypatch, capsys
):
    """Two cameras, one message each per frame. Arriving one message at a time, a frame is complete at
    its frame-topic message, so the other camera's message of the same stamp comes late (dropped, with
    a note; no traceback); arriving together (a backlog), they are framed as the offline reader does."""
    write_detections2d(readers.read_trace(conformance_dir / "strem/data/channels.json"), tmp_path / "two.mcap")
    data = (tmp_path / "two.mcap").read_bytes()
    main(["spre", "--online", ".", str(tmp_path / "two.mcap")])
    offline = [line.rsplit(":", 1)[1] for line in capsys.readouterr().out.splitlines()]
    code, lines, err = stdin_run(monkeypatch, capsys, data, ["spre", "--online", "."])
    assert (code, lines) == (0, [f"-:{span}" for span in offline]) and "dropped" not in err
    unchunked = mcap_file(list(follow_mcap(tmp_path / "two.mcap")), chunks=False)
    monkeypatch.setattr(sys, "stdin", SimpleNamespace(buffer=OneRecordPerRead(unchunked)))
    code = main(["spre", "--online", "."])
    out, err = capsys.readouterr()
    assert code == 0 and out and "Traceback" not in err
    assert "box messages arrived after their frame was built and were dropped" in err


class OneRecordPerRead:
    """Standard input that hands out an MCAP stream one record per read."""

    def __init__(self, data: bytes):
        self.data = data
        self.position = 0

    def read1(self, size: int = -1) -> bytes:
        start = self.position
        if start == 0:
            end = len(MAGIC)
        elif start + 9 <= len(self.data):
            end = start + 9 + struct.unpack_from("<Q", self.data, start + 1)[0]
        else:
            end = len(self.data)
        piece = self.data[start : end if size < 0 else min(end, start + size)]
        self.position += len(piece)
        return piece

    read = read1


def test_idle_timeout_ends_following_a_writer_that_stopped(files, capsys):
    target = files / "stopped.mcap"
    target.write_bytes(mcap_file(strem_messages(), finish=False))
    started = time.monotonic()
    code = main(["spre", "[[:car:]][[:pedestrian:]]", "--follow", str(target), "--idle-timeout", "0.3"])
    assert code == 0 and 0.3 <= time.monotonic() - started < 5
    assert capsys.readouterr().out.splitlines() == [f"{target}:{k - 1}-{k}" for k in (2, 5, 8)]
