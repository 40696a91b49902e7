# Seed 000, 5.1 accuracy scenario 2 (Appendix 0.B.3): a car is initially stationary, waiting
# for an unprotected left turn; it waits for another car on the opposing lane to pass by and
# then turns left. The ego stands at the end of its lane until it no longer sees the oncoming
# car within 40 m (the appendix says 20 m, but the stop lines of Town01's junctions are 23 m
# apart), then follows the left-turn trajectory through the junction.
# Map: Town01 (examples/sample/Town01.xodr; its junctions are T-junctions).
# Expected primitive behaviours: ego Stationary -> FollowTrajectory -> Turn (inside the
# junction) -> FollowTrajectory (-> FollowLane once the trajectory ends); otherCar FollowLane
# (straight through the junction).
model scenic.simulators.newtonian.driving_model

behavior StationaryBehavior():
    while True:
        take SetThrottleAction(0), SetBrakeAction(1)

behavior EgoBehavior(trajectory):
    do StationaryBehavior() until not ((ego can see otherCar) and (distance to otherCar) <= 40)
    do FollowTrajectoryBehavior(trajectory=trajectory, target_speed=6)
    do FollowLaneBehavior(target_speed=8)

def leftTurnsWithOncomingTraffic():
    """(left turn, oncoming straight maneuver) pairs of every junction of the map."""
    pairs = []
    for junction in network.intersections:
        for turn in junction.maneuvers:
            if turn.type is ManeuverType.LEFT_TURN:
                for other in junction.maneuvers:
                    if other.type is ManeuverType.STRAIGHT and other.endLane.road is turn.startLane.road:
                        pairs.append((turn, other))
    return pairs

choice = Uniform(*leftTurnsWithOncomingTraffic())
leftTurn, oncoming = choice[0], choice[1]
junction = leftTurn.intersection
egoLane = leftTurn.startLane

ego = new Car on egoLane.centerline,
    with behavior EgoBehavior([egoLane, leftTurn.connectingLane, leftTurn.endLane])
otherCar = new Car on oncoming.startLane.centerline, with name "otherCar",
    with behavior FollowLaneBehavior(target_speed=8)

require (distance from ego to junction) < 6
require (distance from otherCar to junction) < 12
require ego can see otherCar
require (distance to otherCar) <= 40
