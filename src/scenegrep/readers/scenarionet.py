"""ScenarioNet scenario pickles (nuScenes, Waymo and other datasets converted by ScenarioNet).

A scenario is a dict: ``id``, ``length``, ``metadata`` (``ts`` frame times in s,
``sdc_id`` the ego track, ``dataset``, ...), ``tracks`` (per track: ``type``,
``metadata.type`` the dataset's own class, ``state`` arrays of length ``length``:
``position`` (n, 3) m, ``heading`` yaw from +x (rad), ``velocity`` (n, 2) m/s,
``length``/``width``/``height`` m, ``valid``), and ``map_features`` (lanes with a
``polyline`` centreline and optionally a ``polygon`` or per-point ``width``, road
lines, road edges, crosswalks).

Pickles run code when loaded carelessly. This reader never calls ``pickle.load``
on a user's file: :class:`RestrictedUnpickler` resolves only numpy arrays, dtypes
and plain containers, maps ScenarioNet/MetaDrive classes to ``dict`` and refuses
every other global.

Map conventions: nuScenes lanes without a polygon are lane connectors, i.e. lanes
inside intersections; their polygon is the centreline widened by the median
half-width of the scene's other lanes (clipped to [1.5, 2.5] m). Lanes with a
per-point ``width`` (Waymo) get the polygon between their left and right widths
(at least 1 m each side); among those, a lane whose centreline crosses another's on
the same level away from their ends is an intersection lane
(:func:`scenegrep.model.lane_topology.crossing_lanes`), and so is a lane a traffic
signal controls (``dynamic_map_states``). Topology the pickle lacks (nuScenes) is derived from
geometry (:mod:`scenegrep.model.lane_topology`). ScenarioNet swaps the nuScenes
ego's length and width (1.73 x 4.08 m for a 4.08 m Renault Zoe); this reader
swaps them back.
"""

from __future__ import annotations

import io
import pickle
import warnings
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import shapely

from ..errors import UserError, at
from ..model import Area, Lane, LaneNeighbour, LabelTrace, MapSource, ObjectTable, RoadMap, StateTable, TraceSource
from ..model.geometry import heading_from_yaw
from ..model.trace import checked_frame_count
from ..model.lane_shapes import lane_polygon
from ..model.lane_topology import (
    crossing_lanes,
    derive_intersections,
    derive_roads,
    link_by_endpoints,
    neighbours_from_geometry,
)
from .common import read_bytes

FORMAT = "scenarionet"
MIN_HALF_WIDTH_M = 1.0
CONNECTOR_HALF_WIDTH_M = (1.5, 2.5)
MPH_TO_MS = 0.44704

_ALLOWED = {
    ("numpy", "ndarray"),
    ("numpy", "dtype"),
    ("numpy.core.multiarray", "_reconstruct"),
    ("numpy._core.multiarray", "_reconstruct"),
    ("numpy.core.multiarray", "scalar"),
    ("numpy._core.multiarray", "scalar"),
    ("collections", "defaultdict"),
    ("collections", "OrderedDict"),
    ("builtins", "int"),
    ("builtins", "float"),
    ("builtins", "str"),
    ("builtins", "list"),
    ("builtins", "dict"),
    ("builtins", "tuple"),
    ("builtins", "set"),
    ("builtins", "bool"),
}
_AS_DICT = ("metadrive", "scenarionet")


class RestrictedUnpickler(pickle.Unpickler):
    """Unpickles only data: numpy arrays and plain containers (see the module docstring)."""

    def find_class(self, module: str, name: str) -> Any:
        if module.split(".")[0] in _AS_DICT:
            return dict
        if (module, name) not in _ALLOWED:
            raise pickle.UnpicklingError(f"refusing to unpickle global {module}.{name}")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            return super().find_class(module, name)


def load_scenario(path: str | Path) -> dict[str, Any]:
    """The scenario dict of a ScenarioNet pickle, loaded with :class:`RestrictedUnpickler`."""
    data = read_bytes(path)
    try:
        scenario = RestrictedUnpickler(io.BytesIO(data)).load()
    except (pickle.UnpicklingError, EOFError, ValueError, TypeError, AttributeError, IndexError, KeyError) as exc:
        raise UserError(
            f"not a valid ScenarioNet pickle (truncated or corrupt?): {exc or type(exc).__name__}", at(path)
        ) from None
    if not isinstance(scenario, dict) or not {"tracks", "metadata", "map_features"} <= scenario.keys():
        raise UserError("not a ScenarioNet scenario (expected a dict with tracks, metadata and map_features)", at(path))
    return scenario


