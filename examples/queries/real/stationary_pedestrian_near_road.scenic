# Finds: a pedestrian standing still (under 0.2 m/s throughout the window) within 3 m of a lane (RefAV "stationary" + "near" a lane)
# Run: scenario window=2s tolerance_heading=0.2 tolerance_position=0.5 unknown_layers=permissive all=true
model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
walker = new Pedestrian in everywhere, with behavior AnyBehavior(), with regionContainedIn everywhere
require always (walker.speed < 0.2)
require always ((distance from walker to network.laneRegion) < 3)
