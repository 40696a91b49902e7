"""Every query kind returns on a bag what it returns on the trace the bag was written from.

The AV2 log 7fab2350 is written as TrackedObjects, vision_msgs Detection3DArray or Foxglove
SceneUpdate cubes, with /tf (:mod:`scenegrep.writers.ros_bag`, :mod:`scenegrep.writers.foxglove`);
the trace compared is the log as those messages can carry it: classes as Autoware labels
(TrackedObjects), no velocity (the others), no ego velocity (``/tf`` carries none), the bag's
attributes. ``/tf`` carries no ego size either: the bag is queried with ``--ego-size`` (the log's
own ego size); without it, a query that needs the ego's extent is an error naming the option. Both
are queried through the command line with the log's own map, and their match rows must be equal.
"""

from __future__ import annotations

import json
import re
from dataclasses import replace

import numpy as np
import pytest

from scenegrep.cli.main import main
from scenegrep.model import ObjectTable
from scenegrep.readers.ros.options import BagOptions
from scenegrep.readers.ros.reader import read_trace as read_bag
from scenegrep.writers.trace_parquet import write_trace_parquet

from scenegrep.writers.foxglove import write_scene_updates
from scenegrep.writers.ros_bag import ORIGIN_NS, write_tracked
from scenegrep.writers.ros_messages import KIND_LABEL

from .ros_writer import read_back_id

LABELS = ("UNKNOWN", "CAR", "TRUCK", "BUS", "TRAILER", "MOTORCYCLE", "BICYCLE", "PEDESTRIAN", "ANIMAL", "HAZARD")
REAL = "examples/queries/real"
ONCOMING_NEAR = """model scenic.simulators.newtonian.driving_model
ego = new Car with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
car = new Vehicle with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require (distance from ego to car) < 15
require abs(relative heading of car from ego) > 2.5
"""
QUERIES = [  # (command, query, options)
    ("scene", ONCOMING_NEAR, ["--unknown-layers", "permissive"]),
    ("scenario", f"{REAL}/oncoming_vehicle.scenic", ["--all", "--unknown-layers", "permissive", "--window", "3s"]),
    ("spre", "[E(p := [:pedestrian:])(@dist(p, [:ego:]) < 15 & <frontof>(p))]{5,}", ["--space", "topdown"]),
]
KEYS = ("status", "correspondence", "start_frame", "end_frame", "start_time", "end_time", "values", "objects")
"""The columns compared (``match`` numbers a trace's matches in its objects' order, which a bag
may list otherwise: rows are compared as a set)."""


MESSAGE_TYPES = [
    "TrackedObjects",
    pytest.param("Detection3DArray", marks=pytest.mark.slow),
    pytest.param("SceneUpdate", marks=pytest.mark.slow),
]


@pytest.fixture(scope="module", params=MESSAGE_TYPES)
def inputs(request, av2_bag, tmp_path_factory):
    """A bag of one message type (+ /tf), the original trace as that bag carries it written as
    Parquet, and the map. TrackedObjects carry UUIDs, Autoware labels and twists; vision_msgs
    and Foxglove cubes the ids and class names as they are, no velocity."""
    trace, bag_path = av2_bag
    folder = tmp_path_factory.mktemp("queries")
    autoware = request.param == "TrackedObjects"
    if request.param == "Detection3DArray":
        bag_path = folder / "vision.mcap"
        write_tracked(trace, bag_path, ORIGIN_NS, box_type="vision_msgs/Detection3DArray")
    elif request.param == "SceneUpdate":
        bag_path = folder / "scene.mcap"
        write_scene_updates(trace, bag_path, "json")
    ego = trace.object_index(trace.ego)
    size = _ego_size(trace)
    bag = read_bag(bag_path, BagOptions(ego_size=size))
    given = [str(o) if not autoware else read_back_id(str(o)) for o in trace.objects.id]
    ids = ["ego" if i == ego else o for i, o in enumerate(given)]
    classes = [LABELS[KIND_LABEL[k]] for k in trace.objects.kinds()] if autoware else list(trace.objects.category)
    categories = ["ego" if i == ego else c for i, c in enumerate(classes)]
    s = trace.states
    unknown = {c: np.where((s.object == ego) | (not autoware), np.nan, getattr(s, c)) for c in ("vx", "vy")}
    carried = replace(
        trace,
        name=bag.name,
        objects=ObjectTable.build(ids, categories),
        states=replace(s, z=np.nan_to_num(s.z), **unknown),
        ego="ego",
        attributes=dict(bag.attributes),
    )
    carried.validate()
    original = write_trace_parquet(carried, folder / "original.parquet")
    return str(bag_path), str(original), trace.map_source.path, ",".join(map(str, size))


