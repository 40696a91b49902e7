# Background traffic, matching none of seed 000's accuracy scenarios: a car follows its lane
# past a pedestrian who stands still on the sidewalk beside the road ahead.
# Map: Town01 (examples/sample/Town01.xodr; it has sidewalks).
# Expected primitive behaviours: ego FollowLane; pedestrian Stationary (no behaviour).
model scenic.simulators.newtonian.driving_model

egoLane = Uniform(*network.lanes)
ego = new Car on egoLane.centerline, with behavior FollowLaneBehavior(target_speed=8)
spot = new OrientedPoint following roadDirection from ego for Range(20, 40)
pedestrian = new Pedestrian at (Range(3, 7) @ 0) relative to spot, with name "pedestrian"

require pedestrian in sidewalk
require ego can see pedestrian
require (distance to intersection) > 70
