"""Label noise per dataset in ../shared/real_data: the numbers behind ``--tolerance-profile``.

For every trace of each dataset (AV2 sensor and forecasting, nuScenes mini, Waymo, CommonRoad),
over the vehicles (cars, trucks, buses, trailers, motorcycles) and the ego:

* ``heading_vs_lane`` (rad): |heading - lane direction| of moving vehicles (speed >= 2 m/s) on a
  lane outside intersections, the lane being the one whose direction at the point is nearest
  (``RoadMap.lane_at`` with the heading) and its direction ``RoadMap.lane_direction_at``;
* ``lateral_offset`` (m): the distance of those vehicles' centres from that lane's centreline;
* ``axis_offset`` (m): for two such vehicles in one lane and frame, the second 4 to 30 m ahead of
  the first along its heading, the second's distance from the first's axis (where Scenic's
  ``ahead of`` puts it);
* ``position_jitter`` (m): per labelled position inside a track with both neighbouring frames,
  the larger coordinate of |p(t) - (p(t-1) + p(t+1)) / 2| (deviation from a smooth track: a
  constant-velocity track gives 0, and braking at 3 m/s² at 10 Hz only 0.015 m);
* ``heading_jitter`` (rad): the same for the heading of moving vehicles (circular midpoint);
* ``size_deviation`` (m): the larger of |length - the track's median| and |width - its median|;
* ``velocity_vs_track`` (m/s): where the data labels velocities (not where a reader estimated
  them, as for AV2 sensor logs), the largest of |vx - vx'|,
  |vy - vy'| and |speed - speed'| against the track's own finite differences (the primed values).

It prints the median and the 90th, 95th and 99th percentiles of each per dataset, and the
profile they give (:data:`scenegrep.scene.profiles.PROFILES` holds these values, documented in
the README): heading = the 90th percentile of ``heading_vs_lane``, position = the largest 90th
percentile of ``axis_offset``, ``position_jitter`` and ``size_deviation``, speed = the 90th
percentile of ``velocity_vs_track``, each rounded up to two significant digits. So each tolerance
admits 90 % of the real deviations from what Scenic's defaults make exact (a car's heading on a
road; a car ``ahead of`` another on its axis) and of the labels' own noise.

    python benchmarks/label_noise.py [--json results.json]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np
import shapely

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "src"))

from scenegrep import readers  # noqa: E402
from scenegrep.model import LabelTrace, RoadMap  # noqa: E402
from scenegrep.model.geometry import heading_difference  # noqa: E402
from scenegrep.model.kinematics import ESTIMATED_VELOCITY, finite_difference_velocity, track_order  # noqa: E402
from scenegrep.model.taxonomy import VEHICLE_KINDS  # noqa: E402

REAL = REPO.parent / "shared" / "real_data"
MOVING = 2.0
"""Speed (m/s) above which a vehicle's heading is its direction of travel."""
PERCENTILES = (50, 90, 95, 99)
PROFILE_PERCENTILE = 90
POSITION_MEASURES = ("axis_offset", "position_jitter", "size_deviation")
AHEAD = (4.0, 30.0)
"""Gaps (m, centre to centre) at which a vehicle counts as ahead of another in its lane."""
MEASURES = (
    "heading_vs_lane",
    "lateral_offset",
    "axis_offset",
    "position_jitter",
    "heading_jitter",
    "size_deviation",
    "velocity_vs_track",
)


def datasets(real: Path) -> dict[str, list[Path]]:
    """Dataset name -> its inputs in the real-data folder."""
    return {
        "av2": sorted((real / "av2" / "sensor").iterdir()) + sorted((real / "av2" / "forecasting").iterdir()),
        "nuscenes": sorted((real / "nuscenes_mini_scenarionet").glob("*.pkl")),
        "waymo": sorted((real / "waymo_womd").iterdir()),
        "commonroad": sorted((real / "commonroad_ngsim").glob("*.xml")),
    }


def vehicles(trace: LabelTrace) -> np.ndarray:
    """Which state rows are vehicles or the ego."""
    kinds = trace.objects.kinds()[trace.states.object]
    vehicle = np.isin(kinds, list(VEHICLE_KINDS))
    if trace.ego is not None:
        vehicle |= trace.states.object == trace.object_index(trace.ego)
    return vehicle


