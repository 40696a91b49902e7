# Finds: a moving vehicle crossing the line ahead of the ego (within 30 m ahead) roughly at right angles (heading 60-120 deg from the ego's), crossing from one side to the other within the window (RefAV "being crossed by" a vehicle)
# Run: scenario window=3s unknown_layers=permissive all=true
# The side of the ego's path it is on is the sign of its bearing relative to the ego's heading,
# (relative heading of (angle from ego to other) from ego): positive on the left.
# Every object is 'in everywhere' with a free heading and region: Scenic's defaults put a
# vehicle on the road, facing along its lane, box inside the road; parked and turning
# vehicles are not.
# Scenic's Vehicle includes bicycles (a Bicycle is a Vehicle); say Car, Truck, Bus... to leave them out.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
other = new Vehicle in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require always other.speed > 1
require always 60 deg < abs(relative heading of other from ego) < 120 deg
require always -30 < (distance past other of ego) < 0
require eventually (relative heading of (angle from ego to other) from ego) > 0
require eventually (relative heading of (angle from ego to other) from ego) < 0
