"""Malformed and hostile inputs, one per class the fuzz suite found: each is a one-line
:class:`UserError` naming the file (and the place where known), decided before memory or time
is spent on what the file claims."""

from __future__ import annotations

import io
import json
import pickle
import shutil
import struct
import time

import numpy as np
import pyarrow as pa
import pyarrow.feather as feather
import pyarrow.parquet as pq
import pytest

from scenegrep import readers
from scenegrep.errors import UserError
from scenegrep.model.trace_arrow import METADATA_KEY
from scenegrep.readers.scenarionet import RestrictedUnpickler
from scenegrep.readers.tfrecord import masked_crc32c
from tests.conftest import REPO

SAMPLE = REPO / "examples/sample/s3_pass_pedestrian-000.parquet"


def _error(path) -> str:
    """The one line of the user error reading ``path`` gives (fails if it reads)."""
    with pytest.raises(UserError) as caught:
        list(readers.read_traces(path))
    line = caught.value.one_line()
    assert str(path) in line and "\n" not in line
    return line


def _json_trace(tmp_path, frames, **top) -> str:
    document = {"scenegrep": "trace", "version": 1, "objects": {"a": {"class": "Car"}}, "frames": frames, **top}
    path = tmp_path / "t.json"
    path.write_text(json.dumps(document).replace("Infinity", "1e999"))
    return _error(path)


def _at(x, time=None):
    frame = {"objects": {"a": {"position": [x, 0], "heading": 0.0}}}
    return frame if time is None else {**frame, "time": time}


def test_a_parquet_frame_position_of_2_31_is_refused_before_sizing_arrays(tmp_path):
    """The 20 KB file that asked for 32 GB: a frame position sized the frame arrays."""
    table = pq.read_table(SAMPLE)
    position = table.column("position").to_numpy().astype(np.int64)
    position[0] = 2**31
    table = table.set_column(table.column_names.index("position"), "position", pa.array(position))
    path = tmp_path / "huge.parquet"
    pq.write_table(table, path)
    start = time.monotonic()
    assert "2147483649 frames: a trace has 0 to 10000000 frames" in _error(path)
    assert time.monotonic() - start < 5


@pytest.mark.parametrize(
    "field, value, message",
    [
        ("attributes", 5, "trace attributes must be a mapping, found int"),
        ("name", ["x"], "trace name, lane ids and source paths must be strings"),
        ("map_source", [1, "opendrive", None], "trace name, lane ids and source paths must be strings"),
        ("objects", [[1]], "not enough values to unpack"),
    ],
)
def test_parquet_metadata_of_wrong_types_is_one_line(tmp_path, field, value, message):
    table = pq.read_table(SAMPLE)
    meta = json.loads(table.schema.metadata[METADATA_KEY])
    meta[field] = value
    path = tmp_path / "meta.parquet"
    pq.write_table(table.replace_schema_metadata({METADATA_KEY: json.dumps(meta)}), path)
    assert message in _error(path)


def test_parquet_columns_metadata_and_vocabularies_are_named(tmp_path):
    table = pq.read_table(SAMPLE)
    meta = json.loads(table.schema.metadata[METADATA_KEY])
    path = tmp_path / "t.parquet"
    pq.write_table(table.drop_columns(["vx"]), path)
    assert "missing column vx" in _error(path)
    del meta["ego"]
    pq.write_table(table.replace_schema_metadata({METADATA_KEY: json.dumps(meta)}), path)
    assert "missing metadata field ego" in _error(path)
    meta = json.loads(table.schema.metadata[METADATA_KEY])
    meta["lane_ids"] = meta["lane_ids"][1:]
    pq.write_table(table.replace_schema_metadata({METADATA_KEY: json.dumps(meta)}), path)
    assert "is not in the file's vocabulary" in _error(path)


@pytest.mark.parametrize("interval", [0, -0.1])
def test_a_non_positive_frame_interval_is_refused(tmp_path, interval):
    assert "frame_interval" in _json_trace(tmp_path, [_at(0), _at(1)], frame_interval=interval)


def test_times_must_increase(tmp_path):
    line = _json_trace(tmp_path, [_at(0, 0.0), _at(1, 0.2), _at(2, 0.1)])
    assert "frame 2 (index 2): time does not increase" in line


@pytest.mark.parametrize("value, shown", [(np.inf, "inf"), (-np.inf, "-inf"), (np.nan, "nan")])
def test_non_finite_positions_are_refused(tmp_path, value, shown):
    table = pq.read_table(SAMPLE)
    x = table.column("x").to_numpy().copy()
    x[5] = value
    path = tmp_path / "x.parquet"
    pq.write_table(table.set_column(table.column_names.index("x"), "x", pa.array(x)), path)
    assert f"x is {shown} (must be finite)" in _error(path)


def test_a_tfrecord_length_beyond_the_file_is_refused_before_reading(tmp_path):
    header = struct.pack("<Q", 2**40)
    path = tmp_path / "huge.tfrecord"
    path.write_bytes(header + struct.pack("<I", masked_crc32c(header)) + b"x" * 100)
    assert "truncated record data at byte 12: expected 1099511627780 bytes, the file ends after 100" in _error(path)


def test_an_empty_av2_annotation_table_is_refused(real_data, tmp_path):
    log = tmp_path / "log"
    shutil.copytree(real_data / "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede", log)
    annotations = log / "annotations.feather"
    annotations.chmod(0o644)
    feather.write_feather(feather.read_table(annotations).slice(0, 0), annotations)
    assert _error(log) == f"{annotations}: holds no rows"


