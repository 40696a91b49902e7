"""Road-map point queries: microseconds per point, batched and one at a time.

For each map (Town06 through the OpenDRIVE cache, an AV2 city map, a nuScenes map) it
draws random points inside the map's extent and times ``lane_at``, ``in_intersection``,
``lane_direction_at`` and ``nominal_directions_at`` over a batch of ``--points`` points and
for single points; medians of ``--repeat`` runs. Scenic's own ``Network.laneAt`` is
timed on Town06 for comparison.

    python benchmarks/bench_map.py [--points 10000] [--repeat 5]
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from timing import median_seconds  # noqa: E402
from scenegrep import readers  # noqa: E402
from scenegrep.model import RoadMap  # noqa: E402

SHARED = REPO.parent / "shared"
MAPS = [
    SHARED / "maps" / "Town06.xodr",
    SHARED / "real_data/av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede/map/"
    "log_map_archive_7fab2350-7eaf-3b7e-a39d-6937a4c1bede____PIT_city_47896.json",
    SHARED / "real_data/nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-0061.pkl",
]


def per_point_us(road_map: RoadMap, x: np.ndarray, y: np.ndarray, repeat: int) -> dict[str, tuple[float, float]]:
    """Query name -> (batched us per point, us per single-point call)."""
    batched = {
        "lane_at": road_map.lane_at,
        "in_intersection": road_map.in_intersection,
        "lane_direction_at": road_map.lane_direction_at,
    }
    out = {}
    for name, query in batched.items():
        batch = median_seconds(lambda q=query: q(x, y), repeat) / len(x)
        single = median_seconds(lambda q=query: [q(x[i : i + 1], y[i : i + 1]) for i in range(200)], 3) / 200
        out[name] = (batch, single)
    one_by_one = median_seconds(lambda: [road_map.nominal_directions_at(a, b) for a, b in zip(x, y)], 1) / len(x)
    out["nominal_directions_at"] = (one_by_one, one_by_one)
    return out


def scenic_lane_at_us(path: Path, road_map: RoadMap, rng: np.random.Generator) -> float:
    """Scenic's Network.laneAt, us per call, on points inside the map's extent."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        from scenic.core.vectors import Vector

        from scenegrep.readers.opendrive import parse_network

        network = parse_network(path)
    x0, y0, x1, y1 = road_map.bounds()
    points = [Vector(a, b) for a, b in zip(rng.uniform(x0, x1, 2000), rng.uniform(y0, y1, 2000))]
    return median_seconds(lambda: [network.laneAt(p) for p in points], 3) / len(points)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=10_000)
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    print(f"{'map':44s} {'query':24s} {'batch us/point':>15s} {'single call us':>15s}")
    for path in MAPS:
        road_map = readers.read_map(path)
        x0, y0, x1, y1 = road_map.bounds()
        x, y = rng.uniform(x0, x1, args.points), rng.uniform(y0, y1, args.points)
        for name, (batch, single) in per_point_us(road_map, x, y, args.repeat).items():
            print(f"{path.name[:44]:44s} {name:24s} {batch * 1e6:15.2f} {single * 1e6:15.1f}")
    scenic = scenic_lane_at_us(MAPS[0], readers.read_map(MAPS[0]), rng)
    print(f"{MAPS[0].name:44s} {'Scenic Network.laneAt':24s} {'':>15s} {scenic * 1e6:15.1f}")


if __name__ == "__main__":
    main()
