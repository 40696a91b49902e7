# Seed 000, Fig. 1, as a query: the other car is uniformly placed on the part of the ego's lane
# that the ego can see; the ego follows its lane and, once the other car is within a distance
# drawn from Range(1, 15) m at each step, changes lanes and follows the new lane. The other car
# has no behaviour, so it is Stationary.
# The simulation version (examples/scenarios/fig1_lane_change.scenic) adds set-up only a
# simulator needs (a left lane running the same way); the scene it samples is in this
# program's support.
model scenic.simulators.newtonian.driving_model

behavior EgoBehavior():
    try:
        do FollowLaneBehavior(target_speed=10)
    interrupt when (distance to otherCar) < Range(1, 15):
        do LaneChangeBehavior(laneSectionToSwitch=self.laneSection._laneToLeft, target_speed=10)
        do FollowLaneBehavior(target_speed=10)

ego = new Car with behavior EgoBehavior()
otherCar = new Car on visible ego.lane, with name "otherCar"
