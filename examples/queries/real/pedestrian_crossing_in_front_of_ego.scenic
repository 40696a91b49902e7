# Finds: a walking pedestrian (over 0.5 m/s) passing across the ego's path within 20 m ahead of it, from one side of the ego's heading axis to the other (RefAV "being crossed by")
# Run: scenario window=3s tolerance_heading=0.2 tolerance_position=0.5 unknown_layers=permissive all=true
# The side is the angle of the pedestrian seen from the ego, from the ego's heading, left positive:
# relative heading of (angle from ego to walker) from ego.heading. The pedestrian starts over 5 deg
# to one side and is later over 5 deg to the other, always within 20 m and 80 deg of the heading
# (so it passes the axis ahead of the ego, not behind). The ego may do anything: when it turns,
# its axis sweeps across the pedestrian too (RefAV's being_crossed_by is as geometric).
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
walker = new Pedestrian in everywhere, with behavior AnyBehavior(), with regionContainedIn everywhere
require always (walker.speed > 0.5)
require always ((distance from ego to walker) < 20)
require always (abs(relative heading of (angle from ego to walker) from ego.heading) < 80 deg)
require ((relative heading of (angle from ego to walker) from ego.heading) > 5 deg and eventually (relative heading of (angle from ego to walker) from ego.heading) < -5 deg) or ((relative heading of (angle from ego to walker) from ego.heading) < -5 deg and eventually (relative heading of (angle from ego to walker) from ego.heading) > 5 deg)
