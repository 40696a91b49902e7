# Finds: a vehicle ahead of the ego in its lane brakes while the ego follows its lane behind it (Brake label; RefAV "braking vehicle in front of the ego")
# Run: scenario window=1s unknown_layers=permissive all=true
# "Ahead in its lane", at every frame of the window: 2-40 m ahead along the ego's heading, at most
# 2 m to either side of its centre line (half a 3.5 m lane and a margin) and heading the same way
# (within 30 deg). Brake is the labeller's label: a deceleration of about 1 m/s2 or more
# (smoothed over 1 s) while moving. The window is short: braking rarely lasts 3 s.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior FollowLaneBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
lead = new Vehicle in everywhere, with behavior BrakeBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require always -40 < (distance past lead of ego) < -2
require always (distance to lead) ** 2 - (distance past lead of ego) ** 2 < 2 ** 2
require always abs(relative heading of lead from ego) < 30 deg
