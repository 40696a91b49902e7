"""The small inputs in examples/ are what examples/make/make_examples.py writes (the parts that
need no Scenic run: the trace and its map, and the MCAP files of the stream and the trace)."""

import importlib.util

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
    assert (tmp_path / "trace.json").read_bytes() == (EXAMPLES / "trace.json").read_bytes()
    assert pq.read_table(tmp_path / "map.parquet").equals(pq.read_table(EXAMPLES / "map.parquet"))
    for name in ("stream.mcap", "trace.mcap"):
        assert (tmp_path / name).read_bytes() == (EXAMPLES / name).read_bytes(), name


def test_the_trace_has_no_map_of_its_own_and_the_map_covers_it():
    trace = readers.read_trace(EXAMPLES / "trace.json")
    assert trace.map_source is None and trace.n_frames == 30
    road_map = readers.read_map(EXAMPLES / "map.parquet")
    lanes = road_map.lane_at(trace.states.x, trace.states.y, trace.states.heading)
    assert (lanes >= 0).all()
    assert (EXAMPLES / "map.parquet").stat().st_size < 100_000