def _column(state: dict[str, Any], key: str, n: int, path: Path, track: str) -> np.ndarray:
    if key not in state:
        raise UserError(f"track {track}: missing state array {key!r}", at(path))
    value = np.asarray(state[key], dtype=np.float64)
    if value.shape[0] != n:
        raise UserError(f"track {track}: state array {key!r} has {value.shape[0]} rows, expected {n}", at(path))
    return value.reshape(n, -1)


def _states(scenario: dict[str, Any], n: int, path: Path) -> tuple[list[str], list[str], dict[str, np.ndarray]]:
    ids, categories = [], []
    parts: dict[str, list[np.ndarray]] = {
        k: [] for k in ("frame", "object", "x", "y", "z", "heading", "length", "width", "height", "vx", "vy")
    }
    for row, (track_id, track) in enumerate(scenario["tracks"].items()):
        state = track.get("state", {})
        valid = _column(state, "valid", n, path, track_id)[:, 0] > 0
        pos = _column(state, "position", n, path, track_id)[valid]
        vel = _column(state, "velocity", n, path, track_id)[valid]
        ids.append(str(track_id))
        categories.append(str(track.get("metadata", {}).get("type") or track.get("type", "unknown")))
        frames = np.flatnonzero(valid)
        columns = {
            "frame": frames,
            "object": np.full(len(frames), row),
            "x": pos[:, 0],
            "y": pos[:, 1],
            "z": pos[:, 2] if pos.shape[1] > 2 else np.full(len(frames), np.nan),
            "heading": heading_from_yaw(_column(state, "heading", n, path, track_id)[valid, 0]),
            "vx": vel[:, 0],
            "vy": vel[:, 1],
        }
        for size in ("length", "width", "height"):
            columns[size] = _column(state, size, n, path, track_id)[valid, 0]
        for key, value in columns.items():
            parts[key].append(value)
    return ids, categories, {k: np.concatenate(v) if v else np.zeros(0) for k, v in parts.items()}


def _fix_nuscenes_ego(columns: dict[str, np.ndarray], ego_row: int | None, dataset: str) -> None:
    if dataset != "nuscenes" or ego_row is None:
        return
    ego = columns["object"] == ego_row
    swapped = ego & (columns["width"] > columns["length"])
    columns["length"][swapped], columns["width"][swapped] = columns["width"][swapped], columns["length"][swapped].copy()


def read_trace(path: str | Path) -> LabelTrace:
    """Read the trace of a ScenarioNet scenario pickle."""
    path = Path(path)
    scenario = load_scenario(path)
    meta = scenario["metadata"]
    n = checked_frame_count(int(scenario.get("length") or len(meta.get("ts", ()))))
    times = np.asarray(meta.get("ts", np.arange(n) * float(meta.get("sample_rate", 0.1))), dtype=np.float64)[:n]
    ids, categories, columns = _states(scenario, n, path)
    ego = str(meta["sdc_id"]) if meta.get("sdc_id") is not None and str(meta["sdc_id"]) in ids else None
    dataset = str(meta.get("dataset", "unknown"))
    _fix_nuscenes_ego(columns, ids.index(ego) if ego else None, dataset)
    states = StateTable.build(**columns)
    attributes = {"dataset": dataset, "scenario_id": str(scenario.get("id", path.stem))}
    for key in ("map", "date", "source_file", "version"):
        if isinstance(meta.get(key), (str, int, float)):
            attributes[key] = meta[key]
    return LabelTrace.build(
        attributes["scenario_id"],
        np.arange(n),
        times - times[0] if n else times,
        ObjectTable.build(ids, categories),
        states,
        ego=ego,
        attributes=attributes,
        source=TraceSource(str(path), FORMAT),
        map_source=MapSource(str(path), FORMAT),
    )


# ---------------------------------------------------------------------- map
def _xy(points: Any) -> np.ndarray:
    """The (n, 2) x, y of a map feature's points; ValueError if they are not n points."""
    try:
        return np.asarray(points, dtype=np.float64).reshape(len(points), -1)[:, :2]
    except (ValueError, TypeError):
        raise ValueError("a map feature's polyline or polygon is not a list of [x, y] or [x, y, z] points") from None


def _is_lane(feature: dict[str, Any]) -> bool:
    return str(feature.get("type", "")).startswith("LANE") and "polyline" in feature and len(feature["polyline"]) >= 2


