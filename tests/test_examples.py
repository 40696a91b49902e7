"""The small inputs in examples/ are what examples/make/make_examples.py writes (the parts that
need no Scenic run: the trace and its map, the MCAP files of the stream and the trace, the
Autoware bag and the Lanelet2 map), and the bag gives back the trace it was written from."""

import importlib.util

import uuid

import numpy as np
import pyarrow.parquet as pq

from scenegrep import readers
from tests.conftest import REPO

EXAMPLES = REPO / "examples"


def make_examples():
    spec = importlib.util.spec_from_file_location("make_examples", EXAMPLES / "make" / "make_examples.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_checked_in_examples_are_what_the_script_writes(tmp_path):
    make = make_examples()
    make.write_trace_and_map(tmp_path)
    make.write_mcaps(tmp_path)
    make.write_drive(tmp_path)
    assert (tmp_path / "trace.json").read_bytes() == (EXAMPLES / "trace.json").read_bytes()
    assert pq.read_table(tmp_path / "map.parquet").equals(pq.read_table(EXAMPLES / "map.parquet"))
    for name in ("stream.mcap", "trace.mcap", "drive.mcap", "lanelet2_map.osm"):
        assert (tmp_path / name).read_bytes() == (EXAMPLES / name).read_bytes(), name


def test_the_trace_has_no_map_of_its_own_and_the_map_covers_it():
    trace = readers.read_trace(EXAMPLES / "trace.json")
    assert trace.map_source is None and trace.n_frames == 30
    road_map = readers.read_map(EXAMPLES / "map.parquet")
    lanes = road_map.lane_at(trace.states.x, trace.states.y, trace.states.heading)
    assert (lanes >= 0).all()
    assert (EXAMPLES / "map.parquet").stat().st_size < 100_000


def test_the_bag_gives_back_the_sample_trace():
    """drive.mcap read back: the sample trace's times, poses and sizes (ego size aside: /tf has
    none), its objects under their UUIDs with Autoware's class names."""
    trace = readers.read_trace(EXAMPLES / "sample" / "fig1_lane_change-000.parquet")
    bag = readers.read_trace(EXAMPLES / "drive.mcap")
    assert np.allclose(bag.frame_time, trace.frame_time, atol=1e-9)
    name = {"ego": "ego", "otherCar": str(uuid.uuid5(uuid.NAMESPACE_URL, "otherCar"))}
    assert sorted(bag.objects.id) == sorted(name[str(o)] for o in trace.objects.id)
    for o in trace.objects.id:
        here, there = bag.object_index(name[str(o)]), trace.object_index(o)
        expected = "ego" if o == "ego" else "CAR"
        assert bag.objects.category[here] == expected
        sizes = () if o == "ego" else ("length", "width", "height")
        for column in ("x", "y", "heading", *sizes):
            assert np.allclose(bag.dense(column)[:, here], trace.dense(column)[:, there], atol=1e-6), (o, column)
    assert (EXAMPLES / "drive.mcap").stat().st_size < 100_000
    assert (EXAMPLES / "lanelet2_map.osm").stat().st_size < 300_000
