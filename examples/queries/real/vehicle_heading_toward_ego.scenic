# Finds: a moving vehicle within 30 m whose velocity points at the ego (within 30 deg) and that closes in on it, for the whole window (RefAV "heading toward" the ego)
# Run: scenario window=1s unknown_layers=permissive all=true
# Moving: over 1 m/s. Pointing at the ego: the cosine of the angle between its velocity and the
# direction from it to the ego over cos 30 deg = 0.866 (a dot product, written out). Closing in:
# the velocity relative to the ego has a component towards the ego (the distance shrinks).
# Every object is 'in everywhere' with a free heading and region: Scenic's defaults put a
# vehicle on the road, facing along its lane, box inside the road; parked and turning
# vehicles are not.
# Scenic's Vehicle includes bicycles (a Bicycle is a Vehicle); say Car, Truck, Bus... to leave them out.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
other = new Vehicle in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require always other.speed > 1
require always (distance to other) < 30
require always (ego.position.x - other.position.x) * other.velocity.x + (ego.position.y - other.position.y) * other.velocity.y > 0.866 * (distance to other) * other.speed
require always (ego.position.x - other.position.x) * (other.velocity.x - ego.velocity.x) + (ego.position.y - other.position.y) * (other.velocity.y - ego.velocity.y) > 0
