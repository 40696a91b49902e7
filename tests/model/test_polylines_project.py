"""``Polylines.arc_at`` (model/_project.c) against shapely's ``line_locate_point``, bit for bit:
random polylines and points, and the adversarial points where GEOS's choice among segments
matters (on vertices, at segment midpoints, on the bisectors of vertices: equidistant from two
segments), on synthetic polylines and on Town01's and Town06's lane centrelines and curbs."""

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.model.polylines import Polylines
from scenegrep.readers.opendrive import read_map


def shapely_arc(polylines: Polylines, line: np.ndarray, points: np.ndarray) -> np.ndarray:
    return shapely.line_locate_point(polylines.geometries[line], shapely.points(points))


def adversarial(line: np.ndarray) -> np.ndarray:
    """The vertices, the segment midpoints and points on both sides of each inner vertex's
    bisector (as far from the segment before as from the one after, up to rounding)."""
    found = [line, (line[1:] + line[:-1]) / 2]
    if len(line) > 2:
        before = line[1:-1] - line[:-2]
        after = line[2:] - line[1:-1]
        before /= np.linalg.norm(before, axis=1)[:, None]
        after /= np.linalg.norm(after, axis=1)[:, None]
        for t in (-3.0, -0.5, 0.5, 3.0):
            found.append(line[1:-1] + t * (before - after))
    return np.concatenate(found)


def check(polylines: Polylines, rng: np.random.Generator, random_points: int) -> int:
    lines, points = [], []
    for k, line in enumerate(polylines.lines):
        if len(line) < 2:
            continue
        near = rng.uniform(line.min(axis=0) - 5, line.max(axis=0) + 5, (random_points, 2))
        chosen = np.concatenate([near, adversarial(line)])
        lines.append(np.full(len(chosen), k))
        points.append(chosen)
    line, point = np.concatenate(lines), np.concatenate(points)
    ours = polylines.arc_at(line, point[:, 0], point[:, 1])
    np.testing.assert_array_equal(ours, shapely_arc(polylines, line, point))
    return len(line)


coordinate = st.floats(-50, 50, allow_nan=False).map(lambda v: round(v, 1))
polyline = st.lists(st.tuples(coordinate, coordinate), min_size=2, max_size=8)


@settings(max_examples=150, deadline=None)
@given(st.lists(polyline, min_size=1, max_size=3), st.integers(0, 2**32 - 1))
def test_random_polylines_match_shapely(lines, seed):
    polylines = Polylines([np.array(line) for line in lines])
    if any(len(line) < 2 for line in polylines.lines):
        return
    check(polylines, np.random.default_rng(seed), random_points=20)


def test_collinear_and_folded_ties():
    """A polyline folded back on itself and one with collinear segments: many segments at the
    same distance (GEOS takes the first)."""
    polylines = Polylines([np.array([[0, 0], [2, 0], [1, 0], [3, 0], [3, 2]]), np.array([[0, 0], [1, 1], [2, 2]])])
    grid = np.stack(np.meshgrid(np.arange(-1, 4.5, 0.25), np.arange(-1, 3.5, 0.25)), axis=-1).reshape(-1, 2)
    for k in range(2):
        line = np.full(len(grid), k)
        ours = polylines.arc_at(line, grid[:, 0], grid[:, 1])
        np.testing.assert_array_equal(ours, shapely_arc(polylines, line, grid))


@pytest.mark.parametrize("town", ["Town01", "Town06"])
def test_map_polylines_match_shapely(maps_dir, town):
    road_map = read_map(maps_dir / f"{town}.xodr")
    rng = np.random.default_rng(7)
    for polylines in (road_map.centreline_polylines, road_map.curb_polylines):
        assert check(polylines, rng, random_points=30) > 1000


def test_no_countable_distance_and_bad_input():
    """Points whose distances are NaN or overflow get -1 (GEOS's start value; shapely raises);
    a line index out of range is a ValueError, not a crash."""
    polylines = Polylines([np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])])
    x, y = np.array([np.nan, np.inf, 1e200, 0.5]), np.array([0.0, 0.0, 1e200, 0.5])
    np.testing.assert_array_equal(polylines.arc_at(np.zeros(4, int), x, y), [-1, -1, -1, 0.5])
    with pytest.raises(ValueError, match="no such polyline"):
        polylines.arc_at(np.array([1]), np.array([0.0]), np.array([0.0]))
    with pytest.raises(ValueError, match="no such polyline"):
        polylines.arc_at(np.array([-1]), np.array([0.0]), np.array([0.0]))
    assert len(polylines.arc_at(np.zeros(0, int), np.zeros(0), np.zeros(0))) == 0


def test_single_point_polyline_has_no_segment():
    """A polyline whose vertices all repeat has no segment: no arc (-1) and no direction (a
    ValueError, not another polyline's segment); the others still answer."""
    polylines = Polylines([np.array([[2.0, 2.0], [2.0, 2.0]]), np.array([[0.0, 0.0], [1.0, 0.0]])])
    np.testing.assert_array_equal(
        polylines.arc_at(np.array([0, 1]), np.array([0.5, 0.5]), np.array([0.5, 0.5])), [-1, 0.5]
    )
    with pytest.raises(ValueError, match="single point"):
        polylines.direction_at(np.array([1, 0]), np.array([0.5, 0.5]), np.array([0.5, 0.5]))
    assert polylines.direction_at(np.array([1]), np.array([0.5]), np.array([0.5]))[0] == -np.pi / 2  # east


def test_no_segment_is_guessed_for_a_point_without_a_finite_distance():
    """A NaN, infinite or overflowing point has no nearest segment: a ValueError, never the
    polyline's first segment; finite points beside it would answer."""
    polylines = Polylines([np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])])
    for x, y in ((np.nan, 0.0), (np.inf, 0.0), (1e200, 1e200)):
        with pytest.raises(ValueError, match="no finite distance"):
            polylines.segment_at(np.zeros(2, int), np.array([1.0, x]), np.array([0.5, y]))
    assert polylines.segment_at(np.zeros(1, int), np.array([1.0]), np.array([0.5]))[0] == 1
