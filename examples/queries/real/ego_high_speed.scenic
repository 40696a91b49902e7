# Finds: the ego driving above 50 km/h (13.9 m/s) for the whole window (nuScenes "high speed")
# Run: scenario window=3s unknown_layers=permissive
# The speed is the recording's own (estimated from positions where a dataset records none) and
# is compared exactly: no speed tolerance applies to a requirement.
# Every object is 'in everywhere' with a free heading and region: Scenic's defaults put a
# vehicle on the road, facing along its lane, box inside the road; parked and turning
# vehicles are not.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require always ego.speed > 13.9
