# Finds: a walking pedestrian (over 0.5 m/s) passing across the ego's path within 20 m ahead of it, from one side of the ego's heading axis to the other (RefAV "being crossed by")
# Run: scenario window=3s tolerance_heading=0.2 tolerance_position=0.5 unknown_layers=permissive all=true
# unknown_layers=permissive: the query reads no layer a map may lack (lanes are always published);
# the choice only lets the labeller's Cross rule label nuScenes, whose crossings are unknown.
# Window 3s: a pedestrian at 1.4 m/s crosses 10 deg of the ego's view at 8 m in about 1 s.
# Tolerances: positions and headings are free here (the ego's roadDeviation, a pedestrian's
# random heading); the requirements are exact, so the tolerances only touch sizes and overlaps.
# The side is the angle of the pedestrian seen from the ego, from the ego's heading, left positive:
# relative heading of (angle from ego to walker) from ego.heading. The pedestrian starts over 5 deg
# to one side and is later over 5 deg to the other, always within 20 m and 80 deg of the heading
# (so it passes the axis ahead of the ego, not behind). The ego may do anything: when it turns,
# its axis sweeps across the pedestrian too (RefAV's being_crossed_by is as geometric).
# The pedestrian is placed anywhere ('in everywhere': Scenic's default puts it on the walkable
# region, sidewalks and crossings, which strict would shrink to the crossings alone).
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
walker = new Pedestrian in everywhere, with behavior AnyBehavior(), with regionContainedIn everywhere
require always (walker.speed > 0.5)
require always ((distance from ego to walker) < 20)
require always (abs(relative heading of (angle from ego to walker) from ego.heading) < 80 deg)
require ((relative heading of (angle from ego to walker) from ego.heading) > 5 deg and eventually (relative heading of (angle from ego to walker) from ego.heading) < -5 deg) or ((relative heading of (angle from ego to walker) from ego.heading) < -5 deg and eventually (relative heading of (angle from ego to walker) from ego.heading) > 5 deg)
