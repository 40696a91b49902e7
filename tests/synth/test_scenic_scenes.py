"""Scenes sampled with the real Scenic: facts checked against Scenic's documented semantics."""

from dataclasses import replace

import numpy as np
import pytest
import shapely

from scenegrep.errors import UserError
from scenegrep.readers import read_map, read_trace
from scenegrep.synth.scenic_scenes import sample_scenes
from scenegrep.writers import write_trace_json

pytestmark = pytest.mark.slow

AHEAD = """\
model scenic.domains.driving.model
ego = new Car on road
other = new Car ahead of ego by Range(4, 10)
"""

NEVER = """\
model scenic.domains.driving.model
ego = new Car on road
other = new Car ahead of ego by 5
require (distance to other) < 1
"""


@pytest.fixture(scope="module")
def ahead(tmp_path_factory):
    path = tmp_path_factory.mktemp("programs") / "ahead.scenic"
    path.write_text(AHEAD)
    return path


@pytest.fixture(scope="module")
def town01(maps_dir):
    return maps_dir / "Town01.xodr"


@pytest.fixture(scope="module")
def trace(ahead, town01, scenic_cache):
    return sample_scenes(ahead, 30, map_path=town01, seed=0)


def test_objects_and_frames(trace, ahead, town01):
    assert (trace.n_frames, trace.name, trace.ego) == (30, "ahead", "ego")
    assert trace.objects.id.tolist() == ["ego", "obj1"]
    assert trace.objects.category.tolist() == ["Car", "Car"]
    assert np.array_equal(trace.frame_index, np.arange(30)) and np.array_equal(trace.frame_time, np.arange(30.0))
    assert trace.present().all()
    assert np.all(trace.states.length == 4.5) and np.all(trace.states.width == 2)
    assert trace.map_source.path == str(town01) and trace.map_source.format == "opendrive"
    assert trace.attributes["program"] == str(ahead) and trace.attributes["seed"] == 0


def test_other_car_is_ahead_by_the_sampled_gap(trace):
    """``ahead of ego by d``: centre at ego.position + rotate((0, 4.5/2 + d + 4.5/2)) by the ego's heading,
    with the ego's orientation (2-D mode has no contact tolerance)."""
    x, y, heading = trace.dense("x"), trace.dense("y"), trace.dense("heading")
    dx, dy, h = x[:, 1] - x[:, 0], y[:, 1] - y[:, 0], heading[:, 0]
    longitudinal = -np.sin(h) * dx + np.cos(h) * dy  # heading 0 = +y, counter-clockwise
    lateral = np.cos(h) * dx + np.sin(h) * dy
    assert np.all(np.abs(lateral) < 1e-6)
    assert np.all((longitudinal >= 8.5 - 1e-9) & (longitudinal <= 14.5 + 1e-9))
    assert np.all(np.abs(heading[:, 1] - h) < 1e-9)
    assert np.all((heading > -np.pi) & (heading <= np.pi))


def test_positions_are_on_the_drivable_area(trace, town01, scenic_cache):
    drivable = read_map(town01).drivable
    distance = shapely.distance(drivable, shapely.points(trace.states.x, trace.states.y))
    assert np.all(distance <= 1e-6)


def test_map_cache_is_in_the_user_cache(trace, scenic_cache):
    assert len(list(scenic_cache.glob("scenic-maps/*/Town01.snet"))) == 1


def test_seed_reproduces(trace, ahead, town01, scenic_cache):
    assert sample_scenes(ahead, 30, map_path=town01, seed=0).equals(trace)
    assert not sample_scenes(ahead, 30, map_path=town01, seed=1).equals(trace)


def test_unsatisfiable_program_is_a_one_line_user_error(tmp_path, town01, scenic_cache):
    program = tmp_path / "never.scenic"
    program.write_text(NEVER)
    with pytest.raises(UserError) as caught:
        sample_scenes(program, 1, map_path=town01, max_iterations=50)
    message = str(caught.value)
    assert "\n" not in message and message.startswith(f"{program}: ") and "50 iterations" in message


def test_json_round_trip(trace, tmp_path):
    path = write_trace_json(trace, tmp_path / "ahead.json")
    assert replace(read_trace(path), source=None).equals(trace)


def test_unwritable_cache_leaves_no_snet_beside_the_map(ahead, town01, tmp_path, monkeypatch):
    """When the cache cannot be written, Scenic reads the map itself and writes no .snet beside it."""
    (tmp_path / "not-a-folder").write_text("")
    monkeypatch.setenv("SCENEGREP_CACHE", str(tmp_path / "not-a-folder"))
    mine = tmp_path / "maps" / "Town01.xodr"
    mine.parent.mkdir()
    mine.write_bytes(town01.read_bytes())
    assert sample_scenes(ahead, 2, map_path=mine).n_frames == 2
    assert sorted(p.name for p in mine.parent.iterdir()) == ["Town01.xodr"]
