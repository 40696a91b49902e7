# Seed 000, 5.1 accuracy scenario 1 (Appendix 0.B.3), as a query: a stationary car is on the
# ego's lane, visible from the ego. The ego follows its lane by default and changes lanes once
# the stationary car is in front of it within 1 to 15 m.
# Simulated by examples/scenarios/s1_lane_change_stationary_car.scenic (Town06).
model scenic.simulators.newtonian.driving_model

behavior EgoBehavior():
    try:
        do FollowLaneBehavior(target_speed=8)
    interrupt when (distance to parkedCar) < Range(1, 15):
        do LaneChangeBehavior(target_speed=8)
        do FollowLaneBehavior(target_speed=8)

ego = new Car with behavior EgoBehavior()
parkedCar = new Car on visible ego.lane, with name "parkedCar"