def test_a_corrupt_feather_string_offset_is_refused_not_an_abort(real_data, tmp_path):
    """Feather buffers are used where they lie: a bit flip in a string column's offsets made Arrow
    allocate without bound (std::bad_alloc, an abort) when the column was converted."""
    log = tmp_path / "log"
    shutil.copytree(real_data / "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede", log)
    annotations = log / "annotations.feather"
    annotations.chmod(0o644)
    table = feather.read_table(annotations)
    column = table.column("track_uuid").combine_chunks()
    offsets = np.frombuffer(column.buffers()[1], np.int32).copy()
    offsets[2] = -2_000_000_000
    broken = pa.Array.from_buffers(pa.string(), len(column), [None, pa.py_buffer(offsets), column.buffers()[2]])
    table = table.set_column(table.column_names.index("track_uuid"), "track_uuid", broken)
    feather.write_feather(table, annotations, compression="uncompressed")
    assert "non-monotonic offset" in _error(log)


def test_duplicate_track_ids_of_different_types_are_refused(real_data, tmp_path):
    source = real_data / "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-0757.pkl"
    scenario = RestrictedUnpickler(io.BytesIO(source.read_bytes())).load()
    track = next(iter(scenario["tracks"].values()))
    scenario["tracks"]["7"] = track
    scenario["tracks"][7] = track
    path = tmp_path / "dup.pkl"
    path.write_bytes(pickle.dumps(scenario))
    assert "object ids must be unique: '7' is given twice" in _error(path)


def test_a_huge_commonroad_time_step_is_refused(real_data, tmp_path):
    path = tmp_path / "far.xml"
    text = (real_data / "commonroad_ngsim/USA_US101-3_3_T-1.xml").read_text()
    path.write_text(text.replace("<time>\n        <exact>0</exact>", "<time>\n        <exact>99999999999</exact>", 1))
    assert "frames: a trace has 0 to 10000000 frames" in _error(path)


def test_invalid_utf8_in_a_strem_file_is_shown_escaped(tmp_path):
    path = tmp_path / "s.json"
    path.write_bytes(b'{"version": "0.2.0", "frames": [\xff]}')
    assert _error(path) == f"{path}:1:33: frames[0]: expected '{{' but found '\\xff'"


@pytest.mark.parametrize("value", [[{"x": 1.0, "y": 2.0}, [1, 2, 3]], "x", None, {"x": []}])
def test_a_map_value_of_a_wrong_type_is_one_line(real_data, tmp_path, value):
    source = real_data / "av2/forecasting/0a1e6f0a-1817-4a98-b02e-db8c9327d151"
    document = json.loads(next(source.glob("log_map_archive_*.json")).read_text())
    next(iter(document["lane_segments"].values()))["left_lane_boundary"] = value
    path = tmp_path / "log_map_archive_x.json"
    path.write_text(json.dumps(document))
    with pytest.raises(UserError) as caught:
        readers.read_map(path)
    assert caught.value.one_line().startswith(f"{path}: ")


def test_nan_stays_an_unknown_size_and_velocity():
    """NaN means unknown where the data model allows it (z, sizes, velocities): real files use it."""
    trace = readers.read_trace(SAMPLE)
    assert np.isnan(trace.states.z).all()


def test_streamed_documents_are_checked_like_files():
    """``spre --online`` and ``scenario --online`` decode documents from stdin without the
    file readers' dispatcher: the data model's refusals are one line there too."""
    from scenegrep.readers.strem_json import iter_documents
    from scenegrep.readers.trace_json import decode

    frames = [{"index": k, "timestamp": t, "samples": []} for k, t in enumerate([1.0, 0.5])]
    stream = io.BytesIO(json.dumps({"version": "0.2.0", "frames": frames}).encode() + b"\n")
    with pytest.raises(UserError, match=r"^<stdin>: not a valid strem-json input: frame 1 \(index 1\): time does not"):
        list(iter_documents(stream))
    document = {
        "scenegrep": "trace",
        "version": 1,
        "objects": {"a": {"class": "Car"}},
        "frames": [{"time": t, "objects": {"a": {"position": [0, 0], "heading": 0}}} for t in (1.0, 0.0)],
    }
    with pytest.raises(UserError, match=r"^<stdin>:1: not a valid scenegrep-json input: frame 1 \(index 1\)"):
        decode(json.dumps(document).encode(), "<stdin>:1", "stdin")


def test_a_parquet_footer_with_a_column_name_not_in_utf8_is_one_line_when_sniffed(tmp_path, capsys):
    """Found by the fuzz suite: detecting the format reads the Parquet schema, whose names
    Arrow decodes as UTF-8 (a UnicodeDecodeError escaped as a traceback from `info`)."""
    from scenegrep.cli.main import main

    data = bytearray((REPO / "examples" / "sample" / "s3_pass_pedestrian-000.parquet").read_bytes())
    footer = len(data) - 8 - int.from_bytes(data[-8:-4], "little")  # the footer's length precedes 'PAR1'
    data[data.index(b"heading", footer)] = 0xC4  # the first name in the footer is the schema's column name
    bad = tmp_path / "bad.parquet"
    bad.write_bytes(bytes(data))
    assert main(["info", "--no-map", str(bad)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"scenegrep: error: {bad}: ") and "Traceback" not in err[0]
