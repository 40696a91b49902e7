"""ROS 2 bags (MCAP) of Autoware TrackedObjects + /tf written from real traces read back as the
same traces; dropped, out-of-order, truncated, mistyped and unknown messages."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from scenegrep import readers
from scenegrep.cli.main import main
from scenegrep.errors import UserError
from scenegrep.model import LabelTrace, TraceSource, concatenate
from scenegrep.model.geometry import heading_difference
from scenegrep.model.trace import EGO_SIZE_UNKNOWN
from scenegrep.readers.ros.bag import bag_messages
from scenegrep.readers.ros.framing import FrameBuilder
from scenegrep.readers.ros.options import BagOptions
from scenegrep.readers.ros.reader import read_trace

from scenegrep.writers.foxglove import write_scene_updates
from scenegrep.writers.ros_bag import TRACKED_TOPIC as TOPIC
from scenegrep.writers.ros_bag import ORIGIN_NS, BagWriter, frame_stamps, write_tracked

from .ros_writer import read_back_id, write_faulty

NUSCENES = "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-0061.pkl"
ORIGIN = ORIGIN_NS


@pytest.fixture(scope="module")
def av2(av2_bag) -> tuple[LabelTrace, Path]:
    return av2_bag


@pytest.fixture(scope="module")
def short(av2, tmp_path_factory) -> tuple[LabelTrace, Path]:
    """The first 25 frames of the AV2 log, the bag of the variant tests."""
    trace = av2[0].slice_frames(0, 25)
    return trace, tmp_path_factory.mktemp("short")


def assert_same(
    original: LabelTrace,
    bag: LabelTrace,
    frames: np.ndarray | None = None,
    id_of=read_back_id,
    velocity: bool = True,
    ego_size: bool = False,
) -> None:
    """``bag`` holds ``original``'s frames (all, or the positions ``frames``): the same objects
    (``id_of``: the id the bag gives an original id), kinds, positions (1e-6 m), headings, sizes
    and velocities (unless the messages carry none: ``velocity``; the ego's pose only, and its
    size when the reader was given it: ``ego_size``, else unknown and said so), times."""
    if frames is not None:
        keep = np.zeros(original.n_frames, dtype=bool)
        keep[frames] = True
        original = original.select_frames(keep)
    assert bag.n_frames == original.n_frames
    np.testing.assert_allclose(bag.frame_time, original.frame_time - original.frame_time[0], atol=1e-9)
    ids = ["ego" if i == original.ego else id_of(i) for i in original.objects.id]
    rows = bag.objects.row_of()
    present = np.bincount(original.states.object, minlength=original.n_objects) > 0
    assert sorted(rows) == sorted(np.array(ids)[present].tolist())
    new_row = np.array([rows.get(i, -1) for i in ids])
    kinds = dict(zip(bag.objects.id, bag.objects.kinds()))
    for i, kind in zip(ids, original.objects.kinds()):
        if i in kinds and i != "ego":
            assert kinds[i] == kind, i
    s = original.states
    order = np.lexsort((new_row[s.object], s.frame))
    b = bag.states
    assert len(b) == len(s)
    np.testing.assert_array_equal(b.frame, s.frame[order])
    np.testing.assert_array_equal(b.object, new_row[s.object[order]])
    for column in ("x", "y"):
        np.testing.assert_allclose(getattr(b, column), getattr(s, column)[order], rtol=0, atol=1e-6)
    np.testing.assert_allclose(b.z, np.nan_to_num(s.z[order]), rtol=0, atol=1e-6)
    assert np.abs(heading_difference(b.heading, s.heading[order])).max() < 1e-9
    not_ego = b.object != rows["ego"]
    for column in ("length", "width", "height", "vx", "vy")[: 5 if velocity else 3]:
        compared = np.ones(len(b), bool) if ego_size and column in ("length", "width", "height") else not_ego
        np.testing.assert_allclose(
            getattr(b, column)[compared], getattr(s, column)[order][compared], rtol=0, atol=1e-6, equal_nan=True
        )
    if not ego_size:  # /tf carries no ego size
        assert np.isnan(b.length[~not_ego]).all() and "--ego-size" in bag.attributes[EGO_SIZE_UNKNOWN]
    assert (EGO_SIZE_UNKNOWN in bag.attributes) != ego_size
    if not velocity:
        assert np.isnan(b.vx).all()


def test_tracked_objects_and_tf_give_back_the_trace(av2):
    trace, path = av2
    bag = readers.read_trace(path)
    assert readers.detect_format(path) == "ros-bag"
    assert bag.ego == "ego" and bag.attributes["time_origin_ns"] == ORIGIN
    assert_same(trace, bag)


def test_given_the_ego_size_the_ego_comes_back_whole(av2):
    """With ``ego_size`` (``--ego-size``) the AV2 ego's recorded size comes back too (AV2 gives
    one size to the ego: read from the log's own rows), and the trace no longer says it is unknown."""
    trace, path = av2
    ego = trace.states.object == trace.object_index(trace.ego)
    size = tuple(float(np.unique(getattr(trace.states, c)[ego]).item()) for c in ("length", "width", "height"))
    assert_same(trace, read_trace(path, BagOptions(ego_size=size)), ego_size=True)


