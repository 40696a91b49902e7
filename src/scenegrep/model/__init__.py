"""The data model every query reads: label traces and road maps. Imports no query code."""

from .behaviours import BehaviourLabels
from .images import BoxTable, ImageLayer, SampleTable
from .objects import ObjectTable
from .roadmap import Area, Lane, LaneNeighbour, RoadMap
from .states import StateTable
from .trace import LabelTrace, MapSource, TraceSource

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
]