def speeds(trace: LabelTrace) -> np.ndarray:
    """Speed (m/s) of every state row: the labelled velocity, else finite differences."""
    labelled = trace.states.speed()
    vx, vy = finite_difference_velocity(trace.states, trace.frame_time)
    return np.where(np.isfinite(labelled), labelled, np.hypot(vx, vy))


def lane_measures(trace: LabelTrace, road_map: RoadMap | None) -> dict[str, np.ndarray]:
    """``heading_vs_lane`` and ``lateral_offset`` of the moving vehicles on a lane."""
    states = trace.states
    if road_map is None or not road_map.lanes:
        return {"heading_vs_lane": np.zeros(0), "lateral_offset": np.zeros(0)}
    rows = np.flatnonzero(vehicles(trace) & (speeds(trace) >= MOVING))
    x, y, heading = states.x[rows], states.y[rows], states.heading[rows]
    lane = road_map.lane_at(x, y, heading)
    keep = (lane >= 0) & ~road_map.in_intersection(x, y)
    rows, lane = rows[keep], lane[keep]
    x, y, heading = x[keep], y[keep], heading[keep]
    direction = road_map.lane_direction_at(x, y, lane)
    offset = shapely.distance(road_map.lane_centrelines[lane], shapely.points(x, y))
    return {
        "heading_vs_lane": np.abs(heading_difference(heading, direction)),
        "lateral_offset": offset,
        "axis_offset": axis_offsets(states.frame[rows], lane, x, y, heading),
    }


def axis_offsets(frame: np.ndarray, lane: np.ndarray, x: np.ndarray, y: np.ndarray, heading: np.ndarray) -> np.ndarray:
    """For every pair of moving vehicles in one lane and frame where the second is ahead of the
    first (by ``AHEAD`` along the first's heading), the second's distance from the first's axis:
    what Scenic's ``ahead of`` puts at 0."""
    order = np.lexsort((lane, frame))
    key = frame[order].astype(np.int64) * (int(lane.max(initial=0)) + 1) + lane[order]
    first, second = pairs_within_groups(key)
    a, b = order[first], order[second]
    dx, dy = x[b] - x[a], y[b] - y[a]
    along = -dx * np.sin(heading[a]) + dy * np.cos(heading[a])
    across = dx * np.cos(heading[a]) + dy * np.sin(heading[a])
    ahead = (along >= AHEAD[0]) & (along <= AHEAD[1])
    return np.abs(across[ahead])


def velocity_measures(trace: LabelTrace) -> dict[str, np.ndarray]:
    """``velocity_vs_track`` of the vehicles whose velocity the data labels (none where the reader
    estimated velocities from the positions)."""
    if ESTIMATED_VELOCITY in trace.attributes:
        return {"velocity_vs_track": np.zeros(0)}
    states = trace.states
    vx, vy = finite_difference_velocity(states, trace.frame_time)
    difference = np.fmax(
        np.maximum(np.abs(states.vx - vx), np.abs(states.vy - vy)),
        np.abs(states.speed() - np.hypot(vx, vy)),
    )
    return {"velocity_vs_track": difference[vehicles(trace) & np.isfinite(difference)]}


