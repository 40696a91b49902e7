"""The view model and its JSON document: frames, correspondences, SpRE classes, map cropping."""

from __future__ import annotations

import json

import numpy as np
import shapely
import pytest
from hypothesis import given
from hypothesis import strategies as st

from scenegrep.errors import UserError
from scenegrep.model import LabelTrace, ObjectTable, StateTable
from scenegrep.view.data import MAP_MARGIN, QueryInfo, build_view, crop_to_trace
from scenegrep.view.page import script_json, view_page
from scenegrep.view.payload import payload
from tests.spre.test_semantics import image_trace


def small_trace(presence: list[list[bool]], classes: list[str], start_index: int = 100) -> LabelTrace:
    """A trace whose object o is at (10 f + o, o) in frame f where presence[f][o]."""
    frames, objects = np.nonzero(np.array(presence, dtype=bool))
    states = StateTable.build(frames, objects, frames * 10.0 + objects, objects * 1.0, np.zeros(len(frames)))
    ids = [f"o{k}" for k in range(len(classes))]
    n = len(presence)
    return LabelTrace.build(
        "t", np.arange(start_index, start_index + n), np.arange(n) * 0.1, ObjectTable.build(ids, classes), states
    )


@given(st.lists(st.lists(st.booleans(), min_size=3, max_size=3), min_size=1, max_size=8))
def test_payload_frames_hold_exactly_the_trace_observations(presence):
    trace = small_trace(presence, ["car", "pedestrian", "bus"])
    doc = payload(build_view(trace))
    offsets, objects = doc["states"]["offsets"], doc["states"]["object"]
    for f, row in enumerate(presence):
        shown = objects[offsets[f] : offsets[f + 1]]
        assert shown == [o for o in range(3) if row[o]]
        assert doc["states"]["x"][offsets[f] : offsets[f + 1]] == [10.0 * f + o for o in shown]


def test_a_match_window_is_given_in_frame_positions_and_its_objects_are_checked():
    trace = small_trace([[True, True, False]] * 5, ["car", "car", "bus"])
    row = {"status": "match", "match": 0, "start_frame": 101, "end_frame": 103, "correspondence": '{"ego": "o1"}'}
    view = build_view(trace, rows=[row])
    assert [(m.first, m.last, dict(m.correspondence)) for m in view.matches] == [(1, 3, {"ego": "o1"})]
    with pytest.raises(UserError, match="frames 101-107"):
        build_view(trace, rows=[{**row, "end_frame": 107}])
    with pytest.raises(UserError, match="names object 'o9'"):
        build_view(trace, rows=[{**row, "correspondence": '{"ego": "o9"}'}])
    with pytest.raises(UserError, match="no match 4"):
        view.match(4)


def test_a_trace_without_a_match_carries_the_explanation():
    trace = small_trace([[True, False, False]] * 2, ["car", "car", "bus"])
    view = build_view(trace, rows=[{"status": "no match", "match": -1, "explanation": "ego never brakes"}])
    assert view.matches == () and view.note == "no match: ego never brakes"
    frames = [{"status": "no match", "match": -1, "start_frame": f, "explanation": f"gap {f}"} for f in (0, 1)]
    assert build_view(trace, rows=frames).note == "no match at frame 0: gap 0\nno match at frame 1: gap 1"


def test_spre_marks_observations_of_the_named_classes_with_their_filters():
    trace = small_trace([[True, True, True]] * 3, ["vehicle.car", "human.pedestrian.adult", "bus"])
    view = build_view(trace, query=QueryInfo("spre", "[[:pedestrian:]] | [[:bus:]]"))
    kinds = np.array(["car", "pedestrian", "bus"])[trace.states.object]
    assert view.marked.tolist() == np.isin(kinds, ["pedestrian", "bus"]).tolist()
    assert payload(view)["states"]["marked"] == view.marked.astype(int).tolist()


def test_image_streams_are_drawn_in_the_image_and_mark_boxes():
    car, ped = ("car", 10, 10, 4, 4), ("ped", 50, 50, 4, 4)
    trace = image_trace([[[car, ped], [ped]], [[car]]], channels=("front", "back"))
    view = build_view(trace, query=QueryInfo("spre", "[[:ped:]]"))
    doc = payload(view)
    assert view.image_space and doc["space"] == "image" and [b["channel"] for b in doc["boxes"]] == ["front", "back"]
    assert doc["boxes"][0]["offsets"] == [0, 2, 3] and doc["boxes"][1]["offsets"] == [0, 1, 1]
    assert doc["boxes"][0]["marked"] == [0, 1, 0] and doc["boxes"][1]["marked"] == [1]


def test_the_map_is_cropped_to_the_trace(maps_dir):
    from scenegrep import readers

    road_map = readers.read_map(maps_dir / "Town06.xodr")
    trace = small_trace([[True, False, False]] * 3, ["car", "car", "car"])
    cropped = crop_to_trace(road_map, trace)
    assert 0 < len(cropped.lanes) < len(road_map.lanes)
    radius = MAP_MARGIN + np.hypot(20, 0) / 2
    for lane in cropped.lanes:
        assert lane.polygon.distance(shapely.Point(10, 0)) <= radius + 1e-6


def test_the_page_is_self_contained_and_its_data_cannot_close_the_script():
    trace = small_trace([[True]], ["car"])
    page = view_page(build_view(trace, query=QueryInfo("scene", "# </script><b>")))
    assert "</script><b>" not in page
    assert "http://" not in page and "https://" not in page and "src=" not in page
    assert json.loads(script_json({"q": "</script>"}))["q"] == "</script>"


def test_a_spre_run_on_some_channels_marks_only_their_boxes():
    car, ped = ("car", 10, 10, 4, 4), ("ped", 50, 50, 4, 4)
    trace = image_trace([[[car, ped], [ped]], [[car], []]], channels=("front", "back"))
    view = build_view(trace, query=QueryInfo("spre", "[[:ped:]]", {"channels": ["back"]}))
    assert view.marked_boxes.tolist() == [False, False, True, False]
