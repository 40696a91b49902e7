"""The data model every query reads: label traces and road maps. Imports no query code.

The road-map classes load on first use (they need shapely), so code that only reads
traces, such as a SpRE run over a STREM stream, does not pay for them.
"""

from typing import Any

from .behaviours import BehaviourLabels
from .images import BoxTable, ImageLayer, SampleTable
from .objects import ObjectTable
from .states import StateTable
from .trace import LabelTrace, MapSource, TraceSource, concatenate

_ROADMAP = ("Area", "Lane", "LaneNeighbour", "RoadMap")

__all__ = [
    "Area",
    "BehaviourLabels",
    "BoxTable",
    "ImageLayer",
    "LabelTrace",
    "Lane",
    "LaneNeighbour",
    "MapSource",
    "ObjectTable",
    "RoadMap",
    "SampleTable",
    "StateTable",
    "TraceSource",
    "concatenate",
]


def __getattr__(name: str) -> Any:
    if name in _ROADMAP:
        from . import roadmap

        return getattr(roadmap, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
