# Finds: the ego standing (under 0.5 m/s) at the window's start and faster than 3 m/s before its end (a start from standstill; nuScenes "wait at intersection" then go, RefAV "accelerating")
# Run: scenario window=5s unknown_layers=permissive
# 5 s: a car pulling away reaches 3 m/s within about 2-3 s, so the window may start while it
# still waits.
# Every object is 'in everywhere' with a free heading and region: Scenic's defaults put a
# vehicle on the road, facing along its lane, box inside the road; parked and turning
# vehicles are not.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
require ego.speed < 0.5
require eventually ego.speed > 3