def pairs_within_groups(key: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every ordered pair (i, j) of positions of a sorted ``key`` array with equal keys."""
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    counts = np.diff(np.r_[starts, len(key)])
    squares = counts * counts
    first = np.repeat(np.arange(len(key)), np.repeat(counts, counts))
    local = np.arange(len(first)) - np.repeat(np.cumsum(squares) - squares, squares)
    second = np.repeat(starts, squares) + local % np.repeat(counts, squares)
    return first, second


def track_measures(trace: LabelTrace) -> dict[str, np.ndarray]:
    """``position_jitter``, ``heading_jitter`` and ``size_deviation`` of the vehicles' tracks."""
    states = trace.states
    order = track_order(states)
    order = order[vehicles(trace)[order]]
    obj, frame = states.object[order], states.frame[order]
    inner = np.flatnonzero((obj[1:-1] == obj[:-2]) & (obj[1:-1] == obj[2:]))
    inner = inner[(frame[inner + 1] - frame[inner] == 1) & (frame[inner + 2] - frame[inner + 1] == 1)]
    before, row, after = order[inner], order[inner + 1], order[inner + 2]
    jitter = np.maximum(
        np.abs(states.x[row] - (states.x[before] + states.x[after]) / 2),
        np.abs(states.y[row] - (states.y[before] + states.y[after]) / 2),
    )
    turn = heading_difference(states.heading[after], states.heading[before])
    heading_jitter = np.abs(heading_difference(states.heading[row], states.heading[before] + turn / 2))
    moving = speeds(trace)[row] >= MOVING
    return {
        "position_jitter": jitter,
        "heading_jitter": heading_jitter[moving],
        "size_deviation": size_deviation(states.object[order], states.length[order], states.width[order]),
    }


def size_deviation(obj: np.ndarray, length: np.ndarray, width: np.ndarray) -> np.ndarray:
    """Per row, the larger deviation of length or width from its object's median (NaN sizes dropped)."""
    deviation = np.fmax(np.abs(length - track_median(obj, length)), np.abs(width - track_median(obj, width)))
    return deviation[np.isfinite(deviation)]


def track_median(obj: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Per row, the median of the finite ``values`` of its object (NaN when it has none)."""
    finite = np.isfinite(values)
    order = np.lexsort((values, ~finite, obj))
    ids, starts = np.unique(obj[order], return_index=True)
    n = np.bincount(np.searchsorted(ids, obj[finite]), minlength=len(ids))
    low = order[starts + np.maximum(n - 1, 0) // 2]
    high = order[starts + np.maximum(n, 1) // 2]
    medians = np.where(n > 0, (values[low] + values[high]) / 2, np.nan)
    return medians[np.searchsorted(ids, obj)]


def measure(paths: list[Path]) -> dict[str, np.ndarray]:
    """Every measure's samples over the traces of some inputs."""
    samples: dict[str, list[np.ndarray]] = {name: [] for name in MEASURES}
    for path in paths:
        for trace in readers.read_traces(path):
            road_map = readers.read_map(trace.map_source) if trace.map_source is not None else None
            for name, values in (
                lane_measures(trace, road_map) | track_measures(trace) | velocity_measures(trace)
            ).items():
                samples[name].append(values[np.isfinite(values)])
    return {name: np.concatenate(parts) if parts else np.zeros(0) for name, parts in samples.items()}


def summary(samples: dict[str, np.ndarray]) -> dict[str, dict[str, float]]:
    """Per measure: the sample count and the percentiles."""
    found = {}
    for name, values in samples.items():
        stats = {f"p{p}": float(np.percentile(values, p)) if len(values) else float("nan") for p in PERCENTILES}
        found[name] = {"n": len(values), **stats}
    return found


def profile(samples: dict[str, np.ndarray]) -> dict[str, float]:
    """The tolerance profile the samples give (see the module docstring), rounded up to two
    significant digits."""
    position = max(np.percentile(samples[name], PROFILE_PERCENTILE) for name in POSITION_MEASURES)
    heading = np.percentile(samples["heading_vs_lane"], PROFILE_PERCENTILE)
    speed = np.percentile(samples["velocity_vs_track"], PROFILE_PERCENTILE)
    return {"position": round_up(float(position)), "heading": round_up(float(heading)), "speed": round_up(float(speed))}


def round_up(value: float) -> float:
    """``value`` rounded up to two significant digits."""
    exponent = math.floor(math.log10(value)) - 1
    return float(f"{math.ceil(value / 10.0**exponent - 1e-9)}e{exponent}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", metavar="FILE", help="also write the numbers as JSON")
    args = parser.parse_args()
    report = {}
    for name, paths in datasets(REAL).items():
        samples = measure(paths)
        report[name] = {"inputs": len(paths), "measures": summary(samples), "profile": profile(samples)}
        print(f"{name} ({len(paths)} inputs)")
        for measure_name, stats in report[name]["measures"].items():
            cells = "  ".join(f"p{p} {stats[f'p{p}']:.4f}" for p in PERCENTILES)
            print(f"  {measure_name:16s} n {stats['n']:7d}  {cells}")
        print("  profile: " + ", ".join(f"{k} {v:.3g}" for k, v in report[name]["profile"].items()))
    if args.json:
        Path(args.json).write_text(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
