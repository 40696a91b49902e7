# Background traffic, matching none of seed 000's accuracy scenarios: three cars follow their
# lanes on a multi-lane road at the same target speed (a leader ahead of the ego on its lane,
# a neighbour beside the ego on the lane to its left, running the same way), far from
# junctions. Nobody stops, changes lanes or turns.
# Map: Town06 (examples/sample/Town06.xodr).
# Expected primitive behaviours: FollowLane for every car.
model scenic.simulators.newtonian.driving_model

def isLeftNeighbour(car, other):
    section, beside = car._laneSection, other._laneSection
    if section is None or beside is None:
        return False
    return beside is section._laneToLeft and beside.isForward == section.isForward

ego = new Car with behavior FollowLaneBehavior(target_speed=9)
leader = new Car following roadDirection from ego for Range(15, 35), with name "leader",
    with behavior FollowLaneBehavior(target_speed=9)
neighbour = new Car left of ego by Range(1, 2), with name "neighbour",
    with behavior FollowLaneBehavior(target_speed=9)

require leader in ego.lane
require isLeftNeighbour(ego, neighbour)
require (distance to intersection) > 150
