# Seed 000, 5.1 accuracy scenario 1 (Appendix 0.B.3): a car follows a lane, then changes lanes
# to avoid a stationary car in front. A stationary car is on the ego's lane ahead, visible from
# the ego; the ego follows its lane by default and changes to the lane on its right once the
# stationary car is within 1 to 15 m.
# Map: Town06 (examples/sample/Town06.xodr): multi-lane roads; the lane on the right must run
# the same way as the ego's.
# Expected primitive behaviours: ego FollowLane -> LaneChange -> FollowLane; parkedCar Stationary.
model scenic.simulators.newtonian.driving_model

behavior EgoBehavior():
    try:
        do FollowLaneBehavior(target_speed=8)
    interrupt when (distance to parkedCar) < Range(1, 15):
        do LaneChangeBehavior(laneSectionToSwitch=self.laneSection._laneToRight, target_speed=8)
        do FollowLaneBehavior(target_speed=8)

def hasSameDirectionRightLane(car):
    section = car._laneSection
    if section is None or section._laneToRight is None:
        return False
    return section._laneToRight.isForward == section.isForward

ego = new Car with behavior EgoBehavior()
parkedCar = new Car following roadDirection from ego for Range(15, 40), with name "parkedCar"

require parkedCar in ego.lane
require ego can see parkedCar
require hasSameDirectionRightLane(ego)
require (distance to intersection) > 70
