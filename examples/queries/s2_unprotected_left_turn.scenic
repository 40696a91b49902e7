# Seed 000, 5.1 accuracy scenario 2 (Appendix 0.B.3), as a query: another car, visible to the
# ego, comes from a different traffic direction (facing 70 to 180 degrees away from the ego's
# heading) and follows its lane. The ego stays stationary until it no longer sees the other car
# within 40 m (20 m in the appendix; Town01's stop lines are 23 m apart), then turns left along
# a trajectory and follows the lane it ends in.
# Simulated by examples/scenarios/s2_unprotected_left_turn.scenic (Town01).
model scenic.simulators.newtonian.driving_model

behavior StationaryBehavior():
    while True:
        take SetThrottleAction(0), SetBrakeAction(1)

behavior EgoBehavior():
    do StationaryBehavior() until not ((ego can see otherCar) and (distance to otherCar) <= 40)
    do FollowTrajectoryBehavior(target_speed=6)
    do FollowLaneBehavior(target_speed=8)

ego = new Car with behavior EgoBehavior()
otherCar = new Car visible, with name "otherCar", with behavior FollowLaneBehavior(target_speed=8)

require abs(relative heading of otherCar) >= 70 deg
