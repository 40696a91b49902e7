"""scenegrep's JSON trace format: reading, writing back, errors."""

import json
from dataclasses import replace

import numpy as np
import pytest

from scenegrep.errors import UserError
from scenegrep.readers import trace_json
from scenegrep.writers import write_trace_json

DOC = {
    "scenegrep": "trace",
    "version": 1,
    "name": "table2",
    "ego": "car2",
    "frame_interval": 0.1,
    "map": {"path": "town.xodr", "format": "opendrive"},
    "attributes": {"weather": "clear"},
    "objects": {
        "car1": {"class": "Car", "size": [4.5, 2.0]},
        "car2": {"class": "Car", "attributes": {"colour": "red"}},
    },
    "frames": [
        {
            "objects": {
                "car1": {"position": [0, 0], "heading": 0.0, "behaviours": ["Stationary"], "lane": "Lane1"},
                "car2": {
                    "position": [0, 20, 1],
                    "heading": 0.0,
                    "size": [4, 2, 1.5],
                    "behaviours": {"FollowLane": 0.9, "LaneChange": 0.3},
                },
            }
        },
        {
            "time": 0.15,
            "objects": {"car2": {"position": [0, 14], "heading": 0.1, "velocity": [0, -60]}},
            "samples": [
                {
                    "channel": "cam",
                    "image": "1.png",
                    "image_size": [640, 480],
                    "boxes": [{"class": "car", "center": [10, 20], "size": [5, 6], "rotation": 0.2, "object": "car1"}],
                }
            ],
        },
    ],
}


def write(tmp_path, doc):
    path = tmp_path / "trace.json"
    path.write_text(json.dumps(doc))
    return path


def test_reads_every_field(tmp_path):
    t = trace_json.read_trace(write(tmp_path, DOC))
    assert t.name == "table2" and t.ego == "car2" and t.attributes == {"weather": "clear"}
    assert t.frame_index.tolist() == [0, 1] and t.frame_time.tolist() == [0.0, 0.15]
    assert t.map_source.path == str(tmp_path / "town.xodr")
    rows = list(zip(t.states.frame, t.objects.id[t.states.object]))
    assert rows == [(0, "car1"), (0, "car2"), (1, "car2")]
    assert t.states.length[:2].tolist() == [4.5, 4.0]
    assert np.isnan(t.states.length[2]) and t.states.z[1] == 1.0 and np.isnan(t.states.z[0])
    assert t.lane_names().tolist() == ["Lane1", "", ""]
    assert t.behaviours.sets() == [{"Stationary"}, {"FollowLane", "LaneChange"}, set()]
    boxes = t.images.boxes
    assert boxes.oriented.tolist() == [True] and t.objects.id[boxes.object[0]] == "car1"
    assert t.objects.attributes[1] == {"colour": "red"}


def test_write_then_read_is_equal(tmp_path):
    t = trace_json.read_trace(write(tmp_path, DOC))
    again = trace_json.read_trace(write_trace_json(t, tmp_path / "again.json"))
    assert again.equals(replace(t, source=again.source))


@pytest.mark.parametrize(
    "change, message",
    [
        (
            lambda d: d["frames"][1]["objects"].update({"ghost": {"position": [0, 0], "heading": 0}}),
            "'ghost' is not declared",
        ),
        (
            lambda d: d["frames"][0]["objects"]["car1"].pop("heading"),
            r":1:\d+: frames\[0\]\.objects: Object missing required field `heading`",
        ),
        (lambda d: d.update({"ego": "car9"}), "ego 'car9' is not declared"),
        (lambda d: d["frames"][0]["objects"]["car1"].update({"speed": 3}), "unknown field `speed`"),
        (lambda d: d.update({"version": 2}), r"trace.json:1:\d+: version: Invalid enum value 2"),
    ],
)
def test_errors(tmp_path, change, message):
    doc = json.loads(json.dumps(DOC))
    change(doc)
    with pytest.raises(UserError, match=message):
        trace_json.read_trace(write(tmp_path, doc))
