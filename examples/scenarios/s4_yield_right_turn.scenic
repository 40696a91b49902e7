# Seed 000, 5.1 accuracy scenario 4 (Appendix 0.B.3): a car yields to another car before making
# a right turn. The ego approaches a junction following its lane; once it sees the other car
# (coming from its left, going straight across into the lane the ego turns into) within 30 m
# (the appendix says 20 m; Town01's junctions are wide), it follows the lane at a lower target
# speed until it no longer sees that car, stops for 2 s, and turns right.
# The ego never follows its lane within 11 m of the junction: there FollowLaneBehavior would
# pick a turn of its own. Scenic 3.1.1's RegulatedControlAction never brakes, so the slower
# FollowLaneBehavior coasts; StationaryBehavior brakes fully.
# Map: Town01 (examples/sample/Town01.xodr; the ego comes from the stem of a T-junction).
# Expected primitive behaviours: ego FollowLane -> Stationary -> FollowTrajectory -> Turn
# (inside the junction) -> FollowTrajectory (-> FollowLane once the trajectory ends);
# otherCar FollowLane.
model scenic.simulators.newtonian.driving_model

behavior StationaryBehavior():
    while True:
        take SetThrottleAction(0), SetBrakeAction(1)

behavior EgoBehavior(trajectory):
    do FollowLaneBehavior(target_speed=6) until ((ego can see otherCar) and (distance to otherCar) <= 30
                                                 or (distance to junction) < 11)
    do FollowLaneBehavior(target_speed=2) until (not (ego can see otherCar)) or (distance to junction) < 11
    do StationaryBehavior() for 2 seconds
    do FollowTrajectoryBehavior(trajectory=trajectory, target_speed=5)
    do FollowLaneBehavior(target_speed=6)

def rightTurnsWithCrossingTraffic():
    """(right turn, straight maneuver into the same lane) pairs of every junction of the map."""
    pairs = []
    for junction in network.intersections:
        for turn in junction.maneuvers:
            if turn.type is ManeuverType.RIGHT_TURN:
                for other in junction.maneuvers:
                    if other.type is ManeuverType.STRAIGHT and other.endLane is turn.endLane:
                        pairs.append((turn, other))
    return pairs

choice = Uniform(*rightTurnsWithCrossingTraffic())
rightTurn, crossing = choice[0], choice[1]
junction = rightTurn.intersection
egoLane = rightTurn.startLane

ego = new Car on egoLane.centerline,
    with behavior EgoBehavior([egoLane, rightTurn.connectingLane, rightTurn.endLane])
otherCar = new Car on crossing.startLane.centerline, with name "otherCar",
    with behavior FollowLaneBehavior(target_speed=8)

require 15 < (distance from ego to junction) < 25
require (distance from otherCar to junction) < 10
