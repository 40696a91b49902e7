# Finds: the ego standing (below 0.5 m/s) for 2 s at or just before an intersection (nuScenes "wait at intersection")
# Run: scenario window=2s all=true unknown_layers=permissive
# At or just before: the ego's centre is within 10 m of the map's intersection region at every frame
# (a car at the stop line has its centre a few metres before it). The speed is the recording's
# (estimated from positions where a dataset records none), compared exactly.
model scenic.simulators.newtonian.driving_model

ego = new Car in everywhere, with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere, with behavior AnyBehavior()
require always (ego.speed < 0.5)
require always ((distance from ego.position to intersection) < 10)
