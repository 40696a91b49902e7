# Finds: a moving vehicle passing the ego in the opposite direction (heading 150-210 deg from the ego's) within 20 m to its side: ahead of the ego at the window's start, level with or behind it later (RefAV "heading in relative direction: opposite")
# Run: scenario window=3s unknown_layers=permissive all=true
# "distance past X of ego" is Scenic's: how far the ego is past X along its own heading, so it is
# negative while X is ahead; the side offset is sqrt(distance^2 - (distance past)^2).
# Every object is 'in everywhere' with a free heading and region: Scenic's defaults put a
# vehicle on the road, facing along its lane, box inside the road; parked and turning
# vehicles are not.
# Scenic's Vehicle includes bicycles (a Bicycle is a Vehicle); say Car, Truck, Bus... to leave them out.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
other = new Vehicle in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require always other.speed > 1
require always abs(relative heading of other from ego) > 150 deg
require always (distance to other) ** 2 - (distance past other of ego) ** 2 < 20 ** 2
require (distance past other of ego) < 0
require eventually (distance past other of ego) >= 0
