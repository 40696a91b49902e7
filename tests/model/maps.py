"""A small synthetic road map used by the model tests.

Three straight lanes 100 m long along y: ``n1`` (x 0..3.5, northbound), ``n2``
(x 3.5..7, northbound, right of n1) and ``s1`` (x -3.5..0, southbound); ``n1`` is
followed by ``n1b`` (y 100..200); a crossing lane ``x1`` (y 50..53.5, eastbound)
overlaps all three and is an intersection lane; a crosswalk covers y 60..63, its centreline running
east (Scenic orients it that way). The map publishes
no sidewalks or shoulders (those layers are unknown); its crosswalks and curbs are as given.
"""

import numpy as np
import shapely

from scenegrep.model import Area, Lane, RoadMap


def box(x0, y0, x1, y1):
    return shapely.box(x0, y0, x1, y1)


def synthetic_lanes() -> list[Lane]:
    return [
        Lane("n1", box(0, 0, 3.5, 100), np.array([[1.75, 0], [1.75, 100]])),
        Lane("n2", box(3.5, 0, 7, 100), np.array([[5.25, 0], [5.25, 100]])),
        Lane("s1", box(-3.5, 0, 0, 100), np.array([[-1.75, 100], [-1.75, 0]])),
        Lane("n1b", box(0, 100, 3.5, 200), np.array([[1.75, 100], [1.75, 200]])),
        Lane("x1", box(-3.5, 50, 7, 53.5), np.array([[-3.5, 51.75], [7, 51.75]]), is_intersection=True),
    ]


def synthetic_map() -> RoadMap:
    lanes = tuple(synthetic_lanes())
    return RoadMap(
        "synthetic",
        lanes,
        roads=(Area("r", box(-3.5, 0, 7, 100), ("n1", "n2", "s1")),),
        intersections=(Area("i", box(-3.5, 50, 7, 53.5), ("x1",)),),
        crosswalks=(Area("c", box(-3.5, 60, 7, 63), centreline=np.array([[-3.5, 61.5], [7, 61.5]])),),
        curbs=(np.array([[-3.5, 0], [-3.5, 100]]),),
        unknown_layers=frozenset({"sidewalk", "shoulder"}),
    )
