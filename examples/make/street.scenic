# The scene behind examples/stream.json (examples/make/make_examples.py): the ego follows a car
# along a lane of Town01 and comes up behind a pedestrian walking along the lane's right edge;
# a front camera on the ego sees the car ahead and the pedestrian.
# Map: Town01 (examples/sample/Town01.xodr).
model scenic.simulators.newtonian.driving_model

behavior WalkAlongLaneBehavior(speed=1.2):
    while True:
        take SetWalkingDirectionAction(self.heading), SetWalkingSpeedAction(speed)

egoLane = Uniform(*network.lanes)
ego = new Car on egoLane.centerline, with behavior FollowLaneBehavior(target_speed=6)
ahead = new OrientedPoint following roadDirection from ego for Range(12, 16)
leader = new Car at ahead, with name "leader", with behavior FollowLaneBehavior(target_speed=6)
spot = new OrientedPoint following roadDirection from ego for Range(35, 45)
pedestrian = new Pedestrian at (Range(1.3, 1.5) @ 0) relative to spot, facing roadDirection,
    with name "pedestrian", with regionContainedIn None, with behavior WalkAlongLaneBehavior()

require pedestrian in ego.lane
require leader in ego.lane
require (distance to intersection) > 70
