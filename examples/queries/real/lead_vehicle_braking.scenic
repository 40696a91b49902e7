# Finds: a vehicle 2-40 m ahead of the ego in its lane braking (the labeller's Brake label) while the ego follows its lane behind it (a "lead vehicle braking" request)
# Run: scenario window=1s unknown_layers=permissive all=true
# "Ahead in its lane", at every frame of the window: 2-40 m ahead along the ego's heading, at most
# 2 m to either side of its centre line (half a 3.5 m lane and a margin) and heading the same way
# (within 30 deg). Brake is the labeller's label: a deceleration of about 1 m/s2 or more
# (smoothed over 1 s) while moving; FollowLane is the ego moving along its lane. The window is
# short: braking rarely lasts 3 s.
# Every object is 'in everywhere' with a free heading and region: Scenic's defaults put a
# vehicle on the road, facing along its lane, box inside the road; parked and turning
# vehicles are not.
# Scenic's Vehicle includes bicycles (a Bicycle is a Vehicle); say Car, Truck, Bus... to leave them out.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior FollowLaneBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
lead = new Vehicle in everywhere, with behavior BrakeBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require always -40 < (distance past lead of ego) < -2
require always (distance to lead) ** 2 - (distance past lead of ego) ** 2 < 2 ** 2
require always abs(relative heading of lead from ego) < 30 deg
