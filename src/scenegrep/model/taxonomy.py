"""Object classes: each dataset's own class names and the canonical kinds they map to.

A label trace keeps every object's class exactly as the dataset spells it
(``REGULAR_VEHICLE``, ``vehicle.car``, ``car``). Queries that reason about what an
object *is* (a Scenic ``Car`` must correspond to a car-like object) use its
canonical kind, one of :data:`KINDS`, computed here from the class name.
"""

from __future__ import annotations

import re
from functools import lru_cache

KINDS = ("car", "truck", "bus", "trailer", "motorcycle", "bicycle", "pedestrian", "animal", "static", "other")
"""Canonical kinds, in the order used for display."""

VEHICLE_KINDS = frozenset({"car", "truck", "bus", "trailer", "motorcycle"})
"""Kinds that drive on lanes with an engine."""

_EXACT = {
    # Argoverse 2 categories
    "regular_vehicle": "car",
    "large_vehicle": "truck",
    "box_truck": "truck",
    "truck": "truck",
    "truck_cab": "truck",
    "vehicular_trailer": "trailer",
    "bus": "bus",
    "school_bus": "bus",
    "articulated_bus": "bus",
    "railed_vehicle": "other",
    "motorcycle": "motorcycle",
    "motorcyclist": "motorcycle",
    "bicycle": "bicycle",
    "bicyclist": "bicycle",
    "wheeled_rider": "bicycle",
    "wheeled_device": "other",
    "wheelchair": "pedestrian",
    "stroller": "pedestrian",
    "pedestrian": "pedestrian",
    "official_signaler": "pedestrian",
    "dog": "animal",
    "bollard": "static",
    "construction_cone": "static",
    "construction_barrel": "static",
    "sign": "static",
    "stop_sign": "static",
    "mobile_pedestrian_crossing_sign": "static",
    "message_board_trailer": "static",
    "traffic_light_trailer": "static",
    "mobile_pedestrian_sign": "static",
    # Waymo / ScenarioNet / CommonRoad / generic names
    "vehicle": "car",
    "car": "car",
    "cyclist": "bicycle",
    "traffic_cone": "static",
    "traffic_barrier": "static",
    "parkedvehicle": "car",
    "parked_vehicle": "car",
    "priorityvehicle": "car",
    "taxi": "car",
    "van": "car",
    "ego": "car",
    "ped": "pedestrian",
    "person": "pedestrian",
    "constructionzone": "static",
    "building": "static",
    "pillar": "static",
    "median_strip": "static",
    "roadboundary": "static",
    "unknown": "other",
    "other": "other",
    # Autoware ObjectClassification labels (others are above: CAR, TRUCK, BUS, ...)
    "trailer": "trailer",
    "animal": "animal",
    "hazard": "static",
    "over_drivable": "static",
    "under_drivable": "static",
    "train": "other",
}

_PREFIXES = (
    # nuScenes dotted categories, most specific first
    ("vehicle.bus", "bus"),
    ("vehicle.truck", "truck"),
    ("vehicle.trailer", "trailer"),
    ("vehicle.construction", "truck"),
    ("vehicle.emergency", "car"),
    ("vehicle.car", "car"),
    ("vehicle.motorcycle", "motorcycle"),
    ("vehicle.bicycle", "bicycle"),
    ("vehicle", "car"),
    ("human.pedestrian", "pedestrian"),
    ("human", "pedestrian"),
    ("animal", "animal"),
    ("movable_object", "static"),
    ("static_object", "static"),
)


@lru_cache(maxsize=4096)
def kind_of(category: str) -> str:
    """Canonical kind of a dataset class name (case- and separator-insensitive)."""
    text = category.strip().lower()
    for prefix, kind in _PREFIXES:
        if text == prefix or text.startswith(prefix + "."):
            return kind
    key = re.sub(r"[\s\-]+", "_", text)
    if key in _EXACT:
        return _EXACT[key]
    return _EXACT.get(key.replace("_", ""), "other")
