# Seed 000, 5.1 accuracy scenario 3 (Appendix 0.B.3): a car follows a lane and passes a
# pedestrian walking along the ego's lane. The ego follows its lane until the pedestrian is
# within 1 to 15 m, then follows the lane at a lower target speed until it has passed them.
# The pedestrian walks near the lane's right edge, so the car passes beside them.
# Map: Town01 (examples/sample/Town01.xodr).
# Note: Scenic 3.1.1's RegulatedControlAction never brakes (its brake is always 0), so in the
# Newtonian simulator a lower target speed makes FollowLaneBehavior coast, not brake.
# Expected primitive behaviours: ego FollowLane throughout; pedestrian WalkAlongLane.
model scenic.simulators.newtonian.driving_model

behavior WalkAlongLaneBehavior(speed=1.2):
    while True:
        take SetWalkingDirectionAction(self.heading), SetWalkingSpeedAction(speed)

behavior EgoBehavior():
    try:
        do FollowLaneBehavior(target_speed=8)
    interrupt when (distance to pedestrian) < Range(1, 15):
        do FollowLaneBehavior(target_speed=3) until ((distance to pedestrian) > 5
                                                     and not (ego can see pedestrian))

egoLane = Uniform(*network.lanes)
ego = new Car on egoLane.centerline, with behavior EgoBehavior()
spot = new OrientedPoint following roadDirection from ego for Range(25, 40)
pedestrian = new Pedestrian at (Range(1.3, 1.5) @ 0) relative to spot, facing roadDirection,
    with name "pedestrian", with regionContainedIn None, with behavior WalkAlongLaneBehavior()

require pedestrian in ego.lane
require (distance to intersection) > 70
