"""Coverage on ground truth from Scenic (slow): scenes sampled from a program whose ranges are
narrower than the query's are covered exactly where the sampled values lie.

Two programs: a car ahead of the ego by a distance (closed-form intervals) and a car at a
bearing and range from the ego (trigonometric: intervals by bisection), whose two variables are
also checked jointly. The sampled values come from the labels' raw positions and sizes, not
from scenegrep.
"""

from __future__ import annotations

import numpy as np
import pytest

from scenegrep.dataset import QuerySpec
from scenegrep.dataset.coverage import AMBIGUOUS, coverage_of, variables_of
from scenegrep.dataset.files import query_files
from scenegrep.synth.scenic_scenes import sample_scenes
from scenegrep.writers.trace_json import write_trace_json

pytestmark = [pytest.mark.slow, pytest.mark.real_data]

HEADER = "model scenic.domains.driving.model\nego = new Car on road\n"
AHEAD = "other = new Car ahead of ego by Range({}, {})\n"
POLAR = "other = new Car offset along Range({}, {}) deg by 0 @ Range({}, {}), with regionContainedIn None\n"
SCENES = 8
BINS = 10


def _ahead(trace) -> dict[str, np.ndarray]:
    """Distance from the ego's front to the other car's back, along the ego's axis (m)."""
    ego, other = _positions(trace)
    gap = np.hypot(*(other[:, :2] - ego[:, :2]).T) - (ego[:, 2] + other[:, 2]) / 2
    return {"Range(2, 12)": gap}


def _polar(trace) -> dict[str, np.ndarray]:
    """Bearing (deg, Scenic's headings: 0 = +y, counter-clockwise) and range (m) of the other car."""
    ego, other = _positions(trace)
    dx, dy = (other[:, :2] - ego[:, :2]).T
    return {"Range(-30, 30)": np.degrees(np.arctan2(-dx, dy)), "Range(4, 12)": np.hypot(dx, dy)}


def _positions(trace) -> tuple[np.ndarray, np.ndarray]:
    """Per scene, (x, y, length) of the ego and of the other car."""
    s = trace.states
    found = []
    for label in ("ego", "obj1"):
        rows = np.flatnonzero(s.object == trace.object_index(label))
        rows = rows[np.argsort(s.frame[rows])]
        found.append(np.column_stack([s.x[rows], s.y[rows], s.length[rows]]))
    return found[0], found[1]


CASES = {
    "ahead": (AHEAD.format(4, 6), AHEAD.format(2, 12), _ahead, 11),
    "polar": (POLAR.format(-10, 10, 6, 8), POLAR.format(-30, 30, 4, 12), _polar, 12),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def case(request, maps_dir, scenic_cache, tmp_path_factory):
    simulated, queried, truth_of, seed = CASES[request.param]
    folder = tmp_path_factory.mktemp(request.param)
    (folder / "simulated.scenic").write_text(HEADER + simulated)
    (folder / "query.scenic").write_text(HEADER + queried)
    town = maps_dir / "Town01.xodr"
    trace = sample_scenes(folder / "simulated.scenic", SCENES, map_path=town, seed=seed)
    write_trace_json(trace, folder / "scenes.json")
    spec = QuerySpec.from_file("scene", folder / "query.scenic", intervals=True)
    results = query_files([str(folder / "scenes.json")], spec)  # the scenes name their map (Town01)
    coverage = coverage_of(results.matches.to_pylist(), variables_of(spec), BINS)
    return coverage, truth_of(trace)


def _axis(coverage, prefix: str) -> int:
    """The index of the one axis whose variable's label starts with ``prefix`` (the Range's text)."""
    (found,) = [a for a, axis in enumerate(coverage.axes) if axis.name.startswith(prefix + "@")]
    return found


def test_every_sampled_scene_matches(case):
    coverage, _ = case
    assert [r["start_frame"] for r in coverage.rows] == list(range(SCENES))


def test_recovered_intervals_hold_the_sampled_values(case):
    coverage, truth = case
    for name, values in truth.items():
        a = _axis(coverage, name)
        assert np.all(coverage.lo[:, a] <= values + 1e-6) and np.all(values - 1e-6 <= coverage.hi[:, a]), name
        width = coverage.hi[:, a] - coverage.lo[:, a]
        assert np.all(width < 0.02), (name, width)


def test_covered_exactly_where_the_sampled_values_lie(case):
    coverage, truth = case
    for name, values in truth.items():
        a = _axis(coverage, name)
        axis = coverage.axes[a]
        assert axis.basis == "declared"
        expected = np.searchsorted(axis.edges, values, side="right") - 1
        straddles = np.array(
            [np.any((lo < axis.edges) & (axis.edges < hi)) for lo, hi in zip(coverage.lo[:, a], coverage.hi[:, a])]
        )
        assert np.array_equal(coverage.assigned[:, a], np.where(straddles, AMBIGUOUS, expected)), name
        assert straddles.sum() <= 1, name
        kept = expected[~straddles]
        assert np.array_equal(coverage.counts(a), np.bincount(kept, minlength=axis.bins)), name
        simulated = (axis.edges[1:] > values.min()) & (axis.edges[:-1] <= values.max())
        gaps = coverage.counts(a) == 0
        assert np.all(gaps[~simulated]), f"{name}: bins outside the simulated range must be gaps"


@pytest.mark.parametrize("case", ["polar"], indirect=True)
def test_joint_coverage_of_the_pair(case):
    coverage, truth = case
    assert len(truth) == 2
    (a, va), (b, vb) = sorted((_axis(coverage, name), values) for name, values in truth.items())
    ka = np.searchsorted(coverage.axes[a].edges, va, side="right") - 1
    kb = np.searchsorted(coverage.axes[b].edges, vb, side="right") - 1
    both = (coverage.assigned[:, a] >= 0) & (coverage.assigned[:, b] >= 0)
    expected = np.zeros((coverage.axes[a].bins, coverage.axes[b].bins), dtype=int)
    np.add.at(expected, (ka[both], kb[both]), 1)
    assert (a, b) in coverage.pairs()
    assert np.array_equal(coverage.joint(a, b), expected)
    assert expected.sum() >= SCENES - 2
