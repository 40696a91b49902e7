# Seed 000, Fig. 1: the ego follows its lane and, once the other car (stationary, on the ego's
# lane ahead) is within a distance drawn from Range(1, 15) m (re-drawn at every step), changes
# to the lane on its left and follows that lane.
# Map: Town06 (examples/sample/Town06.xodr): multi-lane roads; the lane on the left must run
# the same way as the ego's.
# Expected primitive behaviours: ego FollowLane -> LaneChange -> FollowLane; otherCar Stationary.
model scenic.simulators.newtonian.driving_model

behavior EgoBehavior():
    try:
        do FollowLaneBehavior(target_speed=10)
    interrupt when (distance to otherCar) < Range(1, 15):
        do LaneChangeBehavior(laneSectionToSwitch=self.laneSection._laneToLeft, target_speed=10)
        do FollowLaneBehavior(target_speed=10)

def hasSameDirectionLeftLane(car):
    section = car._laneSection
    if section is None or section._laneToLeft is None:
        return False
    return section._laneToLeft.isForward == section.isForward

ego = new Car with behavior EgoBehavior()
otherCar = new Car following roadDirection from ego for Range(10, 30), with name "otherCar"

require otherCar in ego.lane
require hasSameDirectionLeftLane(ego)
require (distance to intersection) > 60
