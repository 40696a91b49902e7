# Finds: a vehicle within 30 m whose heading points at the ego, within 30 deg, for the whole window, moving or not (RefAV "facing toward" the ego)
# Run: scenario window=1s unknown_layers=permissive all=true
# Scenic's apparent heading of X from the ego is X's heading minus the bearing of X from the ego:
# 0 when X faces away, +-180 deg when it faces the ego.
# Every object is 'in everywhere' with a free heading and region: Scenic's defaults put a
# vehicle on the road, facing along its lane, box inside the road; parked and turning
# vehicles are not.
# Scenic's Vehicle includes bicycles (a Bicycle is a Vehicle); say Car, Truck, Bus... to leave them out.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
other = new Vehicle in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require always abs(apparent heading of other from ego) > 150 deg
require always (distance to other) < 30