def _connector_half_width(features: dict[str, Any]) -> float:
    widths = [
        shapely.Polygon(_xy(f["polygon"])).area / shapely.LineString(_xy(f["polyline"])).length / 2
        for f in features.values()
        if _is_lane(f) and "polygon" in f and len(f["polygon"]) >= 3
    ]
    widths = [w for w in widths if np.isfinite(w)]
    low, high = CONNECTOR_HALF_WIDTH_M
    return float(np.clip(np.median(widths), low, high)) if widths else low


def _ids(values: Any) -> tuple[str, ...]:
    return tuple(str(v) for v in (values or ()))


def _neighbour(entries: Any) -> LaneNeighbour | None:
    entries = list(entries or ())
    if not entries:
        return None
    first = entries[0]
    return LaneNeighbour(str(first["feature_id"] if isinstance(first, dict) else first), True)


def _lane(lane_id: str, feature: dict[str, Any], connector_half_width: float) -> Lane:
    centre = _xy(feature["polyline"])
    speed = feature.get("speed_limit_mph")
    common = dict(
        successors=_ids(feature.get("exit_lanes")),
        predecessors=_ids(feature.get("entry_lanes")),
        left=_neighbour(feature.get("left_neighbor")),
        right=_neighbour(feature.get("right_neighbor")),
        kind="bike" if "BIKE" in str(feature["type"]) else "vehicle",
        speed_limit=float(speed) * MPH_TO_MS if speed else None,
    )
    if "polygon" in feature and len(feature["polygon"]) >= 3:
        return Lane(lane_id, shapely.make_valid(shapely.Polygon(_xy(feature["polygon"]))), centre, **common)
    if "width" in feature:
        width = np.maximum(np.asarray(feature["width"], dtype=np.float64).reshape(len(centre), -1), MIN_HALF_WIDTH_M)
        return Lane(lane_id, lane_polygon(centre, width[:, 0], width[:, -1]), centre, **common)
    return Lane(
        lane_id,
        lane_polygon(centre, connector_half_width, connector_half_width),
        centre,
        is_intersection=True,
        **common,
    )


def read_map(path: str | Path, key: str | None = None) -> RoadMap:
    """Read the road map of a ScenarioNet scenario pickle (``key`` is unused: one map per file)."""
    path = Path(path)
    scenario = load_scenario(path)
    features: dict[str, Any] = scenario["map_features"]
    half = _connector_half_width(features)
    lane_features = {str(k): f for k, f in features.items() if _is_lane(f)}
    lanes = [_lane(k, f, half) for k, f in lane_features.items()]
    widened = [i for i, f in enumerate(lane_features.values()) if "polygon" not in f and "width" in f]
    crossing = crossing_lanes(
        [np.asarray(list(lane_features.values())[i]["polyline"], dtype=np.float64) for i in widened]
    )
    signalled = {str(signal.get("lane")) for signal in scenario.get("dynamic_map_states", {}).values()}
    for i, flag in zip(widened, crossing):
        lanes[i] = replace(lanes[i], is_intersection=bool(flag) or lanes[i].id in signalled)
    if not any(lane.successors or lane.predecessors for lane in lanes):
        lanes = link_by_endpoints(lanes)
    lanes = neighbours_from_geometry(lanes)
    crosswalks = tuple(
        Area(str(k), shapely.make_valid(shapely.Polygon(_xy(f["polygon"]))))
        for k, f in features.items()
        if f.get("type") == "CROSSWALK" and len(f.get("polygon", ())) >= 3
    )
    curbs = tuple(
        _xy(f["polyline"])
        for k, f in features.items()
        if (str(f.get("type", "")).startswith("ROAD_EDGE") or str(k).startswith("boundary_"))
        and len(f.get("polyline", ())) >= 2
    )
    name = str(scenario["metadata"].get("map") or scenario.get("id", path.stem))
    return RoadMap(
        name,
        tuple(lanes),
        derive_roads(lanes),
        derive_intersections(lanes),
        crosswalks,
        (),
        curbs,
        source=str(path),
        unknown_layers=_unknown_layers(scenario, bool(crosswalks)),
    )


CROSSWALK_DATASETS = frozenset({"waymo"})
"""Source datasets whose ScenarioNet conversion writes their crosswalks (nuScenes' does not)."""


def _unknown_layers(scenario: dict[str, Any], has_crosswalks: bool) -> frozenset[str]:
    """Sidewalks and shoulders are not in the format; crosswalks are published when the file holds
    some or its source dataset's conversion writes them (see :data:`CROSSWALK_DATASETS`)."""
    dataset = str(scenario["metadata"].get("dataset", "")).lower()
    known_crossings = has_crosswalks or dataset in CROSSWALK_DATASETS
    return frozenset({"sidewalk", "shoulder"} | (set() if known_crossings else {"crossing"}))
