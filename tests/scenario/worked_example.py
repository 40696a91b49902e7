"""Seed 000 §4.6: the Fig. 1 program and the label trace of Table 2 (m = 5), on a small map.

Table 2 gives positions as (lateral, ?, distance along the road); here car1 stands at the
origin and car2 drives north towards it along Lane1 (x from -1.75 to 1.75 m), moving left
(towards Lane2, x from -5.25 to -1.75 m) while it changes lanes: car2's map position at step
t is (-lateral, -along). Both lanes run north (heading 0). The lane columns of Table 2 are
not needed: the program reads lanes only through the map.
"""

import numpy as np
import shapely

from scenegrep.model import Area, BehaviourLabels, Lane, LabelTrace, ObjectTable, RoadMap, StateTable

CAR2_LATERAL = [0.0, 0.0, 0.3, 0.6, 1.0]
CAR2_ALONG = [20.0, 14.0, 10.0, 6.0, 1.0]
CAR2_LABELS = ["FollowLane", "FollowLane", "LaneChange", "LaneChange", "FollowLane"]


def worked_map() -> RoadMap:
    lane1 = Lane("Lane1", shapely.box(-1.75, -60, 1.75, 60), np.array([[0.0, -60], [0.0, 60]]))
    lane2 = Lane("Lane2", shapely.box(-5.25, -60, -1.75, 60), np.array([[-3.5, -60], [-3.5, 60]]))
    road = Area("road", shapely.box(-5.25, -60, 1.75, 60), ("Lane1", "Lane2"))
    return RoadMap("worked-example", (lane1, lane2), roads=(road,))


def worked_trace(car2_labels: list[str] = CAR2_LABELS, car1_label: str = "Stationary") -> LabelTrace:
    """Table 2 as a label trace (one label per object per step)."""
    n = len(car2_labels)
    frame = np.repeat(np.arange(n), 2)
    obj = np.tile([0, 1], n)
    x = np.ravel([[0.0, -CAR2_LATERAL[t]] for t in range(n)])
    y = np.ravel([[0.0, -CAR2_ALONG[t]] for t in range(n)])
    states = StateTable.build(
        frame=frame,
        object=obj,
        x=x,
        y=y,
        heading=np.zeros(2 * n),
        length=np.full(2 * n, 4.5),
        width=np.full(2 * n, 2.0),
    )
    labels = BehaviourLabels.from_sets([{car1_label} if o == 0 else {car2_labels[f]} for f, o in zip(frame, obj)])
    objects = ObjectTable.build(["car1", "car2"], ["car", "car"])
    return LabelTrace.build("table2", np.arange(n), np.arange(n) * 0.5, objects, states, behaviours=labels)