def _ego_size(trace) -> tuple[float, float, float]:
    """The ego's (length, width, height) as the log records it (one size for every frame)."""
    ego = trace.states.object == trace.object_index(trace.ego)
    return tuple(float(np.unique(getattr(trace.states, c)[ego]).item()) for c in ("length", "width", "height"))


def _rounded(value):
    """``value`` with every float rounded to 1e-6 (the bag's positions are within 1e-6 m)."""
    if isinstance(value, float):
        return round(value, 6)
    if isinstance(value, dict):
        return {k: _rounded(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_rounded(v) for v in value]
    return value


def _rows(argv, capsys) -> tuple[int, list[dict], str]:
    """The exit code, the result rows (sorted) and the error (without the input's and trace's names)."""
    code = main([*argv, "--json"])
    captured = capsys.readouterr()
    error = (
        re.sub(r"^scenegrep: error: .*?: (\S+ is unknown): trace '[^']*' ", r"\1: ", captured.err) if code == 2 else ""
    )
    rows = [_rounded({k: row.get(k) for k in KEYS}) for row in map(json.loads, captured.out.splitlines())]
    return code, sorted(rows, key=lambda row: json.dumps(row, sort_keys=True)), error


@pytest.mark.parametrize("query", QUERIES, ids=["scene", "scenario", "spre"])
def test_each_query_kind_returns_on_the_bag_what_it_returns_on_the_trace(inputs, query, capsys, tmp_path):
    bag, original, map_path, ego_size = inputs
    command, text, options = query
    if command == "scene":
        (tmp_path / "near.scenic").write_text(text)
        text = str(tmp_path / "near.scenic")
    map_option = [] if command == "spre" else ["--map", map_path]  # the bag has no map; the trace names its own
    from_bag = _rows([command, text, bag, *options, *map_option, "--ego-size", ego_size], capsys)
    from_trace = _rows([command, text, original, *options], capsys)
    assert from_bag == from_trace
    code, rows, error = from_bag
    if code == 2:  # a scenario on speeds over messages without velocities: refused alike
        assert "speed is unknown" in error and query[0] == "scenario" and "TrackedObjects" not in bag
    else:
        assert any(row["status"] == "match" for row in rows)  # the query finds something to compare


EXTENT_QUERIES = [  # (command, query, options): each needs the ego's extent
    ("scene", ONCOMING_NEAR, ["--unknown-layers", "permissive"]),
    ("scenario", f"{REAL}/oncoming_vehicle.scenic", ["--unknown-layers", "permissive", "--window", "3s"]),
    ("spre", "[@area([:ego:]) > 1]", ["--space", "topdown"]),
    ("spre", "[NE([:ego:] & [:car:])]", ["--space", "topdown"]),
]


@pytest.mark.parametrize("query", EXTENT_QUERIES, ids=["scene", "scenario", "spre-area", "spre-intersection"])
def test_without_the_ego_size_a_query_that_needs_the_ego_extent_is_an_error(av2_bag, query, capsys, tmp_path):
    """/tf carries no ego size: a scene's containment of the ego's box, a SpRE's area of the ego's
    region or its intersection are one-line errors naming --ego-size, never a default size; a
    SpRE on the ego's centre (distance, side) needs none and runs."""
    trace, bag = av2_bag
    command, text, options = query
    if command == "scene":
        (tmp_path / "near.scenic").write_text(text)
        text = str(tmp_path / "near.scenic")
    options = options if command == "spre" else [*options, "--map", trace.map_source.path]
    assert main([command, text, str(bag), *options]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no size for its ego 'ego'" in err and "--ego-size LENGTH,WIDTH,HEIGHT" in err
    centre = "[@dist([:ego:], [:car:]) < 10 & <frontof>([:car:])]"
    assert main(["spre", "--space", "topdown", centre, str(bag), "-q"]) in (0, 1)
    assert capsys.readouterr().err.count("error") == 0


def test_live_input_takes_the_ego_size_too(av2_bag, capsys):
    """``--follow`` reads the bag with the same options: the ego's area is an error without
    --ego-size, and with it the frames where the ego's box (4.87 m x 1.85 m in AV2) is over 9 m²."""
    _, bag = av2_bag
    query = ["spre", "--space", "topdown", "[@area([:ego:]) > 9]", "--follow", str(bag), "--idle-timeout", "1"]
    assert main(query) == 2
    assert "--ego-size LENGTH,WIDTH,HEIGHT" in capsys.readouterr().err
    assert main([*query, "--ego-size", "4.87,1.85,1.48"]) == 0
    assert len(capsys.readouterr().out.splitlines()) == 156  # every frame: one line each
    assert main([*query, "--ego-size", "2,1.85,1.48"]) == 1  # 3.7 m²: none
