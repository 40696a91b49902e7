# Finds: a pedestrian walking (over 0.5 m/s) within 15 m of the ego while the ego drives (over 2 m/s)
# Run: scenario window=2s tolerance_heading=0.2 tolerance_position=0.5 unknown_layers=permissive all=true
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
walker = new Pedestrian in everywhere, with behavior AnyBehavior(), with regionContainedIn everywhere
require always (ego.speed > 2)
require always (walker.speed > 0.5)
require always ((distance from ego to walker) < 15)
