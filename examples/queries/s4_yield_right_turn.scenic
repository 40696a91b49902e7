# Seed 000, 5.1 accuracy scenario 4 (Appendix 0.B.3), as a query: the ego approaches a junction
# following its lane; another car heading in a different traffic direction (70 to 180 degrees
# away) follows its lane. Once the ego sees the other car within 30 m (20 m in the appendix;
# Town01's junctions are wide) it follows the lane more slowly until it no longer sees the car,
# stands for 2 s, turns right along a trajectory and follows the lane it ends in. Near the
# junction (11 m) the ego stops following its lane at once, as in the simulation program.
# Simulated by examples/scenarios/s4_yield_right_turn.scenic (Town01).
model scenic.simulators.newtonian.driving_model

behavior StationaryBehavior():
    while True:
        take SetThrottleAction(0), SetBrakeAction(1)

behavior EgoBehavior():
    do FollowLaneBehavior(target_speed=6) until ((ego can see otherCar) and (distance to otherCar) <= 30
                                                 or (distance to intersection) < 11)
    do FollowLaneBehavior(target_speed=2) until (not (ego can see otherCar)) or (distance to intersection) < 11
    do StationaryBehavior() for 2 seconds
    do FollowTrajectoryBehavior(target_speed=5)
    do FollowLaneBehavior(target_speed=6)

ego = new Car with behavior EgoBehavior()
otherCar = new Car with name "otherCar", with behavior FollowLaneBehavior(target_speed=8)

require abs(relative heading of otherCar) >= 70 deg
require (distance to intersection) < 25
require (distance from otherCar to intersection) < 10