@pytest.mark.parametrize(
    ("given", "reason"),
    [
        ("0,1.9,1.5", "three lengths over 0"),
        ("-4.9,1.9,1.5", "three lengths over 0"),
        ("nan,1.9,1.5", "three lengths over 0"),
        ("inf,1.9,1.5", "three lengths over 0"),
        ("4.9,1.9,101", "at most 100 m"),
        ("4.9,1.9", "LENGTH,WIDTH,HEIGHT"),
        ("4.9,1.9,1.5,1", "LENGTH,WIDTH,HEIGHT"),
        ("4.9,wide,1.5", "LENGTH,WIDTH,HEIGHT in metres"),
        ("", "LENGTH,WIDTH,HEIGHT"),
    ],
)
def test_a_bad_ego_size_is_one_line(av2, given, reason, capsys):
    assert main(["info", str(av2[1]), f"--ego-size={given}"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("scenegrep: error: --ego-size") and reason in err and err.count("\n") == 1


@pytest.mark.slow
def test_nuscenes_scene_0061_gives_back_the_trace(real_data, tmp_path):
    trace = readers.read_trace(real_data / NUSCENES)
    write_tracked(trace, tmp_path / "n.mcap", ORIGIN)
    assert_same(trace, readers.read_trace(tmp_path / "n.mcap"))


def test_a_bag_directory_reads_as_its_mcap_file(av2, tmp_path):
    trace, path = av2
    (tmp_path / "metadata.yaml").write_text("rosbag2_bagfile_information:\n  storage_identifier: mcap\n")
    (tmp_path / "rec_0.mcap").write_bytes(path.read_bytes())
    assert readers.detect_format(tmp_path) == "ros-bag"
    assert_same(trace, readers.read_trace(tmp_path))


def test_fed_one_message_at_a_time_each_chunk_is_one_frame_and_all_is_the_offline_trace(short):
    trace, folder = short
    write_faulty(trace, folder / "late.mcap", ORIGIN, late_tf=True)  # each /tf after its frame's objects
    builder = FrameBuilder(BagOptions(), "late", TraceSource(str(folder / "late.mcap"), "ros-bag"))
    chunks = []
    for message in bag_messages(folder / "late.mcap"):
        chunk = builder.feed([message])
        if chunk is not None:
            assert chunk.n_frames == 1
            chunks.append(chunk)
    assert len(chunks) == trace.n_frames  # each frame once its /tf arrived, the last one too
    assert builder.finish() is None
    online = concatenate(chunks)
    assert_same(trace, online)
    assert online.equals(read_trace(folder / "late.mcap"))


def test_dropped_messages_leave_out_their_frames(short):
    trace, folder = short
    write_faulty(trace, folder / "drop.mcap", ORIGIN, drop=frozenset({0, 7, 8}))
    assert_same(trace, readers.read_trace(folder / "drop.mcap"), np.setdiff1d(np.arange(25), [0, 7, 8]))


def test_frames_at_a_rate_hold_the_latest_message_of_each_window(short):
    trace, folder = short
    write_tracked(trace, folder / "rate.mcap", ORIGIN)
    bag = read_trace(folder / "rate.mcap", BagOptions(rate=5.0))
    stamps = frame_stamps(trace, ORIGIN)
    window = (stamps - stamps[0]) // 200_000_000
    latest = np.flatnonzero(np.r_[window[1:] != window[:-1], True])
    np.testing.assert_allclose(bag.frame_time, np.unique(window) * 0.2)
    objects = bag.states.object != bag.object_index("ego")
    expected = trace.select_frames(np.isin(np.arange(25), latest))
    np.testing.assert_allclose(
        np.sort(bag.states.x[objects]),
        np.sort(expected.states.x[expected.states.object != expected.object_index(expected.ego)]),
        atol=1e-6,
    )


def test_a_missing_transform_names_the_topic_and_log_time(short, tmp_path):
    trace, _ = short
    path = tmp_path / "no_tf.mcap"
    write_tracked(trace, path, ORIGIN)
    kept = [m for m in bag_messages(path) if not (m.topic == "/tf" and m.log_time > frame_stamps(trace, ORIGIN)[20])]
    rewritten = tmp_path / "cut.mcap"
    _copy(kept, rewritten)
    with pytest.raises(UserError) as error:
        readers.read_trace(rewritten)
    log_time = int(frame_stamps(trace, ORIGIN)[20]) + 20_000_000  # frame 20's /tf was logged after its stamp
    assert f"topic {TOPIC}, message at log time {log_time} ns: no transform map <- base_link" in error.value.one_line()


def test_unknown_types_are_skipped_with_a_note(short, tmp_path, capsys):
    trace, _ = short
    path = tmp_path / "unknown.mcap"
    write_tracked(trace, path, ORIGIN)
    messages = list(bag_messages(path))
    point = messages[0]._replace(topic="/weird", schema_name="geometry_msgs/msg/Point", data=b"\0\1\0\0" + bytes(24))
    _copy([point, *messages], tmp_path / "more.mcap", extra_schema=b"float64 x\nfloat64 y\nfloat64 z")
    assert_same(trace, readers.read_trace(tmp_path / "more.mcap"))
    assert (
        "skipped topics of unsupported types: /weird (geometry_msgs/msg/Point, cdr encoding)" in capsys.readouterr().err
    )


@pytest.mark.parametrize("cut", [0.5, 0.999])
def test_a_truncated_bag_is_a_one_line_error(av2, tmp_path, cut):
    _, path = av2
    data = path.read_bytes()
    (tmp_path / "cut.mcap").write_bytes(data[: int(len(data) * cut)])
    with pytest.raises(UserError) as error:
        readers.read_trace(tmp_path / "cut.mcap")
    assert "truncated or corrupt" in error.value.one_line() and "\n" not in error.value.one_line()


def test_a_message_that_does_not_fit_its_schema_names_topic_and_log_time(short, tmp_path):
    trace, _ = short
    path = tmp_path / "bad.mcap"
    write_tracked(trace, path, ORIGIN)
    messages = list(bag_messages(path))
    target = next(i for i, m in enumerate(messages) if m.topic == TOPIC and i > 10)
    messages[target] = messages[target]._replace(data=messages[target].data[:200])
    _copy(messages, tmp_path / "short.mcap")
    with pytest.raises(UserError) as error:
        readers.read_trace(tmp_path / "short.mcap")
    assert f"topic {TOPIC}, message at log time {messages[target].log_time} ns: truncated" in error.value.one_line()


def _copy(messages, path: Path, extra_schema: bytes | None = None, encodings: dict | None = None) -> None:
    """Write raw messages again (their schemas from the messages themselves; message encodings
    ``cdr`` unless ``encodings`` names another for a topic)."""
    writer = BagWriter(path)
    mcap = writer.writer._writer
    schemas: dict[str, int] = {}
    channels: dict[str, int] = {}
    for m in messages:
        if m.topic not in channels:
            data = extra_schema if m.topic == "/weird" else m.schema_data
            schemas.setdefault(m.schema_name, mcap.register_schema(m.schema_name, m.schema_encoding, data))
            channels[m.topic] = mcap.register_channel(
                m.topic, (encodings or {}).get(m.topic, "cdr"), schemas[m.schema_name]
            )
        mcap.add_message(channels[m.topic], m.log_time, m.data, m.log_time)
    writer.close()


def test_info_lists_topics_and_the_options_reach_the_reader(av2, capsys):
    _, path = av2
    assert main(["info", "--json", str(path)]) == 0
    summary = json.loads(capsys.readouterr().out)
    topics = {t["topic"]: t for t in summary["topics"]}
    assert topics[TOPIC]["messages"] == 156 and topics["/tf"]["type"] == "tf2_msgs/msg/TFMessage"
    assert topics[TOPIC]["rate_hz"] == pytest.approx(155 / (summary["traces"][0]["duration_s"]), rel=1e-3)
    assert main(["info", "--json", str(path), "--rate", "2", "--ego-frame", "none"]) == 0
    trace = json.loads(capsys.readouterr().out)["traces"][0]
    assert trace["frames"] == 31 and trace["ego"] is None
    assert main(["info", str(path), "--rate", "2", "--frame-topic", TOPIC]) == 2
    assert "give --rate or --frame-topic, not both" in capsys.readouterr().err
    assert main(["info", str(path), "--rate", "nan"]) == 2


@pytest.mark.parametrize(
    "command",
    [["scene", "prog.scenic"], ["scenario", "prog.scenic", "--window", "3"], ["spre", "<car>"]],
)
def test_bag_options_with_a_dataset_are_refused_not_ignored(command, tmp_path, capsys):
    """A dataset's traces were read from their bags at ingest: options that change how bags are
    read cannot apply to them, so they are an error, not silently dropped; the defaults are fine."""
    options = (["--rate", "2"], ["--frame-topic", TOPIC], ["--topics", TOPIC], ["--ego-frame", "none"])
    for option in (*options, ["--ego-size", "4.9,1.9,1.5"]):
        assert main([*command, "--dataset", str(tmp_path), *option]) == 2
        assert "a dataset's traces were read at ingest" in capsys.readouterr().err
    assert main([*command, "--dataset", str(tmp_path), "--map-frame", "map"]) == 2  # no program, no catalog
    assert "read at ingest" not in capsys.readouterr().err


def test_detected_objects_with_odometry_give_back_every_observation(short):
    """DetectedObjects carry no ids: each observation is an object ``<stamp ns>:<rank>``; the ego
    comes from a nav_msgs/Odometry topic instead of /tf."""
    trace, folder = short
    path = folder / "detected.mcap"
    write_tracked(trace, path, ORIGIN, box_type="autoware_perception_msgs/DetectedObjects", ego_topic="/odom")
    bag = readers.read_trace(path)
    stamps = frame_stamps(trace, ORIGIN)
    s, b = trace.states, bag.states
    ego = trace.object_index(trace.ego)
    rows = bag.objects.row_of()
    for f in range(trace.n_frames):
        mine = np.flatnonzero((s.frame == f) & (s.object != ego))
        theirs = np.array([rows[f"{stamps[f]}:{k}"] for k in range(len(mine))])
        at = np.searchsorted(b.frame * bag.n_objects + b.object, f * bag.n_objects + theirs)
        for column in ("x", "y", "length", "width", "height", "vx", "vy"):
            np.testing.assert_allclose(getattr(b, column)[at], getattr(s, column)[mine], atol=1e-6, equal_nan=True)
        assert np.abs(heading_difference(b.heading[at], s.heading[mine])).max() < 1e-9
        assert bag.objects.kinds()[theirs].tolist() == trace.objects.kinds()[s.object[mine]].tolist()
    ego_rows = b.object == rows["ego"]
    for column in ("x", "y", "vx", "vy"):  # odometry gives the ego's twist too
        np.testing.assert_allclose(getattr(b, column)[ego_rows], getattr(s, column)[s.object == ego], atol=1e-6)
    assert bag.n_objects == np.sum(s.object != ego) + 1


def test_vision_detection3d_arrays_give_back_the_trace_with_its_ids_and_classes(short):
    trace, folder = short
    path = folder / "vision.mcap"
    write_tracked(trace, path, ORIGIN, box_type="vision_msgs/Detection3DArray")
    bag = readers.read_trace(path)
    assert_same(trace, bag, id_of=str, velocity=False)
    classes = dict(zip(trace.objects.id, trace.objects.category))
    assert all(classes[i] == c for i, c in zip(bag.objects.id, bag.objects.category) if i != "ego")


@pytest.mark.parametrize("encoding", ["json", "protobuf"])
def test_foxglove_scene_updates_give_back_the_trace(short, encoding):
    trace, folder = short
    path = folder / f"scene_{encoding}.mcap"
    write_scene_updates(trace, path, encoding)
    bag = readers.read_trace(path)
    assert_same(trace, bag, id_of=str, velocity=False)
    classes = dict(zip(trace.objects.id, trace.objects.category))
    assert all(classes[i] == c for i, c in zip(bag.objects.id, bag.objects.category) if i != "ego")


@pytest.mark.parametrize(
    ("data", "reason"),
    [
        (b"{not json", "not JSON"),
        (b'{"entities": 3}', "entities must be a list of objects"),
        (b'{"entities": [{"cubes": [{"size": {"x": "big"}}]}]}', "entities[0].cubes[0].size.x is str, not a number"),
        (b"[" * 100_000, "not JSON"),
    ],
)
def test_a_malformed_scene_update_names_topic_and_log_time(short, tmp_path, data, reason):
    trace, folder = short
    path = folder / "scene_json.mcap"
    if not path.exists():
        write_scene_updates(trace, path, "json")
    messages = list(bag_messages(path))
    target = next(i for i, m in enumerate(messages) if m.topic == "/markers" and i > 6)
    messages[target] = messages[target]._replace(data=data)
    _copy(messages, tmp_path / "bad.mcap", encodings={"/markers": "json"})
    with pytest.raises(UserError) as error:
        readers.read_trace(tmp_path / "bad.mcap")
    line = error.value.one_line()
    assert (
        f"topic /markers, message at log time {messages[target].log_time} ns: not a valid foxglove.SceneUpdate" in line
    )
    assert reason in line


def test_a_sqlite_bag_directory_reads_as_the_same_messages_in_mcap(short, tmp_path):
    """A rosbag2 directory of .db3 files (written with rosbags, the definitions stored) is read
    through rosbags into the same trace as the MCAP file of the same messages."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    trace, folder = short
    mcap = folder / "for_db3.mcap"
    write_tracked(trace, mcap, ORIGIN)
    messages = list(bag_messages(mcap))
    with Writer(tmp_path / "bag", version=9, storage_plugin=StoragePlugin.SQLITE3) as writer:
        connections = {}
        for m in messages:
            if m.topic not in connections:
                definition = m.schema_data.decode()
                connections[m.topic] = writer.add_connection(
                    m.topic, m.schema_name, msgdef=definition, rihs01="RIHS01_" + "0" * 64
                )
            writer.write(connections[m.topic], m.log_time, m.data)
    assert readers.detect_format(tmp_path / "bag") == "ros-bag"
    from_sqlite = readers.read_trace(tmp_path / "bag")
    assert_same(trace, from_sqlite)
    assert from_sqlite.states.equals(readers.read_trace(mcap).states)


@pytest.mark.parametrize(
    ("patch", "reason"),
    [
        (lambda data: b"\x00\x00" + data[2:], "big-endian CDR"),
        (lambda data: data[:28] + b"\xff\xff\xff\x7f" + data[32:], "objects (count too large)"),
        (lambda data: data[:12] + b"\xff\xff\xff\xff" + data[16:], "header.frame_id (length too large)"),
    ],
    ids=["endianness", "object count", "frame id length"],
)
def test_hostile_counts_are_refused_before_anything_is_sized_by_them(short, tmp_path, patch, reason):
    """A sequence count or string length past the message's bytes (each element takes one byte
    at least) is an error before any array is sized by it; so is big-endian CDR."""
    trace, folder = short
    path = folder / "hostile.mcap"
    if not path.exists():
        write_tracked(trace, path, ORIGIN)
    messages = list(bag_messages(path))
    target = next(i for i, m in enumerate(messages) if m.topic == TOPIC)
    messages[target] = messages[target]._replace(data=patch(messages[target].data))
    _copy(messages, tmp_path / "bad.mcap")
    with pytest.raises(UserError) as error:
        readers.read_trace(tmp_path / "bad.mcap")
    line = error.value.one_line()
    assert f"topic {TOPIC}, message at log time {messages[target].log_time} ns" in line and reason in line


def test_frame_topic_and_topics_choose_the_frames_and_the_boxes(short, tmp_path):
    """Two box topics of the same frames: each frame of ``--frame-topic`` holds both topics'
    boxes (the other topic's latest message at or before it); ``--topics`` reads only those named.
    (An id given on two topics is one object: its first row in a frame is kept.)"""
    trace, folder = short
    detected = "/perception/object_recognition/detection/objects"
    write_tracked(trace, tmp_path / "tracked.mcap", ORIGIN)
    write_tracked(trace, tmp_path / "detected.mcap", ORIGIN, box_type="autoware_perception_msgs/DetectedObjects")
    second = [m for m in bag_messages(tmp_path / "detected.mcap") if m.topic != "/tf"]
    both = sorted([*bag_messages(tmp_path / "tracked.mcap"), *second], key=lambda m: m.log_time)
    _copy(both, tmp_path / "both.mcap")
    framed = read_trace(tmp_path / "both.mcap", BagOptions(frame_topic=detected))
    assert framed.n_frames == trace.n_frames
    observations = len(trace.states) - trace.n_frames  # without the ego's
    assert framed.n_objects == (trace.n_objects - 1) + observations + 1  # UUIDs, one id per detection, the ego
    assert len(framed.states) == 2 * observations + trace.n_frames
    only = read_trace(tmp_path / "both.mcap", BagOptions(topics=(TOPIC,)))
    assert_same(trace, only)
    with pytest.raises(UserError, match="give --rate or --frame-topic, not both"):
        BagOptions(rate=2.0, frame_topic=TOPIC)
