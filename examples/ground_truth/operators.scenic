# Operators in requirements and positions: front of, offset by on an oriented point, visible from,
# distance past, apparent heading, relative position, can see, intersects, distance to a region, lanes.
# violate: c lateral 0.05
# violate: q heading 0.05
# violate: c forward 12
model scenic.domains.driving.model
ego = new Car on road, with visibleDistance 40
c = new Car ahead of ego by Range(3, 8)
p = new Pedestrian at ((front of c) offset by (Range(-1, 1), Range(1, 3))), facing Range(0, 360) deg,
    with regionContainedIn None
q = new Pedestrian visible from c, facing toward ego, with regionContainedIn None
require (distance past c of ego) < 0
require abs(apparent heading of c from ego) < 0.5
require (relative position of c from ego).y > -100
require ego can see c
require not (p intersects c)
require (distance to intersection) > 2
require c in ego.lane
